"""IMU log readers: x-IMU GUI exports, x-IMU3 logs, Fusion-style and mapped CSVs.

Everything is converted to SI once, here, at the file boundary: gyroscope
deg/s -> rad/s, accelerometer g -> m/s^2 (``rocklab.G``), timestamps us -> s.

Formats
-------
``ximu-gui``
    Original x-IMU GUI export ``<base>_CalInertialAndMag.csv`` (older name
    ``<base>_CalInertialMagnetic.csv``): ``Packet number``, gyroscope deg/s,
    accelerometer g, magnetometer G.  Packet numbers count every packet type
    (quaternion, battery, date/time ...), so they skip by design; time comes
    from the sample index and the inertial rate.  The rate is read from
    ``<base>_Registers.csv``: ``fs = floor(2**(value - 1))`` Hz of the register
    named ``InertialAndMagneticDataRate`` (address 69, current firmware) or
    ``InertialMagneticDataRate`` (address 54, firmware of the older
    ``_CalInertialMagnetic`` files), as in the x-IMU-MATLAB-Library
    ``xIMUdataClass.m``.  Runs of lost packets (a packet-number gap far larger
    than the interleaving pattern) are counted as dropped samples and the time
    axis skips them.
``ximu3``
    x-IMU3 ``Inertial.csv`` (``Timestamp (us)`` device clock, gyroscope deg/s,
    accelerometer g).  Times come from the timestamps; gaps longer than 1.5
    nominal periods count as dropped samples.  A ``HighGAccelerometer.csv`` next
    to it (``Timestamp (us), X (g), Y (g), Z (g)``) replaces saturated samples
    of the main accelerometer (+-16 g).
``fusion``
    CSV with ``Time (s)``, gyroscope deg/s, accelerometer g (x-io Fusion
    example layout).
``phyphox``, ``sensor-logger``
    A phone app's export (folder or ``.zip``): the accelerometer (gravity included) and the
    gyroscope in a CSV each with their own sample times, merged onto the faster sensor's times
    (``_phone.py``).
``mapped``
    Any CSV through ``mapping={column: "role:unit"}``, roles ``t``,
    ``gyro_x|y|z``, ``acc_x|y|z``; units ``s|ms|us``, ``deg/s|rad/s``,
    ``g|m/s2``.
"""

from __future__ import annotations

import dataclasses

from pathlib import Path

import numpy as np

from ..._errors import InputError, where
from ...blocks import G
from ._csv import (
    ACC_UNITS,
    GYRO_UNITS,
    ROLES,
    TIME_UNITS,
    XIMU3_FULL_SCALE_G,
    check_increasing,
    gap_drops,
    inertial_columns,
    numeric_column,
    read_csv,
    saturation,
    stack,
)
from ._log import ImuLog
from ._phone import phone_files, phone_layout, read_phone
from ._ximu import read_ximu_gui, read_ximu_registers, ximu_rate_from_registers

__all__ = ["ImuLog", "read_imu", "imu_log_files", "read_ximu_registers", "ximu_rate_from_registers"]


# --------------------------------------------------------------------------- x-IMU3
def _read_ximu3(path: Path, rate_hz: float | None, full_scale_g: float | None) -> ImuLog:
    df = read_csv(path)
    tcol = "Timestamp (us)"
    if tcol not in df.columns:
        raise InputError(f"{where(path, 1)}missing column 'Timestamp (us)'; not an x-IMU3 Inertial.csv")
    cols = inertial_columns(df, path)
    gyro, acc = stack(df, cols, path)
    t = numeric_column(df, tcol, path) * 1e-6
    check_increasing(t, path, tcol)
    period = 1.0 / rate_hz if rate_hz else float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    dropped = gap_drops(t, period)
    fs = XIMU3_FULL_SCALE_G if full_scale_g is None else full_scale_g
    sat = saturation(acc, fs)
    n_hg = 0
    hg = path.with_name("HighGAccelerometer.csv")
    if sat.any() and hg.is_file():
        acc, n_hg = _merge_high_g(hg, t, acc, sat)
    return ImuLog(t, gyro, acc, 1.0 / period, dropped, sat, str(path), "ximu3", None, n_hg)


