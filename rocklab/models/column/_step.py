"""Time stepping of a column in a fixed configuration (Ther thesis §3.3).

Newmark's trapezoidal rule (β = 1/4, γ = 1/2; the scheme of the single-block
model, Čeh et al. 2018 Eq. 5) on ``M(φ) φ̈ = Q(φ, φ̇, t)`` over the open joints,
with the geometry (the App. C B matrix) recomputed at every iterate. Plain
Python registered with numba (see :mod:`._column_kernels`).

Parameter packing (numba-friendly)
----------------------------------
``blk`` : ndarray (n, 5): mass kg, I_G kg m², height m, height of the centre of
mass m, joint half-width less the cut edge m (joint j under block j).
``par`` : ndarray (8,): g m/s², friction coefficient μ (inf = no check),
record start s, record step s, velocity terms (1/0), tolerance, unused ×2.
``accb`` : ndarray (nb,): base acceleration samples, m/s².
"""

from __future__ import annotations

import numpy as np
from numba.extending import register_jitable

from ._kernels import active_dofs, base_acc, geometry, pivots, quad_acc, reactions, solve_small, system

__all__: list[str] = []

P_G, P_MU, P_T0, P_DT, P_VEL = 0, 1, 2, 3, 4


@register_jitable
def evaluate(phi, v, s, t, blk, par, accb, acc_out, N, V, Mc, w):
    """Accelerations of the open joints and the joint resultants at time ``t``.

    ``phi, v`` (n,): joint rotations (rad) and velocities (rad/s), zero at closed
    joints. Writes ``acc_out`` (n,) (zero at closed joints) and ``N, V, Mc`` (n,)
    (see :func:`reactions`); ``w`` is the scratch :class:`Work`. Returns False
    when the mass matrix is singular.
    """
    n = phi.shape[0]
    geometry(phi, s, blk, w.theta, w.thlow, w.C, w.G)
    k = active_dofs(s, blk, w.dj, w.dpx)
    pivots(w.dj, w.dpx, k, w.C, w.thlow, w.PP)
    for q in range(k):
        w.vk[q] = v[w.dj[q]]
    aq = w.aq
    for i in range(n):
        aq[i, 0] = 0.0
        aq[i, 1] = 0.0
    if par[P_VEL] != 0.0 and k > 0:
        quad_acc(w.dj, w.PP, w.vk, k, w.G, aq)
    ug = base_acc(t, par[P_T0], par[P_DT], accb)
    ok = True
    if k > 0:
        system(w.dj, k, w.PP, w.G, blk, aq, ug, par[P_G], w.M, w.Q)
        ok = solve_small(w.M, w.Q, k, w.x, w.A)
    for j in range(n):
        acc_out[j] = 0.0
    for q in range(k):
        acc_out[w.dj[q]] = w.x[q]
    reactions(w.dj, k, w.PP, w.x, w.G, w.C, w.thlow, blk, aq, ug, par[P_G], N, V, Mc, w.F)
    return ok


@register_jitable
def nm_step(phi, v, acc, s, t, dt, blk, par, accb, phi1, v1, acc1, N, V, Mc, w):
    """One implicit trapezoidal step of length ``dt`` from ``t`` (fixed configuration ``s``).

    Solves ``φ1 = φ + dt φ̇ + dt²/4 (φ̈ + φ̈1)``, ``φ̇1 = φ̇ + dt/2 (φ̈ + φ̈1)`` with
    ``φ̈1 = M(φ1)⁻¹ Q(φ1, φ̇1, t + dt)`` by fixed-point iteration (contraction
    factor ~ (p dt)²/4, so two or three sweeps reach round-off). Results in
    ``phi1, v1, acc1`` and the resultants at the end of the step. Returns False
    if the iteration fails (singular matrix or no convergence).
    """
    n = phi.shape[0]
    tol = par[5]
    h2 = 0.25 * dt * dt
    for j in range(n):
        acc1[j] = acc[j]
    ok = True
    for it in range(60):
        diff = 0.0
        for j in range(n):
            if s[j] == 0:
                phi1[j] = 0.0
                v1[j] = 0.0
                continue
            p_new = phi[j] + dt * v[j] + h2 * (acc[j] + acc1[j])
            d = abs(p_new - phi1[j]) if it > 0 else 1.0
            if d > diff:
                diff = d
            phi1[j] = p_new
            v1[j] = v[j] + 0.5 * dt * (acc[j] + acc1[j])
        if it > 0 and diff <= tol:
            break
        ok = evaluate(phi1, v1, s, t + dt, blk, par, accb, acc1, N, V, Mc, w)
        if not ok:
            return False
    # final update so that (phi1, v1, acc1) satisfy the Newmark relations exactly
    for j in range(n):
        if s[j] != 0:
            phi1[j] = phi[j] + dt * v[j] + h2 * (acc[j] + acc1[j])
            v1[j] = v[j] + 0.5 * dt * (acc[j] + acc1[j])
    return ok


@register_jitable
def locate_closing(phi, v, acc, s, t, dt, jc, blk, par, accb, phi1, v1, acc1, N, V, Mc, w):
    """Step length ``dt' ∈ (0, dt]`` after which joint ``jc`` is exactly closed.

    The step of unknown length with ``φ_jc(t + dt') = 0`` (Čeh et al. Eq. 8,
    solved iteratively as the base acceleration makes it non-quadratic): a
    safeguarded secant (Illinois) search on ``g(dt') = s φ_jc`` after the step,
    ``g(0) > 0 > g(dt)``. Leaves the state at ``t + dt'`` in ``phi1, v1, acc1``.
    """
    lo = 0.0
    glo = s[jc] * phi[jc]
    hi = dt
    nm_step(phi, v, acc, s, t, hi, blk, par, accb, phi1, v1, acc1, N, V, Mc, w)
    ghi = s[jc] * phi1[jc]
    side = 0
    x = hi
    for it in range(100):
        if ghi == glo:
            x = 0.5 * (lo + hi)
        else:
            x = (lo * ghi - hi * glo) / (ghi - glo)
        if not (lo < x < hi):
            x = 0.5 * (lo + hi)
        nm_step(phi, v, acc, s, t, x, blk, par, accb, phi1, v1, acc1, N, V, Mc, w)
        gx = s[jc] * phi1[jc]
        if gx > 0.0:
            lo = x
            glo = gx
            if side == -1:
                ghi *= 0.5
            side = -1
        else:
            hi = x
            ghi = gx
            if side == 1:
                glo *= 0.5
            side = 1
        if abs(gx) <= 1e-15 * (1.0 + abs(phi[jc])) or (hi - lo) <= 1e-15 * dt:
            break
    return x


@register_jitable
def state_checks(s, phi, v, blk, par, N, V, Mc, viol):
    """Constraint checks at the end of a step.

    Writes ``viol[j] = |Mc| - a N`` (> 0: the thrust of a closed joint left the
    section, the joint must open, thesis §3.3 first condition). Returns a code:
    0 fine, 1 tension at some joint, 2 sliding (``μN < |V|``).
    """
    n = s.shape[0]
    mu = par[P_MU]
    code = 0
    for j in range(n):
        viol[j] = abs(Mc[j]) - blk[j, 4] * N[j] if s[j] == 0 else -1.0
        if N[j] < 0.0:
            code = 1
        elif mu < np.inf and abs(V[j]) > mu * N[j] and code == 0:
            code = 2
    return code
