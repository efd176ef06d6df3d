"""Rigid-body pose of a point set in every sample (Kabsch / Umeyama without scale).

The pose of a sample is the rotation ``R`` and translation ``t`` that carry the
body's reference shape onto the points seen, ``x = R x_ref + t``, fitted by
weighted least squares (Kabsch 1976; Umeyama 1991 without the scale). Points
the system did not see are left out of that sample's fit; a point whose
residual is far above the run's typical residual is rejected and the pose
refitted, so one swapped or reflected marker cannot bend the block.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


__all__ = ["kabsch", "BodyPoses", "body_poses", "reference_shape"]

#: Fewest points a rigid pose needs (three, not on one line).
MIN_POINTS = 3


def kabsch(ref, cur, weights=None):
    """Best rotation and translation carrying ``ref`` onto ``cur``, for one or many samples.

    Parameters
    ----------
    ref : array_like, shape (p, 3)
        Reference positions, m.
    cur : array_like, shape (n, p, 3) or (p, 3)
        Positions to fit, m; NaN rows are ignored.
    weights : array_like, shape (n, p) or (p,), optional
        Per-point weights (0 drops a point); default 1 where ``cur`` is finite.

    Returns
    -------
    R : ndarray, shape (n, 3, 3) (or (3, 3))
        Proper rotations (det +1), ``cur ~ R ref + t``.
    t : ndarray, shape (n, 3) (or (3,))
    rms_m : ndarray, shape (n,) (or scalar)
        Root-mean-square 3D residual of the points used, m.
    """
    ref = np.asarray(ref, float)
    cur = np.asarray(cur, float)
    single = cur.ndim == 2
    if single:
        cur = cur[None]
    seen = np.isfinite(cur).all(axis=2) & np.isfinite(ref).all(axis=1)[None]
    w = (
        seen.astype(float)
        if weights is None
        else np.where(seen, np.broadcast_to(np.asarray(weights, float), seen.shape), 0.0)
    )
    c = np.where(seen[..., None], cur, 0.0)
    r = np.where(np.isfinite(ref), ref, 0.0)
    sw = w.sum(axis=1)
    sw_safe = np.where(sw > 0, sw, 1.0)
    cc = (w[..., None] * c).sum(axis=1) / sw_safe[:, None]
    cr = (w[..., None] * r[None]).sum(axis=1) / sw_safe[:, None]
    a = r[None] - cr[:, None]
    b = c - cc[:, None]
    h = np.einsum("np,npi,npj->nij", w, a, b)
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(np.transpose(vt, (0, 2, 1)) @ np.transpose(u, (0, 2, 1))))
    d = np.where(d == 0, 1.0, d)
    fix = np.ones((cur.shape[0], 3))
    fix[:, 2] = d
    rot = np.transpose(vt, (0, 2, 1)) @ (fix[:, :, None] * np.transpose(u, (0, 2, 1)))
    t = cc - np.einsum("nij,nj->ni", rot, cr)
    res = c - (np.einsum("nij,pj->npi", rot, r) + t[:, None])
    rms = np.sqrt((w * (res**2).sum(axis=2)).sum(axis=1) / sw_safe)
    bad = sw < MIN_POINTS - 1e-12
    rot[bad] = np.nan
    t[bad] = np.nan
    rms[bad] = np.nan
    if single:
        return rot[0], t[0], float(rms[0])
    return rot, t, rms


def reference_shape(xyz, frames) -> np.ndarray:
    """The body's reference shape: each point's median over ``frames``, filled from the other samples.

    Parameters
    ----------
    xyz : ndarray, shape (n, p, 3)
        Point positions, m (NaN = not seen).
    frames : array of int
        The reference (rest) samples.

    Returns
    -------
    ndarray, shape (p, 3)
        NaN for a point never placed relative to at least three reference points.
    """
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a point never seen at rest stays NaN (filled below)
        ref = np.nanmedian(xyz[frames], axis=0) if len(frames) else np.full(xyz.shape[1:], np.nan)
    missing = ~np.isfinite(ref).all(axis=1)
    if missing.any() and (~missing).sum() >= MIN_POINTS:
        # place the points unseen at rest by the pose of the others in the samples that see them
        rot, t, _ = kabsch(ref[~missing], xyz[:, ~missing])
        ok = np.isfinite(t).all(axis=1)
        for j in np.flatnonzero(missing):
            s = ok & np.isfinite(xyz[:, j]).all(axis=1)
            if s.any():
                back = np.einsum("nji,nj->ni", rot[s], xyz[s, j] - t[s])
                ref[j] = np.median(back, axis=0)
    return ref


@dataclass(frozen=True)
class BodyPoses:
    """Pose of one rigid point set in every sample.

    Attributes
    ----------
    R : ndarray, shape (n, 3, 3)
        Rotation from the reference shape to the sample (NaN where lost).
    t_m : ndarray, shape (n, 3)
        Translation, m (``x = R x_ref + t``).
    rms_m : ndarray, shape (n,)
        RMS 3D residual of the points used, m.
    n_points : ndarray of int, shape (n,)
        Points used in each sample's fit.
    status : ndarray of str, shape (n,)
        ``"ok"``, ``"lost"`` (fewer than three points seen) or ``"degenerate"``
        (the points seen lie on a line).
    ref_m : ndarray, shape (p, 3)
        The reference shape, m.
    n_rejected : int
        Point samples rejected as outliers.
    """

    R: np.ndarray
    t_m: np.ndarray
    rms_m: np.ndarray
    n_points: np.ndarray
    status: np.ndarray
    ref_m: np.ndarray
    n_rejected: int


def body_poses(xyz, ref, outlier_m: float | None = None) -> BodyPoses:
    """Pose of the body with reference shape ``ref`` in each sample of ``xyz``.

    Parameters
    ----------
    xyz : ndarray, shape (n, p, 3)
        Point positions, m (NaN = not seen).
    ref : ndarray, shape (p, 3)
        Reference shape, m.
    outlier_m : float, optional
        A point whose residual exceeds this is dropped from that sample and the
        pose refitted (the worst first, one at a time, while three remain); default
        ``max(6 x the run's median point residual, 0.5 mm)``.

    Returns
    -------
    BodyPoses
    """
    xyz = np.asarray(xyz, float)
    rot, t, rms = kabsch(ref, xyz)
    seen = np.isfinite(xyz).all(axis=2) & np.isfinite(ref).all(axis=1)[None]
    res = np.linalg.norm(xyz - (np.einsum("nij,pj->npi", rot, ref) + t[:, None]), axis=2)
    if outlier_m is None:
        typical = np.nanmedian(res[seen]) if seen.any() else np.nan
        outlier_m = max(6.0 * typical, 5e-4) if np.isfinite(typical) else 5e-4
    # drop the worst point of a sample while it exceeds the limit and three remain, refitting each time
    # (one bad marker pulls the fit, so its neighbours' residuals grow too: never drop them together)
    drop = np.zeros_like(seen)
    rows = np.flatnonzero((np.where(seen, res, 0.0) > outlier_m).any(axis=1))
    for _ in range(max(xyz.shape[1] - MIN_POINTS, 0)):
        if rows.size == 0:
            break
        r_now = np.where(seen[rows] & ~drop[rows], res[rows], -np.inf)
        worst = np.argmax(r_now, axis=1)
        can = (r_now[np.arange(rows.size), worst] > outlier_m) & ((seen[rows] & ~drop[rows]).sum(axis=1) > MIN_POINTS)
        rows, worst = rows[can], worst[can]
        if rows.size == 0:
            break
        drop[rows, worst] = True
        w = (seen[rows] & ~drop[rows]).astype(float)
        r2, t2, rms2 = kabsch(ref, xyz[rows], w)
        rot[rows], t[rows], rms[rows] = r2, t2, rms2
        res[rows] = np.linalg.norm(xyz[rows] - (np.einsum("nij,pj->npi", r2, ref) + t2[:, None]), axis=2)
    used = seen & ~drop
    n_pts = used.sum(axis=1)
    status = np.where(n_pts >= MIN_POINTS, "ok", "lost").astype(object)
    # three or more points on one line fix no rotation about that line
    for i in np.flatnonzero(n_pts >= MIN_POINTS):
        q = ref[used[i]]
        s = np.linalg.svd(q - q.mean(axis=0), compute_uv=False)
        if s[1] < 1e-3 * max(s[0], 1e-12):
            status[i] = "degenerate"
    lost = status != "ok"
    rot[lost] = np.nan
    t[lost] = np.nan
    rms[lost] = np.nan
    return BodyPoses(rot, t, rms, n_pts, status.astype(str), np.asarray(ref, float), int(drop.sum()))
