"""Reference integrator: scipy ``solve_ivp`` with terminal, direction-aware impact events.

Slow but independent of the Newmark kernel: each rocking phase about one corner
is integrated adaptively (DOP853, ``rtol = 1e-10`` by default) until the event
``theta = 0`` crossed towards the other side; the restitution law is applied
and the integration restarts from theta = 0. Same equations, sign convention,
rest and overturning rules as :mod:`._newmark`.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from ...blocks import G
from ._result import KernelResult, block_energy

__all__ = ["run_event"]


def _next_uplift(t_now, rec_t, rec_a, thr, t_stop, after=False):
    """First time >= t_now where |a| exceeds thr (linear interpolation); None if none.

    ``after``: the block just failed to leave the corner at ``t_now`` (the base only touched the
    uplift level there), so the time returned is later than ``t_now``: the crossing after it, or
    at the latest the next sample above ``thr``.
    """
    if rec_t is None:
        return None
    a_now = np.interp(t_now, rec_t, rec_a, left=0.0, right=0.0)
    if abs(a_now) > thr and not after:
        return t_now
    k = np.flatnonzero((rec_t > t_now) & (np.abs(rec_a) > thr) & (rec_t <= t_stop))
    if k.size == 0:
        return None
    k = int(k[0])
    if k == 0:
        return float(rec_t[0])
    a0, a1 = rec_a[k - 1], rec_a[k]
    t0 = max(rec_t[k - 1], t_now)
    if rec_t[k - 1] < t_now:
        a0 = a_now
    lvl = thr if a1 > 0 else -thr
    fr = (lvl - a0) / (a1 - a0) if a1 != a0 else 0.0
    tu = float(t0 + min(max(fr, 0.0), 1.0) * (rec_t[k] - t0))
    return float(rec_t[k]) if after and tu <= t_now else tu


def _phase(t, th, w, s, duration_s, ug, p2, alpha, linearized, fall_rad, ode_method, rtol, atol, max_step):
    """One rocking phase about corner ``s`` from (t s, th rad, w rad/s): ``solve_ivp`` with dense output.

    Events: 0 contact (theta = 0 towards the other side, terminal), 1 |theta| = alpha outward,
    2 |theta| = fall_rad outward (terminal); ``ug(t)`` is the base acceleration / g.
    """

    def rhs(tt, y):
        if linearized:
            return [y[1], p2 * (y[0] - alpha * s) - p2 * ug(tt)]
        c = alpha * s - y[0]
        return [y[1], -p2 * (math.sin(c) + ug(tt) * math.cos(c))]

    def contact(tt, y):
        return y[0]

    contact.terminal = True
    contact.direction = -s

    def over(tt, y):
        return y[0] - s * alpha

    over.direction = s

    def fall(tt, y):
        return y[0] - s * fall_rad

    fall.terminal = True
    fall.direction = s

    return solve_ivp(
        rhs,
        (t, duration_s),
        [th, w],
        method=ode_method,
        rtol=rtol,
        atol=atol,
        events=[contact, over, fall],
        dense_output=True,
        max_step=max_step,
    )


def run_event(
    block,
    theta0,
    omega0,
    duration_s,
    law,
    base,
    linearized,
    rest_tol,
    stop_at_rest,
    t_out,
    rtol=1e-10,
    atol=1e-13,
    ode_method="DOP853",
    fall_rad=0.5 * math.pi,
    max_impacts=100_000,
) -> KernelResult:
    """Event-driven integration on the output times ``t_out`` (n,) s; samples after a stop are dropped.

    Returns the :class:`~rocklab.models.rocking.KernelResult` of every integrator (energy from
    :func:`~rocklab.models.block_energy`, the first ``max_impacts`` impacts in the table).
    """
    alpha, p = block.alpha_rad, block.p_rad_s
    p2 = p * p
    tan_a = math.tan(alpha)
    rest_w2 = 2.0 * p2 * (math.cos(alpha - rest_tol * alpha) - math.cos(alpha))
    if base is not None:
        rec_t, rec_a = base.t_s, base.acc_m_s2 / G
        t_last_up = (
            float(rec_t[np.flatnonzero(np.abs(rec_a) > tan_a)][-1]) if np.any(np.abs(rec_a) > tan_a) else -np.inf
        )
        max_step = base.dt_s
    else:
        rec_t = rec_a = None
        t_last_up = -np.inf
        max_step = np.inf

    def ug(t):
        return 0.0 if rec_t is None else float(np.interp(t, rec_t, rec_a, left=0.0, right=0.0))

    th_out = np.full(t_out.shape, np.nan)
    w_out = np.full(t_out.shape, np.nan)
    imps: list[tuple[float, float, float, float]] = []
    t, th, w = 0.0, float(theta0), float(omega0)
    resting = th == 0.0 and w == 0.0
    s = 1.0 if (th > 0 or (th == 0 and w > 0)) else -1.0
    ever_moved = not resting
    t_over = t_fall = np.nan
    max_abs = abs(th)
    status = "rocking"
    t_end = duration_s
    after = False  # the last uplift did not leave the corner: look for the next one after it
    while t < duration_s:
        if resting:
            tu = _next_uplift(t, rec_t, rec_a, tan_a, duration_s, after)
            after = False
            if tu is None or tu >= duration_s or (stop_at_rest and t >= t_last_up):
                m = t_out >= t - 1e-12
                th_out[m] = 0.0
                w_out[m] = 0.0
                status = "rest" if ever_moved else "no_uplift"
                if stop_at_rest:
                    t_end = t
                break
            m = (t_out >= t - 1e-12) & (t_out <= tu)
            th_out[m] = 0.0
            w_out[m] = 0.0
            t = tu
            s = -1.0 if ug(tu + 1e-9) > 0 else 1.0
            th = w = 0.0
            resting = False
            ever_moved = True

        sol = _phase(t, th, w, s, duration_s, ug, p2, alpha, linearized, fall_rad, ode_method, rtol, atol, max_step)
        t_b = float(sol.t[-1])
        m = (t_out >= t - 1e-12) & (t_out <= t_b)
        if m.any():
            y = sol.sol(t_out[m])
            th_out[m], w_out[m] = y[0], y[1]
        max_abs = max(max_abs, float(np.max(np.abs(sol.y[0]))))
        if sol.t_events[1].size and not np.isfinite(t_over):
            t_over = float(sol.t_events[1][0])
        if sol.t_events[2].size:
            t_fall = float(sol.t_events[2][0])
            max_abs = max(max_abs, fall_rad)
            status = "overturned"
            t_end = t_fall
            break
        if sol.t_events[0].size:
            ti = float(sol.t_events[0][0])
            w_m = float(sol.y_events[0][0][1])
            # lifted from rest and back at the same instant: the base only touched tan(alpha) (e.g. a
            # record scaled to a_p = a_p,min exactly); without this the same phase restarts forever
            stuck = ti <= t and th == 0.0 and w == 0.0
            e = law(w_m, len(imps))
            w_p = e * w_m
            imps.append((ti, w_m, w_p, e))
            t, th = ti, 0.0
            u = ug(ti)
            s_base = (-1.0 if u > 0 else 1.0) if abs(u) > tan_a else 0.0
            if w_p * w_p <= rest_w2 and (s_base == 0.0 or stuck):
                resting = True
                after = stuck
                w = 0.0
                continue
            w = w_p
            s = (1.0 if w_p > 0 else -1.0) if w_p != 0.0 else s_base
            continue
        status = "rocking"
        break
    keep = t_out <= t_end + 1e-12
    th_k, w_k = th_out[keep], w_out[keep]
    imp = np.ascontiguousarray(np.array(imps, float).reshape(-1, 4).T[:, :max_impacts])
    E = block_energy(block, th_k, w_k, linearized)
    return KernelResult(t_out[keep], th_k, w_k, E, imp, len(imps), status, t_over, t_fall, max_abs)
