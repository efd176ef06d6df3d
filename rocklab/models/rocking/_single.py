"""``simulate``: one rigid block rocking on a rigid base (free or under base motion).

Sign convention (Čeh Eq. 1–2, Fig. 1): theta > 0 is rotation about corner A,
``theta'' = -p^2 [sin(alpha sgn(theta) - theta) + (a_g/g) cos(alpha sgn(theta) - theta)]``
with p = sqrt(m g R / I_O) (any alpha_I). A block at rest uplifts only when
|a_g| > g tan(alpha), towards theta > 0 when a_g < 0 (the base moves away
under it). Everything is SI; the base motion is a
:class:`~rocklab.series.BaseMotion` in m/s^2.

Rules (every integrator of :data:`~rocklab.models.rocking.METHODS`):

- **impact** at theta = 0: ``omega+ = eta * omega-`` from the restitution law;
  omega+ decides the new corner (eta < 0: bounce back onto the same corner).
- **rest**: after an impact whose omega+ corresponds to an amplitude below
  ``rest_tol * alpha`` (energy ``<= m g R [cos(alpha(1 - rest_tol)) - cos(alpha)]``)
  while |a_g| <= g tan(alpha), the block is set at rest (theta = omega = 0); it
  uplifts again when |a_g| exceeds g tan(alpha). With ``stop_at_rest`` the run
  stops once at rest and no later base sample exceeds the uplift level.
- **overturning**: ``overturn_t_s`` is the first time |theta| >= alpha with
  outward velocity (cubic Hermite interpolation inside the step); the block
  *falls* (``overturned``, run stops) when |theta| reaches ``fall_rad`` (default
  pi/2: its side touches the ground). Under base motion a block past alpha can
  still come back, so ``overturn_t_s`` may be finite for a block that stays up.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..._errors import MAX_RUN_S, InputError, available_memory_bytes, check_memory, check_time
from ...series import BaseMotion
from ._integrators import RockingProblem, integrator
from ._restitution import make_restitution
from ._result import RockingResult, block_energy

__all__ = ["simulate"]


def _finite(name, v, positive=False):
    if type(v) is float:
        f = v
    else:
        try:
            f = float(v)
        except (TypeError, ValueError):
            raise InputError(f"{name}={v!r}: must be a number") from None
    if not math.isfinite(f) or (positive and f <= 0):
        raise InputError(f"{name}={v!r}: must be a finite{' positive' if positive else ''} number")
    return f


_LAWS: dict = {}  # (law name, block, params) -> Restitution: both are immutable


def _law(restitution, block, law_params):
    """:func:`make_restitution`, memoised for a law named by string with scalar parameters.

    Building a law validates its tables (~15 us); repeated ``simulate`` calls
    (fits, the benchmark) reuse the frozen result.
    """
    if type(restitution) is not str or not all(type(v) in (int, float, str, bool) for v in law_params.values()):
        return make_restitution(restitution, block, **law_params)
    try:
        key = (restitution, block, tuple((k, type(v), v) for k, v in sorted(law_params.items())))
        law = _LAWS.get(key)
    except TypeError:  # an unhashable block subclass
        return make_restitution(restitution, block, **law_params)
    if law is None:
        law = make_restitution(restitution, block, **law_params)
        if len(_LAWS) >= 256:
            _LAWS.clear()
        _LAWS[key] = law
    return law


#: Speed of the compiled single-block loop used for the time estimate, steps/s (measured on one core).
SINGLE_STEPS_PER_S = 3e7


def _problem(
    block,
    theta0_rad,
    omega0_rad_s,
    duration_s,
    dt_s,
    restitution,
    base,
    stop_at_rest,
    output_dt_s,
    linearized,
    rest_tol,
    max_impacts,
    rtol,
    ode_method,
    fall_rad,
    law_params,
) -> RockingProblem:
    """``simulate``'s arguments checked (InputError naming the parameter) into a :class:`RockingProblem`."""
    alpha = block.alpha_rad
    th0 = _finite("theta0_rad", theta0_rad)
    w0 = _finite("omega0_rad_s", omega0_rad_s)
    T = _finite("duration_s", duration_s, positive=True)
    dt = _finite("dt_s", dt_s, positive=True)
    rest_tol = _finite("rest_tol", rest_tol, positive=True)
    if abs(th0) >= alpha:
        raise InputError(
            f"theta0_rad={th0}: |theta0| must be < alpha = {alpha:.6g} rad "
            "(the block would fall at release); give a smaller initial rotation"
        )
    if dt > T:
        raise InputError(f"dt_s={dt}: time step longer than duration_s={T}; use a smaller dt")
    fall = 0.5 * math.pi if fall_rad is None else _finite("fall_rad", fall_rad, positive=True)
    if not (alpha <= fall <= 0.5 * math.pi):
        raise InputError(f"fall_rad={fall}: must be between alpha = {alpha:.6g} and pi/2 rad")
    law = _law(restitution, block, law_params)
    if base is not None and not isinstance(base, BaseMotion):
        raise InputError(
            f"base={type(base).__name__}: give a rocklab.series.BaseMotion "
            "(e.g. BaseMotion.from_samples(acc, dt_s, 'g')) or None"
        )
    every, resample = 1, None
    if output_dt_s is not None:
        odt = _finite("output_dt_s", output_dt_s, positive=True)
        if odt < dt:
            raise InputError(f"output_dt_s={odt}: must be >= dt_s={dt}")
        if odt > T:
            raise InputError(f"output_dt_s={odt}: longer than duration_s={T}; give a spacing <= the duration")
        k = int(round(odt / dt))
        if abs(k * dt - odt) <= 1e-9 * odt:
            every = k
        else:
            resample = odt  # e.g. a camera frame rate: store every step, then Hermite (RockingResult.at)
    return RockingProblem(
        block,
        th0,
        w0,
        T,
        dt,
        law,
        base,
        bool(linearized),
        rest_tol,
        bool(stop_at_rest),
        every,
        resample,
        int(max_impacts),
        fall,
        rtol,
        ode_method,
    )


