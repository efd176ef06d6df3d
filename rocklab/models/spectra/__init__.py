"""Records, pulses, overturning spectra and design: the thesis's §5 (Eq. 13-31, Tables 4-5).

Ground-motion records (AT2, two-column, CSV; :func:`load_base_motion`), pulse parameters
and t_p (:func:`pulse_parameters`), overturning curves and the Overturning Acceleration
Spectrum with t_I, t'_I and beta (:func:`overturning_spectrum`, Eq. 13-20, 28) and t_I's band
over the open choices (:func:`t_I_band`), converged reference verdicts with the chaotic cells
of a grid (:func:`oas_reference`), and the design check and required pier width
(:func:`design_check`, :func:`required_width`, Eq. 21-31).
"""

from ._design import DesignCheck, design_check, required_width, required_width_slender
from ._oas import (
    OASResult,
    critical_impulse,
    fit_inclined_line,
    normalised_critical_impulse,
    overturning_spectrum,
    simplified_oas,
)
from ._oas_column import column_overturning_spectrum
from ._oas_reference import OASReference, oas_reference
from ._oas_curve import OverturningCurve, overturning_curve
from ._oas_sets import CharacteristicOAS, TItpRegression, characteristic_oas, oas_convex_hull, tI_tp_regression
from ._oas_band import BAND_ENSEMBLE, TIBand, t_I_band
from ._pulses import (
    F_SINE,
    PULSE_KINDS,
    PulseParameters,
    lobe_impulses,
    pulse_fullness,
    pulse_motion,
    pulse_parameters,
    pulse_shape,
)
from ._record_measures import RecordMeasures, record_measures, response_spectrum
from ._records import BUNDLED_RECORDS, bundled_record, load_base_motion
from ._records import not_a_record


__all__ = [
    "load_base_motion",
    "RecordMeasures",
    "record_measures",
    "response_spectrum",
    "bundled_record",
    "BUNDLED_RECORDS",
    "PulseParameters",
    "pulse_parameters",
    "lobe_impulses",
    "pulse_shape",
    "pulse_motion",
    "pulse_fullness",
    "PULSE_KINDS",
    "F_SINE",
    "OASResult",
    "overturning_spectrum",
    "column_overturning_spectrum",
    "OASReference",
    "oas_reference",
    "OverturningCurve",
    "overturning_curve",
    "CharacteristicOAS",
    "characteristic_oas",
    "oas_convex_hull",
    "TItpRegression",
    "tI_tp_regression",
    "critical_impulse",
    "normalised_critical_impulse",
    "fit_inclined_line",
    "simplified_oas",
    "t_I_band",
    "TIBand",
    "BAND_ENSEMBLE",
    "DesignCheck",
    "design_check",
    "required_width",
    "required_width_slender",
    "not_a_record",
]
