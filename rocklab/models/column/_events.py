"""Opening and impact models of a multi-block column (Ther thesis §3.2.2–3.2.3, App. B).

Both enumerate the configurations the closed joints may take and keep the
kinematically admissible one of highest kinetic energy. The formulation keeps
both the clockwise and the counter-clockwise rotation of every joint as
unknowns (thesis Eq. 4), so the mass matrix of the union of candidate DOFs is
built once per event and each candidate solves a sub-system of it.

Plain Python registered with numba (see :mod:`._column_kernels`). Internal sign
conventions are those of :mod:`._column_kernels`.
"""

from __future__ import annotations

import numpy as np
from numba.extending import register_jitable

from ._kernels import base_acc, geometry, pivots, quad_acc, reactions, solve_small, system
from ._step import P_DT, P_G, P_T0, P_VEL

__all__: list[str] = []


@register_jitable
def _union(s, px, a, extra_j, extra_px, n_extra, dj, dpx):
    """DOF list: open joints (pivot ``px``), then ``extra`` DOFs, then CW and CCW of closed joints.

    Returns (k_open, k_total, closed joint list, n_closed).
    """
    n = s.shape[0]
    k = 0
    for j in range(n):
        if s[j] != 0:
            dj[k] = j
            dpx[k] = px[j]
            k += 1
    k_open = k
    for e in range(n_extra):
        dj[k] = extra_j[e]
        dpx[k] = extra_px[e]
        k += 1
    closed = np.empty(n, np.int64)
    nc = 0
    for j in range(n):
        if s[j] == 0 and not (n_extra > 0 and extra_j[0] == j):
            closed[nc] = j
            nc += 1
            dj[k] = j
            dpx[k] = a[j]  # clockwise: pivot at the right corner
            dj[k + 1] = j
            dpx[k + 1] = -a[j]  # counter-clockwise: pivot at the left corner
            k += 2
    return k_open, k, closed, nc