def _merge_high_g(hg: Path, t: np.ndarray, acc: np.ndarray, sat: np.ndarray):
    df = read_csv(hg)
    need = ["Timestamp (us)", "X (g)", "Y (g)", "Z (g)"]
    miss = [c for c in need if c not in df.columns]
    if miss:
        raise InputError(
            f"{where(hg, 1)}missing columns {', '.join(miss)}; expected 'Timestamp (us),X (g),Y (g),Z (g)'"
        )
    th = numeric_column(df, need[0], hg) * 1e-6
    check_increasing(th, hg, need[0])
    acc = acc.copy()
    idx = np.flatnonzero(sat)
    for k, c in enumerate(need[1:]):
        acc[idx, k] = np.interp(t[idx], th, numeric_column(df, c, hg) * G)
    return acc, int(idx.size)


# --------------------------------------------------------------------------- generic
def _read_timed(path: Path, rate_hz, full_scale_g, mapping) -> ImuLog:
    df = read_csv(path)
    if mapping:
        cols: dict[str, tuple[str, float]] = {}
        tcol, tf = None, 1.0
        for name, spec in mapping.items():
            role, _, unit = str(spec).partition(":")
            role, unit = role.strip().lower(), unit.strip().lower()
            if name not in df.columns:
                raise InputError(
                    f"{where(path, 1, name)}mapped column not in the header ({', '.join(df.columns)}); fix the mapping"
                )
            table = (
                TIME_UNITS
                if role == "t"
                else GYRO_UNITS
                if role.startswith("gyro_")
                else ACC_UNITS
                if role.startswith("acc_")
                else None
            )
            if table is None or (role != "t" and role not in ROLES):
                raise InputError(
                    f"mapping[{name!r}]: unknown role {role!r}; use t, gyro_x|y|z or acc_x|y|z as 'role:unit'"
                )
            if unit not in table:
                raise InputError(f"mapping[{name!r}]: unknown unit {unit!r} for {role}; use one of {', '.join(table)}")
            if role == "t":
                tcol, tf = name, table[unit]
            else:
                cols[role] = (name, table[unit])
        missing = [r for r in ROLES if r not in cols]
        if missing:
            raise InputError(
                f"mapping: roles {', '.join(missing)} not mapped; map every gyro_x|y|z and acc_x|y|z column"
            )
        fmt = "mapped"
    else:
        cols = inertial_columns(df, path)
        tcol = next((c for c in df.columns if c.lower() in ("time (s)", "t_s")), None)
        tf, fmt = 1.0, "fusion"
        if tcol is None and rate_hz is None:
            raise InputError(
                f"{where(path, 1)}no 'Time (s)' column and no rate; add the "
                "column 'Time (s)', or give the rate with --rate (read_imu(..., rate_hz=) from Python)"
            )
    gyro, acc = stack(df, cols, path)
    if tcol is None:
        t = np.arange(len(df)) / float(rate_hz)
    else:
        t = numeric_column(df, tcol, path) * tf
        check_increasing(t, path, tcol)
    period = 1.0 / rate_hz if rate_hz else float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    return ImuLog(t, gyro, acc, 1.0 / period, gap_drops(t, period), saturation(acc, full_scale_g), str(path), fmt)


def _resolve(path: Path) -> tuple[Path, str | None]:
    """``(path, its layout)`` for a phone export's folder or zip (:func:`._phone.phone_layout`),
    else ``(the inertial CSV, None)`` for a CSV, a log folder or a base prefix."""
    layout = phone_layout(path)
    return (path, layout) if layout else (_inertial_csv(path), None)


