"""The assumption audit for a plane (2D) track: one camera, the block's θ and origin in the rocking plane.

A video tracker gives, per frame, the block's levelled angle and the position
of its origin in the plane (x right, y up, m). That is a rigid motion in two
dimensions, so the pivot edges and their sliding and uplift come out of the
same kind of least-squares fit as in 3D (every sample's origin turns about
one ground point per half-cycle); twist and out-of-plane rotation cannot be seen from one
camera and are not checked. Without a metric scale only the impacts
(double impacts) are checked.
"""

from __future__ import annotations

import math

import numpy as np

from ._audit import AuditResult, AuditTolerances, audit_rocking
from ._rocking import find_impacts, segment_ids

__all__ = ["audit_plane_track", "plane_pivot_motion"]


def _fit_arms(R, o, th, seg, min_theta, width=None, sign=1.0):
    """Least-squares arms ``d+, d-`` (from each edge to the origin, rest axes) and the ground points.

    Every sample on side ``s`` of half-cycle ``j`` obeys ``o_k = w_j + R_k d_s``: the
    origin turns about a ground point. With ``width``, ``d+- = d_mid +- sign * width / 2 * e_x``.
    """
    rows = [
        (k, side)
        for side in (1, -1)
        for k in np.flatnonzero(np.isfinite(th) & (side * th > min_theta) & np.isfinite(o).all(axis=1))
    ]
    if len(rows) < 10 or {side for _, side in rows} != {1, -1}:
        return np.full(2, np.nan), np.full(2, np.nan), float("nan")
    keys = sorted({(int(seg[k]), side) for k, side in rows})
    col = {key: i for i, key in enumerate(keys)}
    n_d = 2 if width is not None else 4
    A = np.zeros((2 * len(rows), n_d + 2 * len(keys)))
    b = np.zeros(2 * len(rows))
    half = 0.5 * (width or 0.0) * sign
    for r, (k, side) in enumerate(rows):
        sl = slice(2 * r, 2 * r + 2)
        if width is not None:
            A[sl, :2] = R[k]
            b[sl] = o[k] - side * half * R[k][:, 0]
        else:
            A[sl, (0 if side > 0 else 2) : (2 if side > 0 else 4)] = R[k]
            b[sl] = o[k]
        j = n_d + 2 * col[(int(seg[k]), side)]
        A[sl, j : j + 2] = np.eye(2)
    sol, *_ = np.linalg.lstsq(A, b, rcond=None)
    rms = float(np.sqrt(np.mean((A @ sol - b) ** 2)))
    if width is not None:
        return sol[:2] + np.array([half, 0.0]), sol[:2] - np.array([half, 0.0]), rms
    return sol[:2], sol[2:4], rms


