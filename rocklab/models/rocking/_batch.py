"""``simulate_batch``: many independent rocking runs in one parallel numba call.

Made for overturning spectra and fits: thousands of (size, slenderness,
amplitude) combinations under one base record. Each entry runs the same
Newmark kernel as :func:`~rocklab.models.simulate` (exact contact, same rest
and overturning rules) without storing histories.
"""

from __future__ import annotations

import math

import numpy as np
from numba import parallel_chunksize

from ..._errors import InputError
from ._newmark import run_batch
from ._taylor_record import order_for, run_taylor_record, safe_tail
from ...series import BaseMotion
from ._result import BatchResult

__all__ = ["simulate_batch", "free_rocking_overturns"]

_HALF_PI = 0.5 * math.pi
#: Runs a thread takes at a time from the batch's parallel loop (dynamic scheduling): runs differ in cost
#: (a block that overturns early against one rocking to the record's end), so a static split into one share per
#: thread leaves one thread idle at the end (on FF-1's default OAS a modelled balance 0.95 on 2 threads against
#: 0.996 in chunks of 2).
RUNS_PER_CHUNK = 2


def simulate_batch(
    p_rad_s,
    alpha_rad,
    *,
    base: BaseMotion | None = None,
    scale=1.0,
    theta0_rad=0.0,
    omega0_rad_s=0.0,
    eta=None,
    alpha_I=4.0 / 3.0,
    dt_s: float = 1e-3,
    duration_s: float | None = None,
    free_after_s: float = 0.0,
    stop_on_overturn: bool = True,
    fall_rad=None,
    max_p_dt: float = 0.02,
    rest_tol: float = 1e-6,
    method: str = "newmark",
    taylor_tol: float = 1e-16,
    stop_when_safe: bool = False,
) -> BatchResult:
    """Run m independent blocks (broadcast arrays) in parallel; summaries only.

    Parameters
    ----------
    p_rad_s, alpha_rad : array_like
        Frequency parameter (rad/s) and slenderness angle (rad) per entry.
    base : BaseMotion, optional
        One base record (m/s^2) shared by all entries, multiplied by ``scale``.
    scale : array_like
        Factor on the record per entry (dimensionless; e.g. PGA / record PGA).
    theta0_rad, omega0_rad_s : array_like
        Initial conditions (|theta0| < alpha).
    eta : array_like, optional
        Constant restitution per entry; default Housner ``1 - 2 sin^2(alpha)/alpha_I``.
    alpha_I : array_like
        Corner inertia coefficient (only for the default eta).
    dt_s : float
        Time step, s. Each entry is sub-stepped so that ``p h <= max_p_dt``; the
        trapezoidal rule's rate error is ~(p h)^2/12 (3e-5 at 0.02). Measured on
        El Centro 1940 (1200 runs: R = 0.1–5 m, alpha = 0.2, scale 0.1–1.5,
        5 s of free rocking after): dt = 1e-3 s against 1e-4 s flips the fall
        flag of 8 runs (0.7 %, all at the overturning boundary, where the
        response is chaotic), max |theta|/alpha of the rocking runs differs by
        3e-5 (median) / 3e-3 (90th percentile), overturn times by ~1e-4 s.
    duration_s : float, optional
        Simulated time, s. Default: end of the record + ``free_after_s``.
    free_after_s : float
        Free-rocking time added after the record when ``duration_s`` is None, s.
    stop_on_overturn : bool
        Stop an entry once it is deemed fallen (|theta| >= ``fall_rad``). Runs
        always end when |theta| reaches pi/2 (the side hits the ground).
    fall_rad : array_like, optional
        Overturning criterion, rad; default pi/2 (the block actually falls). Pass
        ``alpha_rad`` for the common "|theta| > alpha" criterion.
    max_p_dt : float
        Largest p * h allowed (sub-stepping of small blocks).
    rest_tol : float
        Rest threshold as a fraction of alpha (see :func:`simulate`).
    method : {"newmark", "taylor"}
        ``"newmark"``: trapezoidal steps of ``dt_s`` sub-stepped to ``p h <= max_p_dt``, exact
        contact (Čeh §3). ``"taylor"``: one Taylor-series step per record interval (split so
        that ``p h <= max_p_dt``; 0.25 suffices, the order adapts), impacts, uplift and
        overturning as roots of the series (:mod:`~rocklab.models.rocking._taylor_record`);
        ``dt_s`` is not used: the record's own interval sets the steps.
    taylor_tol : float
        For ``"taylor"``: the order of each entry is the smallest with ``(p h)^(n+1)/(n+1)!``
        below this (1e-16: truncation below rounding).
    stop_when_safe : bool
        Stop an entry (status 4) once the rest of the record cannot bring it to |theta| = alpha, an energy
        bound (:mod:`~rocklab.models.rocking._taylor_record`): its verdict, not overturning and safe in free
        rocking after the record, is then known. ``"taylor"`` checks at every record sample; ``"newmark"``
        where its lean loops hand over (impacts, uplifts, the record's end), with 1 % of the energy room left
        to the trapezoidal rule's error. For verdicts only: the end state, ``t_end_s`` and the maximum are
        those of the stop.

    Returns
    -------
    BatchResult
        ``overturned`` (m,) bool, ``overturn_t_s`` (m,) first |theta| >= alpha
        outward (NaN if never), ``max_abs_theta_over_alpha`` (m,), ``n_impacts`` (m,),
        and the state where each run ended (``theta_end_rad``, ``omega_end_rad_s``,
        ``t_end_s``) for verdicts beyond the simulated span (see
        :func:`free_rocking_overturns`).
    """
    p, al, sc, th0, w0, et, fr = _entries(p_rad_s, alpha_rad, scale, theta0_rad, omega0_rad_s, alpha_I, eta, fall_rad)
    duration_s = _checked_span(base, dt_s, duration_s, free_after_s)
    entries = (p, al, sc, th0, w0, et, fr)
    if method == "taylor":
        return _taylor_batch(base, entries, duration_s, max_p_dt, taylor_tol, rest_tol, stop_when_safe)
    if method != "newmark":
        raise InputError(f"simulate_batch: method={method!r}: use 'newmark' or 'taylor'")
    return _newmark_batch(base, entries, dt_s, duration_s, max_p_dt, rest_tol, stop_on_overturn, stop_when_safe)