def _check_cost(problem: RockingProblem) -> None:
    """InputError before a run that would not fit in memory or would take far too long."""
    T, dt, every, n_steps = problem.duration_s, problem.dt_s, problem.output_every, problem.n_steps
    nbytes, seconds = 40.0 * n_steps / every, T / dt / SINGLE_STEPS_PER_S
    # the messages are written only for a run that fails a check (formatting them cost a run of
    # B6M a hundredth of its time)
    if nbytes > 0.5 * available_memory_bytes():
        check_memory(
            nbytes,
            f"{T:g} s at dt = {dt:g} s ({n_steps} steps stored every {every})",
            "shorten duration_s or give a coarser output_dt_s",
        )
    if not seconds <= MAX_RUN_S:
        check_time(
            seconds,
            f"{T:g} s at dt = {dt:g} s ({T / dt:.3g} steps)",
            "give a coarser dt_s (e.g. 1e-4 s) or a shorter duration_s",
        )


def simulate(
    block,
    theta0_rad: float = 0.0,
    omega0_rad_s: float = 0.0,
    duration_s: float = 10.0,
    dt_s: float = 1e-4,
    restitution="housner",
    base: BaseMotion | None = None,
    method: str = "newmark",
    stop_at_rest: bool = True,
    output_dt_s: float | None = None,
    *,
    linearized: bool = False,
    rest_tol: float = 1e-6,
    max_impacts: int = 100_000,
    rtol: float = 1e-10,
    ode_method: str = "DOP853",
    fall_rad: float | None = None,
    **law_params,
) -> RockingResult:
    """Simulate one rocking block.

    Parameters
    ----------
    block : rocklab.Block
    theta0_rad, omega0_rad_s : float
        Initial rotation (rad, |theta0| < alpha) and angular velocity (rad/s).
        ``omega0 = 0`` is a thread-burn release; both 0 is a block at rest
        (it moves only if the base exceeds the uplift acceleration).
    duration_s : float
        Simulated time, s.
    dt_s : float
        Newmark time step, s (for ``method="event"`` only the default output step).
        Trapezoidal error per unit time ~ (p dt)^2 / 12; dt = 1e-4 s puts impact
        times of a 0.2 m block within ~1e-7 s of the adaptive reference.
    restitution : str or Restitution or float
        A key of :data:`~rocklab.models.RESTITUTION_LAWS` (``housner``,
        ``modified`` (k=), ``constant`` (eta=), ``axes`` (x1_m=, x2_m=),
        ``cut_corner`` (b2_m=), ``bumps`` (n=), ``per_impact`` (eta=[...] /
        omega_rad_s= / func=)), a :class:`Restitution`, or a number (constant eta).
    base : BaseMotion, optional
        Horizontal base acceleration (m/s^2), linearly interpolated onto the
        steps, zero outside the record. None: free rocking.
    method : {"newmark", "taylor", "event"} or Integrator
        A key of :data:`~rocklab.models.rocking.METHODS`: numba Newmark kernel with
        exact contact (fast; ``dt_s`` sets its accuracy), Taylor series of order 12
        between exact impacts (free rocking of the full equation only; ``p h <= 0.2``
        steps, impact times to ~1e-10 s; ``dt_s`` or ``output_dt_s`` is only the
        output grid), or scipy ``solve_ivp`` DOP853 with impact events (reference,
        ``rtol``); or an :class:`~rocklab.models.rocking.Integrator` instance (e.g.
        ``Newmark(lean=False)``).
    stop_at_rest : bool
        Stop the output when the block is at rest for good (see module doc).
    output_dt_s : float, optional
        Output spacing, s (default ``dt_s``). A whole multiple of ``dt_s`` keeps
        every k-th step; any other value (a camera frame interval, say) is
        resampled from every step by :meth:`RockingResult.at`.
    linearized : bool
        Integrate the linearised equation (DeJong Eq. 5), e.g. for closed forms.
    rest_tol : float
        Rest threshold as a fraction of alpha (amplitude), default 1e-6.
    rtol : float
        Relative tolerance of the event method (default 1e-10). With a base record
        the forcing has a kink at every sample that DOP853's error estimate does
        not see; use 1e-12 there for impact times to ~1e-8 s.
    ode_method : str
        ``solve_ivp`` method of the event integrator (``"DOP853"``, ``"Radau"``, ...).
    fall_rad : float, optional
        |theta| at which the block counts as fallen and the run stops (default
        pi/2, the side hits the ground; e.g. ``block.alpha_rad`` for the common
        "|theta| > alpha" criterion).
    max_impacts : int
        Impacts stored in the table (all are counted).
    **law_params
        Parameters of the restitution law (``k``, ``eta``, ``n``, ...).

    Returns
    -------
    RockingResult

    Raises
    ------
    InputError
        |theta0| >= alpha, non-finite or non-positive numbers, unknown law/method, a
        problem the method does not integrate (``taylor`` with a base record).

    Examples
    --------
    A 4.5 × 20.25 cm block released from 0.15 rad (Čeh's B5M), Housner's restitution:

    >>> from rocklab import Block
    >>> from rocklab.models import simulate
    >>> r = simulate(Block(0.045, 0.2025), theta0_rad=0.15, duration_s=3.0)
    >>> round(r.restitution.eta, 4), len(r.impacts), round(float(r.impacts["t_s"].iloc[0]), 3)
    (0.9294, 22, 0.217)
    """
    meth = integrator(method)
    problem = _problem(
        block,
        theta0_rad,
        omega0_rad_s,
        duration_s,
        dt_s,
        restitution,
        base,
        stop_at_rest,
        output_dt_s,
        linearized,
        rest_tol,
        max_impacts,
        rtol,
        ode_method,
        fall_rad,
        law_params,
    )
    return _run(meth, problem)


