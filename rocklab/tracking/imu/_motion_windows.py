"""Shared IMU signal helpers: still/moving detection, axes, quaternions, tilt angles.

All angles rad, rates rad/s, accelerations m/s^2.
"""

from __future__ import annotations

import numpy as np

from ..._errors import InputError
from ...blocks import G

__all__ = []

#: Default stillness thresholds (stated in the docs of block_rotation/table_acceleration).
STILL_GYRO_RAD_S = np.deg2rad(2.0)
STILL_ACC_M_S2 = 0.03 * G
SMOOTH_S = 0.05
#: Floor of the fine (noise-scaled) accelerometer-vector thresholds, m/s^2 (2 mg):
#: a noise-free log must still have rest windows.
_FINE_ACC = 0.002 * G


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


def motion_mask(
    t_s, gyro, acc, rate_hz, gyro_thr=STILL_GYRO_RAD_S, acc_thr=STILL_ACC_M_S2, smooth_s=SMOOTH_S, bias=None
):
    """Boolean mask of moving samples.

    A sample moves when, averaged over ``smooth_s``, the bias-removed gyro
    norm exceeds ``gyro_thr`` or the accelerometer norm departs from the
    local gravity level by more than ``acc_thr``.  ``bias`` defaults to the
    median rate of the first 0.5 s (logs start at rest), or of the log's stillest 0.5 s when
    the first move (:func:`still_window`).
    """
    n = len(t_s)
    w = max(1, int(round(smooth_s * rate_hz)))
    k = max(3, int(0.5 * rate_hz))
    i0 = still_window(gyro, k, gyro_thr)
    if bias is None:
        bias = np.median(gyro[i0 : i0 + k], axis=0)
    gm = moving_average(rownorm(gyro - bias), w)
    an = rownorm(acc)
    g_level = np.median(an[i0 : i0 + k]) if n else G
    am = moving_average(np.abs(an - g_level), w)
    return (gm > gyro_thr) | (am > acc_thr)


