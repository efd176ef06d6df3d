"""Numba kernel: Newmark trapezoidal rocking with exact contact detection (Čeh §3).

One function, :func:`run_block`, integrates one block and is shared by
:func:`rocklab.models.simulate` (with output) and
:func:`rocklab.models.simulate_batch` (``out_every = 0``: no storage, inside a
``prange``). Everything is SI; the base acceleration enters as ``ug = a / g``.

Equation of motion (Čeh Eq. 1–2, general alpha_I through p), s = side of the
rotation corner (+1: corner A, theta > 0)::

    theta'' = -p^2 [sin(alpha s - theta) + ug cos(alpha s - theta)]
    linearised (DeJong Eq. 5):  theta'' = p^2 (theta - alpha s) - p^2 ug

Newmark trapezoidal rule (beta = 1/4, gamma = 1/2, Čeh Eq. 5–7), solved with
Newton–Raphson. When theta changes sign within a step the step is redone for the
length tau that lands exactly on theta = 0 (Čeh Eq. 8–9; with ug varying
linearly over the step the condition is a cubic in tau solved by safeguarded
Newton), the pre-impact omega and theta'' follow from Eq. 10–11, the
restitution law gives omega+ and the rest of the step continues with the other
equation (several impacts per step are allowed).

Free rocking (full equation, no base record or past its end) runs its steps
between impacts in the lean loop :func:`~rocklab.models.rocking._newmark_lean.free_steps`
(same trapezoidal step, solved by a jerk-corrected predictor and a checked
fixed-point update), rocking under the record in the same loop with the base term,
:func:`~rocklab.models.rocking._newmark_lean.forced_steps`, and steps at rest in which
the base stays below the uplift level in a short scan; impacts, uplift,
overturning and anything else the lean loops decline are handled by the
general step here (``lean=False``: every step, the reference in the tests).
The kernels compile with ``fastmath={"contract"}``: multiply-adds are fused
(rounding only; no reassociation or other fast-math liberties).

Notes on the paper: Eq. 8 as printed reads ``A dt'^2 - 4 w dt' - theta = 0``; the
Newmark relation and Eq. 9 both need ``- 4 theta``, which is used here.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ...blocks import G
from ._newmark_contact import contact_tau, cross_fraction, restitution_at, store_impact
from ._newmark_lean import forced_steps, free_steps, sdcd
from ._taylor_record import safe_bound

#: Status codes returned by the kernel (``SAFE``: stopped by the safe stop, batch runs only).
ROCKING, REST, OVERTURNED, NO_UPLIFT, SAFE = 0, 1, 2, 3, 4
STATUS_NAMES = ("rocking", "rest", "overturned", "no_uplift", "safe")
#: Share of the energy room the safe stop leaves to the trapezoidal rule: its energy error relative to the
#: exact motion's, which the bound is for, is of order (p h)^2 / 12 (3e-5 at p h = 0.02), far below 1 %.
SAFE_ROOM = 0.99
_HALF_PI = 0.5 * math.pi
#: Sub-steps in a row that leave the time unchanged before the rest of the step is skipped
#: (an honest sequence has at most two: a lift-off at the step's start, then the flight).
_MAX_STALLED = 8


@njit(cache=True, inline="always")
def _ug_at(t, acc, t0, inv_dta, fac):
    """Base acceleration * fac at time t (fac = scale/g): linear interpolation, 0 outside."""
    n = acc.shape[0]
    if n == 0:
        return 0.0
    x = (t - t0) * inv_dta
    if x < 0.0 or x > n - 1:
        return 0.0
    i = int(x)
    if i >= n - 1:
        return acc[n - 1] * fac
    f = x - i
    return (acc[i] * (1.0 - f) + acc[i + 1] * f) * fac


@njit(cache=True, inline="always")
def _f(th, s, ug, p2, alpha, lin):
    if lin:
        return p2 * (th - alpha * s) - p2 * ug
    c = alpha * s - th
    return -p2 * (math.sin(c) + ug * math.cos(c))


@njit(cache=True, inline="always")
def _shift(sc0, cc0, d):
    """sin and cos of (c0 - d) from sin c0, cos c0 for an increment |d| < 0.2.

    Taylor series of sin d and cos d (:func:`sdcd`): a few multiplications
    instead of two libm calls per Newton iteration.
    """
    sd, cd = sdcd(d)
    return sc0 * cd - cc0 * sd, cc0 * cd + sc0 * sd


@njit(cache=True, inline="always")
def _sincos(th0, th, s, alpha, sc0, cc0):
    """sin/cos of c = alpha s - th, from their values at th0."""
    d = th - th0
    if abs(d) < 0.2:
        return _shift(sc0, cc0, d)
    c = alpha * s - th
    return math.sin(c), math.cos(c)


@njit(cache=True, inline="always")
def _newmark(th0, w0, a0, s, h, c1, c4h, ug1, p2, alpha, lin, sc0, cc0):
    """One trapezoidal step of length h; returns theta1, omega1, acc1, sin c1, cos c1.

    Newton–Raphson on the residual of Čeh Eq. 6–7 (``c = alpha s - theta``; sc0,
    cc0 = sin/cos of c at th0, carried along by :func:`_shift`). The predictor
    ``th0 + h w0 + h^2 a0 / 2`` is O(h^3) off, and Newton's next error is bounded by
    ``|f''| / (2 R') d^2 <= p^2 (1 + |ug|) h^2 d^2 / 8`` (R' ~ 4/h^2), so the loop stops
    as soon as that bound is below the tolerance: one Newton update per step in
    practice. c1 = 4/h^2 and c4h = 4/h are precomputed for full steps.
    """
    rhs0 = c4h * w0 + a0
    th = th0 + h * w0 + 0.5 * h * h * a0
    tol = 1e-15 * (abs(th0) + h * abs(w0) + h * h * abs(a0)) + 1e-300
    k2 = 0.125 * p2 * (1.0 + abs(ug1)) * h * h
    if lin:
        sc, cc = sc0, cc0
    else:
        sc, cc = _sincos(th0, th, s, alpha, sc0, cc0)
    for _ in range(50):
        if lin:
            f = p2 * (th - alpha * s) - p2 * ug1
            df = p2
        else:
            f = -p2 * (sc + ug1 * cc)
            df = p2 * (cc - ug1 * sc)
        d = (c1 * (th - th0) - rhs0 - f) / (c1 - df)
        th -= d
        if not lin:
            # c = alpha s - th grows by d
            if abs(d) < 0.2:
                sc, cc = _shift(sc, cc, -d)
            else:
                sc = math.sin(alpha * s - th)
                cc = math.cos(alpha * s - th)
        if abs(d) <= tol or k2 * d * d <= tol:
            break
    a1 = c1 * (th - th0) - rhs0
    return th, w0 + 0.5 * h * (a0 + a1), a1, sc, cc


@njit(cache=True, inline="always")
def _energy(th, w, cc, cos_a, p2, alpha, lin):
    """Energy above rest per unit I_O (rad^2/s^2); cc = cos(alpha - |theta|)."""
    if lin:
        ath = abs(th)
        return 0.5 * w * w + p2 * (alpha * ath - 0.5 * ath * ath)
    return 0.5 * w * w + p2 * (cc - cos_a)


@njit(cache=True)
def _safe_from(t, th, w, resting, tail, acc_t0, inv_dta, k_alpha, c_tail, p2, alpha, cos_a, stop_at_rest, t_last):
    """True where the rest of the record cannot lift the block (|theta| < alpha at ``t`` s) to alpha: sqrt(K)
    plus ``c_tail`` times the |acc| integral from the record sample at or before ``t`` (``tail``) below
    ``k_alpha`` = p sqrt(1 - cos alpha), with the margins of ``SAFE_ROOM``; never for a block at rest after the
    last uplift sample (that run ends at rest anyway)."""
    if resting and stop_at_rest and t >= t_last:
        return False
    x = (t - acc_t0) * inv_dta
    k = 0 if x <= 0.0 else min(int(x), tail.shape[0] - 1)
    excess = 0.0 if resting else 0.5 * w * w + p2 * (math.cos(alpha - abs(th)) - cos_a)
    return safe_bound(excess, tail[k], k_alpha, c_tail, p2, SAFE_ROOM)


@njit(cache=True, fastmath={"contract"})
def run_block(
    p,
    alpha,
    theta0,
    omega0,
    h,
    n_steps,
    acc,
    acc_t0,
    acc_dt,
    scale,
    eta_mode,
    eta_x,
    eta_y,
    lin,
    rest_w2,
    t_last_uplift,
    stop_at_rest,
    out_every,
    imp_cap,
    fall_rad=_HALF_PI,
    stop_on_fall=True,
    e_scale=1.0,
    lean=True,
    tail=None,
):
    """Integrate one block for n_steps steps of h (s).

    Returns
    -------
    tuple
        ``out_theta, out_omega, out_energy`` (n_out,): samples at every
        ``out_every``-th step (t = i h out_every), energy above rest per unit I_O
        times ``e_scale`` (rad^2/s^2 with the default 1; pass I_O for J); ``n_out``; ``imp`` (4, k): rows t_s,
        omega_before, omega_after, eta of the first ``imp_cap`` impacts; ``n_imp``
        (all impacts); ``status`` code; ``t_over`` (first |theta| >= alpha outward,
        NaN); ``t_fall`` (|theta| reached fall_rad, NaN); ``max_abs_theta``;
        ``t_end`` (s, last time integrated); ``theta_end``, ``omega_end`` (state at
        ``t_end``, rad and rad/s; 0, 0 at rest). The run always ends when |theta|
        reaches pi/2 (the side hits the ground), and at fall_rad when stop_on_fall.
        ``lean=False`` takes every step in the general loop (reference for tests).
        ``tail``: empty, or per record sample k a bound on the integral of |acc| from sample k to the
        record's end (:func:`~rocklab.models.rocking._taylor_record.safe_tail`): the run then stops (status
        ``SAFE``) where the energy the rest of the record can give cannot lift the block to alpha (the bound
        of :mod:`~rocklab.models.rocking._taylor_record`, its room cut to ``SAFE_ROOM`` for the rule's energy
        error), checked between the lean loops' stretches (at impacts, uplifts, the record's end).
    """
    p2 = p * p
    tan_a = math.tan(alpha)
    inv_dta = 1.0 / acc_dt
    fac = scale / G
    c1h = 4.0 / (h * h)
    c4h = 4.0 / h
    n_out_max = n_steps // out_every + 1 if out_every > 0 else 0
    out_th = np.empty(n_out_max)
    out_w = np.empty(n_out_max)
    out_e = np.empty(n_out_max)
    imp = np.empty((4, imp_cap))
    n_imp = 0
    t_over = np.nan
    t_fall = np.nan
    status = ROCKING
    ever_moved = False

    th = theta0
    w = omega0
    resting = False
    if th != 0.0:
        s = 1.0 if th > 0.0 else -1.0
    elif w != 0.0:
        s = 1.0 if w > 0.0 else -1.0
    else:
        s = 1.0
        resting = True
    ug = _ug_at(0.0, acc, acc_t0, inv_dta, fac)
    if resting and abs(ug) > tan_a:
        resting = False
        s = -1.0 if ug > 0.0 else 1.0
    if not resting:
        ever_moved = True
    u_prev = ug
    a = _f(th, s, ug, p2, alpha, lin) if not resting else 0.0
    sc = math.sin(alpha * s - th)
    cc = math.cos(alpha * s - th)
    sin_a = math.sin(alpha)
    cos_a = math.cos(alpha)
    max_abs = abs(th)
    n_out = 0
    if out_every > 0:
        out_th[0] = th
        out_w[0] = w
        out_e[0] = _energy(th, w, cc, cos_a, p2, alpha, lin) * e_scale
        n_out = 1
    step = 0
    countdown = out_every  # output every out_every steps (no integer modulo in the hot loop)
    t_end = 0.0
    # free rocking (full equation, no base record or past its end: ug = 0 exactly) runs
    # in the lean loop free_steps; anything else (impact in the step,
    # |theta| >= alpha, rest) is left to the general step below, which takes that
    # step from the same state. One sample of margin keeps _ug_at's rounding out.
    # Under the record the same holds for forced_steps (steps ending inside the record;
    # its fixed-point update needs the contraction L = p^2 (1 + max|ug|) h^2 / 4 small).
    t_free = acc_t0 + acc.shape[0] * acc_dt if acc.shape[0] > 0 else -np.inf
    lip = 1.0
    if acc.shape[0] > 1:
        L = 0.25 * h * h * p2 * (1.0 + np.max(np.abs(acc)) * abs(fac))
        lip = L / (1.0 - L) if L < 0.5 else 1.0
    n_acc = acc.shape[0]
    check = tail is not None and tail.shape[0] == n_acc and n_acc > 1 and not lin
    k_alpha = math.sqrt(p2 * (1.0 - cos_a))
    c_tail = p2 * abs(fac) / math.sqrt(2.0)
    while step < n_steps:
        if (
            check
            and abs(th) < alpha
            and _safe_from(
                step * h,
                th,
                w,
                resting,
                tail,
                acc_t0,
                inv_dta,
                k_alpha,
                c_tail,
                p2,
                alpha,
                cos_a,
                stop_at_rest,
                t_last_uplift,
            )
        ):
            status = SAFE
            t_end = step * h
            break
        if lean and not lin and not resting and abs(th) < alpha:
            if step * h > t_free:
                th, w, a, sc, cc, step, max_abs, n_out, countdown = free_steps(
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
                )
            elif lip < 0.01:
                th, w, a, sc, cc, step, max_abs, n_out, countdown = forced_steps(
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
                )
                u_prev = _ug_at(step * h, acc, acc_t0, inv_dta, fac)
            t_end = step * h
            if step >= n_steps:
                break
        elif lean and resting:
            # at rest: skip the steps that end with the base below the uplift level (and
            # before the last uplift when runs stop at rest); the general step takes the next one
            while step < n_steps:
                t1 = (step + 1) * h
                if stop_at_rest and t1 >= t_last_uplift:
                    break
                u1 = _ug_at(t1, acc, acc_t0, inv_dta, fac)
                if abs(u1) > tan_a:
                    break
                step += 1
                u_prev = u1
                countdown -= 1
                if countdown == 0:
                    countdown = out_every
                    out_th[n_out] = th
                    out_w[n_out] = w
                    out_e[n_out] = 0.0
                    n_out += 1
            t_end = step * h
            if step >= n_steps:
                break
        t0 = step * h
        t1 = (step + 1) * h
        u1 = _ug_at(t1, acc, acc_t0, inv_dta, fac)
        tc = t0  # current time within the step
        th_beg = th
        w_beg = w
        u_c = u_prev
        n_sub = 0
        tc_seen = -1.0
        stalled = 0
        while tc < t1:
            rem = t1 - tc
            if rem <= 1e-12 * h:
                break
            # a cycle that makes no progress in time ends the step: lift-off with |ug| = tan(alpha)
            # to the ulp, a contact after tau ~ 1e-30 s (tc unchanged) with omega+ = 0, rest,
            # lift-off again, for ever (a point of tests/test_single_batch.py)
            stalled = stalled + 1 if tc == tc_seen else 0
            if stalled > _MAX_STALLED:
                break
            tc_seen = tc
            n_sub += 1
            if resting:
                if abs(u1) > tan_a:
                    # uplift: where |ug| crosses tan(alpha) on the linear ramp u_c -> u1
                    thr = tan_a if u1 > 0.0 else -tan_a
                    fr = (thr - u_c) / (u1 - u_c) if u1 != u_c else 0.0
                    fr = min(max(fr, 0.0), 1.0)
                    tc = tc + fr * rem
                    u_c = u_c + fr * (u1 - u_c)
                    s = -1.0 if u1 > 0.0 else 1.0
                    resting = False
                    ever_moved = True
                    th = 0.0
                    w = 0.0
                    a = _f(0.0, s, u_c, p2, alpha, lin)
                    sc = s * sin_a
                    cc = cos_a
                    continue
                break
            if tc == t0:
                rem = h  # a full step: reuse the constants
                th1, w1, a1, sc1, cc1 = _newmark(th, w, a, s, h, c1h, c4h, u1, p2, alpha, lin, sc, cc)
            else:
                th1, w1, a1, sc1, cc1 = _newmark(
                    th, w, a, s, rem, 4.0 / (rem * rem), 4.0 / rem, u1, p2, alpha, lin, sc, cc
                )
            if th1 * s > 0.0 or (th1 == 0.0 and w1 * s > 0.0):
                th, w, a, sc, cc = th1, w1, a1, sc1, cc1
                tc = t1
            else:
                # contact within the (rest of the) step
                tau = contact_tau(th, w, a, s, rem, u_c, u1, p2, alpha, lin)
                if tau > rem:
                    tau = rem
                if th == 0.0 or tau <= 0.0:
                    w_m = -w  # Eq. 10 with theta_n = 0 (back at the corner after a short flight)
                else:
                    w_m = -2.0 * th / tau - w  # Eq. 10
                ti = tc + tau
                u_i = u_c + (u1 - u_c) * (tau / rem)
                e = restitution_at(eta_mode, eta_x, eta_y, n_imp, w_m)
                w_p = e * w_m
                n_imp = store_impact(imp, n_imp, ti, w_m, w_p, e)
                th = 0.0
                tc = ti
                u_c = u_i
                if abs(u_i) > tan_a:
                    # the base holds the block up: it keeps moving even if omega+ is tiny
                    s_base = -1.0 if u_i > 0.0 else 1.0
                else:
                    s_base = 0.0
                if w_p * w_p <= rest_w2 and s_base == 0.0:
                    resting = True
                    w = 0.0
                    a = 0.0
                    if stop_at_rest and ti >= t_last_uplift:
                        break
                    continue
                if w_p != 0.0:
                    s = 1.0 if w_p > 0.0 else -1.0
                else:
                    s = s_base
                w = w_p
                a = _f(0.0, s, u_i, p2, alpha, lin)
                sc = s * sin_a
                cc = cos_a
                if n_sub > 100000:
                    resting = True
                    w = 0.0
                    a = 0.0
        step += 1
        u_prev = u1
        t_end = t1
        ath = abs(th)
        if ath > max_abs:
            max_abs = ath
        if (step & 1023) == 0 and not resting and not lin:
            # re-anchor the incremental sin/cos against rounding drift
            sc = math.sin(alpha * s - th)
            cc = math.cos(alpha * s - th)
        countdown -= 1
        if countdown == 0:
            countdown = out_every
            out_th[n_out] = th
            out_w[n_out] = w
            out_e[n_out] = 0.0 if resting else _energy(th, w, cc, cos_a, p2, alpha, lin) * e_scale
            n_out += 1
        if ath >= alpha and th * w > 0.0 and t_over != t_over:
            t_over = t1 - h + h * cross_fraction(th_beg * s, w_beg * s, th * s, w * s, h, alpha)
        if ath >= fall_rad and t_fall != t_fall:
            t_fall = t1 - h + h * cross_fraction(th_beg * s, w_beg * s, th * s, w * s, h, fall_rad)
            status = OVERTURNED
            if stop_on_fall:
                break
        if ath >= _HALF_PI:
            # the side of the block hits the ground: the rocking model ends here
            status = OVERTURNED
            if t_fall != t_fall:
                t_fall = t1
            break
        if resting and stop_at_rest and t1 >= t_last_uplift:
            status = REST
            break
    if status != OVERTURNED and status != SAFE:
        if resting:
            status = REST if ever_moved else NO_UPLIFT
        else:
            status = ROCKING
    return (
        out_th[:n_out],
        out_w[:n_out],
        out_e[:n_out],
        n_out,
        imp[:, : min(n_imp, imp_cap)],
        n_imp,
        status,
        t_over,
        t_fall,
        max_abs,
        t_end,
        th,
        w,
    )


@njit(cache=True)
def run_single(
    p,
    alpha,
    theta0,
    omega0,
    h,
    n_steps,
    acc,
    acc_t0,
    acc_dt,
    eta_mode,
    eta_x,
    eta_y,
    lin,
    rest_w2,
    t_last_uplift,
    stop_at_rest,
    out_every,
    imp_cap,
    fall_rad,
    e_scale,
    lean=True,
):
    """:func:`run_block` for ``simulate``: output times and a contiguous impact table in the same call.

    Returns ``t, theta, omega, energy`` (n_out,; energy times ``e_scale``),
    ``imp`` (4, k) C-contiguous, ``n_imp``, ``status``, ``t_over``, ``t_fall``,
    ``max_abs`` (one dispatch from Python instead of several numpy calls). ``lean=False``:
    general loop only (see :func:`run_block`).
    """
    # writeable law tables and typed (non-literal) flags: the same run_block signature as
    # run_batch's, so the kernel compiles once for both (a second specialisation: ~15 CPU-s cold)
    th, w, e, n_out, imp, n_imp, st, t_over, t_fall, max_abs, t_end, _, _ = run_block(
        p,
        alpha,
        theta0,
        omega0,
        h,
        n_steps,
        acc,
        acc_t0,
        acc_dt,
        1.0,
        eta_mode,
        eta_x.copy(),
        eta_y.copy(),
        lin,
        rest_w2,
        t_last_uplift,
        stop_at_rest,
        out_every,
        imp_cap,
        fall_rad,
        np.bool_(True),
        e_scale,
        np.bool_(lean),
        np.zeros(0),
    )
    t = np.empty(n_out)
    dto = h * out_every
    for i in range(n_out):
        t[i] = i * dto
    return t, th, w, e, np.ascontiguousarray(imp), n_imp, st, t_over, t_fall, max_abs


@njit(cache=True)
def _last_over(acc, t0, dta, thr):
    """Time of the last record sample with |acc| > thr (m/s^2); -inf if none."""
    for k in range(acc.shape[0] - 1, -1, -1):
        if abs(acc[k]) > thr:
            return t0 + k * dta
    return -np.inf


@njit(cache=True, parallel=True)
def run_batch(p, alpha, th0, w0, eta, h, n_steps, acc, acc_t0, acc_dt, scale, rest_tol, fall_rad, stop_on_fall, tail):
    """m independent blocks in parallel (summaries only); see ``simulate_batch``. ``tail``: empty, or the
    record's :func:`~rocklab.models.rocking._taylor_record.safe_tail` (the safe stop of :func:`run_block`).

    Lives in this module so that numba's on-disk cache of this caller is
    invalidated together with :func:`run_block` (the cache only tracks the
    caller's own source file).
    """
    m = p.shape[0]
    over = np.zeros(m, np.bool_)
    t_over = np.empty(m)
    mx = np.empty(m)
    nimp = np.zeros(m, np.int64)
    status = np.zeros(m, np.int8)
    steps = np.zeros(m, np.int64)
    th_end = np.zeros(m)
    w_end = np.zeros(m)
    ex = np.zeros(1)
    # typed (non-literal) constants: literal 0/True/False would make numba compile a second
    # specialisation of run_block next to run_single's (compile time only)
    zero = np.int64(0)
    no, yes = np.bool_(False), np.bool_(True)
    for i in prange(m):
        a = alpha[i]
        p2 = p[i] * p[i]
        rest_w2 = 2.0 * p2 * (math.cos(a - rest_tol * a) - math.cos(a))
        sc = abs(scale[i])
        t_last = _last_over(acc, acc_t0, acc_dt, G * math.tan(a) / sc) if sc > 0 else -np.inf
        ey = np.empty(1)
        ey[0] = eta[i]
        fr = fall_rad[i]
        r = run_block(
            p[i],
            a,
            th0[i],
            w0[i],
            h[i],
            n_steps[i],
            acc,
            acc_t0,
            acc_dt,
            scale[i],
            zero,
            ex,
            ey,
            no,
            rest_w2,
            t_last,
            yes,
            zero,
            zero,
            fr,
            stop_on_fall,
            1.0,
            yes,
            tail,
        )
        nimp[i] = r[5]
        status[i] = r[6]
        t_over[i] = r[7]
        over[i] = r[6] == 2
        mx[i] = r[9] / a
        steps[i] = int(r[10] / h[i] + 0.5)
        th_end[i] = r[11]
        w_end[i] = r[12]
    return over, t_over, mx, nimp, status, steps, th_end, w_end
