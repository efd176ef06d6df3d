"""Numba kernel for many single-block runs under one record (OAS, overturning curves).

Why a specialised kernel: an OAS needs ~10^4 runs of the same record at
different scales and block sizes, each of which only has to answer "does it
overturn, and when". This kernel integrates the nonlinear single-block
equation (Čeh Eq. 1–2 / DeJong Eq. 3, the sign convention of ``simulate``)

    theta'' = -p^2 [ sin(alpha*s - theta) + u(t) cos(alpha*s - theta) ],  s = sgn(theta)

with ``u = (base acceleration)/g`` linear between record samples, by RK4 with
exact impact location (cubic Hermite root inside the step), restitution
``omega+ = eta * omega-`` at theta = 0, and a start from rest when
``|u| > tan(alpha)`` (located by linear interpolation). Early exit at
overturning; blocks that never uplift cost only the threshold scan.

Options encoded as integers (see ``_oas.py`` for the user-facing names):
``crit`` 0 = overturned at |theta| >= alpha, 1 = fallen at |theta| >= pi/2.
``free`` 0 = stop at the record end, 1 = exact energy verdict for free rocking
after the record end, 2 = integrate ``free_s`` more seconds with u = 0.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

__all__ = ["run_one", "run_batch", "run_grid"]

_REST_EPS = 1e-7  # |omega|/p below which an impact ends the motion (Zeno cut-off)


@njit(cache=True, inline="always")
def _acc(th, s, u, p2, alpha):
    a = alpha * s - th
    return -p2 * (math.sin(a) + u * math.cos(a))


@njit(cache=True)
def _rk4(th, om, s, h, ua, ub, p2, alpha):
    um = 0.5 * (ua + ub)
    k1t = om
    k1o = _acc(th, s, ua, p2, alpha)
    k2t = om + 0.5 * h * k1o
    k2o = _acc(th + 0.5 * h * k1t, s, um, p2, alpha)
    k3t = om + 0.5 * h * k2o
    k3o = _acc(th + 0.5 * h * k2t, s, um, p2, alpha)
    k4t = om + h * k3o
    k4o = _acc(th + h * k3t, s, ub, p2, alpha)
    return (th + h / 6.0 * (k1t + 2 * k2t + 2 * k3t + k4t),
            om + h / 6.0 * (k1o + 2 * k2o + 2 * k3o + k4o))


@njit(cache=True)
def _hermite_root(th0, om0, th1, om1, h):
    """Root in (0, h) of the cubic Hermite through (th0, om0) and (th1, om1)."""
    lo, hi = 0.0, 1.0
    f_lo = th0
    for _ in range(40):
        x = 0.5 * (lo + hi)
        x2 = x * x
        x3 = x2 * x
        f = ((2 * x3 - 3 * x2 + 1) * th0 + (x3 - 2 * x2 + x) * h * om0
             + (-2 * x3 + 3 * x2) * th1 + (x3 - x2) * h * om1)
        if (f > 0) == (f_lo > 0):
            lo = x
            f_lo = f
        else:
            hi = x
    return 0.5 * (lo + hi) * h


@njit(cache=True)
def _free_verdict(th, om, s, p2, alpha, eta, crit):
    """Exact fate of free rocking (no base motion) with restitution eta: True = overturns."""
    if s == 0:
        return False
    ath = abs(th)
    if crit == 0 and ath >= alpha:
        return True
    e = 0.5 * om * om + p2 * math.cos(alpha - ath)
    outward = th * om > 0
    if outward:
        if ath >= alpha or e > p2:
            return True
    elif ath > alpha and e < p2:
        return True  # beyond the top, too slow to come back over it: falls
    ke = e - p2 * math.cos(alpha)  # kinetic energy at the next impact
    return p2 * math.cos(alpha) + eta * eta * ke > p2


@njit(cache=True)
def run_one(acc, dt, scale, p, alpha, eta, crit, free, free_s, h_ph):
    """One run. Returns (overturned, t_over_s, max|theta|/alpha, n_impacts).

    ``acc`` is the record in g (shape (n,)), ``dt`` its step (s), ``scale`` a
    factor on it; ``h_ph`` the largest RK4 step in units of 1/p.
    """
    n = acc.size
    p2 = p * p
    thr = math.tan(alpha)
    lim = alpha if crit == 0 else 0.5 * math.pi
    nsub = max(1, int(math.ceil(dt * p / h_ph)))
    hn = dt / nsub
    eps = _REST_EPS * p
    th = 0.0
    om = 0.0
    s = 0
    maxth = 0.0
    nimp = 0
    n_free = int(math.ceil(free_s / dt)) if free == 2 else 0
    n_int = n - 1 + n_free
    for i in range(n_int):
        if i < n - 1:
            u0 = scale * acc[i]
            u1 = scale * acc[i + 1]
        else:
            u0 = 0.0
            u1 = 0.0
        if s == 0 and abs(u0) <= thr and abs(u1) <= thr:
            continue
        t0 = i * dt
        tau = 0.0
        guard = 0
        while tau < dt - 1e-12 * dt:
            guard += 1
            if guard > 100000:
                break
            ua = u0 + (u1 - u0) * tau / dt
            if s == 0:
                if abs(ua) > thr:
                    s = -1 if ua > 0 else 1
                else:
                    # first time in [tau, dt] where |u| exceeds the threshold (u is linear)
                    if abs(u1) <= thr:
                        break
                    target = thr if u1 > 0 else -thr
                    tau = tau + (target - ua) / (u1 - ua) * (dt - tau)
                    s = -1 if u1 > 0 else 1
                    ua = target
                th = 0.0
                om = 0.0
            h = min(hn, dt - tau)
            ub = u0 + (u1 - u0) * (tau + h) / dt
            th1, om1 = _rk4(th, om, s, h, ua, ub, p2, alpha)
            if s * th1 <= 0.0:
                if th == 0.0 and om * s <= 0.0:
                    # pushed back while starting from rest: stays at rest
                    s = 0
                    th = 0.0
                    om = 0.0
                    tau += h
                    continue
                sig = _hermite_root(th, om, th1, om1, h)
                if sig <= 0.0:
                    sig = 1e-12 * h
                uc = u0 + (u1 - u0) * (tau + sig) / dt
                thc, omc = _rk4(th, om, s, sig, ua, uc, p2, alpha)
                om = eta * omc
                th = 0.0
                nimp += 1
                tau += sig
                if abs(om) < eps:
                    s = 0
                    om = 0.0
                else:
                    s = 1 if om > 0 else -1
                continue
            th = th1
            om = om1
            tau += h
            ath = abs(th)
            if ath > maxth:
                maxth = ath
            if ath >= lim:
                return True, t0 + tau, maxth / alpha, nimp
    if free == 1 and s != 0:
        if _free_verdict(th, om, s, p2, alpha, eta, crit):
            return True, (n - 1) * dt, maxth / alpha, nimp
    return False, np.nan, maxth / alpha, nimp


@njit(cache=True, parallel=True)
def run_batch(acc, dt, scale, p, alpha, eta, crit, free, free_s, h_ph):
    """Independent runs; ``scale``, ``p``, ``alpha``, ``eta`` are arrays of shape (m,)."""
    m = scale.size
    over = np.zeros(m, dtype=np.bool_)
    tov = np.full(m, np.nan)
    mth = np.zeros(m)
    nim = np.zeros(m, dtype=np.int64)
    for k in prange(m):
        o, t, r, ni = run_one(acc, dt, scale[k], p[k], alpha[k], eta[k], crit, free, free_s, h_ph)
        over[k] = o
        tov[k] = t
        mth[k] = r
        nim[k] = ni
    return over, tov, mth, nim


@njit(cache=True, parallel=True)
def run_grid(acc, dt, scales, ps, alpha, eta, crit, free, free_s, h_ph):
    """All (scale, p) pairs: returns overturned and t_over of shape (n_scales, n_p)."""
    nl = scales.size
    ns = ps.size
    over = np.zeros((nl, ns), dtype=np.bool_)
    tov = np.full((nl, ns), np.nan)
    for k in prange(nl * ns):
        i = k // ns
        j = k % ns
        o, t, r, ni = run_one(acc, dt, scales[i], ps[j], alpha, eta, crit, free, free_s, h_ph)
        over[i, j] = o
        tov[i, j] = t
    return over, tov
