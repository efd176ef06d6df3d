"""Block rotation about the rocking axis from an IMU log (offline tilt).

Method (``block_rotation``)
---------------------------
1. Motion: a sample moves when, over 50 ms, the gyro norm (minus the median
   rate of the first 0.5 s) exceeds 2 deg/s or the accelerometer norm departs
   from gravity by 0.03 g.  The rest window before release is the still
   stretch before the first motion (>= 0.1 s); the rest window after stop is
   the still stretch after the last motion.
2. Gyro bias: mean rate in the rest window before release.
3. Axis: named by the user (``"y"``, ``"-y"`` ...) or the principal axis of the
   bias-free rate during motion; an automatic axis is signed so the initial
   tilt (or, without one, the largest excursion) is positive.
4. Tilt: integral (trapezoid over the sample times) of the bias-free rate
   about the axis, anchored to the accelerometer tilt in both rest windows:
   the angle is zero where the block rests upright at the end (or, without an
   end rest or when it ends > 20 deg away from it -- overturned -- where the
   sensor axis nearest to gravity at the start is vertical); the
   remaining linear drift (residual bias) is removed so both rest windows
   match their accelerometer tilt.
5. Release: the first motion, refined by extrapolating the initial
   (constant-acceleration) rate ramp back to zero.
6. Impacts: the block passes theta = 0 with a drop of |omega| and an
   acceleration spike.  Note: in the rocking model the angular velocity keeps
   its sign through an impact (omega+ = eta * omega-); it is the *angle* that
   changes sign.  The impact instant inside a sample comes from the fraction
   of the sample's mean rate between the extrapolated pre- and post-impact
   rates.
7. Kind of run (``release=``): a thread-burn release (``"thread"``: block
   held tilted, released, rests upright at the end) or a forced run on a
   shake table (``"none"``: block upright at rest, the table moves, the block
   may rock and ends wherever it ends).  ``"auto"`` calls a run forced when
   the accelerometer *vector* leaves its initial level (by 0.03 g, 50 ms
   means, >= 0.1 s) more than 0.1 s before the gyro's rotation starts (its
   rate ramp, once above 2 deg/s, extrapolated back to zero): the table
   carries the block before it uplifts, whereas a released block rotates at
   once (slowly, when released near its overturning tilt).  A run read as a
   release is read again as forced when the block rested upright (within
   1 deg of its end rest) and the accelerometer left its rest (by twice its
   stillness at the start) in the 0.1 s before the rotation's start: a
   sharp table pulse uplifts a block at once, and a thread holds a block
   tilted.  In a forced run the upright reference is the *initial* rest
   (theta = 0 there), the rest windows end where the table starts / begin
   where it has stopped (accelerometer vector, not only its norm), the end
   rest's tilt is measured by the accelerometer, and ``release_t_s`` is NaN.
   (Anchoring a forced run on the end rest as upright offsets the whole
   history by the end tilt whenever the block stops -- or the log ends --
   away from upright.)
8. Optional second estimate: imufusion's AHRS (1.3 API, no magnetometer),
   its twist about the axis, and the RMS difference to the gyro estimate.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._diagnostics import warn
from ..._errors import InputError
from ...blocks import G
from ._motion_windows import (
    axis_vector,
    cumtrapz,
    first_motion,
    forced_run,
    last_motion_end,
    motion_mask,
    moving_average,
    quat_mul,
    rownorm,
    still_acc_start,
    still_window,
    table_push,
    tilt_about,
    twist_angle,
)
from ._read import ImuLog
from ._validity import FORCED_PUSH_MIN, RockingCheck, check_rocking, half_swing_peaks, warn_no_rest, warn_not_rocking

__all__ = ["ImuRotation", "block_rotation", "ahrs_rotation", "ahrs_quaternions"]

#: Largest tilt at the start rest, rad, of a block that rested upright (the upright reference's
#: error, a mis-mount or a sloping table, is < 0.3 deg; a thread holds a block at >= 1 deg).
UPRIGHT_START_RAD = np.deg2rad(1.0)


@dataclass(frozen=True)
class ImuRotation:
    """Block rotation about its rocking axis estimated from one IMU.

    Attributes
    ----------
    t_s : ndarray (n,)
        Sample times, s (the log's clock).
    theta_rad : ndarray (n,)
        Rotation about the rocking axis, rad; 0 = upright (the rest at the end
        for a thread release, the rest at the start for a forced run).
    omega_rad_s : ndarray (n,)
        Bias-corrected angular rate about the axis, rad/s.
    acc_m_s2 : ndarray (n, 3)
        Accelerometer, sensor frame, m/s^2 (copied from the log for export).
    axis : ndarray (3,)
        Rocking axis, unit vector in the sensor frame.
    gyro_bias_rad_s : ndarray (3,)
        Gyro bias, rad/s: mean rate in the rest window before release.
    theta0_rad : float
        Accelerometer tilt in the rest window before release, rad (0 for a
        forced run: that window defines upright).
    drift_rad_s : float
        Residual bias along the axis removed by the two-window anchoring, rad/s
        (the total bias along the axis is ``gyro_bias_rad_s @ axis + drift_rad_s``).
    release_t_s : float
        Release instant, s (NaN if the log shows no rest then motion, and for
        a forced run, which has no release).
    impact_t_s : ndarray (k,)
        Impact instants, s.
    rest_t_s : float
        Start of the final rest, s (NaN if still moving at the end).
    rate_hz, dropped_samples, format, source : from the log.
    ahrs_theta_rad : ndarray (n,) or None
        imufusion AHRS estimate about the same axis, rad (``ahrs=True``).
    ahrs_rms_diff_rad : float
        RMS of ``ahrs_theta_rad - theta_rad`` (wrapped to +-pi) from release to
        rest, rad (NaN without AHRS).
    status : str
        ``"ok"``, ``"no_rest_before"`` (bias from the first 0.5 s), ``"no_rest_after"``
        (drift not anchored at the end) or ``"no_motion"``.
    message : str
        Human-readable note on the status.
    run_kind : str
        ``"thread"`` (released from a tilt; upright = end rest) or ``"forced"``
        (shake table; upright = initial rest, ``theta0_rad`` = 0, no release).
    rocking : RockingCheck or None
        The evidence that the log is a rocking block (axis angle to the horizontal,
        share of the rotation about the axis, turn range; ``_validity``).
    """

    t_s: np.ndarray
    theta_rad: np.ndarray
    omega_rad_s: np.ndarray
    acc_m_s2: np.ndarray
    axis: np.ndarray
    gyro_bias_rad_s: np.ndarray
    theta0_rad: float
    drift_rad_s: float
    release_t_s: float
    impact_t_s: np.ndarray
    rest_t_s: float
    rate_hz: float
    dropped_samples: int = 0
    format: str = ""
    source: str = ""
    ahrs_theta_rad: np.ndarray | None = field(default=None, repr=False)
    ahrs_rms_diff_rad: float = float("nan")
    status: str = "ok"
    message: str = ""
    run_kind: str = "thread"
    rocking: RockingCheck | None = field(default=None, repr=False)

    def to_frame(self):
        """``t_s, theta_rad, omega_rad_s, acc_{x,y,z}_m_s2`` (+ ``theta_ahrs_rad``)."""
        import pandas as pd

        d = {
            "t_s": self.t_s,
            "theta_rad": self.theta_rad,
            "omega_rad_s": self.omega_rad_s,
            "acc_x_m_s2": self.acc_m_s2[:, 0],
            "acc_y_m_s2": self.acc_m_s2[:, 1],
            "acc_z_m_s2": self.acc_m_s2[:, 2],
        }
        if self.ahrs_theta_rad is not None:
            d["theta_ahrs_rad"] = self.ahrs_theta_rad
        return pd.DataFrame(d)

    def to_dict(self) -> dict:
        """JSON-ready summary (the ``rocklab imu --json`` keys)."""
        return {
            "format": self.format,
            "sample_rate_hz": float(self.rate_hz),
            "n_samples": int(len(self.t_s)),
            "dropped_samples": int(self.dropped_samples),
            "gyro_bias_rad_s": [float(v) for v in self.gyro_bias_rad_s],
            "axis": [float(v) for v in self.axis],
            "theta0_rad": float(self.theta0_rad),
            "drift_rad_s": float(self.drift_rad_s),
            "release_t_s": float(self.release_t_s),
            "impact_t_s": [float(v) for v in self.impact_t_s],
            "rest_t_s": float(self.rest_t_s),
            "ahrs_rms_diff_rad": float(self.ahrs_rms_diff_rad),
            "status": self.status,
            "message": self.message,
            "run_kind": self.run_kind,
            "axis_tilt_rad": float(self.rocking.axis_tilt_rad) if self.rocking else float("nan"),
            "axis_share": float(self.rocking.axis_share) if self.rocking else float("nan"),
            "lateral_acc_m_s2": float(self.rocking.lateral_acc_m_s2) if self.rocking else float("nan"),
            "not_rocking_reasons": list(self.rocking.reasons) if self.rocking else [],
            "source": self.source,
        }


def _check_gyro_vs_tilt(source, gyro_change_rad, tilt_change_rad, status, msg):
    """The gyro's integral between the two rests must equal the accelerometer's tilt change.

    Swapped gyro axes, the wrong rocking axis, a gyro in rad/s under a deg/s header or a
    clock jump break this (``W-IMU-AXES``; status ``suspect``). Tolerance: 20 % + 1 deg.
    """
    mismatch = gyro_change_rad - tilt_change_rad
    tol = 0.2 * max(abs(tilt_change_rad), abs(gyro_change_rad)) + np.deg2rad(1.0)
    if abs(mismatch) <= tol:
        return status, msg
    d = warn(
        "W-IMU-AXES",
        f"{source}: the gyro integrates to {np.rad2deg(gyro_change_rad):.4g} deg between the "
        f"rests but the accelerometer tilts by {np.rad2deg(tilt_change_rad):.4g} deg; check "
        "the gyro columns (axes, deg/s vs rad/s), --axis and the clock",
    )
    return ("suspect" if status == "ok" else status), (msg + "; " if msg else "") + d.message


def _check_still_tilt(log: ImuLog, fs: float) -> None:
    """No gyro motion but the accelerometer tilted between start and end: the gyro is not
    measuring the rocking (units or axes; ``W-IMU-AXES``)."""
    k = max(3, min(log.n // 4, int(round(0.5 * fs))))
    a0, a1 = log.acc_m_s2[:k].mean(axis=0), log.acc_m_s2[-k:].mean(axis=0)
    c = float(np.dot(a0, a1) / (np.linalg.norm(a0) * np.linalg.norm(a1) + 1e-300))
    ang = float(np.arccos(np.clip(c, -1.0, 1.0)))
    if ang > np.deg2rad(2.0):
        warn(
            "W-IMU-AXES",
            f"{log.source}: the gyro shows no motion but gravity turned by {np.rad2deg(ang):.4g} "
            "deg between the start and the end; check the gyro columns' units (deg/s vs rad/s)",
        )


def _vertical_axis(f: np.ndarray) -> np.ndarray:
    k = int(np.argmax(np.abs(f)))
    v = np.zeros(3)
    v[k] = np.sign(f[k])
    return v


def block_rotation(
    log: ImuLog,
    axis: str | None = None,
    *,
    release: str = "auto",
    ahrs: bool = False,
    still_gyro_deg_s: float = 2.0,
    still_acc_g: float = 0.03,
    min_rest_s: float = 0.1,
) -> ImuRotation:
    """Rotation of a rocking block about its rocking axis from its IMU log.

    Parameters
    ----------
    log : ImuLog
        Block IMU samples; the log should start at rest (block held before
        release) and, for drift anchoring, end at rest.
    axis : {"x", "y", "z", "-x", "-y", "-z"} or None
        Rocking axis in the sensor frame; None finds it (principal axis of the
        rate during motion, signed so the initial tilt is positive).
    release : {"auto", "thread", "none"}
        Kind of run (module doc, step 7): ``"thread"`` -- released from a
        held tilt, upright at the end; ``"none"`` -- forced (shake table),
        upright at the start; ``"auto"`` -- decided from the log.
    ahrs : bool
        Also run imufusion's AHRS (slower: a Python loop over samples).
    still_gyro_deg_s, still_acc_g : float
        Stillness thresholds (50 ms averages): gyro norm, deg/s; |acc| - g, g.
    min_rest_s : float
        Shortest rest window used for bias / anchoring, s.

    Returns
    -------
    ImuRotation
    """
    n = log.n
    if n < 8:
        raise InputError(f"{log.source}: {n} samples; need at least 8 to estimate a rotation")
    if release not in ("auto", "thread", "none"):
        raise InputError(
            f"release={release!r}: use 'auto', 'thread' (thread-burn release) or 'none' (forced run on a shake table)"
        )
    t, gyro, acc, fs = log.t_s, log.gyro_rad_s, log.acc_m_s2, float(log.rate_hz)
    moving, forced, (i_move, i_end), status, msg = _motion_span(log, release, still_gyro_deg_s, still_acc_g)
    s0, s1, e0, e1, has_end, min_rest, status, msg = _rest_windows(n, fs, i_move, i_end, min_rest_s, status, msg)
    inner = None
    if status == "no_rest_before":
        s0, s1, inner = _inner_rest(t, gyro, moving, fs, (s0, s1), e0 if has_end else n, np.deg2rad(still_gyro_deg_s))
    restless = status == "no_rest_before" and not has_end and inner is None
    bias, w, u, omega = _bias_and_axis(t, gyro, moving, axis, (s0, s1), i_move if restless else None)
    if restless:
        # nothing rests: the whole motion stands in for the rests, for the bias and the tilt anchor
        s0, s1 = i_move, n
        msg = "no rest in the log: gyro bias from the motion's trend, tilt from its mean"
    if has_end:
        e0 = _strict_rest_start(omega, e0, e1, float(np.std(omega[s0:s1])), fs, min_rest)
        if forced:
            e0 = still_acc_start(acc, e0, e1, float(np.linalg.norm(np.std(acc[s0:s1], axis=0))), fs, min_rest)
            if e1 - e0 < min_rest:
                has_end = False
                if status == "ok":
                    status, msg = "no_rest_after", "table still moving at the end: drift not anchored"
    f_start = acc[s0:s1].mean(axis=0)
    f_end = acc[e0:e1].mean(axis=0) if has_end else None
    f_ref, msg = _upright(u, f_start, f_end, forced, msg)
    theta, omega, drift, th_start, changes = _anchored(t, omega, u, (f_ref, f_start, f_end), (s0, s1), (e0, e1))
    at_rest = status not in ("no_rest_before", "no_motion")
    min_run = max(2, int(round(0.1 * fs)))
    push = table_push(t, gyro, acc, fs, np.deg2rad(still_gyro_deg_s), min_run) if at_rest else None
    upright_start = release == "auto" and not forced and has_end and abs(th_start) < UPRIGHT_START_RAD
    if upright_start and push is not None and push >= FORCED_PUSH_MIN:
        # it rested upright and the support pushed it before it started to turn: a table pulse
        # that uplifts the block within 0.1 s (a released block is held tilted), not a release
        return block_rotation(
            log, axis, release="none", ahrs=ahrs, still_gyro_deg_s=still_gyro_deg_s, still_acc_g=still_acc_g,
            min_rest_s=min_rest_s,
        )  # fmt: skip
    rocking, status, msg = _judge(
        log, (w, u, theta, omega, moving), forced, (i_move, i_end, has_end, inner), (f_start, th_start, drift, changes),
        (status, msg), min_rest_s, push,
    )  # fmt: skip
    if axis is None:
        ref = th_start if abs(th_start) > np.deg2rad(1.0) else theta[np.argmax(np.abs(theta))]
        if ref < 0:
            u, theta, omega, th_start, drift = -u, -theta, -omega, -th_start, -drift
    release_t = _release_time(t, omega, i_move, s0, s1) if status != "no_motion" and not forced else np.nan
    impacts = _impacts(t, theta, omega, acc, moving, i_move, i_end, fs) if status != "no_motion" else np.empty(0)
    rest_t = float(t[e0]) if has_end else np.nan
    ahrs_theta, ahrs_rms = None, np.nan
    if ahrs:
        ref = (e0, e1) if has_end else (s0, s1)
        span = (i_move, i_end) if status != "no_motion" else (0, n)
        ref_theta = float(theta[e0:e1].mean() if has_end else th_start)
        ahrs_theta, ahrs_rms = _ahrs_comparison(log, u, bias, theta, ref, ref_theta, span)
    return ImuRotation(
        t,
        theta,
        omega,
        acc,
        u,
        bias,
        th_start,
        float(drift),
        release_t,
        impacts,
        rest_t,
        fs,
        log.dropped_samples,
        log.format,
        log.source,
        ahrs_theta,
        ahrs_rms,
        status,
        msg,
        "forced" if forced else "thread",
        rocking,
    )


def _bias_and_axis(t, gyro, moving, axis, rest, trend_from):
    """(gyro bias (3,) rad/s, bias-free rates (n, 3), rocking axis (3,), rate about it (n,)).

    The bias is the mean rate over the ``rest`` window ``(s0, s1)``; the axis the principal
    direction of the moving rates unless ``axis`` names it. ``trend_from``: for a log with no
    rest before or after its motion, its first moving sample, and the bias is then
    :func:`_trend_bias` from there (the first 0.5 s move: their mean is no bias).
    """
    s0, s1 = rest
    bias = gyro[s0:s1].mean(axis=0)
    w = gyro - bias
    if axis is None:
        mv = w[moving] if moving.any() else w
        u = np.linalg.svd(mv, full_matrices=False)[2][0]
    else:
        u = axis_vector(axis)
    if trend_from is not None:
        bias = _trend_bias(t, gyro, u, trend_from)
        w = gyro - bias
    return bias, w, u, w @ u


def _inner_rest(t, gyro, moving, fs, rest, stop, thr):
    """(s0, s1, its time span or None): for a log in motion from its start, the stillest 0.5 s
    before sample ``stop`` (the final rest, or the end), when the motion mask calls it still, stands
    in for the rest before (gyro bias, start tilt); else ``rest`` unchanged and None."""
    k = max(3, int(round(0.5 * fs)))
    i0 = still_window(gyro[:stop], k, thr)
    if i0 > 0 and i0 + k <= stop and not moving[i0 : i0 + k].any():
        return i0, i0 + k, (float(t[i0]), float(t[i0 + k - 1]))
    return rest[0], rest[1], None


def _trend_bias(t, gyro, u, i0: int) -> np.ndarray:
    """Gyro bias (3,) rad/s of a log that moves from its start to its end, so no rest measures it.

    Off the axis ``u``: the mean rate from sample ``i0`` on (the block turns about ``u`` only).
    About ``u``: the slope of a straight line fitted to the integrated rate, since an oscillation's
    angle (a rocking block's, a pendulum's) has no trend of its own over many cycles, while a bias
    integrates to one. The first 0.5 s of such a log move: their mean rate is the motion's, not
    the bias (a pendulum swinging 10 deg gave a 3.7 deg/s "bias" and a 170 deg ramp in 48 s).
    """
    g, tt = gyro[i0:], t[i0:] - t[i0]
    if len(tt) < 3:
        return gyro.mean(axis=0)
    mean = g.mean(axis=0)
    slope = float(np.polyfit(tt, cumtrapz(tt, g @ u), 1)[0])
    return mean - float(mean @ u) * u + slope * u


def _judge(log, motion, forced, span, anchoring, state, min_rest_s, push):
    """(rocking evidence, status, message) of a block's rotation, with its warnings.

    ``motion`` = (bias-free rates (n, 3), axis, theta, omega, moving mask); ``span`` = (first
    moving sample, end of the motion, a rest after?, the still span (s, s) inside the motion that
    stood in for a missing rest before, or None);
    ``anchoring`` = (accelerometer mean at the start rest (3,), tilt there, drift, (gyro change,
    tilt change) between the rests or None); ``state`` = (status, message); ``push`` the table's
    push before the rotation (:func:`table_push`; None without a rest before), judged for a forced run.
    """
    w, u, theta, omega, moving = motion
    i_move, i_end, has_end, inner = span
    f_start, th_start, drift, changes = anchoring
    status, msg = state
    t, acc, fs = log.t_s, log.acc_m_s2, float(log.rate_hz)
    # rocking: one axis carries the rate and the block turns by less than 90 deg; other motion
    # (a hand-held sensor) has no single tilt to compare the gyro with
    planar = float(np.sum(omega[moving] ** 2)) >= 0.9 * float(np.sum(w[moving] ** 2)) if moving.any() else False
    if has_end and planar and float(np.max(np.abs(theta))) < 0.5 * np.pi:
        status, msg = _check_gyro_vs_tilt(log.source, *changes, status, msg)
    # without a rest before, the bias came from moving samples: the drift then corrects it
    judge = status != "no_rest_before"
    rocking = None
    if status != "no_motion":
        # a released block only loses energy: its half swings shrink (a table feeds energy in)
        peaks = None if forced else half_swing_peaks(theta, i_move, i_end, th_start if judge else None)
        rocking = check_rocking(t, w, u, f_start, fs, drift, judge, peaks, has_end, acc, push if forced else None)
    if rocking is not None and rocking.reasons:
        # a spinning or hand-held sensor: worse than any rest-window status
        status, msg = "suspect", warn_not_rocking(log.source, rocking) + ("; " + msg if msg else "")
    elif status in ("no_rest_before", "no_rest_after"):  # theta unanchored: a coded warning (run shows it)
        msg = warn_no_rest(log.source, status, t, i_move, i_end, min_rest_s, omega, rest_after=has_end, inner=inner)
    return rocking, status, msg


def _motion_span(log: ImuLog, release, still_gyro_deg_s, still_acc_g):
    """(moving mask, forced run?, (first moving sample, end of the motion), status, message) of a block's log.

    A forced run (shake table) is recognised from the log unless ``release`` says which kind of run it is;
    its carried motion then counts as motion. No motion: status ``no_motion``, both indices ``n``.
    """
    n, t, gyro, acc, fs = log.n, log.t_s, log.gyro_rad_s, log.acc_m_s2, float(log.rate_hz)
    moving = motion_mask(t, gyro, acc, fs, np.deg2rad(still_gyro_deg_s), still_acc_g * G)
    min_run = max(2, int(round(0.1 * fs)))
    forced, i_carry, i_carry_end = forced_run(t, gyro, acc, fs, np.deg2rad(still_gyro_deg_s), still_acc_g * G, min_run)
    if release != "auto":
        forced = release == "none"
    i_move = first_motion(moving, min_run)
    if forced and i_carry is not None:
        i_move = i_carry if i_move is None else min(i_move, i_carry)
    status, msg = "ok", ""
    if i_move is None:
        i_move, i_end = n, n
        status, msg = "no_motion", "no motion found above the stillness thresholds"
        _check_still_tilt(log, fs)
    else:
        # Decaying rocking fragments the motion mask; the last moving sample ends it.
        i_end = last_motion_end(moving, 1) or i_move
        if forced and i_carry_end is not None:
            i_end = max(i_end, i_carry_end)
    return moving, forced, (i_move, i_end), status, msg


def _upright(u, f_start, f_end, forced, msg):
    """(specific force of the upright block, message): the reference tilts about ``u`` are measured from.

    ``f_start``, ``f_end``: mean accelerometer vectors (3,) of the rests before and after (None: no rest after).
    """
    has_end = f_end is not None
    f_ref = f_end if has_end else _vertical_axis(f_start)
    if forced:
        # Shake table: the block starts upright; the end rest is measured, not assumed.
        f_ref = f_start
    elif has_end and abs(float(tilt_about(u, _vertical_axis(f_start), f_end))) > np.deg2rad(20.0):
        # Ended far from upright (overturned, or stopped leaning on something):
        # upright is then the sensor axis nearest to gravity at the start
        # (square mounting); both windows still anchor the drift.
        f_ref = _vertical_axis(f_start)
        msg = "ended > 20 deg from upright: upright = sensor axis nearest gravity at start"
    return f_ref, msg


def _anchored(t, omega, u, forces, rest_before, rest_after):
    """The rate integrated into a tilt about ``u`` anchored on the rests' accelerometer tilts.

    ``forces`` = (upright, rest before, rest after or None) specific forces (3,); the rests are sample
    windows. With a rest after, the gyro's drift (rad/s) makes the integral meet both tilts.
    Returns (theta rad, omega rad/s, drift rad/s, tilt at the start rad, (gyro change, tilt change) rad
    between the rests or None).
    """
    f_ref, f_start, f_end = forces
    (s0, s1), (e0, e1) = rest_before, rest_after
    integ = cumtrapz(t, omega)
    th_start = float(tilt_about(u, f_ref, f_start))
    ts_mid, is_mean = t[s0:s1].mean(), integ[s0:s1].mean()
    drift, changes = 0.0, None
    if f_end is not None:
        th_end = float(tilt_about(u, f_ref, f_end))
        te_mid, ie_mean = t[e0:e1].mean(), integ[e0:e1].mean()
        drift = ((ie_mean - is_mean) - (th_end - th_start)) / (te_mid - ts_mid)
        changes = (ie_mean - is_mean, th_end - th_start)
    theta = th_start + (integ - is_mean) - drift * (t - ts_mid)
    return theta, omega - drift, drift, th_start, changes


def _rest_windows(n, fs, i_move, i_end, min_rest_s, status, msg):
    """The rest windows before and after the motion, samples ``[s0, s1)`` and ``[e0, e1)``
    (50 ms trimmed next to the motion: the smoothing widens its edges), whether the end one is
    long enough, the shortest rest in samples, and the status with its message."""
    guard = max(1, int(round(0.05 * fs)))
    min_rest = max(3, int(round(min_rest_s * fs)))
    s0, s1 = 0, max(0, i_move - guard)
    if s1 - s0 < min_rest:
        s0, s1 = 0, max(3, min(n, int(0.5 * fs)))
        status = "no_rest_before" if status == "ok" else status
        msg = msg or "no rest before the first motion: bias from the first 0.5 s"
    e0, e1 = min(n, i_end + guard), n
    has_end = (e1 - e0) >= min_rest and status != "no_motion"
    if not has_end and status == "ok":
        status, msg = "no_rest_after", "still moving at the end: drift not anchored"
    return s0, s1, e0, e1, has_end, min_rest, status, msg


def _ahrs_comparison(log, u, bias, theta, ref_slice, ref_theta, span):
    """imufusion's AHRS tilt about ``u`` and its RMS difference from ``theta`` over ``span``, rad."""
    ahrs_theta = ahrs_rotation(log, u, bias, ref_slice=ref_slice, ref_theta=ref_theta)
    a, b = span
    diff = (ahrs_theta[a:b] - theta[a:b] + np.pi) % (2 * np.pi) - np.pi
    return ahrs_theta, float(np.sqrt(np.mean(diff**2)))


def _strict_rest_start(omega, e0, e1, sigma, fs, min_rest) -> int:
    """Start of the final rest by a stricter test than the motion mask.

    Decaying rocking wobbles below the 2 deg/s motion threshold for a while;
    anchoring on that would bias the upright reference.  Rest here means the
    0.25 s mean square of omega stays below ``sigma^2 (1 + 6 sqrt(2 / w)) +
    (0.02 deg/s)^2`` (``sigma``: rate noise in the first rest window, ``w`` the
    window in samples: 6 standard deviations of a noise-only mean square)
    until the end of the log.
    """
    w = max(2, int(round(0.25 * fs)))
    thr = sigma**2 * (1.0 + 6.0 * np.sqrt(2.0 / w)) + np.deg2rad(0.02) ** 2
    busy = moving_average(omega[e0:e1] ** 2, w) >= thr
    hits = np.flatnonzero(busy)
    start = e0 if hits.size == 0 else e0 + int(hits[-1]) + 1 + w // 2
    return start if e1 - start >= min_rest else e0


def _release_time(t, omega, i_move, s0, s1) -> float:
    """Back-extrapolate the initial rate ramp to zero rate."""
    sigma = float(np.std(omega[s0:s1])) if s1 - s0 > 2 else 0.0
    lo = max(4 * sigma, np.deg2rad(0.5))
    n = len(t)
    j0 = max(0, i_move - int(0.2 * (n / max(t[-1] - t[0], 1e-9))))
    seg = np.abs(omega[j0:])
    above = np.flatnonzero(seg > lo)
    if above.size == 0:
        return float(t[i_move])
    a = j0 + int(above[0])
    # Fit the ramp until the rate reaches 5x the start level or 40 ms, whichever first.
    hi = max(5 * lo, np.deg2rad(3.0))
    b = a + 1
    while b < n and abs(omega[b]) < hi and t[b] - t[a] < 0.04:
        b += 1
    b = min(n, max(b + 1, a + 4))
    tt, ww = t[a:b], omega[a:b]
    slope, icpt = np.polyfit(tt - tt[0], ww, 1)
    if slope == 0 or np.sign(slope) != np.sign(ww[-1]):
        return float(t[a])
    tr = tt[0] - icpt / slope
    return float(np.clip(tr, t[max(0, a - 50)], t[a]))


def _impacts(t, theta, omega, acc, moving, i_move, i_end, fs) -> np.ndarray:
    """Impact instants: theta sign changes marked by an acceleration spike (see module doc).

    The spike is the second difference of the accelerometer vector (an impact
    changes the mounting point's velocity within one sample); without a clear
    spike the largest rate step near the crossing is used.
    """
    a, b = i_move, min(i_end, len(t) - 1)
    if b - a < 4:
        return np.empty(0)
    th = theta[a : b + 1]
    cross = a + np.flatnonzero(np.signbit(th[1:]) != np.signbit(th[:-1]))
    if cross.size == 0:
        return np.empty(0)
    n = len(t)
    spike = np.zeros(n)
    i0, i1 = max(1, a - 1), min(n - 1, b + 2)  # only where impacts can be
    spike[i0:i1] = rownorm(acc[i0:i1] - 0.5 * (acc[i0 - 1 : i1 - 1] + acc[i0 + 1 : i1 + 1]))
    spike_thr = max(8.0 * float(np.median(spike[a:b])), 0.05 * G)
    jumps = np.abs(np.diff(omega))
    jump_thr = max(4.0 * float(np.median(jumps[a:b])), np.deg2rad(0.3))
    half = max(3, int(round(0.05 * fs)))
    out: list[float] = []
    last = -np.inf
    for c in cross:
        lo, hi = max(2, c - half), min(n - 3, c + half + 1)
        if hi <= lo:
            continue
        j = lo + int(np.argmax(spike[lo:hi]))
        if spike[j] >= spike_thr:
            tk = _subsample(t, omega, j)
        else:
            k = lo + int(np.argmax(jumps[lo:hi]))
            if jumps[k] < jump_thr:
                continue
            tk = 0.5 * (t[k] + t[k + 1])
        if tk - last > 1.5 / fs:
            out.append(tk)
            last = tk
    return np.asarray(out)


def _subsample(t, omega, j) -> float:
    """Impact instant inside sample ``j`` (the one holding the acceleration spike).

    Samples are means over their interval, so the impact sample mixes the
    pre- and post-impact rates: the share of the pre-impact rate (each side
    extrapolated linearly from its two neighbours) places the impact inside
    the interval; clipped to the interval.
    """
    wm = omega[j - 1] + (omega[j - 1] - omega[j - 2]) * (t[j] - t[j - 1]) / (t[j - 1] - t[j - 2])
    wp = omega[j + 1] - (omega[j + 2] - omega[j + 1]) * (t[j + 1] - t[j]) / (t[j + 2] - t[j + 1])
    dt = 0.5 * (t[j + 1] - t[j - 1])
    f = 0.5 if wm == wp else float(np.clip((omega[j] - wp) / (wm - wp), 0.0, 1.0))
    return float(t[j] - 0.5 * dt + f * dt)


def ahrs_quaternions(
    log: ImuLog, bias_rad_s=None, gain: float = 0.5, acceleration_rejection_deg: float = 10.0
) -> np.ndarray:
    """imufusion AHRS orientation (gyro + accelerometer, no magnetometer), (n, 4) w, x, y, z.

    imufusion 1.3 API: ``Ahrs().set_settings(AhrsSettings(...))`` then
    ``update_no_magnetometer(gyro_deg_s, acc_g)`` per sample (NWU earth frame;
    the quaternion turns sensor-frame vectors into earth-frame vectors).
    Uneven sample spacing is passed on with ``set_sample_period``.
    """
    import imufusion

    fs = float(log.rate_hz)
    ahrs = imufusion.Ahrs()
    ahrs.set_settings(
        imufusion.AhrsSettings(
            sample_rate=fs,
            convention=imufusion.CONVENTION_NWU,
            gain=gain,
            gyroscope_range=2000.0,
            acceleration_rejection=acceleration_rejection_deg,
            magnetic_rejection=0.0,
            rejection_timeout=int(5 * fs),
        )
    )
    bias = np.zeros(3) if bias_rad_s is None else np.asarray(bias_rad_s, float)
    gyro_dps = np.rad2deg(log.gyro_rad_s - bias)
    acc_g = log.acc_m_s2 / G
    n = log.n
    q = np.empty((n, 4))
    dt = np.diff(log.t_s, prepend=log.t_s[0] - 1.0 / fs)
    uneven = not np.allclose(dt, 1.0 / fs, rtol=1e-3)
    for i in range(n):
        if uneven:
            ahrs.set_sample_period(float(dt[i]))
        ahrs.update_no_magnetometer(gyro_dps[i], acc_g[i])
        q[i] = ahrs.get_quaternion()
    return q


def ahrs_rotation(
    log: ImuLog,
    u: np.ndarray,
    bias: np.ndarray,
    ref_slice: tuple[int, int],
    ref_theta: float = 0.0,
    gain: float = 0.5,
    acceleration_rejection_deg: float = 10.0,
) -> np.ndarray:
    """imufusion AHRS estimate of the rotation about ``u``, rad (n,).

    The AHRS quaternion is made relative to its mean over ``ref_slice`` and
    the twist about ``u`` is taken (swing-twist), then offset by ``ref_theta``.
    """
    q = ahrs_quaternions(log, bias, gain, acceleration_rejection_deg)
    a, b = ref_slice
    qr = q[a:b].mean(axis=0)
    qr /= np.linalg.norm(qr)
    conj = qr * np.array([1, -1, -1, -1])
    rel = quat_mul(conj[None, :], q)
    return twist_angle(rel, u) + ref_theta
