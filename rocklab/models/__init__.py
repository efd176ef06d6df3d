"""Physics: single-block rocking, restitution laws, integrators, columns, spectra."""

from ._records import BUNDLED_RECORDS, UNITS_TO_M_S2, BaseMotion, bundled_record, load_base_motion
from ._restitution import RESTITUTION_LAWS, Restitution, make_restitution
from ._batch import simulate_batch
from ._result import BatchResult, RockingResult, block_energy
from ._single import simulate
from ._column_sim import STATE_NAMES, Column, ColumnResult, simulate_column, uplift_acc_m_s2
from ._column_geometry import ImpactOutcome, app_c_reduction, column_impact, full_mass_matrix, mass_points
from ._column_maps import ColumnMaps, column_overturning_maps, sine_pulse
from ._column_compare import SequenceComparison, compare_sequences, joint_sequence


__all__ = ["BaseMotion", "load_base_motion", "UNITS_TO_M_S2", "bundled_record", "BUNDLED_RECORDS",
           "simulate", "RockingResult", "block_energy", "simulate_batch", "BatchResult",
           "RESTITUTION_LAWS", "Restitution", "make_restitution",
           # columns (helper "column")
           "Column", "ColumnResult", "simulate_column", "uplift_acc_m_s2", "STATE_NAMES",
           "ImpactOutcome", "app_c_reduction", "column_impact", "full_mass_matrix", "mass_points",
           "ColumnMaps", "column_overturning_maps", "sine_pulse",
           "SequenceComparison", "compare_sequences", "joint_sequence"]
