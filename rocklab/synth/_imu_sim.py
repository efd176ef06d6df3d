"""IMU log simulator: rocking truth -> noisy IMU samples -> x-io CSV files.

Physics (planar rocking, see ``simulate_imu_log``): block frame with origin at
the bottom centre, x along the width towards corner A (+b/2), y the rocking
axis, z up.  theta > 0 is a rotation about +y pivoting on corner A
(x = +b/2), theta < 0 about corner B (x = -b/2) -- the Čeh sign convention.
A sensor fixed at ``mount_m = (x, z)`` on the block face measures

- rate: (0, theta', 0) in the block frame, averaged over the sample interval;
- specific force: R(theta)^T (a_P - g) with a_P the mean acceleration of the
  mounting point over the sample interval (rigid rotation about the active
  pivot corner: tangential theta'' and centripetal omega^2 terms, the
  velocity jump of an impact appearing as a one-sample spike) plus the table
  acceleration along x, and g = (0, 0, -G).

Interval means make the rate samples integrate exactly to the angle, as an
integrating (band-limited) MEMS sensor does.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .._errors import InputError
from .._io import atomic_path
from ..blocks import G
from ..tracking.imu import ImuLog

__all__ = ["simulate_imu_log", "write_ximu_csv", "write_ximu3_csv"]

#: Earth field used for the simulated magnetometer, G, world frame (x, y, z up).
_MAG_WORLD_G = np.array([0.2, 0.0, -0.45])


def _rot_y(theta):
    """R(theta) (.., 3, 3): block -> world, positive tilts +z towards +x."""
    c, s = np.cos(theta), np.sin(theta)
    z, o = np.zeros_like(c), np.ones_like(c)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def _base_fn(base):
    if base is None:
        return lambda t: np.zeros_like(t), lambda t: np.zeros_like(t)
    tb = np.asarray(getattr(base, "t_s", base[0] if isinstance(base, tuple) else None), float)
    ab = np.asarray(getattr(base, "acc_m_s2", base[1] if isinstance(base, tuple) else None), float)
    vb = np.concatenate(([0.0], np.cumsum(0.5 * (ab[1:] + ab[:-1]) * np.diff(tb))))
    return (lambda t: np.interp(t, tb, ab, left=0.0, right=0.0), lambda t: np.interp(t, tb, vb, left=0.0, right=vb[-1]))


def simulate_imu_log(
    t_s,
    theta_rad,
    block=None,
    *,
    omega_rad_s=None,
    mount_m=None,
    sensor_rotation=None,
    rate_hz: float = 256.0,
    t_start_s: float | None = None,
    rest_before_s: float = 0.0,
    rest_after_s: float = 0.0,
    gyro_noise_deg_s: float = 0.1,
    gyro_bias_deg_s=0.5,
    acc_noise_g: float = 0.005,
    acc_bias_g=0.0,
    base=None,
    drop_bursts: int = 0,
    drop_max: int = 8,
    seed: int = 0,
    clock_offset_s: float = 0.0,
    clock_drift: float = 0.0,
) -> ImuLog:
    """Simulate what an IMU fixed to a rocking block (or the table) logs.

    Parameters
    ----------
    t_s, theta_rad : array_like (m,)
        Truth: block rotation history, s and rad (fine grid, e.g. the
        simulator output).  Held at the first value before and at the last
        value after (block at rest).
    block : Block, optional
        Block geometry (``b_m`` width, ``h_m`` height).  None: a sensor
        rigidly on the table (theta must then be zero).
    omega_rad_s : array_like (m,), optional
        Truth angular velocity, rad/s (default: gradient of theta).
    mount_m : (x_m, z_m), optional
        Sensor position in the block frame, m (default: face centre ``(0, h/2)``).
    sensor_rotation : ndarray (3, 3), optional
        Sensor-from-block rotation (mis-mount); default identity (sensor x along
        the width, y along the rocking axis, z up).
    rate_hz : float
        Sample rate, Hz.
    t_start_s : float, optional
        Time of the first sample, s (default ``t_s[0] - rest_before_s``).
    rest_before_s, rest_after_s : float
        Extra rest logged before ``t_s[0]`` and after ``t_s[-1]``, s.
    gyro_noise_deg_s, acc_noise_g : float
        White noise standard deviation per sample (deg/s, g).
    gyro_bias_deg_s : float or array (3,)
        Constant gyro bias, deg/s; a scalar gets a seeded random sign per axis.
    acc_bias_g : float or array (3,)
        Constant accelerometer bias, g.
    base : BaseMotion or (t_s, acc_m_s2), optional
        Table acceleration along world x, m/s^2.
    drop_bursts, drop_max : int
        Number of lost-packet bursts, each 3..``drop_max`` consecutive samples.
    seed : int
        Random seed (noise, bias signs, drop positions).
    clock_offset_s, clock_drift : float
        Logged times are ``t * (1 + drift) + offset`` (device clock vs truth).

    Returns
    -------
    ImuLog
        ``format="simulated"``; ``t_s`` on the device clock; ``dropped_samples``
        counts the removed samples.
    """
    t_tr = np.asarray(t_s, float)
    th_tr = np.asarray(theta_rad, float)
    if t_tr.ndim != 1 or t_tr.shape != th_tr.shape or t_tr.size < 2:
        raise InputError("simulate_imu_log: t_s and theta_rad must be 1-D arrays of equal length >= 2")
    if np.any(np.diff(t_tr) < 0):
        raise InputError("simulate_imu_log: t_s must be non-decreasing")
    if not rate_hz > 0:
        raise InputError(f"rate_hz={rate_hz!r}: must be > 0 Hz")
    om_tr = np.gradient(th_tr, t_tr) if omega_rad_s is None else np.asarray(omega_rad_s, float)
    if block is None:
        if np.any(th_tr != 0):
            raise InputError("simulate_imu_log: block=None (table sensor) needs theta_rad == 0")
        b2, mount = 0.0, np.zeros(2)
    else:
        b2 = 0.5 * block.b_m
        mount = np.array([0.0, 0.5 * block.h_m] if mount_m is None else mount_m, float)
    rng = np.random.default_rng(seed)
    dt = 1.0 / rate_hz
    t0 = t_tr[0] - rest_before_s if t_start_s is None else float(t_start_s)
    t1 = t_tr[-1] + rest_after_s
    n = int(math.floor((t1 - t0) * rate_hz)) + 1
    tk = t0 + np.arange(n) * dt

    f_block, w_block = _block_kinematics(tk, dt, (t_tr, th_tr, om_tr), b2, mount, base)
    S = np.eye(3) if sensor_rotation is None else np.asarray(sensor_rotation, float)
    gb = np.asarray(gyro_bias_deg_s, float)
    if gb.ndim == 0:
        gb = gb * rng.choice([-1.0, 1.0], 3)
    gyro = w_block @ S.T + np.deg2rad(gb) + rng.normal(0.0, np.deg2rad(gyro_noise_deg_s), (n, 3))
    acc = (
        f_block @ S.T
        + np.broadcast_to(np.asarray(acc_bias_g, float), (3,)) * G
        + rng.normal(0.0, acc_noise_g * G, (n, 3))
    )
    keep = np.ones(n, dtype=bool)
    for _ in range(int(drop_bursts)):
        length = int(rng.integers(3, max(4, drop_max + 1)))
        start = int(rng.integers(int(0.2 * n), max(int(0.2 * n) + 1, n - length - int(0.2 * n))))
        keep[start : start + length] = False
    t_dev = tk * (1.0 + clock_drift) + clock_offset_s
    return ImuLog(
        t_dev[keep], gyro[keep], acc[keep], float(rate_hz), int(n - keep.sum()), None, "simulated", "simulated"
    )


def _block_kinematics(tk, dt, truth, b2, mount, base):
    """Specific force (n, 3) m/s² and rate (n, 3) rad/s in the block frame at the sample times ``tk`` (s).

    ``truth`` = (t s, theta rad, omega rad/s) of the block rocking on its edges at ±``b2`` m with the sensor
    at ``mount`` = (x, z) m in the block frame; ``base`` moves the table along world x. Rates and
    accelerations are central differences over one sample interval ``dt`` (s), as a sampling IMU sees them.
    """
    t_tr, th_tr, om_tr = truth
    n = tk.size

    def theta_at(t):
        return np.interp(t, t_tr, th_tr)

    def point_velocity(t):
        th = theta_at(t)
        om = np.interp(t, t_tr, om_tr, left=0.0, right=0.0)
        piv = np.where(th >= 0, b2, -b2)
        rx, rz = mount[0] - piv, mount[1]
        # d/dtheta of R(theta) (r - P) in the x-z plane.
        vx = om * (-rx * np.sin(th) + rz * np.cos(th))
        vz = om * (-rx * np.cos(th) - rz * np.sin(th))
        return vx, vz

    vxa, vza = point_velocity(tk - 0.5 * dt)
    vxb, vzb = point_velocity(tk + 0.5 * dt)
    base_acc, base_vel = _base_fn(base)
    ax = (vxb - vxa) / dt + (base_vel(tk + 0.5 * dt) - base_vel(tk - 0.5 * dt)) / dt
    az = (vzb - vza) / dt
    th_k = theta_at(tk)
    f_world = np.stack([ax, np.zeros(n), az + G], axis=1)
    R = _rot_y(th_k)
    f_block = np.einsum("nji,nj->ni", R, f_world)
    w_block = np.zeros((n, 3))
    w_block[:, 1] = (theta_at(tk + 0.5 * dt) - theta_at(tk - 0.5 * dt)) / dt
    return f_block, w_block


def _sample_index(log: ImuLog) -> np.ndarray:
    return np.rint((log.t_s - log.t_s[0]) * log.rate_hz).astype(np.int64)


def _fmt(x: np.ndarray) -> np.ndarray:
    return np.char.mod("%.7g", x)


def write_ximu_csv(
    log: ImuLog, base_path, *, full_scale_g: float | None = 8.0, first_packet: int = 113
) -> tuple[Path, Path]:
    """Write ``log`` as an original x-IMU GUI export (atomic writes).

    Writes ``<base>_CalInertialAndMag.csv`` (``Packet number``, gyroscope deg/s,
    accelerometer g clipped at ``full_scale_g``, magnetometer G) and
    ``<base>_Registers.csv`` (``InertialAndMagneticDataRate`` at address 69,
    value ``log2(rate) + 1``; ``AccelerometerFullScale``).  Packet numbers
    interleave a quaternion packet every second inertial sample and battery /
    date-time packets at 4 Hz / 1 Hz, as the device does; samples missing from
    ``log`` (dropped) leave their packet numbers out.

    Parameters
    ----------
    log : ImuLog
        Samples; the rate must be a power of two (x-IMU register encoding).
    base_path : str or Path
        Output prefix, e.g. ``session/imu/block_1/00000``.
    full_scale_g : float or None
        Accelerometer clip level, g (x-IMU: 2, 4 or 8).
    first_packet : int
        Packet number of the first inertial sample.

    Returns
    -------
    (Path, Path)
        The inertial CSV and the registers CSV.
    """
    fs = float(log.rate_hz)
    code = math.log2(fs) + 1 if fs > 0 else -1
    if code != int(code) or code < 1:
        raise InputError(
            f"write_ximu_csv: rate {fs:g} Hz is not a power of two; the x-IMU rate register encodes fs = 2**(value-1)"
        )
    base = Path(base_path)
    k = _sample_index(log)
    # Packets per inertial sample: inertial + quaternion at fs/2 + battery 4 Hz + date 1 Hz.
    per = (fs + fs / 2 + 4 + 1) / fs
    pk = first_packet + np.floor(k * per + 1e-9).astype(np.int64)
    gyro = np.rad2deg(log.gyro_rad_s)
    acc = log.acc_m_s2 / G
    if full_scale_g is not None:
        acc = np.clip(acc, -full_scale_g, full_scale_g)
    mag = np.tile(_MAG_WORLD_G, (log.n, 1))
    cols = (
        [pk.astype(str)]
        + [_fmt(gyro[:, i]) for i in range(3)]
        + [_fmt(acc[:, i]) for i in range(3)]
        + [_fmt(mag[:, i]) for i in range(3)]
    )
    head = (
        "Packet number,Gyroscope X (deg/s),Gyroscope Y (deg/s),Gyroscope Z (deg/s),"
        "Accelerometer X (g),Accelerometer Y (g),Accelerometer Z (g),"
        "Magnetometer X (G),Magnetometer Y (G),Magnetometer Z (G)"
    )
    inertial = base.with_name(base.name + "_CalInertialAndMag.csv")
    regs = base.with_name(base.name + "_Registers.csv")
    _write_lines(inertial, head, cols)
    fsc = {2.0: 0, 4.0: 1, 8.0: 2}.get(float(full_scale_g or 8.0), 2)
    rows = [
        (32, fsc, "AccelerometerFullScale"),
        (67, 1, "DateTimeDataRate"),
        (68, 3, "BatteryAndThermometerDataRate"),
        (69, int(code), "InertialAndMagneticDataRate"),
        (70, int(code) - 1, "QuaternionDataRate"),
    ]
    text = "Packet number,Address,Value,Fixed-point value,Name\n" + "".join(
        f"{i + 1},{a},{v},NaN,{nm}\n" for i, (a, v, nm) in enumerate(rows)
    )
    with atomic_path(regs, stamp=False) as tmp:  # a log to read, not an output
        Path(tmp).write_text(text, encoding="utf-8")
    return inertial, regs


def write_ximu3_csv(
    log: ImuLog,
    folder,
    *,
    full_scale_g: float = 16.0,
    high_g_noise_g: float = 0.02,
    clock0_us: int = 19150794,
    seed: int = 0,
) -> tuple[Path, Path]:
    """Write ``log`` as an x-IMU3 device folder: ``Inertial.csv`` + ``HighGAccelerometer.csv``.

    ``Inertial.csv``: ``Timestamp (us)`` (device clock from ``clock0_us``),
    gyroscope deg/s, accelerometer g clipped at ``full_scale_g``.
    ``HighGAccelerometer.csv``: ``Timestamp (us), X (g), Y (g), Z (g)``, the
    unclipped acceleration with coarser noise at the same instants.

    Returns
    -------
    (Path, Path)
        The two CSV paths.
    """
    folder = Path(folder)
    t_us = clock0_us + np.rint((log.t_s - log.t_s[0]) * 1e6).astype(np.int64)
    acc_g = log.acc_m_s2 / G
    main = np.clip(acc_g, -full_scale_g, full_scale_g)
    rng = np.random.default_rng(seed)
    hg = acc_g + rng.normal(0.0, high_g_noise_g, acc_g.shape)
    gyro = np.rad2deg(log.gyro_rad_s)
    head = (
        "Timestamp (us),Gyroscope X (deg/s),Gyroscope Y (deg/s),Gyroscope Z (deg/s),"
        "Accelerometer X (g),Accelerometer Y (g),Accelerometer Z (g)"
    )
    p1 = folder / "Inertial.csv"
    p2 = folder / "HighGAccelerometer.csv"
    _write_lines(
        p1, head, [t_us.astype(str)] + [_fmt(gyro[:, i]) for i in range(3)] + [_fmt(main[:, i]) for i in range(3)]
    )
    _write_lines(p2, "Timestamp (us),X (g),Y (g),Z (g)", [t_us.astype(str)] + [_fmt(hg[:, i]) for i in range(3)])
    return p1, p2


def _write_lines(path: Path, head: str, cols: list[np.ndarray]) -> None:
    body = cols[0].astype(object)
    for c in cols[1:]:
        body = body + "," + c.astype(object)
    with atomic_path(path, stamp=False) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="\n") as fh:
            fh.write(head + "\n")
            fh.write("\n".join(body.tolist()))
            fh.write("\n")
