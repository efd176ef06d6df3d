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

import math
from pathlib import Path

import numpy as np

__all__ = ["write_object_imu"]


def write_object_imu(folder: Path, oid: str, *, block_motion=None, block=None, table=None,
                     mount_m=None, t_end_s: float, rate_hz: float, rng: np.random.Generator) -> dict:
    """Simulate and write ``folder/<oid>_CalInertialAndMag.csv`` + ``_Registers.csv``.

    ``block_motion`` (a ``BlockMotion``) and ``block`` for a sensor on a block;
    only ``table`` (a ``TableMotion``) for the sensor on the table. Errors: a
    gyro bias of 0.2..1 deg/s per axis, white noise (0.1 deg/s, 0.005 g), one
    or two bursts of lost packets; the log starts 0.5..1.5 s before the video.

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
    if block_motion is not None:
        t = block_motion.t_s
        th = -block_motion.phi_rad
        blk = block
    else:
        t, th, blk = np.array([0.0, t_end_s]), np.zeros(2), None
    log = simulate_imu_log(t, th, blk, mount_m=mount_m, rate_hz=rate_hz, t_start_s=t0,
                           rest_after_s=max(0.0, t_end_s - float(t[-1])), gyro_bias_deg_s=bias,
                           base=base, drop_bursts=bursts, seed=seed)
    folder.mkdir(parents=True, exist_ok=True)
    inertial, regs = write_ximu_csv(log, folder / oid)
    return {"files": [inertial.name, regs.name], "rate_hz": float(rate_hz),
            "t0_video_s": t0, "n_samples": int(log.n + log.dropped_samples),
            "dropped_samples": int(log.dropped_samples), "gyro_bias_deg_s": bias.tolist(),
            "gyro_noise_deg_s": 0.1, "acc_noise_g": 0.005,
            "mount_m": None if mount_m is None else [float(v) for v in mount_m],
            "clock": "sample k (reader index) at video time t0_video_s + k / rate_hz",
            "axes": "x along the width (+x world when upright), z up, y away from the camera "
                    "(rocking axis); gyro_y = -d(theta_rad)/dt",
            "writer": "rocklab.tracking._imu_sim.simulate_imu_log + write_ximu_csv"}