@register_jitable
def opening_model(phi, v, s, px, t, dt, blk, par, accb, max_enum, s_out, px_out):
    """Choose which closed joints open (thesis §3.2.2).

    Enumerates the 3^n_closed - 1 configurations of the closed joints (the open
    ones stay open), keeps those whose newly opened joints accelerate into the
    admissible direction (Eq. 5), prefers those whose remaining closed joints
    keep their thrust inside the section, and takes the highest kinetic energy
    after one step ``dt``. With more than ``max_enum`` closed joints (thesis:
    9, about 20 000 cases) the most loaded joint opens alone and the time step
    does the rest (the thesis's step-reduction alternative).

    Returns the number of candidates examined, or 0 if none is admissible;
    the chosen state in ``s_out, px_out``.
    """
    n = phi.shape[0]
    a = blk[:, 4]
    g = par[P_G]
    theta = np.empty(n)
    thlow = np.empty(n)
    C = np.empty((n, 2))
    G = np.empty((n, 2))
    geometry(phi, s, blk, theta, thlow, C, G)
    dj = np.empty(3 * n, np.int64)
    dpx = np.empty(3 * n)
    ex_j = np.zeros(1, np.int64)
    ex_px = np.zeros(1)
    k_open, K, closed, nc = _union(s, px, a, ex_j, ex_px, 0, dj, dpx)
    PP = np.empty((K, 2))
    pivots(dj, dpx, K, C, thlow, PP)
    vK = np.zeros(K)
    for q in range(k_open):
        vK[q] = v[dj[q]]
    aq = np.zeros((n, 2))
    if par[P_VEL] != 0.0:
        quad_acc(dj, PP, vK, k_open, G, aq)
    ug = base_acc(t, par[P_T0], par[P_DT], accb)
    Mf = np.empty((K, K))
    Qf = np.empty(K)
    system(dj, K, PP, G, blk, aq, ug, g, Mf, Qf)
    N = np.empty(n)
    V = np.empty(n)
    Mc = np.empty(n)
    idx = np.empty(n, np.int64)
    sdj = np.empty(n, np.int64)
    sPP = np.empty((n, 2))
    Ms = np.empty((n, n))
    Qs = np.empty(n)
    x = np.empty(n)
    Fs = np.empty((n, 3))
    As = np.empty((n, n + 1))
    digits = np.zeros(max(nc, 1), np.int64)
    hsum = 0.0
    for i in range(n):
        hsum += blk[i, 2]
    acc_tol = 1e-9 * g / hsum
    best_cons = -1.0
    best_ke = -1.0
    found = 0
    if nc <= max_enum:
        total = 3**nc
        cand_range = total - 1
    else:
        cand_range = 0
        # fallback: the closed joint with the largest eccentricity excess opens alone
        reactions(dj, k_open, PP, np.zeros(max(k_open, 1)), G, C, thlow, blk, aq, ug, g, N, V, Mc, Fs)
        worst = -1
        wv = -np.inf  # called because a thrust reached its edge: the largest excess may be ~0
        for c in range(nc):
            j = closed[c]
            # accelerations of the open joints matter little for the choice of joint
            val = abs(Mc[j]) - a[j] * N[j]
            if val > wv:
                wv = val
                worst = c
        for c in range(nc):
            digits[c] = 0
        if worst >= 0:
            digits[worst] = 1 if Mc[closed[worst]] > 0.0 else 2
            cand_range = 1
    for cand in range(cand_range):
        if nc <= max_enum:
            r = cand + 1
            for c in range(nc):
                digits[c] = r % 3
                r //= 3
        k = 0
        for q in range(k_open):
            idx[k] = q
            k += 1
        for c in range(nc):
            if digits[c] != 0:
                idx[k] = k_open + 2 * c + digits[c] - 1
                k += 1
        for p in range(k):
            Qs[p] = Qf[idx[p]]
            sdj[p] = dj[idx[p]]
            sPP[p, 0] = PP[idx[p], 0]
            sPP[p, 1] = PP[idx[p], 1]
            for r2 in range(k):
                Ms[p, r2] = Mf[idx[p], idx[r2]]
        if not solve_small(Ms, Qs, k, x, As):
            continue
        ok = True
        p = k_open
        for c in range(nc):
            if digits[c] != 0:
                sg = -1.0 if digits[c] == 1 else 1.0
                # at the interpolated opening instant the acceleration is ~0: allow round-off
                if sg * x[p] < -acc_tol:
                    ok = False
                p += 1
        if not ok:
            continue
        # consistency of the joints that stay closed (thrust inside the section)
        reactions(sdj, k, sPP, x, G, C, thlow, blk, aq, ug, g, N, V, Mc, Fs)
        consistent = 1.0
        for c in range(nc):
            j = closed[c]
            if digits[c] == 0 and abs(Mc[j]) > a[j] * N[j] * (1.0 + 1e-9) + 1e-12:
                consistent = 0.0
        ke = 0.0
        for p in range(k):
            vp = (vK[idx[p]] if p < k_open else 0.0) + dt * x[p]
            for r2 in range(k):
                vr = (vK[idx[r2]] if r2 < k_open else 0.0) + dt * x[r2]
                ke += 0.5 * vp * Ms[p, r2] * vr
        # lexicographic choice: consistent candidates first, then kinetic energy
        if consistent > best_cons or (consistent == best_cons and ke > best_ke):
            best_cons = consistent
            best_ke = ke
            for j in range(n):
                s_out[j] = s[j]
                px_out[j] = px[j]
            for c in range(nc):
                j = closed[c]
                if digits[c] == 1:
                    s_out[j] = -1
                    px_out[j] = a[j]
                elif digits[c] == 2:
                    s_out[j] = 1
                    px_out[j] = -a[j]
        found += 1
    return found


