"""Shared IMU signal helpers: still/moving detection, axes, quaternions, tilt angles.

All angles rad, rates rad/s, accelerations m/s^2.
"""

from __future__ import annotations

import numpy as np

from .._errors import InputError
from ..blocks import G

__all__ = []

#: Default stillness thresholds (stated in the docs of block_rotation/table_acceleration).
STILL_GYRO_RAD_S = np.deg2rad(2.0)
STILL_ACC_M_S2 = 0.03 * G
SMOOTH_S = 0.05


def rownorm(v: np.ndarray) -> np.ndarray:
    """Euclidean norm of each row of an (n, 3) array (faster than ``np.linalg.norm``)."""
    return np.sqrt(np.einsum("ij,ij->i", v, v))


def moving_average(x: np.ndarray, w: int) -> np.ndarray:
    """Centred running mean of ``x`` along axis 0 over ``w`` samples (edges shrink)."""
    if w <= 1:
        return x.astype(float, copy=True)
    c = np.cumsum(np.concatenate([np.zeros((1,) + x.shape[1:]), x]), axis=0)
    n = len(x)
    i = np.arange(n)
    lo = np.clip(i - w // 2, 0, n)
    hi = np.clip(i - w // 2 + w, 0, n)
    cnt = (hi - lo).reshape((-1,) + (1,) * (x.ndim - 1))
    return (c[hi] - c[lo]) / cnt


def motion_mask(t_s, gyro, acc, rate_hz, gyro_thr=STILL_GYRO_RAD_S, acc_thr=STILL_ACC_M_S2,
                smooth_s=SMOOTH_S, bias=None):
    """Boolean mask of moving samples.

    A sample moves when, averaged over ``smooth_s``, the bias-removed gyro
    norm exceeds ``gyro_thr`` or the accelerometer norm departs from the
    local gravity level by more than ``acc_thr``.  ``bias`` defaults to the
    median rate of the first 0.5 s (logs start at rest).
    """
    n = len(t_s)
    w = max(1, int(round(smooth_s * rate_hz)))
    if bias is None:
        bias = np.median(gyro[: max(3, int(0.5 * rate_hz))], axis=0)
    gm = moving_average(rownorm(gyro - bias), w)
    an = rownorm(acc)
    g_level = np.median(an[: max(3, int(0.5 * rate_hz))]) if n else G
    am = moving_average(np.abs(an - g_level), w)
    return (gm > gyro_thr) | (am > acc_thr)


def runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """``[(start, stop), ...]`` of the True runs of ``mask`` (stop exclusive)."""
    m = np.concatenate(([False], mask.astype(bool), [False]))
    d = np.flatnonzero(np.diff(m.astype(np.int8)))
    return list(zip(d[::2].tolist(), d[1::2].tolist()))


def first_motion(moving: np.ndarray, min_len: int) -> int | None:
    """Index of the first moving run at least ``min_len`` long, or None."""
    for a, b in runs(moving):
        if b - a >= min_len:
            return a
    return None


def last_motion_end(moving: np.ndarray, min_len: int) -> int | None:
    """End (exclusive) of the last moving run at least ``min_len`` long, or None."""
    for a, b in reversed(runs(moving)):
        if b - a >= min_len:
            return b
    return None


_AXES = {"x": 0, "y": 1, "z": 2}


def axis_vector(axis: str) -> np.ndarray:
    """``"y"``, ``"-x"``, ``"+z"`` -> unit vector (3,) in the sensor frame."""
    a = str(axis).strip().lower()
    sign = -1.0 if a.startswith("-") else 1.0
    a = a.lstrip("+-")
    if a not in _AXES:
        raise InputError(f"axis={axis!r}: use x, y or z with an optional sign (e.g. '-y')")
    v = np.zeros(3)
    v[_AXES[a]] = sign
    return v


def tilt_about(u: np.ndarray, f_ref: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Sensor rotation about ``u`` (rad) that turns gravity reading ``f_ref`` into ``f``.

    A sensor turned by +theta about ``u`` sees world-fixed vectors turned by
    -theta, hence the order of the cross product.  ``f`` may be (3,) or (n, 3).
    """
    fr = f_ref - np.dot(f_ref, u) * u
    ff = f - np.outer(np.atleast_2d(f) @ u, u).reshape(np.shape(f))
    s = np.cross(ff, fr) @ u
    c = ff @ fr
    return np.arctan2(s, c)


def rotation_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Smallest rotation matrix (3, 3) turning direction ``a`` into direction ``b``."""
    a = a / np.linalg.norm(a)
    b = b / np.linalg.norm(b)
    v = np.cross(a, b)
    c = float(np.dot(a, b))
    if c < -1 + 1e-12:  # opposite: turn by pi about any perpendicular axis
        p = np.eye(3)[np.argmin(np.abs(a))]
        k = np.cross(a, p)
        k /= np.linalg.norm(k)
        return 2 * np.outer(k, k) - np.eye(3)
    vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + vx + vx @ vx / (1 + c)


def quat_mul(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product of (w, x, y, z) quaternions, broadcasting over rows."""
    pw, px, py, pz = np.moveaxis(np.asarray(p), -1, 0)
    qw, qx, qy, qz = np.moveaxis(np.asarray(q), -1, 0)
    return np.stack([pw * qw - px * qx - py * qy - pz * qz,
                     pw * qx + px * qw + py * qz - pz * qy,
                     pw * qy - px * qz + py * qw + pz * qx,
                     pw * qz + px * qy - py * qx + pz * qw], axis=-1)


def twist_angle(q_rel: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Rotation angle about ``u`` (rad, in (-pi, pi]) of quaternions (n, 4) (swing-twist)."""
    ang = 2.0 * np.arctan2(q_rel[:, 1:] @ u, q_rel[:, 0])
    return (ang + np.pi) % (2 * np.pi) - np.pi


def cumtrapz(t: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Cumulative trapezoid integral of ``y`` over ``t``, starting at 0 (shape of ``y``)."""
    out = np.empty_like(y, dtype=float)
    out[0] = 0.0
    np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(t), out=out[1:])
    return out
