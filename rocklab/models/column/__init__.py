"""Multi-block columns: opening and impact model, simulation, overturning maps, comparison.

Thesis §3.2-3.3 and App. B-C: the column's joints open and close, impacts with the full mass
matrix (:func:`column_impact`) or the App. C reduction; :func:`simulate_column` runs a
column under base motion; :func:`column_overturning_maps` sweeps sine pulses;
:func:`compare_to_measurement` scores a simulated opening sequence against a tracked one.
"""

from ._compare import ColumnComparison, SequenceComparison, compare_sequences, compare_to_measurement, joint_sequence
from ._geometry import ImpactOutcome, app_c_reduction, column_impact, full_mass_matrix, mass_points
from ._maps import ColumnMaps, column_overturning_maps, sine_pulse
from ._sim import STATE_NAMES, Column, ColumnResult, simulate_column, uplift_acc_m_s2

__all__ = [
    "Column",
    "ColumnResult",
    "simulate_column",
    "uplift_acc_m_s2",
    "STATE_NAMES",
    "ImpactOutcome",
    "app_c_reduction",
    "column_impact",
    "full_mass_matrix",
    "mass_points",
    "ColumnMaps",
    "column_overturning_maps",
    "sine_pulse",
    "SequenceComparison",
    "compare_sequences",
    "joint_sequence",
    "ColumnComparison",
    "compare_to_measurement",
]
