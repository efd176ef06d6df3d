"""Synthetic IMU logs run on after the last video frame (the camera is stopped first):
the block keeps moving there as the simulator says, in the gyro and the accelerometer, and the
logs end 1 s after the block has come to rest, as a lab logs until the block rests (the IMU
reader anchors its drift there: no W-IMU-NO-REST on a clean synthetic log)."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest

from rocklab import G, Block
from rocklab.tracking import block_rotation, read_imu
from rocklab.synth import synth_session

GYRO_NOISE = np.deg2rad(0.1)  # rad/s per sample, the synth's error model (session.json)
ACC_NOISE = 0.005 * G  # m/s^2 per sample
MOUNT_FRAC = 0.85  # sensor height on the block, fraction of h (session.json mount_m)


@pytest.fixture(scope="module")
def short(tmp_path_factory):
    """A 1 s video of a block released at ~0.63 s: still rocking when the video ends.

    Returns the session, the block, the log, the log's video times and the truth
    ``theta_sim(t)`` (Čeh convention, = -theta_rad) from an independent longer run.
    """
    from rocklab.models import simulate

    blk = Block(0.1, 0.2, depth_m=0.3, density_kg_m3=2700.0)
    s = synth_session(
        tmp_path_factory.mktemp("tail") / "s", seed=5, size=(160, 90), duration_s=1.0, mp4=False, block=blk
    )
    b = s.meta["blocks"][0]
    rel = b["release_s"]
    res = simulate(
        blk, theta0_rad=-b["theta0_rad"], duration_s=10.0, dt_s=1e-4, restitution="constant", eta=b["eta_true"]
    )
    assert res.status == "rest"  # the run stops when the block rests: res.t_s[-1] is that time

    def theta_sim(t):
        t = np.asarray(t, float)
        return np.where(t < rel, -b["theta0_rad"], np.interp(t - rel, res.t_s, res.theta_rad, right=res.theta_rad[-1]))

    log = read_imu(s.imu["block_1"])
    tv = log.t_s + s.meta["imu"]["block_1"]["t0_video_s"]
    return s, blk, log, tv, theta_sim, res


def _moving_tail(log, tv, t_from, t_to):
    """Indices of the longest run of consecutive samples (no lost packet) in ``(t_from, t_to)``."""
    k = np.rint(log.t_s * log.rate_hz).astype(np.int64)
    idx = np.flatnonzero((tv > t_from) & (tv < t_to))
    runs = np.split(idx, np.flatnonzero(np.diff(k[idx]) != 1) + 1)
    return max(runs, key=len)


def _rest_s(s, res):
    """When the block comes to rest on the video clock, s (the independent run stops there)."""
    return s.meta["blocks"][0]["release_s"] + float(res.t_s[-1])


def test_log_outlasts_the_video_and_truth_covers_the_frames_only(short):
    s, _, log, tv, _, res = short
    t_video = s.n_frames / s.fps
    tr = s.truth[s.truth.object == "block_1"]
    assert len(tr) == s.n_frames == 50 and tr["t_s"].max() == pytest.approx((s.n_frames - 1) / s.fps)
    # The block rests well after the video (independent run) and the IMU logs 1 s past that
    # (last sample within one period of it; the synth's run stops at rest within its 0.1 ms step).
    rel = s.meta["blocks"][0]["release_s"]
    t_rest = rel + float(res.t_s[-1])
    assert t_rest > t_video + 0.3  # measured 0.49 s
    assert t_rest + 1.0 - 1 / log.rate_hz - 2e-4 < tv[-1] <= t_rest + 1.0 + 2e-4
    # The block is still rocking when the video stops: |omega| far from zero there ...
    w_end = np.interp(t_video - rel, res.t_s, res.omega_rad_s)
    assert abs(w_end) > 0.05
    # ... and session.json's impacts are the simulator's through the end of the log,
    # including those after the last frame.
    imp = s.meta["blocks"][0]["impact_t_s"]
    ref = res.impacts["t_s"].to_numpy() + rel
    ref = ref[ref <= tv[-1]]
    got = np.array([t for t in imp if t <= tv[-1]])
    assert np.any(ref > t_video) and len(got) == len(ref)
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-9)


def test_gyro_keeps_following_the_rotation_after_the_video(short):
    s, _, log, tv, theta_sim, res = short
    info = s.meta["imu"]["block_1"]
    dt = 1.0 / log.rate_hz
    tail = _moving_tail(log, tv, s.n_frames / s.fps, _rest_s(s, res))
    assert len(tail) * dt > 0.25  # 0.29 s here (a lost-packet burst falls in the 0.49 s)
    # gyro_y = d(theta_sim)/dt (= -d theta_rad / dt), interval means; the bias is the synth's.
    g = log.gyro_rad_s[tail, 1] - np.deg2rad(info["gyro_bias_deg_s"][1])
    t = tv[tail]
    expect = (theta_sim(t + dt / 2) - theta_sim(t - dt / 2)) / dt
    # Still rocking: the rate is far above the noise (a block frozen at its last pose reads
    # noise only, RMS 0.1 deg/s) ...
    assert np.sqrt(np.mean(expect**2)) > 50 * GYRO_NOISE
    assert np.sqrt(np.mean(g**2)) > 50 * GYRO_NOISE
    # ... and follows the simulator sample by sample to within the white noise.
    assert np.sqrt(np.mean((g - expect) ** 2)) < 1.3 * GYRO_NOISE
    # The integrated rate is the simulator's change of angle over the tail: noise of the
    # sum ~ sigma dt sqrt(N) = 8e-5 rad; the angle itself moves by tenths of a radian.
    ang = np.cumsum(g) * dt
    d_theta = theta_sim(t + dt / 2) - theta_sim(t[0] - dt / 2)
    assert np.max(np.abs(d_theta)) > 0.02
    assert np.max(np.abs(ang - d_theta)) < 5e-4


def test_accelerometer_keeps_following_the_rotation_after_the_video(short):
    """Specific force of the sensor point from rigid rotation about the active corner
    (positions by finite differences here, not the writer's formula), in the sensor frame."""
    s, blk, log, tv, theta_sim, res = short
    dt = 1.0 / log.rate_hz
    tail = _moving_tail(log, tv, s.n_frames / s.fps, _rest_s(s, res))
    t = tv[tail]
    rx, rz = 0.0, MOUNT_FRAC * blk.h_m
    assert s.meta["imu"]["block_1"]["mount_m"] == pytest.approx([rx, rz])

    def pos(tt):
        th = theta_sim(tt)
        piv = np.where(th >= 0, blk.b_m / 2, -blk.b_m / 2)  # theta > 0 pivots on corner A, +x
        c, sn = np.cos(th), np.sin(th)
        return np.stack([piv + c * (rx - piv) + sn * rz, -sn * (rx - piv) + c * rz], -1)

    h = 1e-4
    vel = lambda tt: (pos(tt + h / 2) - pos(tt - h / 2)) / h  # noqa: E731
    a = (vel(t + dt / 2) - vel(t - dt / 2)) / dt
    th = theta_sim(t)
    c, sn = np.cos(th), np.sin(th)
    fx, fz = a[:, 0], a[:, 1] + G
    expect = np.stack([c * fx - sn * fz, sn * fx + c * fz], -1)  # R(theta)^T f, sensor x and z
    # The impacts' velocity jumps are one-sample spikes whose size depends on where in the
    # sample they fall: compare away from them.
    imp = np.array(s.meta["blocks"][0]["impact_t_s"])
    far = np.min(np.abs(t[:, None] - imp[None, :]), axis=1) > 2.5 * dt
    assert far.sum() > 50
    got = log.acc_m_s2[tail][:, [0, 2]]
    # Along the width (sensor x) the specific force swings by metres per second squared as
    # the block rocks from one corner to the other (gravity turning with it, tangential
    # acceleration); a block frozen at its last pose would read one constant plus noise.
    # (Along z it stays near G cos(theta): nothing to tell there beyond the residual.)
    assert np.std(expect[far, 0]) > 20 * ACC_NOISE and np.std(got[far, 0]) > 20 * ACC_NOISE
    res = got[far] - expect[far]
    assert np.sqrt(np.mean(res**2, axis=0)).max() < 1.3 * ACC_NOISE


def test_log_ends_at_rest_so_the_drift_is_anchored(short):
    """The reader finds the final rest where the simulator put it and anchors theta there (status
    ok, no W-IMU-NO-REST); the same log cut 0.5 s after the video, as the synth used to, ends
    while the block moves and is still flagged."""
    s, _, log, tv, _, res = short
    t0 = s.meta["imu"]["block_1"]["t0_video_s"]
    with warnings.catch_warnings(record=True) as found:
        warnings.simplefilter("always")
        rot = block_rotation(log, axis="y")
    assert rot.status == "ok" and not [w for w in found if "W-IMU-NO-REST" in str(w.message)]
    # the rest the reader anchors on starts where the simulated block rests (measured 0.052 s
    # after: the reader's 50 ms trim next to the motion)
    t_rest = _rest_s(s, res)
    assert t_rest - 0.02 < rot.rest_t_s + t0 < t_rest + 0.15
    # the block ends upright, as the simulator's: theta at rest within 0.02 deg of 0 (measured 4e-4)
    assert abs(float(np.mean(rot.theta_rad[rot.t_s + t0 > t_rest + 0.2]))) < np.deg2rad(0.02)
    keep = tv <= s.n_frames / s.fps + 0.5
    cut = replace(
        log,
        t_s=log.t_s[keep],
        gyro_rad_s=log.gyro_rad_s[keep],
        acc_m_s2=log.acc_m_s2[keep],
        saturated=None if log.saturated is None else log.saturated[keep],
        packet=None if log.packet is None else log.packet[keep],
    )
    with warnings.catch_warnings(record=True) as found:
        warnings.simplefilter("always")
        rot_cut = block_rotation(cut, axis="y")
    assert rot_cut.status == "no_rest_after"
    assert [w for w in found if "W-IMU-NO-REST" in str(w.message)]


def test_log_end_rule():
    """1 s after the last block or the table is still; never less than 0.5 s after the film; a block
    still rocking when its simulation ends (the rest search's end) ends the log moving, 0.1 s short
    of that end, whatever the other blocks do."""
    from types import SimpleNamespace

    from rocklab.synth._scene import imu_log_end

    def m(end):
        return SimpleNamespace(t_s=np.array([0.0, end]))

    rest, rocking = {"sim_status": "rest"}, {"sim_status": "rocking"}
    assert imu_log_end([m(7.7), m(3.2)], [rest, rest], 0.6, 4.0) == pytest.approx(8.7)
    assert imu_log_end([m(2.0)], [rest], 7.5, 4.0) == pytest.approx(8.5)  # the table stops last
    assert imu_log_end([m(1.2)], [rest], 0.6, 4.0) == pytest.approx(4.5)  # at rest before the film ends
    assert imu_log_end([m(2.0), m(34.6)], [rest, rocking], 0.6, 4.0) == pytest.approx(34.5)
