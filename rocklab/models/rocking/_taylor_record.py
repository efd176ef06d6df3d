"""Numba: rocking under a record by a Taylor series per record interval, with exact events.

Between two record samples the base acceleration is linear in time, ``ug(tau) = u0 + du tau``
(the same interpolation as the Newmark kernel), so the equation of motion (Čeh Eq. 1-2)

    theta'' = -p^2 [sin(alpha s - theta) + ug cos(alpha s - theta)]

is analytic on the whole interval and its Taylor series about the interval's start is
built exactly by the recurrences of sin and cos of a series (``k S_k = sum_j j c_j
C_{k-j}``, ``k C_k = -sum_j j c_j S_{k-j}``, ``c = alpha s - theta``) plus the product
``ug C``, whose series has two terms per coefficient. One step covers one record interval
(split when ``p dt`` exceeds ``max_p_h``); its order comes from ``p h`` (the series' terms
fall like ``(p h)^k / k!``), so the truncation error is below a tolerance chosen by the
caller. Events are roots of the step's polynomial, not of a discretisation:

- impact: ``theta(tau) = 0`` (Newton, bracketed), then the restitution;
- overturning: ``|theta| = fall_rad`` outward, also at an apex inside the step (where omega
  changes sign over a step, its root is the turning point, and a trough at the corner is an
  impact inside the step);
- uplift from rest: ``|ug| = tan(alpha)`` on the linear interval, in closed form.

Safe stop (optional, for verdicts only): with E = omega^2/2 + p^2 cos(c) and the excess energy over
rest on the corner K = E - p^2 cos(alpha) (>= 0 while |theta| <= alpha, = omega^2/2 at theta = 0),
the equation gives dK/dt = -p^2 ug cos(c) omega, and omega^2 <= 2K, so d sqrt(K)/dt <= p^2 |ug| / sqrt(2);
an impact multiplies K by eta^2 and rest keeps K = 0. Reaching |theta| = alpha needs K >= p^2 (1 - cos
alpha), and so does overturning in free rocking after the record (:func:`free_rocking_overturns`). So at
a record sample where sqrt(K) + p^2 / sqrt(2) * int |ug| dt over the rest of the record stays below
p sqrt(1 - cos(alpha)), the block can neither reach alpha nor overturn later: the run stops there with
status 4 (safe), its verdict known without the rest of the record.

Same rest and overturning rules as the Newmark batch kernel
(:func:`~rocklab.models.rocking._newmark.run_batch`): rest when ``omega+^2 <= rest_w2``
with the base below uplift, the run ends at rest after the record's last sample above
uplift, and at ``fall_rad``. One difference, where the Newmark kernel has no rule: a
tiny rebound while the base holds the block up (``|ug| > tan(alpha)``) leaves the block
on the corner the base pushes it to, instead of a cascade of ever shorter flights.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ...blocks import G
from ._newmark_lean import sdcd
from ._taylor import series_root, series_slope, series_value

__all__ = ["run_taylor_record", "order_for", "safe_tail", "safe_bound", "MAX_ORDER"]

#: Highest order a step may use.
MAX_ORDER = 40

_ROCKING, _REST, _OVERTURNED, _NO_UPLIFT, _SAFE = 0, 1, 2, 3, 4


def order_for(p_h, tol: float) -> np.ndarray:
    """Smallest order n >= 4 with ``(p h)^(n+1) / (n+1)! <= tol`` (the first neglected term), per entry.

    Parameters
    ----------
    p_h : array_like
        Step times p (dimensionless).
    tol : float
        Bound on the first neglected term relative to the motion's scale.

    Returns
    -------
    ndarray of int64, capped at :data:`MAX_ORDER`.
    """
    x = np.atleast_1d(np.asarray(p_h, float))
    out = np.full(x.shape, MAX_ORDER, np.int64)
    term = x.copy()  # (p h)^1 / 1!
    done = np.zeros(x.shape, bool)
    for n in range(1, MAX_ORDER + 1):
        term = term * x / (n + 1)  # (p h)^(n+1) / (n+1)!
        hit = ~done & (term <= tol) & (n >= 4)
        out[hit] = n
        done |= hit
        if n >= 4 and done.all():
            break
    return out


@njit(cache=True, inline="always")
def safe_bound(excess, tail_k, k_alpha, c_tail, p2, room_share):
    """The safe stop's test (module docstring): True when sqrt(``excess``) (K, the energy over rest on
    the corner) plus ``c_tail`` times ``tail_k`` (the |acc| integral over the rest of the record) stays
    below ``k_alpha`` = p sqrt(1 - cos alpha), the squared room cut to ``room_share`` and K's rounding
    (1e-12 p^2) counted against it."""
    room = k_alpha - c_tail * tail_k
    return room > 0.0 and excess + 1e-12 * p2 < room * room * room_share


def safe_tail(acc, dt_s: float) -> np.ndarray:
    """Per sample k, the integral of |acc| from sample k to the last one (acc's unit times s), acc linear between
    samples, rounded up.

    Parameters
    ----------
    acc : array_like, shape (n,)
        Samples of the (piecewise linear) base acceleration.
    dt_s : float
        Sample interval, s.

    Returns
    -------
    ndarray, shape (n,)
        Non-increasing, 0 at the last sample.
    """
    a = np.asarray(acc, float)
    a0, a1 = np.abs(a[:-1]), np.abs(a[1:])
    same = a[:-1] * a[1:] >= 0.0
    total = a0 + a1
    # an interval that crosses zero holds two triangles: (a0^2 + a1^2) / (2 (|a0| + |a1|)) dt
    cross = np.divide(a0 * a0 + a1 * a1, total, out=np.zeros_like(total), where=total > 0)
    seg = 0.5 * np.where(same, total, cross) * float(dt_s)
    out = np.zeros(a.size)
    out[:-1] = np.cumsum(seg[::-1])[::-1]
    return out * (1.0 + 1e-12)  # rounding of the sums stays on the safe side


#: 1/k and 1/((k+1)(k+2)): multiplications instead of divisions in the recurrence's dependency chain.
_INV_K = np.array([0.0] + [1.0 / k for k in range(1, MAX_ORDER + 1)])
_INV_K12 = np.array([1.0 / ((k + 1) * (k + 2)) for k in range(MAX_ORDER + 1)])


@njit(cache=True, inline="always", fastmath={"contract"}, error_model="numpy")
def _coefficients(a, S, C, th, w, p2, sc0, cc0, u0, du, n):
    """Taylor coefficients a[0..n] of theta about (th, w) with ug = u0 + du tau; sc0, cc0 = sin, cos of
    c = alpha s - th."""
    a[0] = th
    a[1] = w
    S[0] = sc0
    C[0] = cc0
    a[2] = -0.5 * p2 * (sc0 + u0 * cc0)
    for k in range(1, n - 1):
        ss = 0.0
        cc = 0.0
        for j in range(1, k + 1):
            jc = j * a[j]  # c_j = -theta_j for j >= 1
            ss -= jc * C[k - j]
            cc += jc * S[k - j]
        ik = _INV_K[k]
        S[k] = ss * ik
        C[k] = cc * ik
        a[k + 2] = -p2 * _INV_K12[k] * (S[k] + u0 * C[k] + du * C[k - 1])


@njit(cache=True, inline="always")
def _root(a, n, lo, hi, target, s):
    """tau in [lo, hi] where s*P(tau) = target, with s*P(lo) > target >= s*P(hi) (P: series ``a``);
    to 2e-16 relative (the reference's exact impacts), 200 steps at most."""
    return series_root(a, n, lo, hi, target, s, 2e-16, 200)


@njit(cache=True, fastmath={"contract"})
def _turn(a, da, n, lo, hi, s):
    """Where omega = 0 between lo and hi (s*omega > 0 at lo, <= 0 at hi; or the reverse): the root of
    the derivative series ``da`` (filled here from ``a``)."""
    for j in range(n):
        da[j] = (j + 1) * a[j + 1]
    if s * series_value(da, n - 1, lo) > 0.0:
        return _root(da, n - 1, lo, hi, 0.0, s)
    return _root(da, n - 1, lo, hi, 0.0, -s)


@njit(cache=True, fastmath={"contract"})
def _step_event(a, da, n, h, th, w, s, fall_rad, y_h, w_h):
    """First event of one step's polynomial on (0, h]: (kind, tau); kind 0 none, 1 impact, 2 fall.

    ``y_h``, ``w_h``: s*theta and s*omega at h. Where omega keeps its sign over the step theta is
    monotone and only the ends matter; where it changes sign, the turning point (a root of omega)
    is checked too: an apex beyond ``fall_rad``, or a trough at or below 0 (an impact inside the step).
    """
    w0 = s * w
    if y_h >= fall_rad:
        return 2, _root(a, n, 0.0, h, -fall_rad, -s)
    if y_h <= 0.0:
        if w0 > 0.0:
            # up and back down within the step: the apex may pass fall_rad, the impact lies after it
            top = _turn(a, da, n, 0.0, h, s)
            y_top = s * series_value(a, n, top)
            if y_top >= fall_rad:
                return 2, _root(a, n, 0.0, top, -fall_rad, -s)
            if y_top <= 0.0:
                return 1, 0.0  # never left the corner
            return 1, _root(a, n, top, h, 0.0, s)
        if th == 0.0:
            return 1, 0.0  # at the corner and not leaving it
        return 1, _root(a, n, 0.0, h, 0.0, s)
    if w0 > 0.0 and w_h < 0.0:
        top = _turn(a, da, n, 0.0, h, s)
        if s * series_value(a, n, top) >= fall_rad:
            return 2, _root(a, n, 0.0, top, -fall_rad, -s)
    elif w0 < 0.0 and w_h > 0.0:
        low = _turn(a, da, n, 0.0, h, s)
        if s * series_value(a, n, low) <= 0.0:
            return 1, _root(a, n, 0.0, low, 0.0, s)
    return 0, h


@njit(cache=True)
def _last_over(acc, thr):
    """Index of the last sample with |acc| > thr; -1 if none."""
    for k in range(acc.shape[0] - 1, -1, -1):
        if abs(acc[k]) > thr:
            return k
    return -1


@njit(cache=True, fastmath={"contract"})
def _segment(k, acc, t0, dta, duration, fac):
    """Segment k of the time axis: (t_start, length, ug at start, slope); k = -1 before the record,
    k = n - 1 after it (ug = 0), 0 <= k < n - 1 the record intervals, all clipped to [0, duration]."""
    n = acc.shape[0]
    if k < 0:
        ta, tb = 0.0, t0
        u_a, du = 0.0, 0.0
    elif k >= n - 1:
        ta, tb = t0 + (n - 1) * dta, duration
        u_a, du = 0.0, 0.0
    else:
        ta, tb = t0 + k * dta, t0 + (k + 1) * dta
        du = (acc[k + 1] - acc[k]) * fac / dta
        u_a = acc[k] * fac
    if tb > duration:
        tb = duration
    if ta < 0.0:
        u_a += du * (0.0 - ta)
        ta = 0.0
    return ta, tb - ta, u_a, du


@njit(cache=True, fastmath={"contract"})
def run_one(p, alpha, eta, scale, th0, w0, acc, t0, dta, duration, order, max_p_h, rest_w2, fall_rad, tail):
    """One block under ``acc * scale`` (m/s^2, samples every ``dta`` s from ``t0``) until ``duration`` s.

    ``tail``: empty, or per sample k a bound on the integral of |acc| from sample k to the record's end
    (:func:`safe_tail`): the run then stops (status 4) at the first record sample where the energy the rest of
    the record can give cannot lift the block to ``alpha`` (the module docstring's safe stop).

    Returns (status, t_over s, theta_end rad, omega_end rad/s, t_end s, n_impacts, max |theta| rad).
    """
    n = order
    p2 = p * p
    tan_a = math.tan(alpha)
    fac = scale / G
    a = np.zeros(MAX_ORDER + 1)
    da = np.zeros(MAX_ORDER + 1)
    S = np.zeros(MAX_ORDER + 1)
    C = np.zeros(MAX_ORDER + 1)
    k_last = _last_over(acc, tan_a / abs(fac)) if fac != 0.0 else -1
    t_last_up = t0 + k_last * dta if k_last >= 0 else -np.inf
    th = th0
    w = w0
    resting = th == 0.0 and w == 0.0
    ever_moved = not resting
    s = 1.0 if (th > 0.0 or (th == 0.0 and w > 0.0)) else -1.0
    status = _ROCKING
    t_over = np.nan
    n_imp = 0
    max_abs = abs(th)
    t = 0.0
    n_acc = acc.shape[0]
    sin_a = math.sin(alpha)
    cos_a = math.cos(alpha)
    sc = math.sin(alpha * s - th)
    cc = math.cos(alpha * s - th)
    n_steps = 0
    L_prev = -1.0
    n_sub = 1
    h_sub = 0.0
    # the safe stop (module docstring): sqrt(K) + c_tail * tail[k] < sqrt(K_alpha), K the excess energy
    k_alpha = math.sqrt(p2 * (1.0 - cos_a))
    c_tail = p2 * abs(fac) / math.sqrt(2.0)
    check = tail.shape[0] == n_acc
    for k in range(-1, n_acc):
        ta, L, u_a, du = _segment(k, acc, t0, dta, duration, fac)
        if L <= 0.0:
            continue
        # (a rest there ends the run anyway; past alpha, with fall_rad > alpha, the bound does not hold)
        if check and k >= 0 and not (resting and ta >= t_last_up) and abs(th) < alpha:
            excess = 0.0 if resting else 0.5 * w * w + p2 * (cc - cos_a)
            if safe_bound(excess, tail[k], k_alpha, c_tail, p2, 1.0 - 1e-9):  # margin above the rounding of K
                t = ta
                status = _SAFE
                break
        if L != L_prev:  # the record's intervals share one length: its division is done once
            n_sub = max(1, int(math.ceil(p * L / max_p_h - 1e-12)))
            h_sub = L / n_sub
            L_prev = L
        tl = 0.0
        stall = 0
        while L - tl > 1e-13 * L:
            t = ta + tl
            u0 = u_a + du * tl
            if resting:
                if t >= t_last_up:
                    status = _REST
                    break
                u1 = u_a + du * L
                if abs(u0) > tan_a:
                    tu = tl
                    ud = u0
                elif abs(u1) > tan_a:
                    thr = tan_a if u1 > 0.0 else -tan_a
                    tu = tl + (thr - u0) / du
                    tu = min(max(tu, tl), L)
                    ud = u1
                else:
                    tl = L
                    break
                tl = tu
                resting = False
                ever_moved = True
                s = -1.0 if ud > 0.0 else 1.0
                th = 0.0
                w = 0.0
                sc = s * sin_a
                cc = cos_a
                stall += 1
                if stall > 50:  # grazing the uplift level without leaving: stay at rest this segment
                    resting = True
                    tl = L
                continue
            h = min(h_sub * (1.0 + 1e-12), L - tl)
            n_steps += 1
            if (n_steps & 31) == 0:  # re-anchor the carried sin/cos against rounding drift
                sc = math.sin(alpha * s - th)
                cc = math.cos(alpha * s - th)
            _coefficients(a, S, C, th, w, p2, sc, cc, u0, du, n)
            y_h = s * series_value(a, n, h)
            w_h = s * series_slope(a, n, h)
            w_s = s * w
            if 0.0 < y_h < fall_rad and not ((w_s > 0.0 and w_h < 0.0) or (w_s < 0.0 and w_h > 0.0)):
                kind, tau = 0, h  # the common step: no root on it (what _step_event finds there too)
            else:
                kind, tau = _step_event(a, da, n, h, th, w, s, fall_rad, y_h, w_h)
            if t_over != t_over and fall_rad > alpha:
                kind_a, tau_a = _step_event(a, da, n, h, th, w, s, alpha, y_h, w_h)
                if kind_a == 2:
                    t_over = ta + tl + tau_a
            if kind == 0:
                th_n = s * y_h
                w_n = s * w_h
            else:
                th_n = series_value(a, n, tau)
                w_n = series_slope(a, n, tau)
            if kind == 0:
                d = th_n - th
                if abs(d) < 0.2:
                    sd, cd = sdcd(d)  # c = alpha s - theta falls by d
                    sc, cc = sc * cd - cc * sd, cc * cd + sc * sd
                else:
                    sc = math.sin(alpha * s - th_n)
                    cc = math.cos(alpha * s - th_n)
                th = th_n
                w = w_n
                tl += tau
                m = abs(th)
                if m > max_abs:
                    max_abs = m
                continue
            if kind == 2:
                if t_over != t_over:
                    t_over = ta + tl + tau
                th = s * fall_rad
                w = w_n
                max_abs = max(max_abs, fall_rad)
                status = _OVERTURNED
                break
            # impact
            tl += tau
            n_imp += 1
            if tau <= 0.0:
                stall += 1
            else:
                stall = 0
            w_p = eta * w_n
            th = 0.0
            u_i = u_a + du * tl
            s_base = (-1.0 if u_i > 0.0 else 1.0) if abs(u_i) > tan_a else 0.0
            if w_p * w_p <= rest_w2 or stall > 50:
                if s_base == 0.0 or stall > 50:
                    # at rest; or held at the uplift level without leaving the corner (the base
                    # grazes tan(alpha)): at rest too, and the resting branch ends the segment
                    resting = True
                    w = 0.0
                    continue
                if w_p * s_base <= 0.0:
                    w_p = 0.0
                s = s_base
                w = w_p
                sc = s * sin_a
                cc = cos_a
                continue
            s = 1.0 if w_p > 0.0 else -1.0
            w = w_p
            sc = s * sin_a
            cc = cos_a
        if status != _ROCKING:
            break
    if status == _OVERTURNED:
        return status, t_over, th, w, t_over, n_imp, max_abs
    if status == _SAFE:
        return status, t_over, (0.0 if resting else th), (0.0 if resting else w), t, n_imp, max_abs
    if status == _REST or resting:
        return (_REST if ever_moved else _NO_UPLIFT), t_over, 0.0, 0.0, t, n_imp, max_abs
    return _ROCKING, t_over, th, w, duration, n_imp, max_abs


@njit(cache=True, parallel=True)
def run_taylor_record(p, alpha, eta, scale, th0, w0, acc, t0, dta, duration, order, max_p_h, rest_tol, fall_rad, tail):
    """m independent blocks in parallel by :func:`run_one` (summaries only; see ``simulate_batch``); ``tail``
    empty or :func:`safe_tail` of ``acc`` (the safe stop).

    Returns ``status`` (int8), ``t_over``, ``theta_end``, ``omega_end``, ``t_end``, ``n_imp``, ``max_abs``, each (m,).
    """
    m = p.shape[0]
    status = np.zeros(m, np.int8)
    t_over = np.empty(m)
    th_end = np.empty(m)
    w_end = np.empty(m)
    t_end = np.empty(m)
    nimp = np.zeros(m, np.int64)
    mx = np.empty(m)
    for i in prange(m):
        a = alpha[i]
        p2 = p[i] * p[i]
        rest_w2 = 2.0 * p2 * (math.cos(a - rest_tol * a) - math.cos(a))
        r = run_one(
            p[i],
            a,
            eta[i],
            scale[i],
            th0[i],
            w0[i],
            acc,
            t0,
            dta,
            duration,
            order[i],
            max_p_h,
            rest_w2,
            fall_rad[i],
            tail,
        )
        status[i] = r[0]
        t_over[i] = r[1]
        th_end[i] = r[2]
        w_end[i] = r[3]
        t_end[i] = r[4]
        nimp[i] = r[5]
        mx[i] = r[6]
    return status, t_over, th_end, w_end, t_end, nimp, mx
