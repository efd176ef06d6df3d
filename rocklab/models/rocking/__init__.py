"""Single-block rocking: the equations of motion, restitution laws and the integrators.

Čeh et al. (2018) Eq. 1-4 (motion), Eq. 5-11 (Newmark trapezoidal steps with exact contact),
Eq. 13-14 (Housner's and the modified restitution); thesis §3.1 and App. A (impacts at
arbitrary axes, consecutive "bump" impacts). :func:`simulate` runs one block (numba Newmark
kernel, Taylor series, or scipy's DOP853 with impact events as the reference: the integrators
of :data:`METHODS`, one contract, :class:`Integrator`); :func:`simulate_batch` many.
"""

from ._batch import free_rocking_overturns, simulate_batch
from ._energy_integral import free_rocking_impact_times
from ._integrators import METHODS, Event, Integrator, Newmark, RockingProblem, Taylor
from ._restitution import (
    RESTITUTION_LAWS,
    Restitution,
    eta_axes,
    eta_bumps,
    eta_housner,
    eta_modified,
    make_restitution,
)
from ._result import BatchResult, KernelResult, RockingResult, block_energy
from ._single import simulate
from ._integrators import check_step


__all__ = [
    "simulate",
    "METHODS",
    "Integrator",
    "RockingProblem",
    "KernelResult",
    "Newmark",
    "Taylor",
    "Event",
    "simulate_batch",
    "free_rocking_overturns",
    "free_rocking_impact_times",
    "RockingResult",
    "BatchResult",
    "block_energy",
    "RESTITUTION_LAWS",
    "Restitution",
    "make_restitution",
    "eta_housner",
    "eta_modified",
    "eta_axes",
    "eta_bumps",
    "check_step",
]
