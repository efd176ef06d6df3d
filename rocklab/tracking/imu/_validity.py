"""Is this IMU log a rocking block (or a still-mounted table sensor)?

A rocking block turns about one edge of its base: a horizontal axis, fixed in
the block (and so in the sensor frame), whatever the sensor's mis-mount.  Its
gyro rate therefore lies along one sensor-frame direction perpendicular to the
gravity reading at rest, and the angle about that axis stays within a half
turn (a block that overturns lies on a side, ~90 deg).  A sensor turned about
its vertical, moved by hand or spun shows none of this; integrating it about
its principal axis gives angles that mean nothing (``W-IMU-NOT-ROCKING``).

The rocking edge also stays put along itself: gravity's share along a horizontal
axis fixed in the world is constant, and the block's rotation about the edge
accelerates the sensor (``alpha x r``, ``omega x (omega x r)``, with ``omega``
along the axis) only across it, wherever the sensor sits. So while the block
turns, the accelerometer's component along the axis keeps its value at rest but
for a table moving along the edge (a lab table shakes across it). A
foot-mounted sensor pitches about a horizontal axis too, but swings sideways
with the leg and rolls: 0.4-0.5 g RMS along its pitch axis in x-io's gait logs,
against the accelerometer noise (5-15 mg) for simulated rocking. This holds for
a forced run as for a release (``LATERAL_ACC_MAX_M_S2``).

A forced run's block rests upright and rides its table until the table's
acceleration uplifts it: the accelerometer leaves its rest before the
rotation starts. A log read as a forced run whose block starts to turn from
rest unpushed (a release, a foot) is not one (``FORCED_PUSH_MIN``); the
message sends it to ``--release auto``, under which every test applies.

A block released from rest (a thread-burn release) only loses energy: each half
swing's |theta| peak is at most the one before, the first at most the release
tilt ``|theta0|``.  A foot-mounted sensor while walking pitches about one
horizontal axis too (all the tests above pass), but swings by tens of degrees
after resting level: a half swing that outgrows the largest earlier one on its
side (``|theta0|`` on the release side) by more than ``SWING_GROWTH_MAX_RAD +
SWING_GROWTH_REL * earlier`` is not free rocking.  An error of the upright
reference (the anchoring's rests) shifts both sides' peaks in opposite senses,
so the first peak on a side is compared with the other side's only when upright
was measured at a final rest.  A
forced run (a shake table feeds energy in) is not judged by this; nor is a
last half swing that topples the block (it ends > 20 deg from upright without
coming back).

A table sensor is meant not to turn at all: gravity is removed in the
orientation measured at the rest before shaking, so any later turn of the
sensor leaks ``2 g sin(turn / 2)`` into the "table acceleration"
(``W-IMU-TABLE``).

A log that does not start or end at rest leaves theta unanchored: the gyro bias
and the starting tilt come from moving samples, or the drift is not held by a
final rest (``W-IMU-NO-REST``).

The bounds are module constants so tests can perturb them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._diagnostics import warn
from ...blocks import G
from ._motion_windows import cumtrapz, moving_average, rownorm

__all__ = []

#: Largest angle of the rocking axis above the horizontal at the rest before release, rad.
#: A level table tilts the axis by its slope (< 2 deg in a lab); a vertical spin is 90 deg.
AXIS_TILT_MAX_RAD = np.deg2rad(20.0)
#: Smallest share of the mean-square rate (while rotating) about the rocking axis.
#: Planar rocking with 0.1 deg/s of gyro noise gives > 0.99.
AXIS_SHARE_MIN = 0.8
#: Largest RMS, over the rotating samples, of the specific force along the rocking axis less its
#: value at rest, m/s^2 (module doc): a table's cross-axis motion (a few % of its shaking)
#: and the accelerometer's cross-axis sensitivity at impacts stay well below it.
LATERAL_ACC_MAX_M_S2 = 0.15 * G
#: Smallest push of the table just before a forced run's block starts to turn, in units of the
#: accelerometer's stillness at the start (``_motion_windows.table_push``): a block rides its
#: table until the table's acceleration uplifts it. Measured <= 1.06 on simulated releases and
#: strides, >= 3.1 on simulated table runs.
FORCED_PUSH_MIN = 2.0
#: Largest range (max - min) of the gyro angle about the axis, rad: a rocking or
#: overturning block stays within a half turn.
TURN_RANGE_MAX_RAD = np.pi
#: Largest residual gyro bias the two-rest anchoring may remove, rad/s (a still MEMS
#: gyro's bias wanders by hundredths of a deg/s over a test).
DRIFT_MAX_RAD_S = np.deg2rad(1.0)
#: Largest growth of a half swing's |theta| peak over the previous one (the first over
#: |theta0|) in a thread-release run, rad, plus ``SWING_GROWTH_REL`` times the previous peak.
#: The upright reference's error (a mis-mount, a sloping table: < 0.3 deg) enters twice.
SWING_GROWTH_MAX_RAD = np.deg2rad(3.0)
SWING_GROWTH_REL = 0.25
#: |theta| past which a last half swing that does not come back is a toppled block, rad.
_TOPPLED_RAD = np.deg2rad(20.0)
#: Largest turn of a table sensor over the log, rad.
TABLE_TURN_MAX_RAD = np.deg2rad(3.0)
#: Rate above which a sample counts as rotating (50 ms means), rad/s.
_ROT_THR_RAD_S = np.deg2rad(2.0)


@dataclass(frozen=True)
class RockingCheck:
    """Measured evidence that a log is a rocking block.

    Attributes
    ----------
    axis_tilt_rad : float
        Angle of the rocking axis above the horizontal plane at the rest before
        the motion, rad (NaN when the log never rotates).
    axis_share : float
        Share of the mean-square bias-free rate about the axis over the rotating
        samples, 0..1 (NaN when fewer than 0.1 s rotate).
    turn_range_rad : float
        Range of the gyro angle about the axis (bias and anchoring drift removed), rad.
    swing_peaks_rad : tuple of float
        |theta| peaks, rad, of the half swing that grew most beyond the bound (module
        doc) and of the largest earlier one it is compared with: (earlier, later);
        empty when none did or the run is forced.
    reasons : tuple of str
        The bounds broken (empty: a rocking block).
    lateral_acc_m_s2 : float
        RMS over the rotating samples of the specific force along the axis less its value at rest,
        m/s^2 (NaN when fewer than 0.1 s rotate or no accelerometer was given).
    """

    axis_tilt_rad: float
    axis_share: float
    turn_range_rad: float
    reasons: tuple = ()
    swing_peaks_rad: tuple = ()
    lateral_acc_m_s2: float = float("nan")

    @staticmethod
    def bounds() -> dict:
        """The bounds in force (this module's constants): ``axis_tilt_max_rad``, ``axis_share_min``,
        ``lateral_acc_max_m_s2``."""
        return {
            "axis_tilt_max_rad": AXIS_TILT_MAX_RAD,
            "axis_share_min": AXIS_SHARE_MIN,
            "lateral_acc_max_m_s2": LATERAL_ACC_MAX_M_S2,
        }


def half_swing_peaks(theta, i_move: int, i_end: int, theta0_rad: float | None = None) -> np.ndarray:
    """Signed peak of each half swing (between zero crossings of theta) over samples ``[i_move, i_end)``, rad.

    ``theta0_rad`` (the release tilt measured at rest) is put first when given; a last
    half swing that does not come back and ends past 20 deg (a toppled block) is left out.
    """
    th = np.asarray(theta[i_move:i_end], float)
    peaks = [] if theta0_rad is None else [float(theta0_rad)]
    if th.size < 2:
        return np.asarray(peaks)
    cut = np.flatnonzero(np.signbit(th[1:]) != np.signbit(th[:-1])) + 1
    segs = np.split(th, cut)
    if abs(th[-1]) > _TOPPLED_RAD and float(np.max(np.abs(segs[-1]))) <= abs(th[-1]) + np.deg2rad(1.0):
        segs = segs[:-1]
    return np.asarray(peaks + [float(s[np.argmax(np.abs(s))]) for s in segs if s.size])


def _worst_growth(peaks: np.ndarray, cross_side: bool) -> tuple:
    """The (earlier, later) |peak| pair that most exceeds the growth bound, or () if none does.

    A peak is compared with the largest earlier peak on its side: an error of the upright
    reference moves both alike. With ``cross_side`` (the upright reference was measured at a
    final rest) the first peak on a side is compared with the largest on the other side.
    """
    best, pair = 0.0, ()
    top = {True: np.nan, False: np.nan}  # largest |peak| so far per side (True: theta > 0)
    for p in peaks:
        side = bool(p > 0)
        ref = top[side]
        if np.isnan(ref) and cross_side:
            ref = top[not side]
        if not np.isnan(ref):
            excess = abs(p) - ref * (1.0 + SWING_GROWTH_REL) - SWING_GROWTH_MAX_RAD
            if excess > best:
                best, pair = excess, (float(ref), float(abs(p)))
        top[side] = abs(p) if np.isnan(top[side]) else max(top[side], abs(p))
    return pair


def check_rocking(
    t, w, u, f_rest, fs, drift_rad_s, judge_drift=True, swing_peaks=None, upright_measured=True, acc=None, push=None
) -> RockingCheck:
    """Measure the rocking evidence (module doc) of bias-free rates ``w`` (n, 3) rad/s about ``u``.

    ``f_rest`` is the accelerometer mean over the rest before the motion (m/s^2,
    sensor frame); ``drift_rad_s`` the residual bias the anchoring removed (also
    removed before the turn range is taken); ``judge_drift`` False when the bias
    came from moving samples (no rest before), which the drift then rightly corrects.
    ``swing_peaks`` (rad, from :func:`half_swing_peaks`) for a thread-release run; None
    for a forced run, whose table feeds energy in. ``upright_measured`` False when upright
    was not measured at a final rest (the two sides' peaks are then not compared).
    ``acc`` (n, 3) m/s^2, the accelerometer, for the specific force along the axis (None: not judged).
    ``push``: for a forced run that starts at rest, the table's push before the block turned
    (``_motion_windows.table_push``; None: not judged).
    """
    w_avg = max(1, int(round(0.05 * fs)))
    rot = moving_average(rownorm(w), w_avg) > _ROT_THR_RAD_S
    if int(rot.sum()) < max(2, int(round(0.1 * fs))):
        return RockingCheck(float("nan"), float("nan"), 0.0)
    g_hat = f_rest / (np.linalg.norm(f_rest) + 1e-300)
    tilt = float(np.arcsin(min(1.0, abs(float(u @ g_hat)))))
    wr = w[rot]
    share = float(np.sum((wr @ u) ** 2) / max(float(np.sum(wr * wr)), 1e-300))
    ang = cumtrapz(t, w @ u - drift_rad_s)
    turn = float(np.max(ang) - np.min(ang))
    lateral = float("nan") if acc is None else float(np.sqrt(np.mean((acc[rot] @ u - float(f_rest @ u)) ** 2)))
    reasons = []
    if tilt > AXIS_TILT_MAX_RAD:
        reasons.append(
            f"the rotation axis is {np.rad2deg(tilt):.3g} deg above the horizontal "
            f"(a rocking edge is horizontal; bound {np.rad2deg(AXIS_TILT_MAX_RAD):.3g} deg)"
        )
    if share < AXIS_SHARE_MIN:
        reasons.append(
            f"only {100 * share:.3g} % of the rotation is about that axis (rocking: > {100 * AXIS_SHARE_MIN:.3g} %)"
        )
    if turn > TURN_RANGE_MAX_RAD:
        reasons.append(
            f"the gyro turns through {np.rad2deg(turn):.4g} deg about it "
            f"(rocking stays within {np.rad2deg(TURN_RANGE_MAX_RAD):.3g} deg)"
        )
    if lateral > LATERAL_ACC_MAX_M_S2:
        reasons.append(
            f"while it turns the sensor accelerates along that axis by {lateral / G:.3g} g RMS "
            f"(a rocking edge stays put along itself, whether released or on a shake table: "
            f"< {LATERAL_ACC_MAX_M_S2 / G:.2g} g)"
        )
    if push is not None and push < FORCED_PUSH_MIN:
        reasons.append(
            f"read as a forced run, it started to turn from rest with no push from a table (the accelerometer "
            f"left its rest by {push:.2g} times its own stillness in the 0.1 s before; a table uplifts a block "
            f"by accelerating it: >= {FORCED_PUSH_MIN:g}); a block released from a held tilt is read with "
            "--release auto, which keeps every test"
        )
    if judge_drift and abs(drift_rad_s) > DRIFT_MAX_RAD_S:
        reasons.append(
            f"holding the rests needs a {np.rad2deg(drift_rad_s):.3g} deg/s gyro drift "
            f"(a still gyro drifts < {np.rad2deg(DRIFT_MAX_RAD_S):.3g} deg/s)"
        )
    grown = _worst_growth(np.asarray(swing_peaks, float), upright_measured) if swing_peaks is not None else ()
    if grown:
        reasons.append(
            f"a half swing reaches {np.rad2deg(grown[1]):.3g} deg after one of {np.rad2deg(grown[0]):.3g} deg "
            f"(a released block only loses energy: bound + {np.rad2deg(SWING_GROWTH_MAX_RAD):.2g} deg "
            f"+ {100 * SWING_GROWTH_REL:.3g} %; only a shake table feeds energy in)"
        )
    return RockingCheck(tilt, share, turn, tuple(reasons), grown, lateral)


def warn_not_rocking(source: str, chk: RockingCheck) -> str:
    """Emit ``W-IMU-NOT-ROCKING`` for a failed :class:`RockingCheck`; returns its message."""
    d = warn(
        "W-IMU-NOT-ROCKING",
        f"{source}: not a rocking block: "
        + "; ".join(chk.reasons)
        + "; theta, release and impacts are meaningless (check the log and the sensor's mounting)",
    )
    return d.message


def table_turn(t, gyro, bias, acc, f_rest, fs, min_rest) -> float:
    """Largest turn of a table sensor over the log, rad.

    The larger of the bias-free gyro's small-angle rotation vector norm and, when the
    log ends still, the angle between the gravity readings of the first and last rests.
    """
    w = gyro - bias
    phi = np.concatenate([np.zeros((1, 3)), np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(t)[:, None], axis=0)])
    turn = float(np.max(rownorm(phi))) if len(t) else 0.0
    k = min(len(t), max(3, int(min_rest)))
    tail = acc[-k:]
    if float(np.max(rownorm(tail - tail.mean(axis=0)))) < 0.05 * np.linalg.norm(f_rest):
        f1 = tail.mean(axis=0)
        c = float(f1 @ f_rest) / (np.linalg.norm(f1) * np.linalg.norm(f_rest) + 1e-300)
        turn = max(turn, float(np.arccos(np.clip(c, -1.0, 1.0))))
    return turn


#: A residual gyro drift (after the start rest's bias) that the W-IMU-NO-REST message converts
#: into the angle it adds by the end of the log, rad/s.
NO_REST_DRIFT_RAD_S = np.deg2rad(0.1)


def warn_no_rest(
    source: str,
    status: str,
    t,
    i_move: int,
    i_end: int,
    min_rest_s: float,
    omega=None,
    rest_after: bool = True,
    inner=None,
) -> str:
    """Emit ``W-IMU-NO-REST`` for a log without a rest before its first motion (``status``
    ``"no_rest_before"``) or after its last (``"no_rest_after"``); returns its message.

    ``omega`` (rad/s, the rate about the axis) names the rate still seen at the end of a log
    whose motion runs to its last sample; ``rest_after`` says whether a rest after the motion
    anchors the drift (else the bias is the motion's trend); ``inner`` the still span (s, s) inside
    the motion the bias came from, if any."""
    if status == "no_rest_before":
        start = f"motion starts {t[min(i_move, len(t) - 1)] - t[0]:.3g} s into the log, before a {min_rest_s:g} s rest"
        if inner is not None:
            how = (
                f": the gyro bias and the tilt anchor come from the still {inner[0]:.4g}-{inner[1]:.4g} s inside "
                "the motion" + (" and the final rest" if rest_after else "")
            )
        elif rest_after:
            how = (
                ": the gyro bias and the starting tilt come from the first 0.5 s, which move, and the final "
                "rest's tilt corrects the drift"
            )
        else:
            how = (
                ", and no rest follows: the gyro bias is the trend of the integrated rate over the motion "
                "(an oscillation has none of its own) and the tilt the motion's mean (about 1 deg RMS on "
                "simulated rocking), so a slow real drift of the block is not seen"
            )
        what = f"{start}{how}; theta0 and the release are not measured (start the logger before the release)"
        return warn("W-IMU-NO-REST", f"{source}: {what}").message
    span = float(t[-1] - t[0])
    if i_end >= len(t) - 1:
        tail = t >= t[-1] - 0.5
        rate = "" if omega is None else f", {np.rad2deg(np.max(np.abs(omega[tail]))):.3g} deg/s in its last 0.5 s"
        where = f"the block still moves when the log ends (motion up to the last sample{rate})"
    else:
        where = (
            f"the log ends {t[-1] - t[i_end]:.2g} s after the last motion, short of the {min_rest_s:g} s rest "
            "that anchors the drift"
        )
    what = (
        f"{where}: the residual gyro drift is not measured, so theta is the gyro integral from the start "
        f"rest alone; a residual drift of {np.rad2deg(NO_REST_DRIFT_RAD_S):.2g} deg/s (a MEMS gyro's bias "
        f"wander) puts it {np.rad2deg(NO_REST_DRIFT_RAD_S) * span:.3g} deg off by the end ({span:.4g} s "
        "after the start; keep logging until the block has rested)"
    )
    return warn("W-IMU-NO-REST", f"{source}: {what}").message
