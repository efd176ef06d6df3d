"""Numba: where inside one Newmark step the block reaches a level (Čeh §3, exact contact).

:func:`contact_tau` is the length of the step that ends exactly at theta = 0
(Čeh Eq. 8–9, a cubic when the base acceleration varies linearly over the
step); :func:`cross_fraction` is where the cubic Hermite of a step reaches a
given |theta| (overturning and fall times); :func:`restitution_at` and
:func:`store_impact` apply the restitution law and fill the impact table. Used by
:func:`~rocklab.models.rocking._newmark.run_block` and the Taylor kernel.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def cross_fraction(x0, v0, x1, v1, h, level):
    """Fraction u in [0, 1] of a step where the cubic Hermite of (x, v) reaches ``level``.

    x0, v0 / x1, v1: position and velocity at the step ends (on one side, x > 0
    outward). Falls back to linear interpolation when the step started on the other
    side (an impact inside the step).
    """
    if x1 == x0:
        return 1.0
    u = min(max((level - x0) / (x1 - x0), 0.0), 1.0)
    if x0 < 0.0:
        return u
    for _ in range(20):
        u2 = u * u
        u3 = u2 * u
        x = (2 * u3 - 3 * u2 + 1) * x0 + (u3 - 2 * u2 + u) * h * v0 + (-2 * u3 + 3 * u2) * x1 + (u3 - u2) * h * v1
        dx = (6 * u2 - 6 * u) * x0 + (3 * u2 - 4 * u + 1) * h * v0 + (6 * u - 6 * u2) * x1 + (3 * u2 - 2 * u) * h * v1
        if dx <= 0.0:
            break
        du = (x - level) / dx
        u = min(max(u - du, 0.0), 1.0)
        if abs(du) < 1e-15:
            break
    return u


@njit(cache=True)
def contact_tau(th0, w0, a0, s, h, u0, u1, p2, alpha, lin):
    """Length tau in (0, h] of the Newmark step that ends exactly at theta = 0.

    G(tau) = -4 th0 - 4 w0 tau + A tau^2 + C3 tau^3 = 0 with the base acceleration
    linear over the step. C3 = 0 (free rocking, or constant ug) is the closed
    form Čeh Eq. 9, written in the cancellation-free form.
    """
    if lin:
        F0 = -p2 * alpha * s
        F1 = -p2
    else:
        F0 = -p2 * s * math.sin(alpha)
        F1 = -p2 * math.cos(alpha)
    du = (u1 - u0) / h
    A = -(a0 + F0 + F1 * u0)
    C3 = -F1 * du
    # quadratic roots (C3 ignored) as the first guess / the exact answer when C3 == 0
    if th0 == 0.0:
        # right after an impact: tau = 0 is a trivial root; G/tau = -4 w0 + A tau (+ C3 tau^2)
        tq = 4.0 * w0 / A if A != 0.0 else h
    else:
        B = -4.0 * w0
        C = -4.0 * th0
        D = B * B - 4.0 * A * C
        if D < 0.0:
            D = 0.0
        sq = math.sqrt(D)
        q = -0.5 * (B + sq) if B >= 0.0 else -0.5 * (B - sq)
        r1 = q / A if A != 0.0 else -1.0
        r2 = C / q if q != 0.0 else -1.0
        tq = h
        if 0.0 < r1 <= h * (1.0 + 1e-12):
            tq = r1
        if 0.0 < r2 <= h * (1.0 + 1e-12) and (r2 < tq or not (0.0 < r1 <= h * (1.0 + 1e-12))):
            tq = r2
    if not (0.0 < tq <= h):
        tq = min(max(tq, 0.0), h)
    if C3 == 0.0:
        return tq if tq > 0.0 else h
    # safeguarded Newton on g(tau) = G(tau)/tau^k (k = 1 when th0 == 0): bracket [lo, hi]
    lo, hi = 0.0, h
    t = tq if tq > 0.0 else 0.5 * h
    # sign of g near 0 is -s (theta starts on side s and must come back)
    for _ in range(100):
        if th0 == 0.0:
            g = -4.0 * w0 + A * t + C3 * t * t
            dg = A + 2.0 * C3 * t
        else:
            g = -4.0 * th0 - 4.0 * w0 * t + A * t * t + C3 * t * t * t
            dg = -4.0 * w0 + 2.0 * A * t + 3.0 * C3 * t * t
        if g * s < 0.0:
            lo = t
        else:
            hi = t
        tn = t - g / dg if dg != 0.0 else 0.5 * (lo + hi)
        if not (lo < tn < hi):
            tn = 0.5 * (lo + hi)
        if abs(tn - t) <= 1e-15 * h:
            t = tn
            break
        t = tn
    return t


@njit(cache=True, inline="always")
def restitution_at(eta_mode, eta_x, eta_y, n_imp, w_m):
    """eta of impact number ``n_imp`` (from 0) with pre-impact omega ``w_m`` (rad/s).

    ``eta_mode`` 0: constant ``eta_y[0]``; 1: per-impact table ``eta_y`` (the last entry
    repeats); 2: ``eta_y`` tabulated over |omega-| at ``eta_x``.
    """
    if eta_mode == 1:
        return eta_y[min(n_imp, eta_y.shape[0] - 1)]
    if eta_mode == 2:
        return np.interp(abs(w_m), eta_x, eta_y)
    return eta_y[0]


@njit(cache=True, inline="always")
def store_impact(imp, n_imp, t, w_m, w_p, e):
    """Row ``n_imp`` of the impact table ``imp`` (4, cap): t_s, omega-, omega+, eta; returns n_imp + 1."""
    if n_imp < imp.shape[1]:
        imp[0, n_imp] = t
        imp[1, n_imp] = w_m
        imp[2, n_imp] = w_p
        imp[3, n_imp] = e
    return n_imp + 1
