"""Event-driven time-stepping loop of the column model (Ther thesis §3.3).

One loop, plain Python registered with numba; :data:`run_core_jit` is its
compiled form (``cache=True``) and :func:`run_core` the pure-Python baseline.
Within a step: closings are located exactly (the step length that lands the
joint on zero, Čeh et al. Eq. 8), openings by linear interpolation of the
eccentricity excess (thesis §3.3); the earliest event wins, the opening or
impact model sets the new configuration and the rest of the step follows, so
the output stays on the grid ``t_k = k dt`` (as in the single-block kernel).
While every joint is closed the column moves with the base and a step costs
one check of the base acceleration against the joints' opening and sliding
levels.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numba.extending import register_jitable

from ._events import impact_model, opening_model
from ._kernels import active_dofs, base_acc, geometry, kinetic_energy, make_work, pivots
from ._step import evaluate, locate_closing, nm_step, state_checks

__all__: list[str] = []

# status codes returned by the loop
ST_END, ST_REST, ST_OVERTURN, ST_TENSION, ST_SLIDING, ST_CAPACITY, ST_NUMERIC = 0, 1, 2, 3, 4, 5, 6
# event kinds
EV_START, EV_OPEN, EV_IMPACT = 0, 1, 2


@register_jitable
def _energy(phi, v, s, blk, g, y0, w):
    """Kinetic and potential energy (J); leaves the geometry in ``w``."""
    n = phi.shape[0]
    geometry(phi, s, blk, w.theta, w.thlow, w.C, w.G)
    k = active_dofs(s, blk, w.dj, w.dpx)
    pivots(w.dj, w.dpx, k, w.C, w.thlow, w.PP)
    for q in range(k):
        w.vk[q] = v[w.dj[q]]
    ke = kinetic_energy(w.dj, k, w.PP, w.vk, w.G, blk)
    pe = 0.0
    for i in range(n):
        pe += blk[i, 0] * g * (w.G[i, 1] - y0[i])
    return ke, pe


@register_jitable
def _overturned(v, s, blk, ovt_angle, w):
    """Static instability of the part above an opening joint, moving outwards.

    The centre of mass of blocks j..n lies beyond the pivot of open joint j
    (gravity now drives the opening) while the joint still opens; for one block
    this is |θ| ≥ α with outward velocity. With ``ovt_angle > 0`` any block
    angle beyond it counts instead. Uses the geometry left in ``w`` by :func:`_energy`.
    """
    n = s.shape[0]
    if ovt_angle > 0.0:
        for i in range(n):
            if abs(w.theta[i]) >= ovt_angle:
                return True
        return False
    for j in range(n):
        if s[j] == 0 or s[j] * v[j] <= 0.0:
            continue
        px = -s[j] * blk[j, 4]
        pxw = w.C[j, 0] + math.cos(w.thlow[j]) * px
        mx = 0.0
        mt = 0.0
        for i in range(j, n):
            mx += blk[i, 0] * w.G[i, 0]
            mt += blk[i, 0]
        if s[j] * (mx / mt - pxw) <= 0.0:
            return True
    return False


@register_jitable
def _apply_opening(t, s, px, s_new, px_new, EVT, EVI, ne):
    ecap = EVT.shape[0]
    for j in range(s.shape[0]):
        if s_new[j] != s[j] and ne < ecap:
            EVT[ne] = t
            EVI[ne, 0] = j
            EVI[ne, 1] = s_new[j]
            EVI[ne, 2] = EV_OPEN
            ne += 1
        s[j] = s_new[j]
        px[j] = px_new[j]
    return ne


@register_jitable
def run_core(
    phi0,
    v0,
    s0,
    blk,
    par,
    accb,
    n_steps,
    dt,
    max_enum,
    n_imp,
    v_tol,
    stop_at_rest,
    ovt_angle,
    stride,
    PHI,
    VEL,
    EN,
    EVT,
    EVI,
    IMP,
    PEAK,
):
    """Integrate ``n_steps`` steps of ``dt`` (s) from t = 0.

    The grid ``t_k = k dt`` is kept: an event inside a step is followed by the
    rest of that step (as in the single-block kernel). Records the state at
    t = 0, at every ``stride``-th step and at the last completed step (when off
    that grid) in ``PHI, VEL, EN (ke, pe)`` (``n_steps // stride + 2`` rows
    suffice); configuration changes in ``EVT (t) / EVI (joint, new state,
    kind)``; impacts in ``IMP`` rows ``(t, joint, v_before, ke_before,
    ke_after, state after)``; the peaks ``PEAK[0] = max |theta|`` per block and
    ``PEAK[1] = max |phi|`` per joint (rad) over EVERY completed step.
    Returns ``(n_rec, n_ev, n_imp_rec, status, t_status, k_last)`` with
    ``k_last`` the step index of the last recorded row.
    """
    n = phi0.shape[0]
    g = par[0]
    t_quiet = par[6]
    ecap = EVT.shape[0]
    icap = IMP.shape[0]
    phi = phi0.copy()
    v = v0.copy()
    s = s0.copy()
    px = np.empty(n)
    for j in range(n):
        px[j] = -s[j] * blk[j, 4]
    w = make_work(n)
    zeros = np.zeros(n)
    zs = np.zeros(n, np.int64)
    y0 = np.zeros(n)
    _energy(zeros, zeros, zs, blk, g, y0, w)
    for i in range(n):
        y0[i] = w.G[i, 1]
    # rigid column (all joints closed): thrust moments S_j and masses M_j above each joint
    Sj = np.zeros(n)
    Mj = np.zeros(n)
    for j in range(n):
        for i in range(j, n):
            Sj[j] += blk[i, 0] * (w.G[i, 1] - w.C[j, 1])
            Mj[j] += blk[i, 0]
    mu = par[1]
    acc = np.zeros(n)
    N = np.empty(n)
    V = np.empty(n)
    Mc = np.empty(n)
    phi1 = np.empty(n)
    v1 = np.empty(n)
    acc1 = np.empty(n)
    N1 = np.empty(n)
    V1 = np.empty(n)
    Mc1 = np.empty(n)
    viol0 = np.empty(n)
    viol1 = np.empty(n)
    s_new = np.empty(n, np.int64)
    px_new = np.empty(n)
    v_new = np.empty(n)
    nr = 0
    ne = 0
    ni = 0
    status = ST_END
    t_status = math.nan
    for j in range(n):
        if s[j] != 0 and ne < ecap:
            EVT[ne] = 0.0
            EVI[ne, 0] = j
            EVI[ne, 1] = s[j]
            EVI[ne, 2] = EV_START
            ne += 1
    if not evaluate(phi, v, s, 0.0, blk, par, accb, acc, N, V, Mc, w):
        return nr, ne, ni, ST_NUMERIC, 0.0, 0
    code = state_checks(s, phi, v, blk, par, N, V, Mc, viol0)
    for j in range(n):
        if viol0[j] > 0.0 and code == 0:
            if opening_model(phi, v, s, px, 0.0, dt, blk, par, accb, max_enum, s_new, px_new) > 0:
                ne = _apply_opening(0.0, s, px, s_new, px_new, EVT, EVI, ne)
                evaluate(phi, v, s, 0.0, blk, par, accb, acc, N, V, Mc, w)
                code = state_checks(s, phi, v, blk, par, N, V, Mc, viol0)
            break
    ke, pe = _energy(phi, v, s, blk, g, y0, w)
    PHI[0, :] = phi
    VEL[0, :] = v
    EN[0, 0] = ke
    EN[0, 1] = pe
    nr = 1
    for i in range(n):
        PEAK[0, i] = abs(w.theta[i])
        PEAK[1, i] = abs(phi[i])
    if code != 0:
        return nr, ne, ni, ST_TENSION if code == 1 else ST_SLIDING, 0.0, 0
    step = 0
    # the state of a step off the output grid waits in row nr (with its joint
    # states in s_pend) until the next one: the last completed step is always kept
    pending = False
    k_pend = 0
    s_pend = s.copy()
    countdown = stride  # no integer modulo in the loop
    while step < n_steps:
        t1 = (step + 1) * dt
        tc = step * dt
        n_sub = 0
        retry = False
        closed = True
        for j in range(n):
            if s[j] != 0:
                closed = False
        if closed:
            # the rigid column moves with the base: nothing to integrate unless a joint opens or slides
            ug1 = abs(base_acc(t1, par[2], par[3], accb))
            quiet = True
            for j in range(n):
                vj = ug1 * Sj[j] - blk[j, 4] * g * Mj[j]
                if vj > 0.0 or ug1 > mu * g:
                    quiet = False
            if quiet:
                for j in range(n):
                    viol0[j] = ug1 * Sj[j] - blk[j, 4] * g * Mj[j]
                tc = t1
        while t1 - tc > 1e-12 * dt:
            rem = t1 - tc
            n_sub += 1
            if n_sub > 100000 or not nm_step(phi, v, acc, s, tc, rem, blk, par, accb, phi1, v1, acc1, N1, V1, Mc1, w):
                status = ST_NUMERIC
                break
            # earliest closing (exact) and opening (linear interpolation) inside the sub-step
            tau_c = math.inf
            jc = -1
            for j in range(n):
                if s[j] != 0 and s[j] * phi1[j] < 0.0:
                    tj = locate_closing(phi, v, acc, s, tc, rem, j, blk, par, accb, phi1, v1, acc1, N1, V1, Mc1, w)
                    if tj < tau_c:
                        tau_c = tj
                        jc = j
            if jc >= 0:
                locate_closing(phi, v, acc, s, tc, rem, jc, blk, par, accb, phi1, v1, acc1, N1, V1, Mc1, w)
            code = state_checks(s, phi1, v1, blk, par, N1, V1, Mc1, viol1)
            tau_o = math.inf
            if not retry:
                for j in range(n):
                    if s[j] == 0 and viol1[j] > 0.0:
                        tt = rem if jc < 0 else tau_c
                        den = viol0[j] - viol1[j]
                        frac = viol0[j] / den if (den < 0.0 and viol0[j] < 0.0) else 0.0
                        if frac * tt < tau_o:
                            tau_o = frac * tt
            if tau_o < math.inf and (jc < 0 or tau_o < tau_c):
                # opening: step to the interpolated instant and ask the opening model
                if tau_o > 0.0:
                    nm_step(phi, v, acc, s, tc, tau_o, blk, par, accb, phi1, v1, acc1, N1, V1, Mc1, w)
                else:
                    for j in range(n):
                        phi1[j] = phi[j]
                        v1[j] = v[j]
                found = opening_model(phi1, v1, s, px, tc + tau_o, dt, blk, par, accb, max_enum, s_new, px_new)
                if found == 0:
                    # thrust not yet outside the section there: take the step, decide at its end
                    retry = True
                    continue
                tc = tc + tau_o
                for j in range(n):
                    phi[j] = phi1[j]
                    v[j] = v1[j]
                ne = _apply_opening(tc, s, px, s_new, px_new, EVT, EVI, ne)
            elif jc >= 0:
                tc = tc + tau_c
                for j in range(n):
                    phi[j] = phi1[j]
                    v[j] = v1[j]
                phi[jc] = 0.0
                ke_b, pe_b = _energy(phi, v, s, blk, g, y0, w)
                vb = v[jc]
                px0 = px[jc]
                sgn = 1.0 if vb > 0.0 else -1.0
                s_before = s.copy()
                ke_a = ke_b
                for k_imp in range(1, n_imp + 1):
                    px_to = -px0 if k_imp == n_imp else px0 * (1.0 - 2.0 * k_imp / n_imp)
                    ke_a = impact_model(phi, v, s, px, jc, px_to, sgn, blk, par, max_enum, v_tol, s_new, px_new, v_new)
                    for j in range(n):
                        s[j] = s_new[j]
                        px[j] = px_new[j]
                        v[j] = v_new[j]
                    if s[jc] == 0:
                        break
                if ni < icap:
                    IMP[ni, 0] = tc
                    IMP[ni, 1] = jc
                    IMP[ni, 2] = vb
                    IMP[ni, 3] = ke_b
                    IMP[ni, 4] = ke_a
                    IMP[ni, 5] = s[jc]
                    ni += 1
                for j in range(n):
                    if (s[j] != s_before[j] or j == jc) and ne < ecap:
                        EVT[ne] = tc
                        EVI[ne, 0] = j
                        EVI[ne, 1] = s[j]
                        EVI[ne, 2] = EV_IMPACT
                        ne += 1
                if ni >= icap or ne >= ecap:
                    status = ST_CAPACITY
                    break
            else:
                tc = t1
                for j in range(n):
                    phi[j] = phi1[j]
                    v[j] = v1[j]
                changed = False
                if retry and code == 0:
                    found = opening_model(phi, v, s, px, tc, dt, blk, par, accb, max_enum, s_new, px_new)
                    if found > 0:
                        ne = _apply_opening(tc, s, px, s_new, px_new, EVT, EVI, ne)
                        changed = True
                if not changed:
                    # the step's last iterate already holds accelerations and resultants
                    for j in range(n):
                        acc[j] = acc1[j]
                        N[j] = N1[j]
                        V[j] = V1[j]
                        Mc[j] = Mc1[j]
                        viol0[j] = viol1[j]
                    retry = False
                    if code != 0:
                        status = ST_TENSION if code == 1 else ST_SLIDING
                        break
                    continue
            retry = False
            if not evaluate(phi, v, s, tc, blk, par, accb, acc, N, V, Mc, w):
                status = ST_NUMERIC
                break
            code = state_checks(s, phi, v, blk, par, N, V, Mc, viol0)
            if code != 0:
                status = ST_TENSION if code == 1 else ST_SLIDING
                break
        step += 1
        if status != ST_END:
            t_status = tc
            break
        PHI[nr, :] = phi
        VEL[nr, :] = v
        any_open = ovt_angle > 0.0
        th = 0.0
        for i in range(n):
            # block angle summed as in geometry(): the peaks equal those of the full history
            th += phi[i]
            if abs(th) > PEAK[0, i]:
                PEAK[0, i] = abs(th)
            if abs(phi[i]) > PEAK[1, i]:
                PEAK[1, i] = abs(phi[i])
            if s[i] != 0:
                any_open = True
        countdown -= 1
        if countdown == 0:
            countdown = stride
            ke, pe = _energy(phi, v, s, blk, g, y0, w)
            EN[nr, 0] = ke
            EN[nr, 1] = pe
            nr += 1
            pending = False
        else:
            # off the output grid: no energy, and the geometry only if the overturning check reads it
            if any_open:
                geometry(phi, s, blk, w.theta, w.thlow, w.C, w.G)
            s_pend[:] = s
            k_pend = step
            pending = True
        if any_open and _overturned(v, s, blk, ovt_angle, w):
            status = ST_OVERTURN
            t_status = t1
            break
        if stop_at_rest and t1 >= t_quiet:
            rest = True
            for j in range(n):
                if s[j] != 0:
                    rest = False
            if rest:
                status = ST_REST
                t_status = t1
                break
    k_last = (nr - 1) * stride
    if pending:
        ke, pe = _energy(PHI[nr], VEL[nr], s_pend, blk, g, y0, w)
        EN[nr, 0] = ke
        EN[nr, 1] = pe
        nr += 1
        k_last = k_pend
    return nr, ne, ni, status, t_status, k_last


run_core_jit = njit(cache=True)(run_core)
