"""Experiment pipelines, Rerun logging, reports and the ``rocklab`` CLI.

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

from ._campaign import CampaignResult, find_experiments, run_campaign
from ._cli import main
from ._config import EXAMPLE_TOML, ExperimentConfig, load_experiment
from ._demo import make_demo_campaign, run_demo
from ._experiment import ExperimentResult, analyse_experiment, run_experiment
from ._rerun import read_rrd_scalars, read_rrd_summary

__all__ = ["main", "load_experiment", "ExperimentConfig", "EXAMPLE_TOML", "run_experiment",
           "analyse_experiment", "ExperimentResult", "run_campaign", "find_experiments", "CampaignResult",
           "run_demo", "make_demo_campaign", "read_rrd_summary", "read_rrd_scalars"]