def still_window(gyro, k: int, gyro_thr: float) -> int:
    """First sample of the ``k`` samples the gyro bias and the gravity level are read from.

    The log's start (0) when its rate spreads by at most ``gyro_thr`` there (rad/s, per axis),
    else the start of the stillest ``k`` samples (least summed variance, searched every ``k // 4``):
    a log that starts in motion (a phone picked up, a logger started late) would otherwise call
    its motion the bias and every later rest motion.
    """
    n = len(gyro)
    if n < 2 * k or float(np.max(np.std(gyro[:k], axis=0))) <= gyro_thr:
        return 0
    starts = np.arange(0, n - k + 1, max(1, k // 4))
    spread = [float(np.sum(np.var(gyro[i : i + k], axis=0))) for i in starts]
    return int(starts[int(np.argmin(spread))])


def acc_departure(acc, f_ref, rate_hz, smooth_s=SMOOTH_S):
    """``smooth_s`` running mean of ``|acc - f_ref|`` (m/s^2), shape (n,).

    A horizontal table acceleration ``a`` changes the accelerometer *norm*
    only by ~``a^2 / 2g`` (0.03 g of norm needs ~0.25 g of table) but turns
    the vector by ``a``: this sees a block carried by a moving table while it
    does not rotate yet.
    """
    w = max(1, int(round(smooth_s * rate_hz)))
    return moving_average(rownorm(acc - np.asarray(f_ref, float)), w)


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
    return np.stack(
        [
            pw * qw - px * qx - py * qy - pz * qz,
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
        ],
        axis=-1,
    )


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


def forced_run(t, gyro, acc, fs, gyro_thr, acc_thr, min_run):
    """Is the block carried by a moving table before it rotates?  (``block_rotation`` doc, step 7)

    Returns ``(forced, i_carry, i_carry_end)``: the decision, the first sample
    whose accelerometer vector leaves its initial level (>= ``min_run``
    samples above ``acc_thr``) and the end of the last stretch where it
    differs from its final level (None when not found).  Both are then
    pushed outwards to where the 0.1 s mean vector is within 5 noise standard
    deviations of that level: the weak start of a table record (below
    ``acc_thr``) would otherwise enter the rest window and, averaged there,
    tilt the upright reference by ~(table velocity / window length) / g.
    """
    n = len(t)
    n0 = max(3, min(n, int(0.5 * fs)))
    f0, f1 = np.median(acc[:n0], axis=0), np.median(acc[-n0:], axis=0)
    dep0 = acc_departure(acc, f0, fs) > acc_thr
    dep1 = acc_departure(acc, f1, fs) > acc_thr
    i_carry = first_motion(dep0, min_run)
    i_carry_end = last_motion_end(dep1, min_run)
    if i_carry is None:
        return False, None, i_carry_end
    w = max(1, int(round(0.05 * fs)))
    g0 = np.median(gyro[:n0], axis=0)
    rate = moving_average(rownorm(gyro - g0), w)
    i_rot = first_motion(rate > gyro_thr, min_run)
    forced = i_rot is None or _ramp_start(t, rate, i_rot, fs) - t[i_carry] > 0.1
    ws = max(2, int(round(0.1 * fs)))
    sm = moving_average(acc, ws)
    thr = max(5.0 * float(np.linalg.norm(np.std(acc[:n0], axis=0))) / np.sqrt(ws), _FINE_ACC)
    quiet = np.flatnonzero(rownorm(sm[:i_carry] - f0) <= thr)
    i_carry = max(0, int(quiet[-1]) + 1 - ws // 2) if quiet.size else 0
    if i_carry_end is not None:
        thr = max(5.0 * float(np.linalg.norm(np.std(acc[-n0:], axis=0))) / np.sqrt(ws), _FINE_ACC)
        quiet = np.flatnonzero(rownorm(sm[i_carry_end:] - f1) <= thr)
        i_carry_end = min(n, i_carry_end + (int(quiet[0]) if quiet.size else n) + ws // 2)
    return bool(forced), i_carry, i_carry_end


def table_push(t, gyro, acc, fs, gyro_thr, min_run) -> float:
    """How hard the support pushed the sensor just before its rotation started, in units of the
    accelerometer's own stillness at the start.

    The largest 50 ms mean of ``|acc - f0|`` (``f0``: the median accelerometer vector of the
    first 0.5 s) from 0.1 s to 30 ms before the rotation's start (where the 50 ms mean rate, once
    above ``gyro_thr`` for ``min_run`` samples, last left its rest noise: 5 standard deviations),
    over its largest value in the first 0.5 s; the 30 ms keep the rotation's own tangential
    acceleration (``alpha x r``, at once) out of the means. A block resting upright uplifts only
    when its table accelerates by ``g tan(alpha)`` and rides the table until then; a released
    block, or a foot, starts to turn unpushed. Measured: <= 1.06 on simulated releases and
    strides, >= 3.1 on simulated shake-table runs (single blocks, three side by side, a column).
    NaN when nothing rotates.
    """
    n = len(t)
    n0 = max(3, min(n, int(0.5 * fs)))
    w = max(1, int(round(0.05 * fs)))
    rate = moving_average(rownorm(gyro - np.median(gyro[:n0], axis=0)), w)
    i_rot = first_motion(rate > gyro_thr, min_run)
    if i_rot is None:
        return float("nan")
    quiet = np.flatnonzero(rate[:i_rot] <= float(np.median(rate[:n0])) + 5.0 * float(np.std(rate[:n0])))
    t0 = float(t[quiet[-1] + 1]) if quiet.size else float(t[i_rot])
    near = (t >= t0 - 0.1) & (t <= t0 - 0.03)
    dep = acc_departure(acc, np.median(acc[:n0], axis=0), fs)
    push = float(np.max(dep[near])) if near.any() else float(dep[i_rot])
    return push / max(float(np.max(dep[:n0])), 1e-12)


def _ramp_start(t, rate, i_rot, fs) -> float:
    """When the rotation that crosses the threshold at ``i_rot`` started, s: its rate ramp over the
    next 50 ms extrapolated back to zero (at most 0.5 s back).

    A block released near its overturning tilt speeds up slowly (its rate reaches 2 deg/s
    0.1-0.15 s after the release) while the accelerometer sees the release at once; the
    threshold crossing alone made such releases "forced" runs (upright = the held tilt).
    """
    j = min(len(t), i_rot + max(4, int(round(0.05 * fs))))
    if j - i_rot < 3:
        return float(t[i_rot])
    slope = float(np.polyfit(t[i_rot:j] - t[i_rot], rate[i_rot:j], 1)[0])
    if slope <= 0:
        return float(t[i_rot])
    return float(t[i_rot] - min(rate[i_rot] / slope, 0.5))


def still_acc_start(acc, e0, e1, sigma, fs, min_rest) -> int:
    """Start of the final rest of a forced run by the accelerometer vector.

    A block resting on a table that still moves is not at rest for the tilt
    reference: its 0.1 s mean accelerometer vector must stay within
    ``5 sigma / sqrt(window)`` (``sigma``: vector noise in the first rest
    window; at least 2 mg) of the mean of the last ``min_rest`` samples.  Returns ``e1`` when
    the end window never settles (no end rest).
    """
    ws = max(2, int(round(0.1 * fs)))
    if e1 - e0 < min_rest:
        return e0
    f1 = acc[e1 - min_rest : e1].mean(axis=0)
    sm = moving_average(acc[e0:e1], ws)
    busy = np.flatnonzero(rownorm(sm - f1) > max(5.0 * sigma / np.sqrt(ws), _FINE_ACC))
    busy = busy[busy < (e1 - e0) - ws // 2]  # the shrinking edge windows at the end are noisier
    return e0 if busy.size == 0 else min(e1, e0 + int(busy[-1]) + 1 + ws // 2)
