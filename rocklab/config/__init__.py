"""Configuration files: the schemas of ``track.toml`` and ``experiment.toml``, their one reader and writer.

The ground floor of rocklab: it imports only :mod:`rocklab._errors`, :mod:`rocklab._io`,
:mod:`rocklab.blocks` and third-party packages, and every package may import it.

- :class:`TomlDoc`: a parsed TOML file with its text; its typed reads and its one unknown-key
  rule raise one-line errors naming ``FILE, line N: 'KEY'``, the rule and the fix.
- ``track.toml``: :class:`TrackConfig` (:func:`load_track_config`, :meth:`TrackConfig.to_toml`,
  the reference page :func:`schema_markdown`).
- ``experiment.toml``: :class:`ExperimentConfig` (:func:`load_experiment_config`,
  :meth:`ExperimentConfig.to_toml`, the commented example :data:`EXAMPLE_TOML`).

Each choice list (target styles, levelling modes, table sources, fit windows, simulated laws...)
and each default (the dataclasses' fields) is defined here once.
"""

from ._experiment_toml import *  # noqa: F403
from ._experiment_toml import __all__ as _experiment_names
from ._toml import TomlDoc, dumps_toml
from ._track_toml import *  # noqa: F403
from ._track_toml import __all__ as _track_names

# each schema module's __all__ is the one list of its public names
__all__ = ["TomlDoc", "dumps_toml", *_track_names, *_experiment_names]
