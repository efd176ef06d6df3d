"""Experiment pipelines, Rerun logging, reports and the ``rocklab`` CLI.

Sub-packages: :mod:`.experiment` (one experiment), :mod:`.campaign` (many, and the demo),
:mod:`.spectra` (record studies), :mod:`.cli` (the command line).

The only subpackage that imports rerun or matplotlib (always inside functions, so
importing it stays light).

- :func:`load_experiment` reads an ``experiment.toml`` (:class:`ExperimentConfig`);
- :func:`run_experiment` runs one experiment into a folder (``rocklab run``);
  :func:`analyse_experiment` does the same in memory (:class:`ExperimentResult`);
- :func:`run_campaign` runs every experiment under a folder, then the campaign fits
  (``rocklab campaign``, :class:`CampaignResult`);
- :func:`run_demo` / :func:`make_demo_campaign`: the synthetic demo campaign (``rocklab demo``);
- :func:`read_rrd_summary` / :func:`read_rrd_scalars` read a written ``.rrd`` back with Rerun's reader.
"""

from .campaign import CampaignResult, find_experiments, make_demo_campaign, run_campaign, run_demo
from .cli import main
from .experiment import (
    EXAMPLE_TOML,
    ExperimentConfig,
    ExperimentResult,
    analyse_experiment,
    load_experiment,
    read_rrd_scalars,
    read_rrd_summary,
    run_experiment,
)

__all__ = [
    "main",
    "load_experiment",
    "ExperimentConfig",
    "EXAMPLE_TOML",
    "run_experiment",
    "analyse_experiment",
    "ExperimentResult",
    "run_campaign",
    "find_experiments",
    "CampaignResult",
    "run_demo",
    "make_demo_campaign",
    "read_rrd_summary",
    "read_rrd_scalars",
]
