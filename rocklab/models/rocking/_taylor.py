"""Numba: free rocking by Taylor series between impacts (``simulate(method="taylor")``).

Between two impacts a free block obeys ``theta'' = -p^2 sin(alpha s - theta)``
(Čeh Eq. 1-2 without base motion): an analytic solution, so long steps of a
high-order method cost far less than many short trapezoidal ones. Each step
builds the Taylor series of theta about the step's start to order
:data:`ORDER` by the recurrences of sin and cos of a series
(``k S_k = sum_j j c_j C_{k-j}``, ``k C_k = -sum_j j c_j S_{k-j}``,
``c = alpha s - theta``), then

- the impact is the root of the polynomial theta(tau) = 0 (Newton, bracketed),
  so contact stays exact: the step ends there and the restitution law applies;
- the output samples inside the step are the polynomial and its derivative at
  their times (dense output of the same order), evaluated in blocks of samples by
  :mod:`._taylor_dense`;
- the energy above rest is constant between impacts (the equation conserves it),
  so it is computed once per half-cycle.

Steps are ``p h <= P_H`` (0.2) at order 12: on B6M (3.9 s of rocking, 90
impacts) impact times agree with ``solve_ivp`` DOP853 at rtol 1e-13 within
3.5e-11 s and theta within 3e-12 rad (the Newmark kernel at dt = 1e-4 s:
2.2e-7 s, 1.2e-7 rad), at half the Newmark kernel's cost on a 1e-4 s output
grid (0.21 ms against 0.41 ms, ``benchmarks/bench_single.py``). Longer steps
are not free: at ``p h <= 0.3`` B6M's impact times move by 1.5e-11 s. Free
rocking only: a base record makes the right-hand side a piecewise-linear
function of time, which the Newmark kernel handles.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._newmark_contact import restitution_at, store_impact
from ._taylor_dense import block_scratch, blocks_fit, dense_blocks, dense_samples, series_slope, series_value

__all__ = ["run_taylor", "ORDER", "P_H"]

#: Order of the Taylor series (terms up to tau^ORDER).
ORDER = 12
#: Largest step times p.
P_H = 0.2

_ROCKING, _REST, _OVERTURNED, _NO_UPLIFT = 0, 1, 2, 3


@njit(cache=True)
def _recurrence_factors(p2, n):
    """``inv[k] = 1/k`` and ``q[k] = p2 / ((k + 1)(k + 2))`` (k < n) of :func:`_coefficients`: one
    multiplication each per term instead of a division."""
    inv = np.zeros(n)
    q = np.zeros(n)
    for k in range(1, n):
        inv[k] = 1.0 / k
        q[k] = p2 / ((k + 1) * (k + 2))
    return inv, q


@njit(cache=True, fastmath={"contract"})
def _coefficients(a, S, C, jc, th, w, s, p2, alpha, n, inv, q):
    """Taylor coefficients a[0..n] of theta about (th, w) on side s.

    ``S, C``: the series of sin c and cos c (c = alpha s - theta); ``jc[j] = j c_j``;
    ``inv, q`` from :func:`_recurrence_factors`.
    """
    a[0] = th
    a[1] = w
    c0 = alpha * s - th
    S[0] = math.sin(c0)
    C[0] = math.cos(c0)
    jc[1] = -w
    a[2] = -0.5 * p2 * S[0]
    jc[2] = -2.0 * a[2]
    for k in range(1, n - 1):
        # two partial sums per series: half the dependent chain of one
        s0 = 0.0
        s1 = 0.0
        c0_ = 0.0
        c1_ = 0.0
        j = 1
        while j + 1 <= k:
            s0 += jc[j] * C[k - j]
            c0_ -= jc[j] * S[k - j]
            s1 += jc[j + 1] * C[k - j - 1]
            c1_ -= jc[j + 1] * S[k - j - 1]
            j += 2
        if j == k:
            s0 += jc[j] * C[0]
            c0_ -= jc[j] * S[0]
        S[k] = (s0 + s1) * inv[k]
        C[k] = (c0_ + c1_) * inv[k]
        a[k + 2] = -q[k] * S[k]
        jc[k + 2] = -(k + 2) * a[k + 2]


@njit(cache=True, fastmath={"contract"})
def series_root(a, n, lo, hi, target, s, rel_tol, max_iter):
    """tau in (lo, hi] where s*P(tau) = target (P: the series ``a[0..n]``), with s*P(lo) > target >=
    s*P(hi): Newton steps kept inside a shrinking bracket, to ``rel_tol`` of tau or of the bracket,
    ``max_iter`` steps at most."""
    f_lo = s * series_value(a, n, lo) - target
    f_hi = s * series_value(a, n, hi) - target
    x = lo + (hi - lo) * f_lo / (f_lo - f_hi) if f_lo != f_hi else hi
    for _ in range(max_iter):
        f = s * series_value(a, n, x) - target
        if f > 0.0:
            lo = x
        else:
            hi = x
        d = s * series_slope(a, n, x)
        xn = x - f / d if d != 0.0 else 0.5 * (lo + hi)
        if not (lo < xn < hi):
            xn = 0.5 * (lo + hi)
        if abs(xn - x) <= rel_tol * max(abs(x), 1e-300) or hi - lo <= rel_tol * hi:
            x = xn
            break
        x = xn
    return x


@njit(cache=True, inline="always", fastmath={"contract"})
def _value_slope(a, n, x):
    """The series ``a[0..n]`` and its derivative at ``x`` (one Horner pass)."""
    v = a[n]
    d = 0.0
    for k in range(n - 1, -1, -1):
        d = d * x + v
        v = v * x + a[k]
    return v, d


@njit(cache=True, fastmath={"contract"})
def _root(a, n, lo, hi, target, s):
    """tau in (lo, hi] where s*theta(tau) = target, with s*theta(lo) > target >= s*theta(hi).

    Newton steps from the secant inside a shrinking bracket. Once a step is below 1e-9 of tau,
    one more step has converged (quadratically, to ~1e-18 of tau) and the run stops: a
    tolerance on the step alone would chase the rounding of theta, which near a small-amplitude
    impact moves tau by more than 1e-15 of itself, for dozens of iterations.
    """
    f_lo = s * series_value(a, n, lo) - target
    f_hi = s * series_value(a, n, hi) - target
    x = lo + (hi - lo) * f_lo / (f_lo - f_hi) if f_lo != f_hi else hi
    last = False
    for _ in range(100):
        v, d = _value_slope(a, n, x)
        f = s * v - target
        if f > 0.0:
            lo = x
        else:
            hi = x
        d = s * d
        xn = x - f / d if d != 0.0 else 0.5 * (lo + hi)
        small = abs(xn - x) <= 1e-9 * abs(x)
        if not (lo < xn < hi):
            if small:
                return x  # a step to the bracket's end: x is already at the rounding of theta
            xn = 0.5 * (lo + hi)
        elif last:
            return xn
        last = small
        if hi - lo <= 1e-15 * hi:
            return xn
        x = xn
    return x


@njit(cache=True, fastmath={"contract"})
def run_taylor(
    p, alpha, th0, w0, n_out, out_dt, eta_mode, eta_x, eta_y, rest_w2, stop_at_rest, imp_cap, fall_rad, e_scale
):
    """Free rocking from (th0, w0) on the output grid ``k out_dt``, k < n_out.

    Returns the same tuple as :func:`~rocklab.models.rocking._newmark.run_single`:
    ``t, theta, omega, energy`` (energy above rest times ``e_scale``), ``imp`` (4, k),
    ``n_imp``, ``status``, ``t_over``, ``t_fall``, ``max_abs``.
    """
    n = ORDER
    p2 = p * p
    cos_a = math.cos(alpha)
    h_max = P_H / p
    a = np.zeros(n + 1)
    S = np.zeros(n + 1)
    C = np.zeros(n + 1)
    jc = np.zeros(n + 1)
    inv, qk = _recurrence_factors(p2, n)
    blocks = blocks_fit(p, out_dt)
    binom, ab, u, vb, db = block_scratch(n, out_dt)
    # uninitialised: the grid after rest is never written (zeroing all of it cost a quarter of a
    # B6M run); the samples the loop does not write are zeroed at the end
    out_th = np.empty(n_out)
    out_w = np.empty(n_out)
    out_e = np.empty(n_out)
    imp = np.empty((4, imp_cap))
    n_imp = 0
    t_over = np.nan
    t_fall = np.nan
    th = th0
    w = w0
    max_abs = abs(th)
    k = 0  # next output sample
    k_dense = 0  # samples written from the series
    t = 0.0
    if th != 0.0:
        s = 1.0 if th > 0.0 else -1.0
    elif w != 0.0:
        s = 1.0 if w > 0.0 else -1.0
    else:
        s = 0.0
    status = _ROCKING if s != 0.0 else _NO_UPLIFT
    energy = (0.5 * w * w + p2 * (math.cos(alpha - abs(th)) - cos_a)) * e_scale
    t_end = (n_out - 1) * out_dt
    while s != 0.0 and k < n_out:
        _coefficients(a, S, C, jc, th, w, s, p2, alpha, n, inv, qk)
        h = min(h_max, t_end - t) if t < t_end else h_max
        if h <= 0.0:
            h = h_max
        th_h = series_value(a, n, h)
        event = 0  # 1 impact, 2 fall
        tau = h
        if s * th_h >= fall_rad:
            event = 2
            tau = _root(a, n, 0.0, h, -fall_rad, -s)  # s*theta rises through fall_rad
        elif s * th_h <= 0.0:
            event = 1
            if th == 0.0:
                # leaving the corner: theta = tau (w + a_2 tau + ...), and the bracket
                # of the series in parentheses starts at tau = 0, where it is w (on side s)
                tau = _root(a[1:], n - 1, 0.0, h, 0.0, s)
            else:
                tau = _root(a, n, 0.0, h, 0.0, s)
        if t_over != t_over and (event == 2 or (event == 0 and s * th_h >= alpha)):
            t_over = t + _root(a, n, 0.0, tau, -alpha, -s)
        # output samples in (t, t + tau]: a counted loop of independent evaluations (vectorised)
        k_end = min(n_out, int(math.floor((t + tau) / out_dt)) + 1)
        while k_end < n_out and k_end * out_dt <= t + tau:
            k_end += 1
        while k_end > k and (k_end - 1) * out_dt > t + tau:
            k_end -= 1
        if k_end > k:
            if blocks:
                dense_blocks(a, n, out_th, out_w, out_e, k, k_end, out_dt, t, energy, binom, ab, u, vb, db)
            else:
                dense_samples(a, n, out_th, out_w, out_e, k, k_end, out_dt, t, energy)
            k = k_end
            k_dense = k
        # the turning point inside the step (omega = 0) sets max |theta|: there the (conserved)
        # energy is all potential, p^2 (cos(alpha - |theta|) - cos(alpha))
        w_tau = series_slope(a, n, tau)
        if s * w >= 0.0 and s * w_tau < 0.0:
            q = min(1.0, cos_a + energy / (e_scale * p2))
            m = alpha - math.acos(q)
            if m > max_abs:
                max_abs = m
        # at an impact theta(tau) is 0 (set below); a full step ends at th_h
        th = th_h if event == 0 else series_value(a, n, tau)
        w = w_tau
        t = t + tau
        if abs(th) > max_abs and event != 1:
            max_abs = abs(th)
        if event == 2:
            t_fall = t
            status = _OVERTURNED
            break
        if event == 1:
            w_m = w
            e = restitution_at(eta_mode, eta_x, eta_y, n_imp, w_m)
            w_p = e * w_m
            n_imp = store_impact(imp, n_imp, t, w_m, w_p, e)
            th = 0.0
            w = w_p
            energy = 0.5 * w * w * e_scale
            if w_p * w_p <= rest_w2:
                status = _REST
                s = 0.0
                w = 0.0
                energy = 0.0
                if stop_at_rest and k < n_out:
                    k += 1  # one sample at rest, as the Newmark kernel's output ends
                break
            s = 1.0 if w_p > 0.0 else -1.0
        if k >= n_out:
            break
    if status == _NO_UPLIFT:
        k = 1 if stop_at_rest else n_out
    elif status == _REST and not stop_at_rest:
        k = n_out  # the rest of the grid is at rest (zeros)
    for i in range(k_dense, k):
        out_th[i] = 0.0
        out_w[i] = 0.0
        out_e[i] = 0.0
    tt = np.empty(k)
    for i in range(k):
        tt[i] = i * out_dt
    if 4 * k >= n_out:
        # views: copying a third of B6M's 10 s grid cost a tenth of its run; the memory kept is at
        # most 4x the output's, and the run needed the whole grid anyway
        out_th, out_w, out_e = out_th[:k], out_w[:k], out_e[:k]
    else:
        out_th, out_w, out_e = out_th[:k].copy(), out_w[:k].copy(), out_e[:k].copy()
    return (
        tt,
        out_th,
        out_w,
        out_e,
        np.ascontiguousarray(imp[:, : min(n_imp, imp_cap)]),
        n_imp,
        status,
        t_over,
        t_fall,
        max_abs,
    )