def _newmark_batch(base, entries, dt_s, duration_s, max_p_dt, rest_tol, stop_on_overturn, stop_when_safe):
    """``simulate_batch(method="newmark")``: the entries (p, alpha, scale, theta0, omega0, eta, fall) run by
    :func:`~rocklab.models.rocking._newmark.run_batch`."""
    p, al, sc, th0, w0, et, fr = entries
    n_sub = np.maximum(1, np.ceil(p * dt_s / max_p_dt - 1e-12)).astype(np.int64)
    h = dt_s / n_sub
    n_steps = np.ceil(duration_s / h - 1e-9).astype(np.int64)
    if base is None:
        acc, t0, dta = np.zeros(0), 0.0, 1.0
        acc.setflags(write=False)  # same numba type as a BaseMotion array: one compile
    else:
        acc, t0, dta = np.ascontiguousarray(base.acc_m_s2, float), float(base.t_s[0]), base.dt_s
    tail = _tail_of(acc, dta) if (stop_when_safe and base is not None) else np.zeros(0)
    with parallel_chunksize(RUNS_PER_CHUNK):
        over, t_over, mx, nimp, status, steps, th_end, w_end = run_batch(
            p, al, th0, w0, et, h, n_steps, acc, t0, dta, sc, float(rest_tol), fr, bool(stop_on_overturn), tail
        )
    return BatchResult(
        overturned=over,
        overturn_t_s=t_over,
        max_abs_theta_over_alpha=mx,
        n_impacts=nimp,
        status=status,
        p_rad_s=p,
        alpha_rad=al,
        scale=sc,
        eta=et,
        dt_s=h,
        n_steps=int(steps.sum()),
        theta_end_rad=th_end,
        omega_end_rad_s=w_end,
        t_end_s=steps * h,
    )


