"""Shake-table IMU: base acceleration along the shaking direction, gravity removed.

Method (``table_acceleration``): the rest window before shaking (still
stretch before the first motion, same thresholds as ``block_rotation``, ended
where the accelerometer *vector* leaves its initial level) gives
the gravity direction in the sensor frame.  The smallest rotation taking it to
vertical corrects a mis-mounted (tilted) sensor; gravity is subtracted; the
named sensor axis, turned by that rotation and projected on the horizontal
plane, is the shaking direction (or the principal horizontal direction of the
acceleration during motion).  A table sensor must not turn: the gyro's turn
over the log and the angle between the gravity readings of the first and last
rests are measured (``turn_rad``); above 3 deg the gravity leak
``2 g sin(turn / 2)`` is flagged (``W-IMU-TABLE``, status ``suspect``).

``level=True`` takes out gravity's leak through a table that tilts while it shakes (a pitching
platform): each sample is turned back by the gyro's rotation since the rest (bias from the rest,
small angles: ``f_rest = f + phi x f``). Its drift (a bias error of 0.01 deg/s left by the rest is
0.1 deg, 0.017 m/s2 of offset, after 10 s) is left for a film to pin
(:func:`rocklab.tracking.fuse_table_motion`, whose offset state takes it out).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._diagnostics import warn
from ..._errors import InputError
from ...blocks import G
from ._motion_windows import axis_vector, first_motion, forced_run, motion_mask, rotation_between
from ._read import ImuLog
from ._validity import TABLE_TURN_MAX_RAD, table_turn

__all__ = ["TableAcceleration", "table_acceleration"]


@dataclass(frozen=True)
class TableAcceleration:
    """Table (base) acceleration from a table-mounted IMU.

    Attributes
    ----------
    t_s : ndarray (n,)
        Sample times, s (the log's clock).
    acc_m_s2 : ndarray (n,)
        Horizontal acceleration along the shaking direction, m/s^2, gravity removed.
    direction : ndarray (3,)
        Shaking direction in the sensor frame (unit vector).
    tilt_rad : float
        Mis-mount tilt: angle between the sensor's gravity reading at rest and
        its nearest axis, rad (corrected).
    rest_s : (float, float)
        Rest window used for the gravity direction, s.
    rate_hz : float
        Sample rate, Hz.
    source : str
        Log file.
    turn_rad : float
        Largest turn of the sensor over the log, rad (gyro, and the gravity of the
        first and last rests); a table sensor should not turn.
    status : str
        ``"ok"`` or ``"suspect"`` (the sensor turned by more than 3 deg: gravity leaks in).
    message : str
        Note on the status.
    """

    t_s: np.ndarray
    acc_m_s2: np.ndarray
    direction: np.ndarray
    tilt_rad: float
    rest_s: tuple
    rate_hz: float
    source: str = ""
    turn_rad: float = 0.0
    status: str = "ok"
    message: str = ""

    def to_frame(self):
        """``t_s, acc_m_s2`` DataFrame."""
        import pandas as pd

        return pd.DataFrame({"t_s": self.t_s, "acc_m_s2": self.acc_m_s2})

    def to_dict(self) -> dict:
        """Summary: direction, tilt, rest window, peak acceleration, rate, source."""
        return {
            "direction": [float(v) for v in self.direction],
            "tilt_rad": float(self.tilt_rad),
            "rest_s": [float(v) for v in self.rest_s],
            "pga_m_s2": float(np.max(np.abs(self.acc_m_s2))) if len(self.acc_m_s2) else 0.0,
            "sample_rate_hz": float(self.rate_hz),
            "turn_rad": float(self.turn_rad),
            "status": self.status,
            "message": self.message,
            "source": self.source,
        }

    def to_base_motion(self, name: str = "table_imu"):
        """As a :class:`rocklab.series.BaseMotion`: uniform grid at the log rate, time from 0.

        Dropped samples are filled by linear interpolation.
        """
        from ...series import BaseMotion

        n = int(np.floor((self.t_s[-1] - self.t_s[0]) * self.rate_hz)) + 1
        t = self.t_s[0] + np.arange(n) / self.rate_hz
        return BaseMotion.from_samples(np.interp(t, self.t_s, self.acc_m_s2), 1.0 / self.rate_hz, "m/s2", name=name)


def table_acceleration(
    log: ImuLog,
    axis: str | None = "x",
    *,
    still_gyro_deg_s: float = 2.0,
    still_acc_g: float = 0.03,
    min_rest_s: float = 0.2,
    level: bool = False,
) -> TableAcceleration:
    """Base acceleration along the shaking direction from a table IMU.

    Parameters
    ----------
    log : ImuLog
        Table IMU samples; the log must start at rest (>= ``min_rest_s``).
    axis : {"x", "y", "z", "-x", ...} or None
        Sensor axis closest to the shaking direction; None: the principal
        horizontal direction of the acceleration during motion (sign: positive
        along the sensor axis it is closest to).
    still_gyro_deg_s, still_acc_g : float
        Stillness thresholds (50 ms averages).
    min_rest_s : float
        Shortest acceptable rest window, s.
    level : bool
        Turn each sample back by the gyro's rotation since the rest (see the module doc).

    Returns
    -------
    TableAcceleration

    Raises
    ------
    InputError
        No rest window at the start of the log.
    """
    fs = float(log.rate_hz)
    moving = motion_mask(log.t_s, log.gyro_rad_s, log.acc_m_s2, fs, np.deg2rad(still_gyro_deg_s), still_acc_g * G)
    min_run = max(2, int(round(0.1 * fs)))
    i_move = first_motion(moving, min_run)
    i_move = log.n if i_move is None else i_move
    # a horizontal table acceleration turns the accelerometer vector long before it changes
    # its norm (the motion mask): the rest that gives gravity ends where the vector leaves
    # its initial level, else the shaking's start tilts "gravity" (0.5 deg, 0.09 m/s2 of
    # offset on a synthetic El Centro run)
    i_carry = forced_run(
        log.t_s, log.gyro_rad_s, log.acc_m_s2, fs, np.deg2rad(still_gyro_deg_s), still_acc_g * G, min_run
    )[1]
    if i_carry is not None:
        i_move = min(i_move, i_carry)
    s1 = max(0, i_move - max(1, int(round(0.05 * fs))))
    if s1 < max(3, int(round(min_rest_s * fs))):
        raise InputError(
            f"{log.source}: no rest of {min_rest_s:g} s before the shaking starts "
            f"(first motion at {log.t_s[i_move]:.3f} s); log a still table first"
        )
    g_s = log.acc_m_s2[:s1].mean(axis=0)
    R = rotation_between(g_s, np.array([0.0, 0.0, 1.0]))
    nearest = np.zeros(3)
    k = int(np.argmax(np.abs(g_s)))
    nearest[k] = np.sign(g_s[k])
    tilt = float(np.arccos(np.clip(abs(g_s[k]) / np.linalg.norm(g_s), -1, 1)))
    bias = log.gyro_rad_s[:s1].mean(axis=0)
    f_s = _levelled(log.t_s, log.gyro_rad_s - bias, log.acc_m_s2) if level else log.acc_m_s2
    a_w = f_s @ R.T
    a_w[:, 2] -= np.linalg.norm(g_s)
    if axis is None:
        mv = a_w[moving, :2] if moving.any() else a_w[:, :2]
        d2 = np.linalg.svd(mv - mv.mean(axis=0), full_matrices=False)[2][0]
        d = np.array([d2[0], d2[1], 0.0])
        back = R.T @ d
        j = int(np.argmax(np.abs(back)))
        if back[j] < 0:
            d = -d
    else:
        d = R @ axis_vector(axis)
        d[2] = 0.0
        if np.linalg.norm(d) < 0.2:
            raise InputError(
                f"axis={axis!r}: that sensor axis is (nearly) vertical on the table; name a horizontal sensor axis"
            )
    d /= np.linalg.norm(d)
    acc = a_w @ d
    turn = table_turn(log.t_s, log.gyro_rad_s, bias, log.acc_m_s2, g_s, fs, int(round(min_rest_s * fs)))
    status, msg = "ok", ""
    if turn > TABLE_TURN_MAX_RAD:
        status = "suspect"
        msg = warn(
            "W-IMU-TABLE",
            f"{log.source}: the table sensor turned by {np.rad2deg(turn):.4g} deg during the log (bound "
            f"{np.rad2deg(TABLE_TURN_MAX_RAD):.3g} deg): up to {2 * G * np.sin(min(turn, np.pi) / 2):.3g} m/s2 of "
            "gravity is left in the table acceleration; check that the sensor is fixed to the table",
        ).message
    rest = (float(log.t_s[0]), float(log.t_s[s1 - 1]))
    return TableAcceleration(log.t_s, acc, R.T @ d, tilt, rest, fs, log.source, turn, status, msg)


def _levelled(t, w, f):
    """Specific force ``f`` (n, 3) turned back into the sensor's orientation at the rest by the
    small rotation ``phi`` the bias-free rate ``w`` (n, 3, rad/s) has integrated to since ``t[0]``."""
    phi = np.concatenate([np.zeros((1, 3)), np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(t)[:, None], axis=0)])
    return f + np.cross(phi, f)