def _inertial_csv(path: Path) -> Path:
    """A log folder or base prefix -> the inertial CSV inside it."""
    if path.is_file():
        return path
    if path.is_dir():
        pats = (
            "*_CalInertialAndMag.csv",
            "*_CalInertialMagnetic.csv",
            "Inertial.csv",
            "*/Inertial.csv",
            "sensor_data.csv",
        )
        for pat in pats:
            hits = sorted(path.glob(pat))
            if len(hits) == 1:
                return hits[0]
            if len(hits) > 1:
                raise InputError(
                    f"{where(path)}{len(hits)} logs match {pat} ({hits[0].name}, {hits[1].name}, ...); give one file"
                )
        from ..._outdir import rocklab_wrote

        # an output of an earlier `imu FOLDER -o FOLDER/theta.csv` is not a second log
        csvs = [c for c in sorted(path.glob("*.csv")) if not rocklab_wrote(c)]
        if len(csvs) == 1:
            return csvs[0]
        raise InputError(
            f"{where(path)}no IMU log found (looked for *_CalInertialAndMag.csv, "
            "Inertial.csv, a single *.csv); give the file"
        )
    for suffix in ("_CalInertialAndMag.csv", "_CalInertialMagnetic.csv"):
        cand = path.with_name(path.name + suffix)
        if cand.is_file():
            return cand
    raise FileNotFoundError(2, "no such file or folder", str(path))


def imu_log_files(path) -> list[Path]:
    """The files :func:`read_imu` reads for ``path`` (the log, and the companions next to it that exist).

    Raises the same errors as :func:`read_imu` for a folder without one log, or a missing path.
    """
    p, layout = _resolve(Path(path))
    if layout:
        return phone_files(p, layout)
    companions = [p.with_name("HighGAccelerometer.csv")]
    for suffix in ("_CalInertialAndMag.csv", "_CalInertialMagnetic.csv"):
        if p.name.endswith(suffix):
            companions.append(p.with_name(p.name[: -len(suffix)] + "_Registers.csv"))
    return [p] + [c for c in companions if c.is_file()]


def read_imu(
    path, rate_hz: float | None = None, mapping: dict | None = None, full_scale_g: float | None = None
) -> ImuLog:
    """Read an IMU log into SI units.

    Parameters
    ----------
    path : str or Path
        An inertial CSV, a log folder (x-IMU GUI export, x-IMU3 device folder,
        phyphox or Sensor Logger export), such an export's ``.zip``, or an x-IMU base prefix (``.../00000``).
    rate_hz : float, optional
        Sample rate, Hz.  Required for x-IMU GUI logs without a rate register
        and CSVs without a time column; for timestamped logs it is the nominal
        rate used to count dropped samples.
    mapping : dict, optional
        ``{column: "role:unit"}`` for other CSV layouts (roles ``t``,
        ``gyro_x|y|z``, ``acc_x|y|z``; units ``s|ms|us``, ``deg/s|rad/s``,
        ``g|m/s2``).
    full_scale_g : float, optional
        Accelerometer full scale, g, for saturation flags (default: x-IMU3
        16 g; x-IMU from its ``AccelerometerFullScale`` register; otherwise a
        clipping plateau is detected).

    Returns
    -------
    ImuLog

    Raises
    ------
    InputError
        Empty file, missing columns, unknown units, non-numeric values,
        non-increasing times, no rate.
    """
    p, layout = _resolve(Path(path))
    if rate_hz is not None and not (np.isfinite(rate_hz) and rate_hz > 0):
        raise InputError(f"rate_hz={rate_hz!r}: the sample rate must be a positive number of Hz")
    return check_imu_log(_read_any(p, layout, rate_hz, mapping, full_scale_g), rate_hz)


#: Sample rates an inertial logger can have, Hz; outside them the timestamps' or the rate
#: register's units are wrong.
RATE_RANGE_HZ = (1.0, 20000.0)