def _checked_span(base, dt_s, duration_s, free_after_s) -> float:
    """``simulate_batch``'s time arguments checked; the simulated span (s), the record's end plus free rocking
    when ``duration_s`` is None."""
    if not (math.isfinite(dt_s) and dt_s > 0):
        raise InputError(f"simulate_batch: dt_s={dt_s!r} must be positive (s)")
    if base is not None and not isinstance(base, BaseMotion):
        raise InputError("simulate_batch: base must be a rocklab.series.BaseMotion or None")
    if duration_s is None:
        if base is None:
            raise InputError("simulate_batch: give duration_s for free rocking (no base record)")
        duration_s = float(base.t_s[-1]) + float(free_after_s)
    if not (math.isfinite(duration_s) and duration_s > 0):
        raise InputError(f"simulate_batch: duration_s={duration_s!r} must be positive (s)")
    return float(duration_s)


#: The last record's :func:`safe_tail`: (samples, interval s, tail); an OAS runs one record in many batches.
_TAIL_CACHE: list = [None]


def _tail_of(acc, dt_s):
    """:func:`~rocklab.models.rocking._taylor_record.safe_tail` of ``acc``, reused while the record is the same."""
    c = _TAIL_CACHE[0]
    if c is not None and c[1] == dt_s and c[0].shape == acc.shape and np.array_equal(c[0], acc):
        return c[2]
    tail = safe_tail(acc, dt_s)
    _TAIL_CACHE[0] = (acc.copy(), dt_s, tail)
    return tail


def _taylor_batch(base, entries, duration_s, max_p_h, tol, rest_tol, stop_when_safe=False) -> BatchResult:
    """``simulate_batch(method="taylor")``: the entries (p, alpha, scale, theta0, omega0, eta, fall) run
    by :func:`~rocklab.models.rocking._taylor_record.run_taylor_record`."""
    p, al, sc, th0, w0, et, fr = entries
    if not (math.isfinite(max_p_h) and 0 < max_p_h <= 1.0):
        raise InputError(f"simulate_batch: max_p_dt={max_p_h!r}: for method='taylor' give p h in (0, 1]")
    if not (math.isfinite(tol) and 0 < tol < 1):
        raise InputError(f"simulate_batch: taylor_tol={tol!r}: give a relative truncation bound in (0, 1)")
    if base is None:
        acc, t0, dta = np.zeros(1), 0.0, float(duration_s)
    else:
        acc, t0, dta = np.ascontiguousarray(base.acc_m_s2, float), float(base.t_s[0]), float(base.dt_s)
    h = np.minimum(dta, max_p_h / p)  # longest step of each entry
    order = order_for(p * h, tol)
    tail = _tail_of(acc, dta) if (stop_when_safe and base is not None) else np.zeros(0)
    with parallel_chunksize(RUNS_PER_CHUNK):
        status, t_over, th_end, w_end, t_end, nimp, mx = run_taylor_record(
            p, al, et, sc, th0, w0, acc, t0, dta, float(duration_s), order, float(max_p_h), float(rest_tol), fr, tail
        )
    return BatchResult(
        overturned=status == 2,
        overturn_t_s=t_over,
        max_abs_theta_over_alpha=mx / al,
        n_impacts=nimp,
        status=status,
        p_rad_s=p,
        alpha_rad=al,
        scale=sc,
        eta=et,
        dt_s=h,
        n_steps=int(np.sum(np.ceil(t_end / h))),
        theta_end_rad=th_end,
        omega_end_rad_s=w_end,
        t_end_s=t_end,
    )


