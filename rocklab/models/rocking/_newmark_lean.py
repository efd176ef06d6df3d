"""Numba: the lean time loops of :func:`~rocklab.models.rocking._newmark.run_block`, free and under a record.

Between impacts every step is the same trapezoidal (Newmark beta = 1/4) step as
in the general loop; only the way its implicit equation is solved differs. With
the base acceleration ``u = ug/g`` (0 for free rocking: no base record, or past
its end), ``theta'' = f(theta, u) = -p^2 (sin c + u cos c)``, ``c = alpha s - theta``:

- predictor ``x = theta1 - theta0 = h w0 + h^2/4 (a0 + a_pred)`` with
  ``a_pred = a0 + h f_theta w0 + f_u (u1 - u0)`` (``f_theta = p^2 (cos c - u sin c)``,
  ``f_u = -p^2 cos c``): off by ~h^4 a''/8;
- one evaluation ``a1 = f(theta0 + x)``, then ``x1 = h w0 + h^2/4 (a0 + a1)``:
  a fixed-point step of the Newmark equation, whose contraction is
  ``L = p^2 (1 + max|u|) h^2 / 4``, so ``|theta0 + x1 - root| <= L/(1-L) |x1 - x|``;
  the step is accepted when that bound is below ``1e-15 (|theta0| + |x|)``
  (almost always at once), otherwise the iteration goes on;
- ``-p^2 sin c`` and ``-p^2 cos c`` are carried at an anchor, the last
  evaluation point, and shifted to the next one by their Taylor series (no libm
  call; exact sin/cos every 1024 steps against drift). For one step of a
  rocking block (|shift| < 2e-4) the series is multiplied out and evaluated by
  Estrin's scheme, which keeps the loop's dependency chain at about 16 cycles;
  the next shift is formed with a single multiply-add after ``a1``;
- under a record, ``u`` at the end of each step is the record's linear
  interpolation at ``t = (step + 1) h`` (the general loop's ``ug(t)``): the
  general loop's formula at the first step end in each record interval, then
  ``+ k du`` for the k-th step after it on the same straight segment
  (rounding-level differences).

One body, :func:`_lean_steps`, serves both cases; :func:`free_steps` and
:func:`forced_steps` compile it with ``free`` a constant, so the free loop
carries no ``u`` terms (free rocking is the case the single-block benchmark
times). With a record of zeros the forced loop gives the free loop's numbers
(tests/test_single_fastpath.py).

theta1, omega1 and a1 satisfy the Newmark relations exactly; ``a1 - f(theta1)``
is ``p^2 |x1 - x|`` (~1e-13 rad/s^2). The loops return (without taking the
step) whenever anything else could happen in a step: theta reaching 0 (impact,
exact contact time in the general loop), |theta| >= alpha (overturning
bookkeeping), an increment too large for the Taylor shift, slow convergence,
or (under a record) a step end outside the record.
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, inline="always", fastmath={"contract"})
def sdcd(d):
    """sin d and cos d for |d| < 0.2 by the shortest Taylor form the size of d allows.

    Truncation error < 2e-17 relative (used by the general Newton step and by
    :func:`_lean_steps` for increments beyond its multiplied-out short form).
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


@njit(cache=True, inline="always", fastmath={"contract"})
def ug_inside(t, acc, t0, inv_dta, fac):
    """Base acceleration * fac at t (the general loop's interpolation) and whether t is inside the record.

    Inside means ``t0 <= t < t_last``; there the value is the same expression as
    ``_newmark._ug_at``. Outside: ``(0.0, False)``.
    """
    x = (t - t0) * inv_dta
    if not (x >= 0.0 and x < acc.shape[0] - 1):
        return 0.0, False
    i = int(x)
    f = x - i
    return (acc[i] * (1.0 - f) + acc[i + 1] * f) * fac, True


@njit(cache=True, inline="always", fastmath={"contract"})
def ug_ramp(j, h, acc, t0, inv_dta, fac):
    """u at the end of step j, ``t = (j + 1) h`` (:func:`ug_inside`), and the ramp it lies on.

    Returns ``u, ok, du, k_max``: u at the end of step ``j + k`` is ``u + k du``
    for ``k <= k_max`` (same record interval; one step of margin against rounding).
    """
    t = (j + 1) * h
    x = (t - t0) * inv_dta
    if not (x >= 0.0 and x < acc.shape[0] - 1):
        return 0.0, False, 0.0, -1.0
    i = int(x)
    f = x - i
    r = h * inv_dta
    k_max = math.floor((i + 1 - x) / r) - 1.0
    return (acc[i] * (1.0 - f) + acc[i + 1] * f) * fac, True, (acc[i + 1] - acc[i]) * fac * r, k_max


