"""Numba: the lean time loop of :func:`~rocklab.models.rocking._newmark.run_block` for free rocking.

Free rocking (no base record, full nonlinear equation) is the case the
single-block benchmark times (issue 2 §4). Between impacts every step is the
same trapezoidal (Newmark beta = 1/4) step as in the general loop; only the way
its implicit equation is solved differs:

- predictor ``x = theta1 - theta0 = h w0 + h^2/4 (a0 + a_pred)`` with
  ``a_pred = a0 + h f'(theta0) w0`` (f' = p^2 cos c): off by ~h^4 a''/8;
- one evaluation ``a1 = f(theta0 + x)``, then ``x1 = h w0 + h^2/4 (a0 + a1)``:
  a fixed-point step of the Newmark equation, whose contraction is
  ``L = p^2 h^2 / 4``, so ``|theta0 + x1 - root| <= L/(1-L) |x1 - x|``; the step
  is accepted when that bound is below ``1e-15 (|theta0| + |x|)`` (almost always
  at once), otherwise the iteration goes on;
- ``-p^2 sin c`` and ``-p^2 cos c`` (``c = alpha s - theta``) are carried at an
  anchor, the last evaluation point, and shifted to the next one by their
  Taylor series (no libm call; exact sin/cos every 1024 steps against drift).
  For one step of a rocking block (|shift| < 2e-4) the series is multiplied out
  and evaluated by Estrin's scheme, which keeps the loop's dependency chain at
  about 16 cycles; the next shift is formed with a single multiply-add after
  ``a1``.

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

    Truncation error < 2e-17 relative (used by the general Newton step and by
    :func:`free_steps` for increments beyond its multiplied-out short form).
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
        sd = d * (
            1.0
            - d2
            * (1.0 / 6.0)
            * (
                1.0
                - d2 * (1.0 / 20.0) * (1.0 - d2 * (1.0 / 42.0) * (1.0 - d2 * (1.0 / 72.0) * (1.0 - d2 * (1.0 / 110.0))))
            )
        )
        cd = 1.0 - d2 * 0.5 * (
            1.0
            - d2
            * (1.0 / 12.0)
            * (
                1.0
                - d2 * (1.0 / 30.0) * (1.0 - d2 * (1.0 / 56.0) * (1.0 - d2 * (1.0 / 90.0) * (1.0 - d2 * (1.0 / 132.0))))
            )
        )
    return sd, cd


@njit(cache=True, inline="always", fastmath={"contract"})
def store_sample(out_th, out_w, out_e, n_out, th, w, off, psn, pcc, p2cos_a, e_scale):
    """Write one output sample of a lean loop; returns the new fill count.

    ``psn, pcc`` are -p^2 (sin, cos) of c at the loop's anchor and ``off`` the
    distance of theta from it, so the energy needs no libm call.
    """
    out_th[n_out] = th
    out_w[n_out] = w
    # -p^2 cos c at theta = anchor + off
    if abs(off) < 1e-8:
        pc1 = pcc + psn * off
    else:
        sd, cd = sdcd(off)
        pc1 = pcc * cd + psn * sd
    out_e[n_out] = (0.5 * w * w - pc1 - p2cos_a) * e_scale
    return n_out + 1


@njit(cache=True, fastmath={"contract"})
def free_steps(
    th,
    w,
    a,
    sc,
    cc,
    s,
    step,
    n_steps,
    h,
    p2,
    alpha,
    cos_a,
    max_abs,
    out_th,
    out_w,
    out_e,
    n_out,
    countdown,
    out_every,
    e_scale,
):
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
    hh4h = hh4 * h
    mp2 = -p2
    p2cos_a = p2 * cos_a
    lip = hh4 * p2 / (1.0 - hh4 * p2)  # contraction L/(1-L) of the fixed-point step
    if lip >= 0.01:
        return th, w, a, sc, cc, step, max_abs, n_out, countdown
    # psc, pcc = -p^2 (sin, cos) of c at the anchor theta_a = th - off
    psc = mp2 * sc
    pcc = mp2 * cc
    off = 0.0
    x = (h - hh4h * pcc) * w + hh2 * a
    xr = x
    broke = False
    while step < n_steps and not broke:
        # blocks of up to 1024 steps, each followed by a re-anchoring with libm sin/cos
        # against the rounding drift of the carried values
        lim = min(n_steps, (step | 1023) + 1)
        broke = True
        while step < lim:
            if abs(xr) < 2e-4:
                # f and -p^2 cos at the anchor + xr: the Taylor shift (errors xr^5/120,
                # xr^6/720) multiplied out and evaluated by Estrin's scheme
                x2 = xr * xr
                a1 = (psc - pcc * xr) + x2 * ((-0.5 * psc + (pcc * (1.0 / 6.0)) * xr) + x2 * (psc * (1.0 / 24.0)))
                pccn = (pcc + psc * xr) + x2 * ((-0.5 * pcc - (psc * (1.0 / 6.0)) * xr) + x2 * (pcc * (1.0 / 24.0)))
            elif abs(xr) < 0.2:
                sd, cd = sdcd(xr)
                a1 = psc * cd - pcc * sd
                pccn = pcc * cd + psc * sd
            else:
                break
            base = h * w + hh4 * a
            x1 = base + hh4 * a1
            dl = x1 - x
            tol = 1e-15 * (abs(th) + abs(x))
            if lip * abs(dl) > tol:
                ok = False
                for _ in range(60):
                    x = x1
                    xr = x + off
                    if not abs(xr) < 0.2:
                        break
                    sd, cd = sdcd(xr)
                    a1 = psc * cd - pcc * sd
                    pccn = pcc * cd + psc * sd
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
            # next predictor (jerk term with the old anchor's cos: it only has to be close)
            kw = h - hh4h * pcc
            wa = w + h2 * a
            q = kw * h2 + hh2
            kwa = kw * wa
            # next evaluation point from the new anchor, x_next + dl, as one multiply-add after a1
            xr = (kwa + (base - x)) + (q + hh4) * a1
            x = kwa + q * a1
            w = wa + h2 * a1
            a = a1
            th = th1
            # the anchor moves to the evaluation point; theta1 lies dl beyond it
            psc = a1
            pcc = pccn
            off = dl
            step += 1
            ath = abs(th)
            if ath > max_abs:
                max_abs = ath
            countdown -= 1
            if countdown == 0:
                countdown = out_every
                n_out = store_sample(out_th, out_w, out_e, n_out, th, w, off, psc, pcc, p2cos_a, e_scale)
            if step == lim:
                broke = False
        if not broke:
            # re-anchor at theta1 against rounding drift of the carried sin/cos
            psc = mp2 * math.sin(alpha * s - th)
            pcc = mp2 * math.cos(alpha * s - th)
            off = 0.0
            xr = x
    sc = math.sin(alpha * s - th)
    cc = math.cos(alpha * s - th)
    return th, w, a, sc, cc, step, max_abs, n_out, countdown
