"""The single-block integrators behind one contract, and their registry :data:`METHODS`.

:func:`~rocklab.models.simulate` validates its arguments once into a
:class:`RockingProblem`, looks the method up in :data:`METHODS` (or takes an
:class:`Integrator` instance, as ``solve_ivp`` takes an ``OdeSolver`` class), calls
:meth:`Integrator.check` for the method's own rules and :meth:`Integrator.run`, which
returns a :class:`~rocklab.models.rocking.KernelResult`. Every integrator applies the same
impact, rest and overturning rules (see :mod:`rocklab.models.rocking._single`):

- ``newmark``: the numba Newmark kernel with exact contact (:mod:`._newmark`);
- ``taylor``: Taylor series of order 12 between exact impacts, free rocking of the full
  equation only (:mod:`._taylor`);
- ``event``: scipy ``solve_ivp`` with impact events, the reference (:mod:`._event`).

A new integrator is a subclass of :class:`Integrator` added to :data:`METHODS`.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, ClassVar, NamedTuple

import numpy as np

from ..._errors import InputError
from ...blocks import G
from ._newmark import STATUS_NAMES, run_single
from ._result import KernelResult
from ._taylor import run_taylor

if TYPE_CHECKING:
    from ...blocks import Block
    from ...series import BaseMotion
    from ._restitution import Restitution

__all__ = [
    "METHODS",
    "Integrator",
    "RockingProblem",
    "Newmark",
    "Taylor",
    "Event",
    "check_step",
    "integrator",
    "P_DT_MAX",
    "P_DT_WARN",
]

#: Largest p*dt the Newmark step may take: beyond it the step cannot follow a rocking half-cycle
#: (about 1/p long) and the result is meaningless; between P_DT_WARN and it, amplitudes and impact
#: times are not converged (W-SIM-DT).
P_DT_MAX = 0.1
P_DT_WARN = 0.01

_EMPTY = np.zeros(0)
_EMPTY.setflags(write=False)  # same numba type as a (read-only) BaseMotion array: one compile


def check_step(p_rad_s: float, dt_s: float, option: str = "dt_s") -> None:
    """:class:`InputError` when ``p dt`` > :data:`P_DT_MAX`; warning ``W-SIM-DT`` above :data:`P_DT_WARN`."""
    pdt = p_rad_s * dt_s
    if pdt > P_DT_MAX:
        raise InputError(
            f"{option}={dt_s:g} s: too coarse for this block (p = {p_rad_s:.4g} rad/s, p dt = "
            f"{pdt:.4g} > {P_DT_MAX}); use dt <= {P_DT_WARN / p_rad_s:.4g} s"
        )
    if pdt > P_DT_WARN:
        from ..._diagnostics import warn

        warn(
            "W-SIM-DT",
            f"{option}={dt_s:g} s gives p dt = {pdt:.4g} (> {P_DT_WARN}) for p = {p_rad_s:.4g} "
            f"rad/s; use dt <= {P_DT_WARN / p_rad_s:.4g} s for converged impacts",
        )


class RockingProblem(NamedTuple):
    """One validated single-block run, as every integrator receives it (SI units).

    ``output_every`` keeps every k-th step of ``dt_s``; ``resample_dt_s`` (or None) is an
    output spacing that is not a whole multiple of ``dt_s`` (a camera frame interval):
    integrators with :attr:`Integrator.any_output_grid` sample it directly, the others
    store every step and :func:`~rocklab.models.simulate` resamples. ``law`` is a
    :class:`~rocklab.models.Restitution`, ``base`` a :class:`~rocklab.series.BaseMotion` or
    None; ``rtol`` and ``ode_method`` concern the ``event`` integrator only.
    """

    block: Block
    theta0_rad: float
    omega0_rad_s: float
    duration_s: float
    dt_s: float
    law: Restitution
    base: BaseMotion | None
    linearized: bool
    rest_tol: float
    stop_at_rest: bool
    output_every: int
    resample_dt_s: float | None
    max_impacts: int
    fall_rad: float
    rtol: float
    ode_method: str

    @property
    def n_steps(self) -> int:
        """Steps of ``dt_s`` that cover ``duration_s``."""
        return int(math.ceil(self.duration_s / self.dt_s - 1e-9))

    @property
    def rest_w2(self) -> float:
        """omega^2 (rad^2/s^2) below which an impact leaves the block at rest (amplitude ``rest_tol`` alpha)."""
        a, p = self.block.alpha_rad, self.block.p_rad_s
        return 2.0 * p * p * (math.cos(a - self.rest_tol * a) - math.cos(a))

    def last_uplift_t_s(self) -> float:
        """Time of the last base sample above the uplift level g tan(alpha), s; -inf if none."""
        if self.base is None:
            return -np.inf
        over = np.abs(self.base.acc_m_s2) > G * math.tan(self.block.alpha_rad)
        return float(self.base.t_s[np.flatnonzero(over)[-1]]) if over.any() else -np.inf


class Integrator:
    """The contract of a single-block integrator.

    Subclasses set :attr:`name` and :attr:`any_output_grid` and implement :meth:`run`;
    :meth:`check` raises :class:`~rocklab.InputError` (or warns) for problems the method
    cannot solve or solves badly, before any work.
    """

    #: The key in :data:`METHODS` and ``RockingResult.method``.
    name: ClassVar[str] = ""
    #: True when :meth:`run` samples ``resample_dt_s`` itself (no resampling afterwards).
    any_output_grid: ClassVar[bool] = False

    def check(self, problem: RockingProblem) -> None:
        """Refuse (InputError) or warn about what this method cannot integrate well."""

    def run(self, problem: RockingProblem) -> KernelResult:
        """Integrate ``problem``."""
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


class Newmark(Integrator):
    """Numba Newmark trapezoidal kernel with exact contact (Čeh §3); ``dt_s`` sets its accuracy.

    Parameters
    ----------
    lean : bool
        Run free and forced rocking in the lean loops (default); False takes every step in
        the general Newton loop (the reference the tests compare the lean loops with).
    """

    name = "newmark"

    def __init__(self, lean: bool = True):
        self.lean = bool(lean)

    def __repr__(self) -> str:
        return f"Newmark(lean={self.lean})"

    def check(self, problem: RockingProblem) -> None:
        check_step(problem.block.p_rad_s, problem.dt_s, "dt_s")

    def run(self, problem: RockingProblem) -> KernelResult:
        pb, base, law = problem.block, problem.base, problem.law
        if base is None:
            acc, acc_t0, acc_dt = _EMPTY, 0.0, 1.0
        else:
            acc, acc_t0, acc_dt = np.ascontiguousarray(base.acc_m_s2, float), float(base.t_s[0]), base.dt_s
        # lean=True is run_single's default: leaving it out keeps the compiled signature (and cache) of
        # the everyday call, whose constant flag the compiler folds
        lean = () if self.lean else (False,)
        t, th, w, E, imp, n_imp, st, t_over, t_fall, max_abs = run_single(
            pb.p_rad_s,
            pb.alpha_rad,
            problem.theta0_rad,
            problem.omega0_rad_s,
            problem.dt_s,
            problem.n_steps,
            acc,
            acc_t0,
            acc_dt,
            law.mode,
            law.eta_x,
            law.eta_y,
            problem.linearized,
            problem.rest_w2,
            problem.last_uplift_t_s(),
            problem.stop_at_rest,
            problem.output_every,
            problem.max_impacts,
            problem.fall_rad,
            pb.I_O_kg_m2,
            *lean,
        )
        return KernelResult(t, th, w, E, imp, int(n_imp), STATUS_NAMES[st], t_over, t_fall, max_abs)


class Taylor(Integrator):
    """Taylor series of order 12 between exact impacts: free rocking of the full equation only.

    Steps of ``p h <= 0.2``, impact times to ~1e-10 s; ``dt_s`` (or the output spacing) is
    only the output grid.
    """

    name = "taylor"
    any_output_grid = True

    def check(self, problem: RockingProblem) -> None:
        if problem.base is not None or problem.linearized:
            raise InputError(
                f"method='taylor' integrates free rocking of the full equation only; "
                f"{'a base record' if problem.base is not None else 'linearized=True'} needs method='newmark'"
            )

    def run(self, problem: RockingProblem) -> KernelResult:
        pb, law = problem.block, problem.law
        odt = problem.dt_s * problem.output_every if problem.resample_dt_s is None else problem.resample_dt_s
        t, th, w, E, imp, n_imp, st, t_over, t_fall, max_abs = run_taylor(
            pb.p_rad_s,
            pb.alpha_rad,
            problem.theta0_rad,
            problem.omega0_rad_s,
            int(math.floor(problem.duration_s / odt + 1e-9)) + 1,
            odt,
            law.mode,
            law.eta_x,
            law.eta_y,
            problem.rest_w2,
            problem.stop_at_rest,
            problem.max_impacts,
            problem.fall_rad,
            pb.I_O_kg_m2,
        )
        return KernelResult(t, th, w, E, imp, int(n_imp), STATUS_NAMES[st], t_over, t_fall, max_abs)


class Event(Integrator):
    """scipy ``solve_ivp`` (``ode_method``, default DOP853, ``rtol``) with impact events: the reference."""

    name = "event"

    def run(self, problem: RockingProblem) -> KernelResult:
        from ._event import run_event

        odt = problem.dt_s * problem.output_every
        t_grid = np.arange(int(math.floor(problem.duration_s / odt + 1e-9)) + 1) * odt
        return run_event(
            problem.block,
            problem.theta0_rad,
            problem.omega0_rad_s,
            problem.duration_s,
            problem.law,
            problem.base,
            problem.linearized,
            problem.rest_tol,
            problem.stop_at_rest,
            t_grid,
            rtol=problem.rtol,
            ode_method=problem.ode_method,
            fall_rad=problem.fall_rad,
            max_impacts=problem.max_impacts,
        )


#: The single-block integrators by name (``simulate(method=...)``).
METHODS: dict[str, Integrator] = {m.name: m for m in (Newmark(), Taylor(), Event())}


def integrator(method) -> Integrator:
    """The :class:`Integrator` for ``method``: a key of :data:`METHODS` (any case) or an instance."""
    if isinstance(method, Integrator):
        return method
    found = METHODS.get(str(method).lower()) if isinstance(method, str) else None
    if found is None:
        raise InputError(
            f"method={method!r}: unknown integrator; use one of {', '.join(repr(k) for k in METHODS)} "
            "(or a rocklab.models.rocking Integrator instance)"
        )
    return found