def _entries(p_rad_s, alpha_rad, scale, theta0_rad, omega0_rad_s, alpha_I, eta, fall_rad):
    """The per-entry arguments broadcast to one length m and checked; eta and fall_rad defaulted.

    Returns (p rad/s, alpha rad, scale, theta0 rad, omega0 rad/s, eta, fall rad), each (m,) float.
    """
    try:
        arrs = np.broadcast_arrays(
            *(
                np.asarray(x, float)
                for x in (
                    p_rad_s,
                    alpha_rad,
                    scale,
                    theta0_rad,
                    omega0_rad_s,
                    alpha_I,
                    np.nan if eta is None else eta,
                    np.nan if fall_rad is None else fall_rad,
                )
            )
        )
    except (ValueError, TypeError) as e:
        raise InputError(
            f"simulate_batch: array arguments do not broadcast ({e}); give equal lengths or scalars"
        ) from None
    p, al, sc, th0, w0, aI, et, fr = (np.array(a, dtype=float).ravel() for a in arrs)
    for name, v in (("p_rad_s", p), ("alpha_rad", al), ("alpha_I", aI)):
        if not np.all(np.isfinite(v) & (v > 0)):
            raise InputError(f"simulate_batch: {name} must be finite and positive everywhere")
    if np.any(al >= _HALF_PI):
        raise InputError("simulate_batch: alpha_rad must be < pi/2")
    for name, v in (("scale", sc), ("theta0_rad", th0), ("omega0_rad_s", w0)):
        if not np.all(np.isfinite(v)):
            raise InputError(f"simulate_batch: {name} must be finite")
    if np.any(np.abs(th0) >= al):
        raise InputError("simulate_batch: |theta0_rad| must be < alpha_rad for every entry")
    et = np.where(np.isnan(et), 1.0 - 2.0 * np.sin(al) ** 2 / aI, et)
    if np.any(np.abs(et) > 1):
        raise InputError("simulate_batch: |eta| must be <= 1")
    fr = np.where(np.isnan(fr), _HALF_PI, fr)
    return p, al, sc, th0, w0, et, fr


def free_rocking_overturns(theta_rad, omega_rad_s, p_rad_s, alpha_rad, eta) -> np.ndarray:
    """Exact fate of a block left to rock freely from a state: does it overturn?

    With no base motion the energy E = omega^2/2 + p^2 cos(alpha - |theta|)
    (per unit I_O, rad^2/s^2) is constant between impacts and the top of the
    corner (|theta| = alpha) needs E > p^2. An impact multiplies the kinetic
    energy at theta = 0, E - p^2 cos(alpha), by eta^2, so only the next impact
    matters: a block that does not get over the top after it never will.

    Parameters
    ----------
    theta_rad, omega_rad_s : array_like
        State (rad, rad/s; the sign of theta names the pivot, as in ``simulate``).
    p_rad_s, alpha_rad : array_like
        Frequency parameter (rad/s) and slenderness angle (rad).
    eta : array_like
        Restitution (omega after / before an impact).

    Returns
    -------
    ndarray of bool
        Broadcast shape of the inputs. |theta| >= alpha moving outward, or
        beyond the top too slow to come back over it, counts as overturning;
        a block at rest (theta = omega = 0) never does.
    """
    try:
        th, w, p, a, e = np.broadcast_arrays(
            *(np.asarray(x, float) for x in (theta_rad, omega_rad_s, p_rad_s, alpha_rad, eta))
        )
    except (ValueError, TypeError) as err:
        raise InputError(
            f"free_rocking_overturns: arguments do not broadcast ({err}); give equal lengths or scalars"
        ) from None
    if not (np.all(np.isfinite(th)) and np.all(np.isfinite(w))):
        raise InputError("free_rocking_overturns: theta_rad and omega_rad_s must be finite")
    if not np.all((p > 0) & np.isfinite(p)) or not np.all((a > 0) & (a < _HALF_PI)):
        raise InputError("free_rocking_overturns: need p_rad_s > 0 and 0 < alpha_rad < pi/2")
    if not np.all(np.abs(e) <= 1):
        raise InputError("free_rocking_overturns: |eta| must be <= 1")
    p2 = p * p
    ath = np.abs(th)
    energy = 0.5 * w * w + p2 * np.cos(a - ath)
    past = ath >= a
    outward = (th * w > 0) | ((th == 0) & (w != 0))
    after_impact = p2 * np.cos(a) + e * e * (energy - p2 * np.cos(a))
    inward = np.where(past & (energy < p2), True, after_impact > p2)
    return np.where(outward, past | (energy > p2), inward) & ((th != 0) | (w != 0))
