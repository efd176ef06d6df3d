"""One experiment, end to end: its config, the stages, the outputs and the Rerun review.

- ``experiment.toml`` (:func:`load_experiment`; the schema is :class:`rocklab.config.ExperimentConfig`);
- the stages: tracking, IMU, sync, the assumption audit, the restitution fit, the simulations
  (:func:`analyse_experiment`, :class:`ExperimentResult`), and a column experiment's own stage;
- the outputs, written atomically into a staged folder (:func:`run_experiment`):
  ``series.csv``, ``summary.md``, figures, ``report.json``;
- the Rerun recordings of an experiment and of a 3D record, and their readers
  (:func:`read_rrd_summary`, :func:`read_rrd_scalars`).
"""

from ._config import load_experiment
from ._experiment import ExperimentResult, analyse_experiment, run_experiment
from ._figures import campaign_figures, experiment_figures
from ._plots_column import plot_column_maps
from ._rerun import read_rrd_scalars, read_rrd_summary
from ._rerun3d import write_track3d_rrd
from ._column_run import base_from_table


__all__ = [
    "load_experiment",
    "run_experiment",
    "analyse_experiment",
    "ExperimentResult",
    "read_rrd_summary",
    "read_rrd_scalars",
    "experiment_figures",
    "campaign_figures",
    "plot_column_maps",
    "write_track3d_rrd",
    "base_from_table",
]
