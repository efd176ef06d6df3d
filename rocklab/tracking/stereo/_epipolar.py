"""Epipolar geometry of a calibrated two-camera rig, on undistorted pixels.

A target seen by both cameras lies on the epipolar line of its image in the other view;
the distance to that line (px) is what pairs targets, estimates the clock offset and tells
the films' order.
"""

from __future__ import annotations

import warnings

import numpy as np

from ._calib import StereoRig

__all__ = ["undistorted", "fundamental", "epi_distance", "epipolar_misfit_px"]


def undistorted(rig: StereoRig, cam: int, uv) -> np.ndarray:
    """Undistorted pixel positions (same K) of ``uv`` (n, 2) seen by camera ``cam`` (NaN kept)."""
    import cv2

    K, dist = (rig.K1, rig.dist1) if cam == 1 else (rig.K2, rig.dist2)
    uv = np.asarray(uv, float).reshape(-1, 2)
    out = np.full_like(uv, np.nan)
    ok = np.isfinite(uv).all(axis=1)
    if ok.any():
        out[ok] = cv2.undistortPoints(uv[ok].reshape(-1, 1, 2), K, dist, P=K).reshape(-1, 2)
    return out


def fundamental(rig: StereoRig) -> np.ndarray:
    """The fundamental matrix of ``rig`` on undistorted pixels: ``x2^T F x1 = 0``."""
    t = rig.T
    tx = np.array([[0, -t[2], t[1]], [t[2], 0, -t[0]], [-t[1], t[0], 0]])
    return np.linalg.inv(rig.K2).T @ tx @ rig.R @ np.linalg.inv(rig.K1)


def epi_distance(F, p1, p2):
    """Symmetric epipolar distance, px, for every pair: p1 (..., 2), p2 (..., 2) broadcast."""
    h1 = np.concatenate([p1, np.ones(p1.shape[:-1] + (1,))], axis=-1)
    h2 = np.concatenate([p2, np.ones(p2.shape[:-1] + (1,))], axis=-1)
    l2 = h1 @ F.T  # lines in image 2
    l1 = h2 @ F  # lines in image 1
    num = np.abs((h2 * l2).sum(axis=-1))
    return 0.5 * (num / np.hypot(l2[..., 0], l2[..., 1]) + num / np.hypot(l1[..., 0], l1[..., 1]))


def epipolar_misfit_px(rig: StereoRig, uv1, uv2) -> float:
    """Median symmetric epipolar distance of paired image points (n, k, 2) of camera 1 and 2, px."""
    n = min(len(uv1), len(uv2))
    k = uv1.shape[1]
    a = undistorted(rig, 1, uv1[:n].reshape(-1, 2)).reshape(n, k, 2)
    b = undistorted(rig, 2, uv2[:n].reshape(-1, 2)).reshape(n, k, 2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return float(np.nanmedian(epi_distance(fundamental(rig), a, b)))
