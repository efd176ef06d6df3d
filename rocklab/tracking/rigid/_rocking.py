"""Rocking about a bottom edge, read off a rigid body's poses.

The single-block equations (Čeh et al. 2018, Eq. 1-4; thesis §3) assume planar
rocking about a fixed bottom edge. Given the rotation ``R`` and translation
``t`` of a block relative to its upright rest pose in every sample, this module
finds, from the data alone:

- the rocking axis ``a`` (horizontal, the dominant direction of the rotation
  vectors) and the rocking direction ``e_r = a x up``;
- the rotation split as ``R = Rz(twist) Rx(out_of_plane) Ry(theta)`` in the
  basis ``(e_r, a, up)``: ``theta`` about the rocking edge (positive tips the top
  towards ``+e_r``), the out-of-plane rotation about ``e_r`` and the twist
  about the vertical;
- the two pivot edges as points of the body (a linear least-squares fit of the
  fixed point of every sample's motion, one ground position per half-cycle so a
  slide at an impact does not bias it), and in every sample the displacement
  of the active edge from its rest position: sliding along ``e_r`` and uplift.

Everything here works in ``d = 2`` (a plane track: ``theta``, ``x``, ``y``) or
``d = 3``; the 2D case has no out-of-plane rotation or twist.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "RockingGeometry",
    "rocking_axes",
    "split_rotation",
    "find_impacts",
    "fit_pivots",
    "pivot_motion",
    "axis_vector",
]


def axis_vector(spec: str) -> np.ndarray:
    """Unit vector of a rig axis named ``x``, ``y``, ``z`` with an optional sign (``-y``)."""
    s = str(spec).strip().lower()
    sign = -1.0 if s.startswith("-") else 1.0
    s = s.lstrip("+-")
    if s not in ("x", "y", "z"):
        raise ValueError(f"axis {spec!r}: must be x, y or z with an optional sign")
    v = np.zeros(3)
    v["xyz".index(s)] = sign
    return v


def rocking_axes(R, up) -> tuple[np.ndarray, np.ndarray, float]:
    """Rocking axis and direction from the rotations of a run.

    Parameters
    ----------
    R : ndarray, shape (n, 3, 3)
        Rotations from the upright rest pose (NaN rows ignored).
    up : ndarray, shape (3,)
        Unit vertical of the rig.

    Returns
    -------
    axis : ndarray, shape (3,)
        Unit horizontal rocking axis ``a``.
    e_r : ndarray, shape (3,)
        Unit rocking direction ``a x up`` (its largest rig component is positive).
    max_rot_rad : float
        Largest horizontal rotation seen, rad (0: the body never rocked; the
        axes are then the rig's first horizontal axis and its normal).
    """
    from scipy.spatial.transform import Rotation

    ok = np.isfinite(R).all(axis=(1, 2))
    rv = Rotation.from_matrix(R[ok]).as_rotvec() if ok.any() else np.zeros((0, 3))
    rv_h = rv - np.outer(rv @ up, up)
    mag = np.linalg.norm(rv_h, axis=1)
    max_rot = float(mag.max()) if mag.size else 0.0
    if max_rot > 0:
        _, _, vt = np.linalg.svd(rv_h, full_matrices=False)
        a = vt[0] - (vt[0] @ up) * up
    else:
        a = np.zeros(3)
    if np.linalg.norm(a) < 1e-9 or max_rot == 0:
        h = np.eye(3)[int(np.argmin(np.abs(up)))]
        a = np.cross(up, h)
    a /= np.linalg.norm(a)
    e_r = np.cross(a, up)
    if e_r[np.argmax(np.abs(e_r))] < 0:
        a, e_r = -a, -e_r
    return a, e_r, max_rot


def split_rotation(R, e_r, axis, up):
    """Rocking angle, out-of-plane rotation and twist of each rotation, rad.

    ``R = B Rz(twist) Rx(out_of_plane) Ry(theta) B^T`` with ``B = [e_r, axis, up]``.

    Returns
    -------
    theta_rad, out_of_plane_rad, twist_rad : ndarray, shape (n,)
    """
    from scipy.spatial.transform import Rotation

    B = np.column_stack([e_r, axis, up])
    n = R.shape[0]
    out = np.full((n, 3), np.nan)
    ok = np.isfinite(R).all(axis=(1, 2))
    if ok.any():
        M = np.einsum("ji,njk,kl->nil", B, R[ok], B)
        out[ok] = Rotation.from_matrix(M).as_euler("yxz")
    return out[:, 0], out[:, 1], out[:, 2]


def find_impacts(t_s, theta_rad, hysteresis_rad: float) -> np.ndarray:
    """Impact times: where ``theta`` changes sign between excursions beyond ``hysteresis_rad``.

    The time is the linear zero crossing nearest the side change, s; noise
    below the hysteresis near rest makes no impacts.
    """
    t = np.asarray(t_s, float)
    th = np.asarray(theta_rad, float)
    ok = np.flatnonzero(np.isfinite(th))
    out = []
    side = 0
    last_i = None
    for i in ok:
        s = 1 if th[i] > hysteresis_rad else (-1 if th[i] < -hysteresis_rad else 0)
        if s == 0:
            continue
        if side != 0 and s != side and last_i is not None:
            # the crossing between the last sample on the old side and this one
            seg = np.arange(last_i, i + 1)
            seg = seg[np.isfinite(th[seg])]
            sgn = np.sign(th[seg])
            k = np.flatnonzero(sgn[:-1] * sgn[1:] <= 0)
            if k.size:
                j0, j1 = seg[k[0]], seg[k[0] + 1]
                f = th[j0] / (th[j0] - th[j1]) if th[j0] != th[j1] else 0.5
                out.append(t[j0] + f * (t[j1] - t[j0]))
            else:
                out.append(0.5 * (t[last_i] + t[i]))
        side = s
        last_i = i
    return np.asarray(out, float)


def segment_ids(t_s, impacts_t_s) -> np.ndarray:
    """Half-cycle index of every sample: 0 before the first impact, k after impact k."""
    return np.searchsorted(np.asarray(impacts_t_s, float), np.asarray(t_s, float), side="right")


@dataclass(frozen=True)
class RockingGeometry:
    """Where a block rocks, found from its motion.

    Attributes
    ----------
    up, axis, e_r : ndarray, shape (d,)
        Unit vertical, rocking axis (3D only; empty in 2D) and rocking direction.
    origin_m : ndarray, shape (d,)
        The body's reference centroid (the origin of the pivot coordinates), m.
    pivot_pos_m, pivot_neg_m : ndarray, shape (d,)
        The edge the block turns about for ``theta > 0`` / ``< 0``, in rest
        coordinates about ``origin_m`` (NaN if that side never rocked), m.
    base_width_m : float
        Distance between the two edges along ``e_r`` (the block's width b), m.
    pivot_height_gap_m : float
        Height difference of the two edges, m (about 0 for a flat base on a flat table).
    """

    up: np.ndarray
    axis: np.ndarray
    e_r: np.ndarray
    origin_m: np.ndarray
    pivot_pos_m: np.ndarray
    pivot_neg_m: np.ndarray
    base_width_m: float
    pivot_height_gap_m: float

    def to_dict(self) -> dict:
        """Plain-number dictionary (vectors as lists)."""
        return {
            "up": self.up.tolist(),
            "axis": self.axis.tolist(),
            "e_r": self.e_r.tolist(),
            "origin_m": self.origin_m.tolist(),
            "pivot_pos_m": self.pivot_pos_m.tolist(),
            "pivot_neg_m": self.pivot_neg_m.tolist(),
            "base_width_m": self.base_width_m,
            "pivot_height_gap_m": self.pivot_height_gap_m,
        }


def _centred(R, t, origin):
    """Translation of the motion about ``origin``: x - o = R (x_ref - o) + t'."""
    return t + np.einsum("nij,j->ni", R, origin) - origin


def fit_pivots(R, t_m, theta_rad, seg, origin, min_theta_rad: float, axis=None):
    """Body points the block turns about on each side (least squares over the samples).

    Solves ``R_k c - w_j = -t'_k`` for the edge ``c`` (rest coordinates about
    ``origin``) and one ground point ``w_j`` per half-cycle ``j``, using the
    samples with ``|theta| > min_theta_rad`` on that side. In 3D the point along
    the edge is pinned to the section through ``origin`` (``c . axis = 0``): the
    motion leaves it free, and noise would otherwise move it along the edge.

    Returns
    -------
    c_pos, c_neg : ndarray, shape (d,)
        NaN for a side with fewer than 5 usable samples.
    """
    d = R.shape[1]
    tc = _centred(R, t_m, origin)
    out = []
    for sign in (1, -1):
        use = np.isfinite(theta_rad) & (sign * theta_rad > min_theta_rad) & np.isfinite(tc).all(axis=1)
        idx = np.flatnonzero(use)
        if idx.size < 5:
            out.append(np.full(d, np.nan))
            continue
        segs, col = np.unique(seg[idx], return_inverse=True)
        pin = axis is not None and d == 3
        A = np.zeros((d * idx.size + pin, d + d * segs.size))
        b = np.zeros(d * idx.size + pin)
        if pin:
            A[-1, :d] = np.asarray(axis, float) * math.sqrt(idx.size)
        for r, (k, j) in enumerate(zip(idx, col)):
            rows = slice(d * r, d * r + d)
            A[rows, :d] = R[k]
            A[rows, d + d * j : d + d * j + d] = -np.eye(d)
            b[rows] = -tc[k]
        sol, *_ = np.linalg.lstsq(A, b, rcond=None)
        out.append(sol[:d])
    return out[0], out[1]


def pivot_motion(R, t_m, theta_rad, origin, c_pos, c_neg):
    """Displacement of the active edge from its rest position in every sample, m.

    Returns
    -------
    ndarray, shape (n, d)
        ``R c + t' - c`` for ``c = c_pos`` where ``theta >= 0`` and ``c_neg`` otherwise.
    """
    tc = _centred(R, t_m, origin)
    c = np.where((theta_rad >= 0)[:, None], c_pos[None], c_neg[None])
    return np.einsum("nij,nj->ni", R, c) + tc - c


def rotation_sigma(rms_m, n_points, ref_m, axis) -> np.ndarray:
    """1-sigma of the rotation about ``axis`` from the fit residual and the points' spread, rad.

    Per-coordinate noise ``s = rms / sqrt(3) * sqrt(3n / (3n - 6))`` over the
    points' squared distances from the axis through their centroid.
    """
    q = ref_m - np.nanmean(ref_m, axis=0)
    d2 = np.nansum(q**2, axis=1) - (q @ axis) ** 2
    spread = float(np.nansum(d2)) / max(len(d2), 1)
    n = np.asarray(n_points, float)
    dof = np.where(3 * n > 6, 3 * n / np.maximum(3 * n - 6, 1), np.nan)
    s = np.asarray(rms_m, float) / np.sqrt(3.0) * np.sqrt(dof)
    return s / np.sqrt(np.maximum(n * spread, 1e-30))