def check_imu_log(log: ImuLog, rate_option_hz: float | None = None) -> ImuLog:
    """Plausibility of a log's clock: rate range, option vs timestamps, clock jumps and gaps.

    Returns the log, with the timestamps' rate when ``rate_option_hz`` disagrees with them
    (``W-IMU-RATE``). Gaps longer than 10 samples and 0.05 s give ``W-IMU-CLOCK``.
    """
    from ..._diagnostics import warn

    lo, hi = RATE_RANGE_HZ
    if log.n > 1:
        d = np.diff(log.t_s)
        period = float(np.median(d))
        ts_rate = 1.0 / period
        if not lo <= ts_rate <= hi:
            raise InputError(
                f"{log.source}: timestamps give {ts_rate:.4g} Hz, not an IMU sample rate "
                f"({lo:g}-{hi:g} Hz); check the time column's units (s/ms/us) or the rate register"
            )
        timed = log.format != "ximu-gui"  # x-IMU GUI times come from packet numbers and the rate
        if timed and rate_option_hz is not None and abs(rate_option_hz / ts_rate - 1) > 0.02:
            warn(
                "W-IMU-RATE",
                f"{log.source}: --rate {rate_option_hz:g} Hz but the timestamps say "
                f"{ts_rate:.4g} Hz; the timestamps are used",
            )
            from ._csv import gap_drops

            log = dataclasses.replace(log, rate_hz=ts_rate, dropped_samples=gap_drops(log.t_s, period))
        gap = d > max(10 * period, 0.05)
        if gap.any():
            i = int(np.argmax(d))
            warn(
                "W-IMU-CLOCK",
                f"{log.source}: {int(gap.sum())} gap(s) in the clock, the longest "
                f"{d[i]:.4g} s at t = {log.t_s[i]:.4g} s ({int(round(d[i] / period)) - 1} "
                "samples missing or a clock jump)",
            )
    if not lo <= log.rate_hz <= hi:
        raise InputError(
            f"{log.source}: sample rate {log.rate_hz:.4g} Hz (rate register or --rate) is not "
            f"an IMU rate ({lo:g}-{hi:g} Hz); check the register or give --rate"
        )
    _check_gravity(log)
    return log


#: The accelerometer's median |a| over a log, in units of G, that a sensor on a block or a table
#: reads: gravity, give or take the motion (a rocking block's or a shaking table's median stays
#: within a few % of G; a phone bouncing on a trampoline: 1.003 G).
GRAVITY_RANGE_G = (0.5, 2.0)


def _check_gravity(log: ImuLog) -> None:
    """:class:`InputError` when the accelerometer does not read gravity: a "linear" accelerometer
    (gravity taken out by the phone or logger) gives no tilt, and values in g under an m/s^2
    header (or the reverse) scale every acceleration by 9.81."""
    if log.n == 0:
        return
    med = float(np.median(np.linalg.norm(log.acc_m_s2, axis=1))) / G
    lo, hi = GRAVITY_RANGE_G
    if lo <= med <= hi:
        return
    if abs(med * G - 1.0) < 0.07:
        why = "values in g read as m/s^2 (or gravity taken out)"
        fix = "name the accelerometer columns with '(g)'"
    elif med < 0.2:
        why = "gravity is not in it (a 'linear' or 'user' acceleration, gravity taken out), so it gives no tilt"
        fix = "log the accelerometer with gravity (phyphox 'Acceleration with g', Sensor Logger 'TotalAcceleration')"
    elif abs(med - G) < 0.5:
        why = "values in m/s^2 read as g"
        fix = "name the accelerometer columns with '(m/s^2)'"
    else:
        why = "far from gravity (an acceleration with gravity taken out, or a wrong unit)"
        fix = "log the accelerometer with gravity and check its columns' units"
    raise InputError(
        f"{log.source}: the accelerometer reads {med * G:.4g} m/s^2 (median |a|) where a sensor at rest or "
        f"rocking reads gravity, {G:.4g} m/s^2: {why}; {fix}"
    )


def _read_any(p: Path, layout: str | None, rate_hz, mapping, full_scale_g) -> ImuLog:
    if mapping:
        return _read_timed(p, rate_hz, full_scale_g, mapping)
    if layout:
        return read_phone(p, layout, full_scale_g)
    if p.name.endswith(("_CalInertialAndMag.csv", "_CalInertialMagnetic.csv")):
        return read_ximu_gui(p, rate_hz, full_scale_g)
    with open(p, encoding="utf-8", errors="replace") as fh:
        head = fh.readline()
    if "Timestamp (us)" in head:
        return _read_ximu3(p, rate_hz, full_scale_g)
    if "Packet number" in head:
        # A renamed x-IMU export: needs the rate from the user.
        if rate_hz is None:
            raise InputError(
                f"{where(p)}x-IMU 'Packet number' log without a "
                "_CalInertialAndMag.csv name; give the rate with --rate / rate_hz="
            )
        return read_ximu_gui(p, rate_hz, full_scale_g)
    return _read_timed(p, rate_hz, full_scale_g, None)
