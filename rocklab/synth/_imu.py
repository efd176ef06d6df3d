"""IMU logs for synthetic sessions (x-IMU GUI format), via the IMU simulator of
``_imu_sim`` (:func:`simulate_imu_log`, :func:`write_ximu_csv`).

This module is the single place synthetic sessions write IMU files.

Sensor mounting (``_imu_sim``'s block frame): ``x`` along the block width
(world ``+x`` when upright), ``z`` up, ``y`` the rocking axis pointing away
from the camera; the simulator's angle is Čeh's ``theta = -theta_rad`` of
``truth.csv`` (see ``_synth_motion``), so ``gyro_y = -d(theta_rad)/dt``.
Sample ``k`` of the log (index counted by the reader, dropped packets
included) is taken at video time ``t0_video_s + k / rate_hz``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["write_object_imu"]


def write_object_imu(
    folder: Path,
    oid: str,
    *,
    block_motion=None,
    block=None,
    table=None,
    mount_m=None,
    t_end_s: float,
    rate_hz: float,
    rng: np.random.Generator,
) -> dict:
    """Simulate and write ``folder/<oid>_CalInertialAndMag.csv`` + ``_Registers.csv``.

    ``block_motion`` (a ``BlockMotion``) and ``block`` for a sensor on a block;
    only ``table`` (a ``TableProgram``) for the sensor on the table. Errors: a
    gyro bias of 0.2..1 deg/s per axis, white noise (0.1 deg/s, 0.005 g), one
    or two bursts of lost packets; the log starts 0.5..1.5 s before the video and
    ends at ``t_end_s`` (video time), which the motions must cover: before their
    first time the pose is held (a block held by its thread), after their last
    one too, which is right only for a block at rest (or fallen).

    Returns the truth for ``session.json``.
    """
    from ._imu_sim import simulate_imu_log, write_ximu_csv

    t0 = -float(rng.uniform(0.5, 1.5))
    seed = int(rng.integers(2**31))
    bias = rng.uniform(0.2, 1.0, 3) * rng.choice([-1.0, 1.0], 3)
    bursts = int(rng.integers(1, 3))
    tb = table if table is not None else block_motion.table
    tg = np.arange(min(t0, 0.0) - 0.1, t_end_s + 0.1, 1e-3)
    base = (tg, tb.a(tg)) if tb.kind != "none" else None
    if block_motion is not None and hasattr(block_motion, "column"):
        log = _rigid_body_log(block_motion, mount_m, t0, t_end_s, rate_hz, bias, seed, bursts)
    else:
        if block_motion is not None:
            t, th, blk = block_motion.t_s, -block_motion.phi_rad, block
        else:
            t, th, blk = np.array([0.0, t_end_s]), np.zeros(2), None
        log = simulate_imu_log(
            t,
            th,
            blk,
            mount_m=mount_m,
            rate_hz=rate_hz,
            t_start_s=t0,
            rest_after_s=max(0.0, t_end_s - float(t[-1])),
            gyro_bias_deg_s=bias,
            base=base,
            drop_bursts=bursts,
            seed=seed,
        )
    folder.mkdir(parents=True, exist_ok=True)
    inertial, regs = write_ximu_csv(log, folder / oid)
    return {
        "files": [inertial.name, regs.name],
        "rate_hz": float(rate_hz),
        "t0_video_s": t0,
        "n_samples": int(log.n + log.dropped_samples),
        "dropped_samples": int(log.dropped_samples),
        "gyro_bias_deg_s": bias.tolist(),
        "gyro_noise_deg_s": 0.1,
        "acc_noise_g": 0.005,
        "mount_m": None if mount_m is None else [float(v) for v in mount_m],
        "clock": "sample k (reader index) at video time t0_video_s + k / rate_hz",
        "axes": "x along the width (+x world when upright), z up, y away from the camera "
        "(rocking axis); gyro_y = -d(theta_rad)/dt",
        "writer": "rocklab.synth._imu_sim.simulate_imu_log + write_ximu_csv",
    }


def _rigid_body_log(view, mount_m, t0, t_end_s, rate_hz, bias_deg_s, seed, bursts):
    """IMU samples of a sensor on any planar rigid body given by ``view.pose(t)``
    (column blocks, which do not pivot on their own corners); same error model
    and axes as ``simulate_imu_log``: interval-mean rate and specific force."""
    from ..blocks import G
    from ..tracking.imu import ImuLog

    rng = np.random.default_rng(seed)
    dt = 1.0 / rate_hz
    n = int(np.floor((t_end_s - t0) * rate_hz)) + 1
    tk = t0 + np.arange(n) * dt
    rx, ry = float(mount_m[0]), float(mount_m[1])

    def pos(t):
        ox, oy, phi = view.pose(t)
        c, s = np.cos(phi), np.sin(phi)
        return np.stack([ox + c * rx - s * ry, oy + s * rx + c * ry], -1)

    h = 1e-4
    vel = lambda t: (pos(t + h / 2) - pos(t - h / 2)) / h  # noqa: E731
    acc_w = (vel(tk + dt / 2) - vel(tk - dt / 2)) / dt
    phi = view.phi(tk)
    c, s = np.cos(phi), np.sin(phi)
    fx, fy = acc_w[:, 0], acc_w[:, 1] + G
    acc = np.zeros((n, 3))
    acc[:, 0] = c * fx + s * fy  # sensor x = (cos, sin) in the world
    acc[:, 2] = -s * fx + c * fy  # sensor z = (-sin, cos)
    gyro = np.zeros((n, 3))
    gyro[:, 1] = -(view.phi(tk + dt / 2) - view.phi(tk - dt / 2)) / dt  # y away from the camera
    gyro += np.deg2rad(bias_deg_s) + rng.normal(0.0, np.deg2rad(0.1), (n, 3))
    acc += rng.normal(0.0, 0.005 * G, (n, 3))
    keep = np.ones(n, dtype=bool)
    for _ in range(bursts):
        length = int(rng.integers(3, 9))
        start = int(rng.integers(int(0.2 * n), max(int(0.2 * n) + 1, n - length - int(0.2 * n))))
        keep[start : start + length] = False
    return ImuLog(tk[keep], gyro[keep], acc[keep], float(rate_hz), int(n - keep.sum()), None, "simulated", "simulated")
