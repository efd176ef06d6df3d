"""App. C reduction of a column and single-event entry points (Ther thesis App. B–C, §3.2).

The explicit forms the thesis prints — each block as three mass points on its
axis, the ``B`` matrix from the current geometry, ``M̃ = BᵀMB`` and
``p̃ = Bᵀp`` (Eq. C2–C16), the full ``2n × 2n`` mass matrix with both opening
directions of every joint (Eq. 4, 10) — and the impact model applied to one
given state (Eq. 7, 9). The simulator uses closed forms of the same products
(:mod:`._column_kernels`); tests check that both agree.

Sign convention here is the thesis's (App. C, Fig. C2): angles and moments
positive COUNTER-CLOCKWISE, ``φ̌ <= 0`` turns about the right corner, ``φ̂ >= 0``
about the left one. :func:`column_impact` uses the public clockwise-positive
convention of :func:`rocklab.models.simulate_column`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..._errors import InputError
from ...blocks import G as G_STD

__all__ = ["mass_points", "app_c_reduction", "full_mass_matrix", "column_impact", "ImpactOutcome"]


def mass_points(block):
    """Three mass points on a block's axis with its mass, centre of mass and inertia.

    Returns ``(y_m, m_kg)``, shape (3,) each: heights above the block's bottom
    face (m) and masses (kg). The end points sit at the bottom and top faces
    with ``m_end = I_G / (2 (h/2)²)`` (thesis App. C: 0.177, 0.646, 0.177 kg for
    a 1 × 4 m, 1 kg block); for squat blocks (``m_end > m/2``) they move outwards
    to ``d = sqrt(I_G/m)`` with the middle mass zero.
    """
    m = block.mass_kg
    IG = (block.alpha_I - 1.0) * m * block.R_m**2
    d = block.h_m / 2
    m_end = IG / (2 * d * d)
    if m_end > m / 2:
        d = math.sqrt(IG / m)
        m_end = m / 2
    hc = block.h_m / 2
    return np.array([hc - d, hc, hc + d]), np.array([m_end, m - 2 * m_end, m_end])


def _geometry(column, phi_ccw):
    """Block frames for joint rotations ``phi_ccw`` (CCW positive, pivots from their signs)."""
    from ._kernels import geometry

    n = column.n
    blk = column.block_array()
    phi = np.asarray(phi_ccw, float)
    s = np.sign(phi).astype(np.int64)
    theta, thlow, C, G = np.empty(n), np.empty(n), np.empty((n, 2)), np.empty((n, 2))
    geometry(phi, s, blk, theta, thlow, C, G)
    return blk, theta, thlow, C, G


def _dof_list(column, dofs):
    out = []
    a = column.half_width_m
    for j, d in dofs:
        if d not in ("cw", "ccw"):
            raise InputError(f"dof ({j}, {d!r}): direction must be 'cw' (right corner) or 'ccw' (left corner)")
        if not 0 <= int(j) < column.n:
            raise InputError(f"dof ({j}, {d!r}): joint index must be in 0..{column.n - 1}")
        out.append((int(j), a[int(j)] if d == "cw" else -a[int(j)]))
    return out


def app_c_reduction(column, phi_ccw_rad=None, dofs=None, ug_m_s2: float = 0.0, g_m_s2: float = G_STD):
    """The App. C reduction for the current geometry.

    Parameters
    ----------
    column : Column
    phi_ccw_rad : array (n,), optional
        Joint rotations, CCW positive (thesis sign), default all zero.
    dofs : list of (joint, "cw" | "ccw"), optional
        Reduced DOFs (rotations about a joint's right / left pivot); default all
        joints clockwise (as Eq. C11).
    ug_m_s2 : float
        Horizontal base acceleration, m/s² (the nodal loads are ``-m ug`` and ``-m g``).

    Returns
    -------
    dict with ``B`` (6n, k) in the order x of all points then y of all points
    (Eq. C11), ``M_diag`` (6n,) kg, ``p`` (6n,) N, ``M_red`` (k, k) kg m²,
    ``p_red`` (k,) N m.
    """
    n = column.n
    phi = np.zeros(n) if phi_ccw_rad is None else np.asarray(phi_ccw_rad, float)
    dl = _dof_list(column, dofs if dofs is not None else [(j, "cw") for j in range(n)])
    blk, theta, thlow, C, G = _geometry(column, phi)
    pts, mass = [], []
    for i, b in enumerate(column.blocks):
        y, mm = mass_points(b)
        for yk, mk in zip(y, mm):
            # point on the block axis, yk above the bottom face; G is at h/2 above it
            off = yk - b.h_m / 2
            pts.append((G[i, 0] - math.sin(theta[i]) * off, G[i, 1] + math.cos(theta[i]) * off, i))
            mass.append(mk)
    npnt = len(pts)
    B = np.zeros((2 * npnt, len(dl)))
    for q, (j, px) in enumerate(dl):
        Px = C[j, 0] + math.cos(thlow[j]) * px
        Py = C[j, 1] + math.sin(thlow[j]) * px
        for r, (x, y, i) in enumerate(pts):
            if i >= j:  # a rotation at joint j moves the blocks above it
                B[r, q] = -(y - Py)
                B[npnt + r, q] = x - Px
    M_diag = np.concatenate([mass, mass])
    p = np.concatenate([-np.asarray(mass) * ug_m_s2, -np.asarray(mass) * g_m_s2])
    return {"B": B, "M_diag": M_diag, "p": p, "M_red": B.T @ (M_diag[:, None] * B), "p_red": B.T @ p}


def full_mass_matrix(column, phi_ccw_rad=None) -> np.ndarray:
    """The ``2n × 2n`` mass matrix ``M_c`` of Eq. (6), DOFs ordered {φ̌_1..φ̌_n, φ̂_1..φ̂_n} (Eq. 4, 10)."""
    n = column.n
    dofs = [(j, "cw") for j in range(n)] + [(j, "ccw") for j in range(n)]
    return app_c_reduction(column, phi_ccw_rad, dofs)["M_red"]


@dataclass(frozen=True)
class ImpactOutcome:
    """Result of the impact model for one closing (public clockwise-positive signs).

    Attributes
    ----------
    states_before, states_after : tuple of str, (n,)
        Joint states ``closed | cw | ccw``.
    omega_before_rad_s, omega_after_rad_s : ndarray (n,)
        Joint rates (block j relative to block j-1), rad/s.
    block_omega_after_rad_s : ndarray (n,)
        Absolute block rates after the impact, rad/s.
    ke_before_J, ke_after_J : float
    energy_loss : float
        ``1 - ke_after/ke_before``.
    """

    states_before: tuple
    states_after: tuple
    omega_before_rad_s: np.ndarray
    omega_after_rad_s: np.ndarray
    block_omega_after_rad_s: np.ndarray
    ke_before_J: float
    ke_after_J: float
    energy_loss: float


def column_impact(
    column,
    closing_joint: int,
    omega_rad_s,
    states,
    theta_rad=None,
    n_impacts: int = 1,
    max_enum_closed: int = 9,
    rest_omega_rad_s: float = 0.0,
) -> ImpactOutcome:
    """Apply the impact model to a column whose joint ``closing_joint`` just closed.

    Parameters
    ----------
    column : Column
    closing_joint : int
    omega_rad_s : array (n,)
        Joint rates before the impact (clockwise positive), rad/s; zero at closed joints.
    states : sequence of str (n,)
        Joint states before the impact; ``states[closing_joint]`` is the
        direction it was open in.
    theta_rad : array (n,), optional
        Joint rotations (clockwise positive; the closing one must be 0), rad.
    n_impacts : int
        Consecutive impacts (1 Housner, 2 one mid-joint bump).
    """
    from ._events import impact_model

    n = column.n
    inv = {"closed": 0, "cw": -1, "ccw": 1}
    try:
        s = np.array([inv[x] for x in states], np.int64)
    except KeyError:
        raise InputError(f"states={states!r}: each must be 'closed', 'cw' or 'ccw'") from None
    jc = int(closing_joint)
    if s.size != n or not 0 <= jc < n or s[jc] == 0:
        raise InputError("closing_joint: must index an open joint of the column (states has one entry per joint)")
    blk = column.block_array()
    a = blk[:, 4]
    px = -s * a
    phi = np.zeros(n) if theta_rad is None else -np.asarray(theta_rad, float)
    phi[jc] = 0.0
    v = -np.asarray(omega_rad_s, float).copy()
    if s[jc] * v[jc] >= 0:
        raise InputError(f"omega_rad_s[{jc}]: the closing joint must move towards closed")
    par = np.array([G_STD, math.inf, 0.0, 1.0, 1.0, 1e-14, 0.0, 0.0])
    ke_b = _ke(column, phi, v, s, px)
    v_b = v.copy()
    px0, sgn = px[jc], (1.0 if v[jc] > 0 else -1.0)
    s_new, px_new, v_new = np.empty(n, np.int64), np.empty(n), np.empty(n)
    s_b = s.copy()
    ke_a = ke_b
    for step in range(1, int(n_impacts) + 1):
        px_to = -px0 if step == n_impacts else px0 * (1.0 - 2.0 * step / n_impacts)
        ke_a = impact_model(
            phi, v, s, px, jc, px_to, sgn, blk, par, max_enum_closed, rest_omega_rad_s, s_new, px_new, v_new
        )
        s, px, v = s_new.copy(), px_new.copy(), v_new.copy()
        if s[jc] == 0:
            break
    names = {0: "closed", -1: "cw", 1: "ccw"}
    return ImpactOutcome(
        tuple(names[int(x)] for x in s_b),
        tuple(names[int(x)] for x in s),
        -v_b,
        -v,
        np.cumsum(-v),
        float(ke_b),
        float(ke_a),
        float(1 - ke_a / ke_b),
    )


def _ke(column, phi, v, s, px):
    from ._kernels import kinetic_energy, pivots

    blk, theta, thlow, C, G = _geometry(column, phi)
    dj = np.array([j for j in range(column.n) if s[j] != 0], np.int64)
    dpx = np.array([px[j] for j in dj])
    PP = np.empty((max(dj.size, 1), 2))
    pivots(dj, dpx, dj.size, C, thlow, PP)
    return kinetic_energy(dj, dj.size, PP, v[dj], G, blk)
