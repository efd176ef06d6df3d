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

from ._experiment_toml import (
    CONTACT_TYPES,
    EXAMPLE_TOML,
    FIT_WINDOWS,
    PRIMARY_SOURCES,
    SIMULATED_LAWS,
    SYNC_METHODS,
    TABLE_SOURCES,
    ExperimentConfig,
    SourceImu,
    SourceTable,
    SourceTrack,
    SourceVideo,
    experiment_name,
    load_experiment_config,
)
from ._toml import TomlDoc, dumps_toml
from ._track_toml import (
    BOARD_KINDS,
    CORNER_REFINEMENTS,
    DOT_COLORS,
    LEVEL_MODES,
    MARKER_STYLES,
    OBJECT_KINDS,
    PLANE_MODES,
    REGION_STYLES,
    TARGET_STYLES,
    BoardConfig,
    MotionConfig,
    ObjectConfig,
    ReferenceConfig,
    TargetsConfig,
    TrackConfig,
    VideoConfig,
    load_track_config,
    schema_markdown,
)

__all__ = [
    "TomlDoc",
    "dumps_toml",
    "TrackConfig",
    "VideoConfig",
    "TargetsConfig",
    "ReferenceConfig",
    "BoardConfig",
    "MotionConfig",
    "ObjectConfig",
    "load_track_config",
    "schema_markdown",
    "TARGET_STYLES",
    "MARKER_STYLES",
    "REGION_STYLES",
    "OBJECT_KINDS",
    "LEVEL_MODES",
    "CORNER_REFINEMENTS",
    "DOT_COLORS",
    "PLANE_MODES",
    "BOARD_KINDS",
    "ExperimentConfig",
    "SourceVideo",
    "SourceTrack",
    "SourceImu",
    "SourceTable",
    "load_experiment_config",
    "experiment_name",
    "EXAMPLE_TOML",
    "CONTACT_TYPES",
    "PRIMARY_SOURCES",
    "TABLE_SOURCES",
    "SYNC_METHODS",
    "FIT_WINDOWS",
    "SIMULATED_LAWS",
]
