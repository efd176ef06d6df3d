"""Experiment pipelines, Rerun logging, reports and the ``rocklab`` CLI.

Sub-packages: :mod:`.experiment` (one experiment), :mod:`.campaign` (many, and the demo),
:mod:`.spectra` (record studies), :mod:`.cli` (the command line).

The only subpackage that imports rerun or matplotlib (always inside functions, so
importing it stays light).

- :func:`load_experiment` reads an ``experiment.toml`` (:class:`rocklab.config.ExperimentConfig`);
- :func:`run_experiment` runs one experiment into a folder (``rocklab run``);
  :func:`analyse_experiment` does the same in memory (:class:`ExperimentResult`);
- :func:`run_campaign` runs every experiment under a folder, then the campaign fits
  (``rocklab campaign``, :class:`CampaignResult`);
- :func:`run_demo` / :func:`make_demo_campaign`: the synthetic demo campaign (``rocklab demo``);
- :func:`read_rrd_summary` / :func:`read_rrd_scalars` read a written ``.rrd`` back with Rerun's reader;
- :func:`oas_many` / :func:`oas_table` and the record-study figures (:mod:`.spectra`).

Every public name of these sub-packages is also here: each sub-package's ``__all__`` is the one list.
"""

from . import campaign, cli, experiment, spectra
from .campaign import *  # noqa: F403
from .cli import *  # noqa: F403
from .experiment import *  # noqa: F403
from .spectra import *  # noqa: F403

# each sub-package's __all__ is the one list of its public names (a name added there is exported here too)
__all__: list[str] = []
__all__ += experiment.__all__
__all__ += campaign.__all__
__all__ += spectra.__all__
__all__ += cli.__all__
