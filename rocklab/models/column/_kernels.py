"""Numerical kernels of the multi-block column model (Ther thesis §3.2–3.3, App. B–C).

Every function here is plain Python on numpy arrays and scalars, registered with
``numba.extending.register_jitable``: called from Python it runs as ordinary
(slow) Python — the baseline of ``benchmarks/bench_column.py`` — and inside the
``numba.njit`` driver of :mod:`._column_sim` it is compiled.

Internal conventions (the public API in :mod:`._column_sim` flips the sign)
-------------------------------------------------------------------------
- Plane frame x to the right, y up, moving with the base; angles positive
  counter-clockwise (thesis App. C, Fig. C2).
- Joint ``j`` (0-based) lies under block ``j``; joint 0 is the base joint.
  ``phi[j]`` is the rotation of block ``j`` relative to block ``j-1``, so the
  absolute angle of block ``i`` is ``sum(phi[:i+1])``.
- Joint state ``s[j]``: 0 closed, -1 open clockwise (phi <= 0, pivot at the
  right corner, thesis φ̌), +1 open counter-clockwise (phi >= 0, pivot at the
  left corner, φ̂). The pivot's offset along the joint is ``px = -s * a[j]``
  where ``a[j]`` is the joint's half-width less the cut edge.
- A degree of freedom (DOF) is a rotation about a pivot ``(joint, px)``; the
  reduced mass matrix of any DOF list is the App. C product BᵀMB written in
  closed form for rigid bodies (three mass points on the axis give the same
  mass, centre of mass and moment of inertia, so the sums are identical).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba.extending import register_jitable

__all__: list[str] = []

#: Scratch arrays of the hot path (allocated once per run; numba types the namedtuple).
Work = namedtuple("Work", "theta thlow C G dj dpx PP vk aq M Q x F A")


@register_jitable
def make_work(n):
    """Scratch arrays for a column of ``n`` blocks."""
    return Work(
        np.empty(n),
        np.empty(n),
        np.empty((n, 2)),
        np.empty((n, 2)),
        np.empty(n, np.int64),
        np.empty(n),
        np.empty((n, 2)),
        np.empty(n),
        np.zeros((n, 2)),
        np.empty((n, n)),
        np.empty(n),
        np.zeros(n),
        np.empty((n, 3)),
        np.empty((n, n + 1)),
    )


@register_jitable
def base_acc(t, t0b, dtb, accb):
    """Base acceleration at time ``t`` (s): linear interpolation, 0 outside the record."""
    nb = accb.shape[0]
    if nb == 0:
        return 0.0
    x = (t - t0b) / dtb
    if x < 0.0 or x > nb - 1:
        return 0.0
    i = int(math.floor(x))
    if i >= nb - 1:
        return accb[nb - 1]
    f = x - i
    return accb[i] * (1.0 - f) + accb[i + 1] * f


@register_jitable
def geometry(phi, s, blk, theta, thlow, C, G):
    """Current geometry from the joint rotations.

    Fills ``theta[i]`` (absolute block angle), ``thlow[j]`` (angle of the face
    under joint ``j``, i.e. of block ``j-1``; 0 for the base), ``C[j]`` (joint
    centre) and ``G[i]`` (centre of mass), all in the base frame, m and rad.
    """
    n = phi.shape[0]
    thp = 0.0
    ox = 0.0
    oy = 0.0
    hp = 0.0
    for i in range(n):
        c = math.cos(thp)
        sn = math.sin(thp)
        cx = ox - sn * hp
        cy = oy + c * hp
        C[i, 0] = cx
        C[i, 1] = cy
        thlow[i] = thp
        px = -s[i] * blk[i, 4]
        pxx = cx + c * px
        pyy = cy + sn * px
        th = thp + phi[i]
        theta[i] = th
        c2 = math.cos(th)
        s2 = math.sin(th)
        ox = pxx - c2 * px
        oy = pyy - s2 * px
        G[i, 0] = ox - s2 * blk[i, 3]
        G[i, 1] = oy + c2 * blk[i, 3]
        thp = th
        hp = blk[i, 2]


@register_jitable
def pivots(dj, dpx, k, C, thlow, PP):
    """Pivot points ``PP[:k]`` (m) of the DOFs ``(dj, dpx)`` in the current geometry."""
    for q in range(k):
        j = dj[q]
        PP[q, 0] = C[j, 0] + math.cos(thlow[j]) * dpx[q]
        PP[q, 1] = C[j, 1] + math.sin(thlow[j]) * dpx[q]


@register_jitable
def quad_acc(dj, PP, v, k, G, aq):
    """Velocity-dependent accelerations of the centres of mass.

    ``a_G,i = -sum_q v_q (2 Omega_q + v_q) (G_i - P_q)`` over DOFs below block
    ``i``, where ``Omega_q`` is the absolute angular velocity of the block under
    the DOF's joint (the pivot moves with it). This is the ``Ḃ φ̇`` term of the
    App. C reduction that the thesis drops (it recomputes B but keeps
    ``M̃ φ̈ = p̃``); with it the energy is conserved between events.
    """
    n = G.shape[0]
    for i in range(n):
        aq[i, 0] = 0.0
        aq[i, 1] = 0.0
    for q in range(k):
        j = dj[q]
        om = 0.0
        for r in range(k):
            if dj[r] < j:
                om += v[r]
        w = v[q] * (2.0 * om + v[q])
        if w == 0.0:
            continue
        for i in range(j, n):
            aq[i, 0] -= w * (G[i, 0] - PP[q, 0])
            aq[i, 1] -= w * (G[i, 1] - PP[q, 1])


@register_jitable
def system(dj, k, PP, G, blk, aq, ug, g, M, Q):
    """Reduced mass matrix ``M[:k,:k]`` (kg m²) and load vector ``Q[:k]`` (N m).

    ``M_pq = sum_{i >= max(j_p, j_q)} m_i (G_i - P_p)·(G_i - P_q) + I_G,i`` and
    ``Q_p = sum_{i >= j_p} (e_z × (G_i - P_p))·m_i (-ug e_x - g e_y - aq_i)``,
    the App. C products BᵀMB and Bᵀp for the current geometry (Eq. C8, C6).
    """
    n = G.shape[0]
    for p in range(k):
        jp = dj[p]
        qp = 0.0
        for i in range(jp, n):
            rx = G[i, 0] - PP[p, 0]
            ry = G[i, 1] - PP[p, 1]
            qp += blk[i, 0] * (-ry * (-ug - aq[i, 0]) + rx * (-g - aq[i, 1]))
        Q[p] = qp
        for r in range(p, k):
            i0 = max(jp, dj[r])
            acc = 0.0
            for i in range(i0, n):
                acc += (
                    blk[i, 0]
                    * ((G[i, 0] - PP[p, 0]) * (G[i, 0] - PP[r, 0]) + (G[i, 1] - PP[p, 1]) * (G[i, 1] - PP[r, 1]))
                    + blk[i, 1]
                )
            M[p, r] = acc
            M[r, p] = acc


@register_jitable
def solve_small(M, Q, k, x, A):
    """Solve ``M[:k,:k] x = Q[:k]`` by Gaussian elimination with partial pivoting.

    ``A`` is scratch of at least (k, k+1). Returns False for a singular matrix.
    Written out because k <= a few and a LAPACK call costs more than the arithmetic.
    """
    for i in range(k):
        for j in range(k):
            A[i, j] = M[i, j]
        A[i, k] = Q[i]
    for c in range(k):
        piv = c
        best = abs(A[c, c])
        for r in range(c + 1, k):
            if abs(A[r, c]) > best:
                best = abs(A[r, c])
                piv = r
        if best == 0.0:
            return False
        if piv != c:
            for j in range(c, k + 1):
                tmp = A[c, j]
                A[c, j] = A[piv, j]
                A[piv, j] = tmp
        for r in range(c + 1, k):
            f = A[r, c] / A[c, c]
            if f != 0.0:
                for j in range(c, k + 1):
                    A[r, j] -= f * A[c, j]
    for i in range(k - 1, -1, -1):
        acc = A[i, k]
        for j in range(i + 1, k):
            acc -= A[i, j] * x[j]
        x[i] = acc / A[i, i]
    return True


@register_jitable
def reactions(dj, k, PP, ddq, G, C, thlow, blk, aq, ug, g, N, V, Mc, F):
    """Contact resultants at every joint for accelerations ``ddq`` of the DOFs.

    For the part above joint ``j``: normal force ``N[j]`` (N, compression
    positive), shear ``V[j]`` (N, along the lower face) and moment ``Mc[j]``
    (N m, counter-clockwise) of the contact forces about the joint centre. The
    eccentricity of the thrust is ``Mc/N`` (positive towards the right corner).
    ``F`` is scratch of shape (n, 3).
    """
    n = G.shape[0]
    fx = F[:, 0]
    fy = F[:, 1]
    tdd = F[:, 2]
    for i in range(n):
        ax = aq[i, 0]
        ay = aq[i, 1]
        td = 0.0
        for q in range(k):
            if dj[q] <= i:
                ax -= ddq[q] * (G[i, 1] - PP[q, 1])
                ay += ddq[q] * (G[i, 0] - PP[q, 0])
                td += ddq[q]
        fx[i] = blk[i, 0] * (ax + ug)
        fy[i] = blk[i, 0] * (ay + g)
        tdd[i] = blk[i, 1] * td
    sx = 0.0
    sy = 0.0
    for j in range(n - 1, -1, -1):
        sx += fx[j]
        sy += fy[j]
        mom = 0.0
        for i in range(j, n):
            mom += (G[i, 0] - C[j, 0]) * fy[i] - (G[i, 1] - C[j, 1]) * fx[i] + tdd[i]
        c = math.cos(thlow[j])
        sn = math.sin(thlow[j])
        N[j] = -sn * sx + c * sy
        V[j] = c * sx + sn * sy
        Mc[j] = mom


@register_jitable
def active_dofs(s, blk, dj, dpx):
    """DOF list of the open joints of state ``s``; returns their number k."""
    k = 0
    for j in range(s.shape[0]):
        if s[j] != 0:
            dj[k] = j
            dpx[k] = -s[j] * blk[j, 4]
            k += 1
    return k


@register_jitable
def kinetic_energy(dj, k, PP, v, G, blk):
    """Kinetic energy (J) of the blocks for DOF velocities ``v`` (rad/s), relative to the base."""
    n = G.shape[0]
    e = 0.0
    for i in range(n):
        vx = 0.0
        vy = 0.0
        w = 0.0
        for q in range(k):
            if dj[q] <= i:
                vx -= v[q] * (G[i, 1] - PP[q, 1])
                vy += v[q] * (G[i, 0] - PP[q, 0])
                w += v[q]
        e += 0.5 * blk[i, 0] * (vx * vx + vy * vy) + 0.5 * blk[i, 1] * w * w
    return e
