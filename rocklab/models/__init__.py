"""Physics: single-block rocking, restitution laws, integrators, columns, spectra."""

from ._records import BUNDLED_RECORDS, UNITS_TO_M_S2, BaseMotion, bundled_record, load_base_motion
from ._restitution import RESTITUTION_LAWS, Restitution, make_restitution
from ._batch import free_rocking_overturns, simulate_batch
from ._result import BatchResult, RockingResult, block_energy
from ._single import simulate
from ._pulses import (F_SINE, PULSE_KINDS, PulseParameters, lobe_impulses, pulse_fullness, pulse_motion,
                      pulse_parameters, pulse_shape)
from ._oas import (OASResult, OverturningCurve, critical_impulse, fit_inclined_line,
                   normalised_critical_impulse, overturning_curve, overturning_spectrum, simplified_oas)
from ._oas_band import BAND_ENSEMBLE, TIBand, t_I_band
from ._design import DesignCheck, design_check, required_width, required_width_slender
from ._equivalent import (FundamentalParameters, Mechanism, block_parameters, equivalence_errors,
                          frame_parameters, free_rocking_period_eq24, linear_sine_pulse_response,
                          overturning_time_eq25, sine_pulse_max_response, strut_parameters,
                          wall_mechanism, wall_parameters)
from ._mechanisms import arch_mechanism, asymmetric_frame, four_bar_mechanism
from ._column_sim import STATE_NAMES, Column, ColumnResult, simulate_column, uplift_acc_m_s2
from ._column_geometry import ImpactOutcome, app_c_reduction, column_impact, full_mass_matrix, mass_points
from ._column_maps import ColumnMaps, column_overturning_maps, sine_pulse
from ._column_compare import (ColumnComparison, SequenceComparison, compare_sequences, compare_to_measurement,
                              joint_sequence)

__all__ = ["BaseMotion", "load_base_motion", "UNITS_TO_M_S2", "bundled_record", "BUNDLED_RECORDS",
           "simulate", "RockingResult", "block_energy", "simulate_batch", "free_rocking_overturns", "BatchResult",
           "RESTITUTION_LAWS", "Restitution", "make_restitution",
           # spectra (helper "spectra")
           "PulseParameters", "pulse_parameters", "lobe_impulses", "pulse_shape", "pulse_motion",
           "pulse_fullness", "PULSE_KINDS", "F_SINE",
           "OASResult", "overturning_spectrum", "OverturningCurve", "overturning_curve",
           "critical_impulse", "normalised_critical_impulse", "fit_inclined_line", "simplified_oas",
           "t_I_band", "TIBand", "BAND_ENSEMBLE",
           "DesignCheck", "design_check", "required_width", "required_width_slender",
           "FundamentalParameters", "Mechanism", "block_parameters", "strut_parameters",
           "frame_parameters", "wall_parameters", "wall_mechanism", "four_bar_mechanism",
           "asymmetric_frame", "free_rocking_period_eq24", "overturning_time_eq25",
           "sine_pulse_max_response", "linear_sine_pulse_response", "arch_mechanism",
           "equivalence_errors",
           # columns (helper "column")
           "Column", "ColumnResult", "simulate_column", "uplift_acc_m_s2", "STATE_NAMES",
           "ImpactOutcome", "app_c_reduction", "column_impact", "full_mass_matrix", "mass_points",
           "ColumnMaps", "column_overturning_maps", "sine_pulse",
           "SequenceComparison", "compare_sequences", "joint_sequence", "ColumnComparison", "compare_to_measurement"]
