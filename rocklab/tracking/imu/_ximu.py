"""Original x-IMU GUI exports: ``<base>_CalInertialAndMag.csv`` + ``<base>_Registers.csv``.

Packet numbers count every packet type (quaternion, battery, date/time ...),
so they skip by design; time comes from the sample index and the inertial
rate, ``fs = floor(2**(value - 1))`` Hz of the register named
``InertialAndMagneticDataRate`` (address 69, current firmware) or
``InertialMagneticDataRate`` (address 54, firmware of the older
``_CalInertialMagnetic`` files), as in the x-IMU-MATLAB-Library
``xIMUdataClass.m``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..._errors import InputError, where
from ._csv import check_increasing, inertial_columns, numeric_column, read_csv, saturation, stack
from ._log import ImuLog

__all__ = ["read_ximu_registers", "ximu_rate_from_registers"]

_RATE_NAMES = ("inertialandmagneticdatarate", "inertialmagneticdatarate")


def read_ximu_registers(path) -> dict:
    """Read an x-IMU GUI ``_Registers.csv``; returns ``{name: value}`` and ``{address: value}``.

    The last occurrence of a register wins.  Keys are the register names as
    written and the integer addresses.
    """
    path = Path(path)
    df = read_csv(path)
    for need in ("Address", "Value"):
        if need not in df.columns:
            raise InputError(
                f"{where(path, 1)}missing column {need!r}; expected x-IMU "
                "'Packet number,Address,Value,Fixed-point value,Name'"
            )
    addr = numeric_column(df, "Address", path).astype(int)
    val = numeric_column(df, "Value", path)
    names = df["Name"].astype(str).str.strip().tolist() if "Name" in df.columns else [""] * len(df)
    out: dict = {}
    for a, v, nm in zip(addr, val, names):
        out[int(a)] = float(v)
        if nm:
            out[nm] = float(v)
    return out


def ximu_rate_from_registers(path, legacy: bool = False) -> float:
    """Inertial sample rate, Hz, from an x-IMU ``_Registers.csv``.

    ``fs = floor(2**(value - 1))`` of the register named
    ``InertialAndMagneticDataRate`` / ``InertialMagneticDataRate``; without
    names, address 69 (or 54 for ``legacy`` ``_CalInertialMagnetic`` logs).
    """
    path = Path(path)
    regs = read_ximu_registers(path)
    value = None
    for k, v in regs.items():
        if isinstance(k, str) and k.lower() in _RATE_NAMES:
            value = v
    if value is None:
        has_names = any(isinstance(k, str) for k in regs)
        addr = 54 if legacy else 69
        if not has_names and addr in regs:
            value = regs[addr]
    if value is None:
        raise InputError(
            f"{where(path)}no inertial rate register (Name "
            "'InertialAndMagneticDataRate', address 69; 54 on old firmware); "
            "give the rate with --rate / rate_hz="
        )
    fs = math.floor(2.0 ** (value - 1))
    if fs <= 0:
        raise InputError(
            f"{where(path, key='InertialAndMagneticDataRate')}value {value:g} means "
            "the inertial data were disabled; give the rate with --rate / rate_hz="
        )
    return float(fs)


def _ximu_full_scale_g(regs_path: Path) -> float | None:
    # AccelerometerFullScale register: 0/1/2 -> +-2/4/8 g (x-IMU user manual).
    try:
        regs = read_ximu_registers(regs_path)
    except (InputError, OSError):
        return None
    v = regs.get("AccelerometerFullScale")
    return None if v is None else float(2 ** (int(v) + 1))


def read_ximu_gui(path: Path, rate_hz: float | None, full_scale_g: float | None) -> ImuLog:
    name = path.name
    legacy = name.endswith("_CalInertialMagnetic.csv")
    suffix = "_CalInertialMagnetic.csv" if legacy else "_CalInertialAndMag.csv"
    regs = path.with_name(name[: -len(suffix)] + "_Registers.csv") if name.endswith(suffix) else None
    if rate_hz is None:
        if regs is None or not regs.is_file():
            raise InputError(
                f"{where(path)}no <base>_Registers.csv next to it to read the sample "
                "rate from; give the rate with --rate / rate_hz="
            )
        rate_hz = ximu_rate_from_registers(regs, legacy=legacy)
    elif regs is not None and regs.is_file():
        # the device's own rate register states the rate: it wins over the option, which would
        # stretch every time (release, impacts) by their ratio
        try:
            stated = ximu_rate_from_registers(regs, legacy=legacy)
        except InputError:  # no usable register: the option is the rate
            stated = None
        if stated is not None and abs(float(rate_hz) / stated - 1) > 0.02:
            from ..._diagnostics import warn

            warn(
                "W-IMU-RATE",
                f"{path}: --rate {float(rate_hz):g} Hz but the log's rate register ({regs.name}) says "
                f"{stated:g} Hz; the register is used (drop --rate)",
            )
            rate_hz = stated
    df = read_csv(path)
    if "Packet number" not in df.columns:
        raise InputError(f"{where(path, 1)}missing column 'Packet number'; not an x-IMU GUI export")
    cols = inertial_columns(df, path)
    gyro, acc = stack(df, cols, path)
    pk = numeric_column(df, "Packet number", path)
    # 16-bit packet counters wrap; unwrap before checking order.
    wrap = np.diff(pk) < -30000
    if wrap.any():
        pk = pk + 65536.0 * np.concatenate(([0], np.cumsum(wrap)))
    check_increasing(pk, path, "Packet number")
    index, dropped = _ximu_sample_index(pk)
    if full_scale_g is None and regs is not None and regs.is_file():
        full_scale_g = _ximu_full_scale_g(regs)
    sat = saturation(acc, full_scale_g)
    return ImuLog(index / rate_hz, gyro, acc, float(rate_hz), dropped, sat, str(path), "ximu-gui", pk)


def _ximu_sample_index(pk: np.ndarray) -> tuple[np.ndarray, int]:
    """Sample index from packet numbers, skipping runs of lost packets.

    Normal gaps are the interleaving pattern (1-3 packets: quaternion,
    battery, date/time packets between inertial ones).  A gap larger than
    twice the largest common gap is a loss.  The index after a loss is the
    packet number measured against the local phase of the packet/sample line
    (mean of ``pk - per * index`` over the preceding 64 samples, ``per`` the
    mean packets per inertial sample on normal gaps), rounded: exact while
    the interleaving jitter stays within +-0.5 sample.  Limitation: a loss of
    one or two inertial packets looks like interleaved battery/date packets
    and is not detected (only runs of about 3 or more lost samples are).
    """
    n = len(pk)
    if n < 3:
        return np.arange(n, dtype=float), 0
    d = np.diff(pk)
    common = np.quantile(d, 0.999) if n > 2000 else np.quantile(d, 0.98)
    lost = np.flatnonzero(d > max(2.0 * common, common + 2))
    if lost.size == 0:
        return np.arange(n, dtype=float), 0
    mask = np.ones(n - 1, dtype=bool)
    mask[lost] = False
    per = float(d[mask].mean())
    index = np.arange(n, dtype=float)
    for g in lost:  # gap between samples g and g + 1
        s = slice(max(0, g - 63), g + 1)
        phase = float(np.mean(pk[s] - per * index[s]))
        new = max(index[g] + 1.0, float(np.rint((pk[g + 1] - phase) / per)))
        index[g + 1 :] += new - index[g + 1]
    return index, int(round(index[-1] - (n - 1)))
