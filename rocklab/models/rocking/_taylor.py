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
  their times (dense output of the same order);
- the energy above rest is constant between impacts (the equation conserves it),
  so it is computed once per half-cycle.

Steps are ``p h <= P_H`` (0.2) at order 12: on B6M (3.9 s of rocking, 90
impacts) impact times agree with ``solve_ivp`` DOP853 at rtol 1e-13 within
3.5e-11 s and theta within 3e-12 rad (the Newmark kernel at dt = 1e-4 s:
2.2e-7 s, 1.2e-7 rad), at about the Newmark kernel's cost on a 1e-4 s output
grid. Free rocking only: a base record makes the right-hand side a
piecewise-linear function of time, which the Newmark kernel handles.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._newmark_contact import restitution_at, store_impact

__all__ = ["run_taylor", "ORDER", "P_H"]

#: Order of the Taylor series (terms up to tau^ORDER).
ORDER = 12
#: Largest step times p.
P_H = 0.2

_ROCKING, _REST, _OVERTURNED, _NO_UPLIFT = 0, 1, 2, 3


@njit(cache=True, inline="always", fastmath={"contract"})
def series_value(a, n, x):
    """The series ``a[0..n]`` at ``x`` (Horner)."""
    v = a[n]
    for k in range(n - 1, -1, -1):
        v = v * x + a[k]
    return v


@njit(cache=True, inline="always", fastmath={"contract"})
def series_slope(a, n, x):
    """The derivative of the series ``a[0..n]`` at ``x`` (Horner)."""
    v = n * a[n]
    for k in range(n - 1, 0, -1):
        v = v * x + k * a[k]
    return v


@njit(cache=True, fastmath={"contract"})
def _dense(a, out_th, out_w, out_e, k0, k1, out_dt, t, energy):
    """theta, omega and energy at the output samples k0 <= k < k1 from one step's series.

    Four samples per pass: their Horner chains are independent, so they overlap in the
    pipeline instead of waiting on one chain's latency.
    """
    n = ORDER
    i = k0
    while i + 4 <= k1:
        x0 = i * out_dt - t
        x1 = x0 + out_dt
        x2 = x1 + out_dt
        x3 = x2 + out_dt
        an = a[n]
        v0 = an
        v1 = an
        v2 = an
        v3 = an
        dn = n * an
        d0 = dn
        d1 = dn
        d2 = dn
        d3 = dn
        for j in range(n - 1, 0, -1):
            aj = a[j]
            jaj = j * aj
            v0 = v0 * x0 + aj
            v1 = v1 * x1 + aj
            v2 = v2 * x2 + aj
            v3 = v3 * x3 + aj
            d0 = d0 * x0 + jaj
            d1 = d1 * x1 + jaj
            d2 = d2 * x2 + jaj
            d3 = d3 * x3 + jaj
        a0 = a[0]
        out_th[i] = v0 * x0 + a0
        out_th[i + 1] = v1 * x1 + a0
        out_th[i + 2] = v2 * x2 + a0
        out_th[i + 3] = v3 * x3 + a0
        out_w[i] = d0
        out_w[i + 1] = d1
        out_w[i + 2] = d2
        out_w[i + 3] = d3
        out_e[i] = energy
        out_e[i + 1] = energy
        out_e[i + 2] = energy
        out_e[i + 3] = energy
        i += 4
    while i < k1:
        x = i * out_dt - t
        out_th[i] = series_value(a, n, x)
        out_w[i] = series_slope(a, n, x)
        out_e[i] = energy
        i += 1


@njit(cache=True, fastmath={"contract"})
def _coefficients(a, S, C, c, th, w, s, p2, alpha, n):
    """Taylor coefficients a[0..n] of theta about (th, w) on side s."""
    a[0] = th
    a[1] = w
    c0 = alpha * s - th
    S[0] = math.sin(c0)
    C[0] = math.cos(c0)
    c[0] = c0
    c[1] = -w
    a[2] = -0.5 * p2 * S[0]
    c[2] = -a[2]
    for k in range(1, n - 1):
        ss = 0.0
        cc = 0.0
        for j in range(1, k + 1):
            jc = j * c[j]
            ss += jc * C[k - j]
            cc -= jc * S[k - j]
        S[k] = ss / k
        C[k] = cc / k
        a[k + 2] = -p2 * S[k] / ((k + 1) * (k + 2))
        c[k + 2] = -a[k + 2]


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


@njit(cache=True, inline="always")
def _root(a, n, lo, hi, target, s):
    """tau in (lo, hi] where s*theta(tau) = target, with s*theta(lo) > target >= s*theta(hi)."""
    return series_root(a, n, lo, hi, target, s, 1e-15, 100)


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
    c = np.zeros(n + 1)
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
        _coefficients(a, S, C, c, th, w, s, p2, alpha, n)
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
            lo = 0.0
            if th == 0.0:
                # leaving the corner: theta ~ w tau; start the bracket where it is clearly on side s
                lo = h
                for _ in range(60):
                    lo *= 0.5
                    if s * series_value(a, n, lo) > 0.0:
                        break
            tau = _root(a, n, lo, h, 0.0, s)
        if t_over != t_over and (event == 2 or s * series_value(a, n, tau) >= alpha):
            t_over = t + _root(a, n, 0.0, tau, -alpha, -s)
        # output samples in (t, t + tau]: a counted loop of independent evaluations (vectorised)
        k_end = min(n_out, int(math.floor((t + tau) / out_dt)) + 1)
        while k_end < n_out and k_end * out_dt <= t + tau:
            k_end += 1
        while k_end > k and (k_end - 1) * out_dt > t + tau:
            k_end -= 1
        if k_end > k:
            _dense(a, out_th, out_w, out_e, k, k_end, out_dt, t, energy)
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
        th = series_value(a, n, tau)
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
