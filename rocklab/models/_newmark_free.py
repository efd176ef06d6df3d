"""Numba: the lean time loop of :func:`~rocklab.models._newmark.run_block` for free rocking.

Free rocking (no base record, full nonlinear equation) is the case the
single-block benchmark times (issue 2 §4). Between impacts every step is the
same trapezoidal (Newmark beta = 1/4) step as in the general loop; only the way
its implicit equation is solved differs:

- predictor ``x = theta1 - theta0 = h w0 + h^2/4 (a0 + a_pred)`` with
  ``a_pred = a0 + h f'(theta0) w0`` (f' = p^2 cos c): off by ~h^4 a''/8;
- one evaluation ``a1 = f(theta0 + x)``, then ``x1 = h w0 + h^2/4 (a0 + a1)``:
  a fixed-point step of the Newmark equation, whose contraction is
  ``L = p^2 h^2 / 4``, so ``|theta0 + x1 - root| <= L/(1-L) |x1 - x|``; the step
  is accepted when that bound is below the tolerance (almost always at once),
  otherwise the iteration goes on;
- sin and cos of ``c = alpha s - theta`` are carried along with a short Taylor
  shift (:func:`sdcd`) instead of libm calls.

theta1, omega1 and a1 satisfy the Newmark relations exactly; ``a1 - f(theta1)``
is ``p^2 |x1 - x|`` (~1e-13 rad/s^2). The loop returns (without taking the
step) whenever anything else could happen in a step: theta reaching 0 (impact,
exact contact time in the general loop), |theta| >= alpha (overturning
bookkeeping), an increment too large for the Taylor shift, or slow convergence.

Kept in its own module to keep ``_newmark.py`` short; ``_newmark`` drops its
on-disk numba cache when this file is newer (numba only tracks the caller's file).
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, inline="always", fastmath={"contract"})
def sdcd(d):
    """sin d and cos d for |d| < 0.2 by the shortest Taylor form the size of d allows.

    Truncation error < 2e-17 relative. The short form (|d| < 2e-4, one step of a
    rocking block) is written as fused multiply-adds: it sits on the dependency
    chain of the time loop.
    """
    d2 = d * d
    ad = abs(d)
    if ad < 2e-4:
        # errors |d|^5/120 (relative 1.3e-17) and d^6/720
        sd = d + (d * (-1.0 / 6.0)) * d2
        cd = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24.0))
    elif ad < 3e-3:
        sd = d * (1.0 - d2 * (1.0 / 6.0) * (1.0 - d2 * (1.0 / 20.0) * (1.0 - d2 * (1.0 / 42.0))))
        cd = 1.0 - d2 * 0.5 * (1.0 - d2 * (1.0 / 12.0) * (1.0 - d2 * (1.0 / 30.0) * (1.0 - d2 * (1.0 / 56.0))))
    else:
        sd = d * (1.0 - d2 * (1.0 / 6.0) * (1.0 - d2 * (1.0 / 20.0) * (1.0 - d2 * (1.0 / 42.0) * (
            1.0 - d2 * (1.0 / 72.0) * (1.0 - d2 * (1.0 / 110.0))))))
        cd = 1.0 - d2 * 0.5 * (1.0 - d2 * (1.0 / 12.0) * (1.0 - d2 * (1.0 / 30.0) * (
            1.0 - d2 * (1.0 / 56.0) * (1.0 - d2 * (1.0 / 90.0) * (1.0 - d2 * (1.0 / 132.0))))))
    return sd, cd


@njit(cache=True, fastmath={"contract"})
def free_steps(th, w, a, sc, cc, s, step, n_steps, h, p2, alpha, cos_a, max_abs, out_th, out_w, out_e,
               n_out, countdown, out_every, e_scale):
    """Whole free-rocking steps from ``step`` on, as long as none needs the general loop.

    State in and out: theta ``th`` (rad, side ``s`` = ±1), omega ``w`` (rad/s),
    theta'' ``a`` (rad/s^2), ``sc, cc`` = sin, cos of ``alpha s - th``; the step
    counter, running max |theta|, and the output buffers (every ``out_every``-th
    step; energy above rest per unit I_O times ``e_scale``) with their fill
    count and countdown, exactly as the general loop keeps them.

    Returns
    -------
    tuple
        ``th, w, a, sc, cc, step, max_abs, n_out, countdown`` after the last step
        taken (the next step, if any, is left to the general loop).
    """
    hh2 = 0.5 * h * h
    hh4 = 0.25 * h * h
    h2 = 0.5 * h
    h3p4 = hh4 * h * p2
    mp2 = -p2
    lip = hh4 * p2 / (1.0 - hh4 * p2)  # contraction L/(1-L) of the fixed-point step
    if lip >= 0.01:
        return th, w, a, sc, cc, step, max_abs, n_out, countdown
    x = (h + h3p4 * cc) * w + hh2 * a
    while step < n_steps:
        if not abs(x) < 0.2:
            break
        sd, cd = sdcd(x)
        psc = mp2 * sc
        pcc = mp2 * cc
        a1 = psc * cd - pcc * sd  # f(theta0 + x) = -p^2 sin(c0 - x)
        base = h * w + hh4 * a
        x1 = base + hh4 * a1
        dl = x1 - x
        tol = 1e-15 * (abs(th) + h * abs(w) + h * h * abs(a)) + 1e-300
        if lip * abs(dl) > tol:
            ok = False
            for _ in range(60):
                x = x1
                if not abs(x) < 0.2:
                    break
                sd, cd = sdcd(x)
                a1 = psc * cd - pcc * sd
                x1 = base + hh4 * a1
                dl = x1 - x
                if lip * abs(dl) <= tol:
                    ok = True
                    break
            if not ok:
                break
        th1 = th + x1
        if th1 * s <= 0.0 or abs(th1) >= alpha:
            break
        # next predictor, written so that only one multiply-add follows a1
        kw = h + h3p4 * cc
        wa = w + h2 * a
        q = kw * h2 + hh2
        x = kw * wa + q * a1
        w = wa + h2 * a1
        a = a1
        th = th1
        scp = sc * cd - cc * sd
        ccp = cc * cd + sc * sd
        # theta1 = theta0 + x_eval + dl with dl ~ 1e-15: the first-order shift is exact
        if abs(dl) < 1e-8:
            sc = scp - ccp * dl
            cc = ccp + scp * dl
        else:
            sd, cd = sdcd(dl)
            sc = scp * cd - ccp * sd
            cc = ccp * cd + scp * sd
        step += 1
        ath = abs(th)
        if ath > max_abs:
            max_abs = ath
        if (step & 1023) == 0:
            # re-anchor the incremental sin/cos against rounding drift
            sc = math.sin(alpha * s - th)
            cc = math.cos(alpha * s - th)
        countdown -= 1
        if countdown == 0:
            countdown = out_every
            out_th[n_out] = th
            out_w[n_out] = w
            out_e[n_out] = (0.5 * w * w + p2 * (cc - cos_a)) * e_scale
            n_out += 1
    return th, w, a, sc, cc, step, max_abs, n_out, countdown
