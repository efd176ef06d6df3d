"""Equivalent rocking mechanisms (DeJong & Dimitrakopoulos 2014, Eq. 1-42).

Fundamental rocking parameters of a block, a strut, a frame, a wall, an asymmetric frame and
an arch (:func:`block_parameters`, :func:`frame_parameters`, :func:`wall_mechanism`,
:func:`asymmetric_frame`, :func:`arch_mechanism`, by Lagrange's equations, Eq. 7-20), the
linearised equation's closed forms (Eq. 24-25, 40-42), the equivalence errors, and time histories
of a mechanism and its equivalent blocks under base motion (:func:`mechanism_time_histories`).
"""

from ._equivalent import (
    FundamentalParameters,
    Mechanism,
    block_parameters,
    equivalence_errors,
    frame_parameters,
    free_rocking_period_eq24,
    linear_sine_pulse_response,
    overturning_time_eq25,
    sine_pulse_max_response,
    strut_parameters,
    wall_mechanism,
    wall_parameters,
)
from ._mechanisms import arch_mechanism, asymmetric_frame, block_mechanism, four_bar_mechanism
from ._response import (
    MechanismResponse,
    equivalent_block_dimensions,
    equivalent_block_mechanism,
    mechanism_response,
    mechanism_time_histories,
)

__all__ = [
    "FundamentalParameters",
    "Mechanism",
    "block_parameters",
    "strut_parameters",
    "frame_parameters",
    "wall_parameters",
    "wall_mechanism",
    "four_bar_mechanism",
    "block_mechanism",
    "asymmetric_frame",
    "arch_mechanism",
    "free_rocking_period_eq24",
    "overturning_time_eq25",
    "sine_pulse_max_response",
    "linear_sine_pulse_response",
    "equivalence_errors",
    "MechanismResponse",
    "mechanism_response",
    "mechanism_time_histories",
    "equivalent_block_mechanism",
    "equivalent_block_dimensions",
]