@register_jitable
def impact_model(phi, v, s, px, jc, px_to, sgn_to, blk, par, max_enum, v_tol, s_out, px_out, v_out):
    """Post-impact configuration and velocities when joint ``jc`` closes (thesis §3.2.3).

    The closing DOF is joint ``jc`` rotating about ``px[jc]`` with velocity
    ``v[jc]``; after the impact joint ``jc`` either stays closed or turns about
    ``px_to`` (the opposite corner, or the next bump of a consecutive-impact
    chain) with a velocity of sign ``sgn_to``; every other closed joint may stay
    closed or open either way (2·3^n_closed candidates, Eq. 9); open joints stay
    open. Velocities follow Eq. (7)/(B6): the impulse acts only on the closing
    DOF, so ``v_S+ = v_S- + M_SS⁻¹ M_S,c v_c``. Candidates whose opening joints
    move the wrong way (or slower than ``v_tol``) are dropped; of the rest the
    one of highest kinetic energy wins. Beyond ``max_enum`` closed joints only
    the closing joint's two options are tried.

    Returns the kinetic energy after the impact (J); ``s_out, px_out, v_out``.
    """
    n = phi.shape[0]
    a = blk[:, 4]
    theta = np.empty(n)
    thlow = np.empty(n)
    C = np.empty((n, 2))
    G = np.empty((n, 2))
    geometry(phi, s, blk, theta, thlow, C, G)
    dj = np.empty(3 * n + 2, np.int64)
    dpx = np.empty(3 * n + 2)
    # the closing DOF is listed among the open ones; the new pivot of jc is the extra DOF
    ex_j = np.array([jc], np.int64)
    ex_px = np.array([px_to])
    k_open, K, closed, nc = _union(s, px, a, ex_j, ex_px, 1, dj, dpx)
    PP = np.empty((K, 2))
    pivots(dj, dpx, K, C, thlow, PP)
    aq = np.zeros((n, 2))
    Mf = np.empty((K, K))
    Qf = np.empty(K)
    system(dj, K, PP, G, blk, aq, 0.0, par[P_G], Mf, Qf)
    qc = -1
    for q in range(k_open):
        if dj[q] == jc:
            qc = q
    vc = v[jc]
    if nc > max_enum:
        nc_enum = 0
    else:
        nc_enum = nc
    idx = np.empty(n + 1, np.int64)
    Ms = np.empty((n + 1, n + 1))
    rhs = np.empty(n + 1)
    dv = np.empty(n + 1)
    vv = np.empty(n + 1)
    As = np.empty((n + 1, n + 2))
    digits = np.zeros(max(nc, 1), np.int64)
    best = -1.0
    total = 2 * 3**nc_enum
    for cand in range(total):
        reopen = cand % 2
        r = cand // 2
        for c in range(nc_enum):
            digits[c] = r % 3
            r //= 3
        k = 0
        for q in range(k_open):
            if q != qc:
                idx[k] = q
                k += 1
        k_keep = k
        if reopen == 1:
            idx[k] = k_open
            k += 1
        for c in range(nc_enum):
            if digits[c] != 0:
                idx[k] = k_open + 1 + 2 * c + digits[c] - 1
                k += 1
        for p in range(k):
            rhs[p] = Mf[idx[p], qc] * vc
            for r2 in range(k):
                Ms[p, r2] = Mf[idx[p], idx[r2]]
        if k > 0 and not solve_small(Ms, rhs, k, dv, As):
            continue
        ok = True
        for p in range(k):
            vv[p] = (v[dj[idx[p]]] if p < k_keep else 0.0) + dv[p]
        p = k_keep
        if reopen == 1:
            if sgn_to * vv[p] <= v_tol:
                ok = False
            p += 1
        for c in range(nc_enum):
            if digits[c] != 0:
                sg = -1.0 if digits[c] == 1 else 1.0
                if sg * vv[p] <= v_tol:
                    ok = False
                p += 1
        if not ok:
            continue
        ke = 0.0
        for p in range(k):
            for r2 in range(k):
                ke += 0.5 * vv[p] * Ms[p, r2] * vv[r2]
        if ke > best:
            best = ke
            for j in range(n):
                s_out[j] = s[j]
                px_out[j] = px[j]
                v_out[j] = 0.0
            s_out[jc] = 0
            px_out[jc] = 0.0
            p = 0
            for q in range(k_keep):
                v_out[dj[idx[q]]] = vv[q]
            p = k_keep
            if reopen == 1:
                s_out[jc] = 1 if sgn_to > 0 else -1
                px_out[jc] = px_to
                v_out[jc] = vv[p]
                p += 1
            for c in range(nc_enum):
                if digits[c] != 0:
                    j = closed[c]
                    s_out[j] = -1 if digits[c] == 1 else 1
                    px_out[j] = a[j] if digits[c] == 1 else -a[j]
                    v_out[j] = vv[p]
                    p += 1
    return best