def _run(meth, problem: RockingProblem) -> RockingResult:
    """``problem`` integrated by ``meth`` (its limits and the run's cost checked first) into a read-only result,
    resampled onto the output grid when the integrator stored every step."""
    meth.check(problem)
    _check_cost(problem)
    out = meth.run(problem)
    # an integrator that samples any grid has sampled the output grid directly
    resample = None if meth.any_output_grid else problem.resample_dt_s
    for a in out[:5]:
        a.setflags(write=False)
    res = RockingResult(
        t_s=out.t_s,
        theta_rad=out.theta_rad,
        omega_rad_s=out.omega_rad_s,
        energy_J=out.energy_J,
        impacts_array=out.impacts,
        status=out.status,
        overturned=out.status == "overturned",
        overturn_t_s=float(out.overturn_t_s),
        fall_t_s=float(out.fall_t_s),
        max_abs_theta_rad=float(out.max_abs_theta_rad),
        block=problem.block,
        restitution=problem.law,
        method=meth.name,
        dt_s=problem.dt_s,
        n_impacts=int(out.n_impacts),
        linearized=problem.linearized,
        base_name=problem.base.name if problem.base is not None else "",
    )
    if resample is None:
        return res
    t = out.t_s
    t2 = np.arange(int(math.floor(t[-1] / resample + 1e-9)) + 1) * resample
    th2, w2 = res.at(t2)
    E2 = block_energy(problem.block, th2, w2, problem.linearized)
    for a in (t2, th2, w2, E2):
        a.setflags(write=False)
    return dataclasses.replace(res, t_s=t2, theta_rad=th2, omega_rad_s=w2, energy_J=E2)