def plane_pivot_motion(t_s, theta_rad, x_m, y_m, sigma_theta_rad: float = 0.0, base_width_m: float | None = None):
    """Sliding and uplift of the active pivot edge of a plane track, m.

    Parameters
    ----------
    t_s, theta_rad : array_like, shape (n,)
        Time, s, and levelled counter-clockwise angle, rad (NaN = lost).
    x_m, y_m : array_like, shape (n,)
        The block's origin in the plane (x right, y up), m, relative to the table.
    sigma_theta_rad : float
        Typical 1-sigma of ``theta``, rad.
    base_width_m : float, optional
        The block's width b, m: the two edges are then fitted as one point pair
        at one height, b apart (far better conditioned when ``theta`` is noisy
        against its amplitude, as for a slender block filmed from afar).

    Returns
    -------
    slide_m, uplift_m : ndarray, shape (n,)
        Position of the active edge along x and up, mapped onto the base's
        middle and relative to its median over the run (constant for planar
        rocking on a fixed edge), m; NaN if the block never rocked to both sides.
    arms_m : tuple of ndarray, shape (2,)
        From the edge for ``theta > 0`` / ``< 0`` to the origin, rest axes, m.
    fit_rms_m : float
        RMS misfit of the origin's positions to rotation about fixed edges, m: how
        far the track itself departs from rigid planar rocking (noise, or a theta
        and a position that disagree); the audit's floor for sliding and uplift.

    Notes
    -----
    No rest pose is needed: a record that ends while the block still rocks has
    none, and an origin taken from a nearly upright frame would put its error,
    divided by theta, into the edges.
    """
    t = np.asarray(t_s, float)
    th = np.asarray(theta_rad, float)
    o = np.column_stack([np.asarray(x_m, float), np.asarray(y_m, float)])
    n = t.size
    nan = np.full(n, np.nan)
    ok = np.isfinite(th) & np.isfinite(o).all(axis=1)
    if ok.sum() < 10:
        return nan, nan.copy(), (np.full(2, np.nan), np.full(2, np.nan)), float("nan")
    c, s = np.cos(th), np.sin(th)
    R = np.stack([np.stack([c, -s], axis=-1), np.stack([s, c], axis=-1)], axis=-2)  # (n, 2, 2)
    hyst = max(5.0 * sigma_theta_rad, math.radians(0.05))
    seg = segment_ids(t, find_impacts(t, th, hyst))
    min_theta = max(math.radians(0.3), 10.0 * sigma_theta_rad)
    d_pos, d_neg, rms = _fit_arms(R, o, th, seg, min_theta)
    if base_width_m is not None and np.isfinite(d_pos).all():
        # which edge is which comes from the free fit (d+ - d- = c- - c+); where they are, from the width
        sign = 1.0 if (d_pos - d_neg)[0] > 0 else -1.0
        d_pos, d_neg, rms = _fit_arms(R, o, th, seg, min_theta, base_width_m, sign)
    if not np.isfinite(d_pos).all():
        return nan, nan.copy(), (d_pos, d_neg), rms
    d_mid = 0.5 * (d_pos + d_neg)
    d = np.where((th >= 0)[:, None], d_pos[None], d_neg[None])
    # the active edge's ground position, moved to where the base's middle is when that edge is at rest
    p = o - np.einsum("nij,nj->ni", R, d) + (d - d_mid)
    p[~ok] = np.nan
    p -= np.nanmedian(p, axis=0)
    return p[:, 0], p[:, 1], (d_pos, d_neg), rms


def audit_plane_track(
    t_s,
    theta_rad,
    x_m=None,
    y_m=None,
    sigma_theta_rad: float | None = None,
    tolerances: AuditTolerances | None = None,
    base_width_m: float | None = None,
) -> AuditResult:
    """:func:`audit_rocking` for a plane track (see the module doc).

    Parameters
    ----------
    t_s, theta_rad : array_like, shape (n,)
    x_m, y_m : array_like, shape (n,), optional
        The block's origin relative to the table, m; None or all NaN (no metric
        scale): only the impacts are checked.
    sigma_theta_rad : float, optional
    tolerances : AuditTolerances, optional
    base_width_m : float, optional
        The block's width, m (see :func:`plane_pivot_motion`).

    Returns
    -------
    AuditResult
        ``source = "2d"``.
    """
    sig = float(sigma_theta_rad) if sigma_theta_rad is not None and np.isfinite(sigma_theta_rad) else 0.0
    slide = uplift = floor = None
    notes = []
    if x_m is not None and y_m is not None and np.isfinite(np.asarray(x_m, float)).any():
        slide, uplift, _, fit_rms = plane_pivot_motion(t_s, theta_rad, x_m, y_m, sig, base_width_m)
        floor = {"slide": fit_rms, "jump": fit_rms}
    else:
        notes.append("no metric position: sliding and uplift not checked")
    res = audit_rocking(
        t_s,
        theta_rad,
        slide_m=slide,
        uplift_m=uplift,
        sigma_theta_rad=sig,
        tolerances=tolerances,
        source="2d",
        noise_floor=floor,
    )
    if notes:
        from dataclasses import replace

        res = replace(res, notes=res.notes + tuple(notes))
    return res