@njit(cache=True, inline="always", fastmath={"contract"})
def _lean_steps(
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
    acc,
    acc_t0,
    inv_dta,
    fac,
    lip,
    free,
):
    """Whole steps from ``step`` on, as long as none needs the general loop.

    State in and out: theta ``th`` (rad, side ``s`` = ±1), omega ``w`` (rad/s),
    theta'' ``a`` (rad/s^2), ``sc, cc`` = sin, cos of ``alpha s - th``; the step
    counter, running max |theta|, and the output buffers (every ``out_every``-th
    step; energy above rest per unit I_O times ``e_scale``) with their fill
    count and countdown, exactly as the general loop keeps them. The record:
    ``acc`` (n,) m/s^2 from ``acc_t0`` s every ``1/inv_dta`` s, times ``fac`` =
    scale/g; ``lip`` is the fixed-point contraction bound L/(1-L) (< 0.01; the
    caller checks). ``free`` (a constant in each caller, so the branches on it
    compile away): u = 0, the record and ``lip`` are not read.

    Returns
    -------
    tuple
        ``th, w, a, sc, cc, step, max_abs, n_out, countdown`` after the last step
        taken (the next step, if any, is left to the general loop).
    """
    if free:
        u1, ok1, ua, ok2, du, k_max, u0 = 0.0, True, 0.0, True, 0.0, math.inf, 0.0
        lip = 0.25 * h * h * p2 / (1.0 - 0.25 * h * h * p2)
        if lip >= 0.01:
            return th, w, a, sc, cc, step, max_abs, n_out, countdown
    else:
        u1, ok1 = ug_inside((step + 1) * h, acc, acc_t0, inv_dta, fac)
        if not ok1:
            return th, w, a, sc, cc, step, max_abs, n_out, countdown
        # u at the end of the next step: ua + k du on the current record interval
        ua, ok2, du, k_max = ug_ramp(step + 1, h, acc, acc_t0, inv_dta, fac)
        u0, ok0 = ug_inside(step * h, acc, acc_t0, inv_dta, fac)
        if not ok0:
            u0 = u1
    k = -1.0  # the loop's first increment gives k = 0: u at the end of step + 1
    hh2 = 0.5 * h * h
    hh4 = 0.25 * h * h
    h2 = 0.5 * h
    hh4h = hh4 * h
    mp2 = -p2
    p2cos_a = p2 * cos_a
    # psn, pcc = -p^2 (sin, cos) of c at the anchor theta_a = th - off
    psn = mp2 * sc
    pcc = mp2 * cc
    off = 0.0
    if free:
        x = (h - hh4h * pcc) * w + hh2 * a
    else:
        x = (h - hh4h * (pcc - u1 * psn)) * w + hh2 * a + hh4 * pcc * (u1 - u0)
    xr = x
    broke = False
    while step < n_steps and not broke:
        # blocks of up to 1024 steps, each followed by a re-anchoring with libm sin/cos
        lim = min(n_steps, (step | 1023) + 1)
        broke = True
        while step < lim:
            if not free:
                if not ok1:
                    break
                # u at the end of the next step (off the dependency chain; exact at each record interval)
                if k < k_max:
                    k += 1.0
                else:
                    ua, ok2, du, k_max = ug_ramp(step + 1, h, acc, acc_t0, inv_dta, fac)
                    k = 0.0
                u2 = ua + k * du if ok2 else u1
            if abs(xr) < 2e-4:
                # -p^2 sin c and -p^2 cos c at the anchor + xr: Taylor shift (errors xr^5/120,
                # xr^6/720) multiplied out and evaluated by Estrin's scheme
                x2 = xr * xr
                sn = (psn - pcc * xr) + x2 * ((-0.5 * psn + (pcc * (1.0 / 6.0)) * xr) + x2 * (psn * (1.0 / 24.0)))
                cn = (pcc + psn * xr) + x2 * ((-0.5 * pcc - (psn * (1.0 / 6.0)) * xr) + x2 * (pcc * (1.0 / 24.0)))
            elif abs(xr) < 0.2:
                sd, cd = sdcd(xr)
                sn = psn * cd - pcc * sd
                cn = pcc * cd + psn * sd
            else:
                break
            a1 = sn if free else sn + u1 * cn
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
                    sn = psn * cd - pcc * sd
                    cn = pcc * cd + psn * sd
                    a1 = sn if free else sn + u1 * cn
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
            # next predictor: a_pred = a1 + h (f_theta w1 + f_u u'), f_theta = u psn - pcc,
            # f_u = pcc (old anchor: it only has to be close)
            kw = h - hh4h * pcc if free else h + hh4h * (u1 * psn - pcc)
            wa = w + h2 * a
            q = kw * h2 + hh2
            kwa = kw * wa if free else kw * wa + hh4 * pcc * (u2 - u1)
            # next evaluation point from the new anchor, x_next + dl, as one multiply-add after a1
            xr = (kwa + (base - x)) + (q + hh4) * a1
            x = kwa + q * a1
            w = wa + h2 * a1
            a = a1
            th = th1
            # the anchor moves to the evaluation point; theta1 lies dl beyond it
            psn = sn
            pcc = cn
            off = dl
            if not free:
                u1 = u2
                ok1 = ok2
            step += 1
            ath = abs(th)
            if ath > max_abs:
                max_abs = ath
            countdown -= 1
            if countdown == 0:
                countdown = out_every
                n_out = store_sample(out_th, out_w, out_e, n_out, th, w, off, psn, pcc, p2cos_a, e_scale)
            if step == lim:
                broke = False
        if not broke:
            # re-anchor at theta1 against rounding drift of the carried sin/cos
            psn = mp2 * math.sin(alpha * s - th)
            pcc = mp2 * math.cos(alpha * s - th)
            off = 0.0
            xr = x
    sc = math.sin(alpha * s - th)
    cc = math.cos(alpha * s - th)
    return th, w, a, sc, cc, step, max_abs, n_out, countdown


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
    acc,
    acc_t0,
    inv_dta,
    fac,
    lip,
):
    """:func:`_lean_steps` for free rocking (u = 0; the record arguments are not read)."""
    return _lean_steps(
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
        acc,
        acc_t0,
        inv_dta,
        fac,
        lip,
        True,
    )


@njit(cache=True, fastmath={"contract"})
def forced_steps(
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
    acc,
    acc_t0,
    inv_dta,
    fac,
    lip,
):
    """:func:`_lean_steps` under the record ``acc`` (steps ending inside it)."""
    return _lean_steps(
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
        acc,
        acc_t0,
        inv_dta,
        fac,
        lip,
        False,
    )
