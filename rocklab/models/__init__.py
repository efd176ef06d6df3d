"""Physics: single-block rocking, columns, spectra and records, equivalent mechanisms.

Sub-packages, one subject each (the paper equations they implement are in each docstring):

- :mod:`rocklab.models.rocking`: one block, restitution laws, integrators;
- :mod:`rocklab.models.column`: multi-block columns;
- :mod:`rocklab.models.spectra`: records, pulses, OAS, t_I, design;
- :mod:`rocklab.models.mechanisms`: equivalent rocking mechanisms.

Every public name of the sub-packages is also here.
"""

from .column import (STATE_NAMES, Column, ColumnComparison, ColumnMaps, ColumnResult, ImpactOutcome,
                     SequenceComparison, app_c_reduction, column_impact, column_overturning_maps, compare_sequences,
                     compare_to_measurement, full_mass_matrix, joint_sequence, mass_points, simulate_column,
                     sine_pulse, uplift_acc_m_s2)
from .mechanisms import (FundamentalParameters, Mechanism, arch_mechanism, asymmetric_frame, block_parameters,
                         equivalence_errors, four_bar_mechanism, frame_parameters, free_rocking_period_eq24,
                         linear_sine_pulse_response, overturning_time_eq25, sine_pulse_max_response,
                         strut_parameters, wall_mechanism, wall_parameters)
from .rocking import (RESTITUTION_LAWS, BatchResult, Restitution, RockingResult, block_energy, eta_axes,
                      eta_bumps, eta_housner, eta_modified,
                      free_rocking_overturns, make_restitution, simulate, simulate_batch)
from .spectra import (BAND_ENSEMBLE, BUNDLED_RECORDS, F_SINE, PULSE_KINDS, UNITS_TO_M_S2, BaseMotion, DesignCheck,
                      OASResult, OverturningCurve, PulseParameters, TIBand, bundled_record, critical_impulse,
                      design_check, fit_inclined_line, load_base_motion, lobe_impulses, normalised_critical_impulse,
                      overturning_curve, overturning_spectrum, pulse_fullness, pulse_motion, pulse_parameters,
                      pulse_shape, required_width, required_width_slender, simplified_oas, t_I_band)

__all__ = ["BaseMotion", "load_base_motion", "UNITS_TO_M_S2", "bundled_record", "BUNDLED_RECORDS",
           "simulate", "eta_housner", "eta_modified", "eta_axes", "eta_bumps", "RockingResult", "block_energy", "simulate_batch", "free_rocking_overturns", "BatchResult",
           "RESTITUTION_LAWS", "Restitution", "make_restitution",
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
           "Column", "ColumnResult", "simulate_column", "uplift_acc_m_s2", "STATE_NAMES",
           "ImpactOutcome", "app_c_reduction", "column_impact", "full_mass_matrix", "mass_points",
           "ColumnMaps", "column_overturning_maps", "sine_pulse",
           "SequenceComparison", "compare_sequences", "joint_sequence", "ColumnComparison", "compare_to_measurement"]
