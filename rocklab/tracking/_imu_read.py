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
``mapped``
    Any CSV through ``mapping={column: "role:unit"}``, roles ``t``,
    ``gyro_x|y|z``, ``acc_x|y|z``; units ``s|ms|us``, ``deg/s|rad/s``,
    ``g|m/s2``.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._errors import InputError, where
from ..blocks import G

__all__ = ["ImuLog", "read_imu", "read_ximu_registers", "ximu_rate_from_registers"]

_GYRO_UNITS = {"deg/s": math.pi / 180.0, "dps": math.pi / 180.0, "°/s": math.pi / 180.0,
               "rad/s": 1.0}
_ACC_UNITS = {"g": G, "m/s2": 1.0, "m/s^2": 1.0, "m/s²": 1.0}
_TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6}
_ROLES = ("gyro_x", "gyro_y", "gyro_z", "acc_x", "acc_y", "acc_z")
_HEAD = re.compile(r"^\s*(gyroscope|accelerometer)\s+([xyz])\s*\(([^)]*)\)\s*$", re.I)

#: Full scale of the x-IMU3 main accelerometer, g (HighGAccelerometer covers impacts).
XIMU3_FULL_SCALE_G = 16.0


@dataclass(frozen=True)
class ImuLog:
    """One IMU's inertial samples in SI units.

    Attributes
    ----------
    t_s : ndarray, shape (n,)
        Sample times, s, strictly increasing (device clock, or index / rate).
    gyro_rad_s : ndarray, shape (n, 3)
        Angular rate in the sensor frame, rad/s.
    acc_m_s2 : ndarray, shape (n, 3)
        Specific force (accelerometer reading) in the sensor frame, m/s^2;
        +G along the upward axis at rest.
    rate_hz : float
        Nominal sample rate, Hz.
    dropped_samples : int
        Samples missing from the log (estimated from timestamp or packet gaps).
    saturated : ndarray of bool, shape (n,)
        Main accelerometer at full scale on some axis (value replaced from the
        high-g accelerometer where one was available).
    source : str
        File the samples were read from (or ``"simulated"``/``"array"``).
    format : str
        ``"ximu-gui" | "ximu3" | "fusion" | "mapped" | "simulated" | "array"``.
    packet : ndarray or None, shape (n,)
        x-IMU GUI packet numbers (unwrapped), else None.
    high_g_samples : int
        Number of samples whose acceleration came from the high-g accelerometer.
    """

    t_s: np.ndarray
    gyro_rad_s: np.ndarray
    acc_m_s2: np.ndarray
    rate_hz: float
    dropped_samples: int = 0
    saturated: np.ndarray | None = None
    source: str = "array"
    format: str = "array"
    packet: np.ndarray | None = field(default=None, repr=False)
    high_g_samples: int = 0

    def __post_init__(self):
        n = len(self.t_s)
        if self.gyro_rad_s.shape != (n, 3) or self.acc_m_s2.shape != (n, 3):
            raise InputError(f"ImuLog: gyro_rad_s {self.gyro_rad_s.shape} and acc_m_s2 "
                             f"{self.acc_m_s2.shape} must both be ({n}, 3); pass (n, 3) arrays")
        if self.saturated is None:
            object.__setattr__(self, "saturated", np.zeros(n, dtype=bool))

    @property
    def n(self) -> int:
        """Number of samples."""
        return len(self.t_s)

    @property
    def duration_s(self) -> float:
        """Time span of the log, s."""
        return float(self.t_s[-1] - self.t_s[0]) if self.n else 0.0

    def to_frame(self):
        """Samples as a DataFrame: ``t_s, gyro_{x,y,z}_rad_s, acc_{x,y,z}_m_s2, saturated``."""
        import pandas as pd

        d = {"t_s": self.t_s}
        for i, ax in enumerate("xyz"):
            d[f"gyro_{ax}_rad_s"] = self.gyro_rad_s[:, i]
        for i, ax in enumerate("xyz"):
            d[f"acc_{ax}_m_s2"] = self.acc_m_s2[:, i]
        d["saturated"] = self.saturated
        return pd.DataFrame(d)

    def to_dict(self) -> dict:
        """Summary (no arrays): format, rate, sample count, drops, saturation, source."""
        return {"format": self.format, "sample_rate_hz": float(self.rate_hz),
                "n_samples": int(self.n), "dropped_samples": int(self.dropped_samples),
                "saturated_samples": int(np.count_nonzero(self.saturated)),
                "high_g_samples": int(self.high_g_samples), "duration_s": self.duration_s,
                "source": self.source}

    def slice(self, i0: int, i1: int) -> "ImuLog":
        """Samples ``i0:i1`` as a new log (same rate and metadata)."""
        pk = None if self.packet is None else self.packet[i0:i1]
        return ImuLog(self.t_s[i0:i1], self.gyro_rad_s[i0:i1], self.acc_m_s2[i0:i1],
                      self.rate_hz, 0, self.saturated[i0:i1], self.source, self.format, pk)


# --------------------------------------------------------------------------- helpers
def _skip_mag(col: str) -> bool:
    return not str(col).strip().lower().startswith("magnetometer")


def _read_csv(path: Path):
    """Parse a CSV with pandas' C parser; numeric errors name the first bad line.

    All-numeric files go through the numba scanner (``_imu_fastcsv``); the
    rest (text, NaN, malformed rows) through pandas.  Magnetometer columns
    are dropped (unused).
    """
    import pandas as pd

    from ._imu_fastcsv import parse_numeric_csv

    fast = parse_numeric_csv(path) if path.is_file() else None
    if fast is not None:
        names, values = fast
        keep = [i for i, c in enumerate(names) if _skip_mag(c)]
        return pd.DataFrame(values[:, keep], columns=[names[i] for i in keep], copy=False)
    try:
        df = pd.read_csv(path, engine="c", usecols=_skip_mag)
    except pd.errors.EmptyDataError:
        raise InputError(f"{where(path)}empty file; an IMU CSV needs a header and data rows") from None
    if len(df) == 0:
        raise InputError(f"{where(path, 2)}no data rows after the header; "
                         "log some samples or pick another file")
    df.columns = [str(c).strip() for c in df.columns]
    return df


def _numeric(df, col, path: Path) -> np.ndarray:
    v = df[col].to_numpy()
    if v.dtype.kind not in "fiu":
        import pandas as pd

        num = pd.to_numeric(df[col], errors="coerce").to_numpy(dtype=float)
        bad = np.flatnonzero(~np.isfinite(num))
        line = int(bad[0]) + 2 if bad.size else None
        raise InputError(f"{where(path, line, col)}value {df[col].iloc[bad[0]]!r} is not a "
                         "number; fix or delete that row")
    v = v.astype(float, copy=False)
    bad = np.flatnonzero(~np.isfinite(v))
    if bad.size:
        raise InputError(f"{where(path, int(bad[0]) + 2, col)}missing or non-finite value; "
                         "fix or delete that row")
    return v


def _inertial_columns(df, path: Path) -> dict[str, tuple[str, float]]:
    """Find ``Gyroscope X (deg/s)`` ... ``Accelerometer Z (g)`` columns and unit factors."""
    found: dict[str, tuple[str, float]] = {}
    for col in df.columns:
        m = _HEAD.match(col)
        if not m:
            continue
        kind, ax, unit = m.group(1).lower(), m.group(2).lower(), m.group(3).strip().lower()
        table = _GYRO_UNITS if kind == "gyroscope" else _ACC_UNITS
        if unit not in table:
            raise InputError(f"{where(path, 1, col)}unknown unit {unit!r}; use one of "
                             f"{', '.join(table)} in the header")
        role = ("gyro_" if kind == "gyroscope" else "acc_") + ax
        found[role] = (col, table[unit])
    missing = [r for r in _ROLES if r not in found]
    if missing:
        names = ", ".join(("Gyroscope " if r.startswith("gyro") else "Accelerometer ")
                          + r[-1].upper() for r in missing)
        raise InputError(f"{where(path, 1)}missing columns {names}; expected x-io headers "
                         "like 'Gyroscope X (deg/s)', 'Accelerometer X (g)' or pass a mapping")
    return found


def _stack(df, cols, path) -> tuple[np.ndarray, np.ndarray]:
    gyro = np.empty((len(df), 3))
    acc = np.empty((len(df), 3))
    for i, ax in enumerate("xyz"):
        c, f = cols["gyro_" + ax]
        gyro[:, i] = _numeric(df, c, path) * f
        c, f = cols["acc_" + ax]
        acc[:, i] = _numeric(df, c, path) * f
    return gyro, acc


def _check_increasing(t: np.ndarray, path: Path, col: str) -> None:
    d = np.diff(t)
    bad = np.flatnonzero(d <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        what = "duplicate" if d[bad[0]] == 0 else "decreasing"
        raise InputError(f"{where(path, i + 2, col)}{what} time ({t[i]!r} after {t[i - 1]!r}); "
                         "times must increase strictly: remove repeated rows or split the log")


def _gap_drops(t: np.ndarray, period: float) -> int:
    """Samples missing from gaps longer than 1.5 nominal periods."""
    d = np.diff(t)
    big = d > 1.5 * period
    return int(np.sum(np.rint(d[big] / period) - 1)) if big.any() else 0


def _saturation(acc_m_s2: np.ndarray, full_scale_g: float | None) -> np.ndarray:
    """Samples with an axis at full scale.

    With a known full scale, |a| >= 0.99 FS.  Otherwise a clipping plateau: an
    axis' extreme value (>= 2 g) repeated on >= 2 samples.
    """
    a = np.abs(acc_m_s2)
    if full_scale_g is not None:
        return np.any(a >= 0.99 * full_scale_g * G, axis=1)
    sat = np.zeros(len(a), dtype=bool)
    for k in range(3):
        m = a[:, k].max(initial=0.0)
        if m >= 2 * G:
            hit = a[:, k] >= m * (1 - 1e-6)
            if np.count_nonzero(hit) >= 2:
                sat |= hit
    return sat


# --------------------------------------------------------------------------- x-IMU GUI
_RATE_NAMES = ("inertialandmagneticdatarate", "inertialmagneticdatarate")


def read_ximu_registers(path) -> dict:
    """Read an x-IMU GUI ``_Registers.csv``; returns ``{name: value}`` and ``{address: value}``.

    The last occurrence of a register wins.  Keys are the register names as
    written and the integer addresses.
    """
    path = Path(path)
    df = _read_csv(path)
    for need in ("Address", "Value"):
        if need not in df.columns:
            raise InputError(f"{where(path, 1)}missing column {need!r}; expected x-IMU "
                             "'Packet number,Address,Value,Fixed-point value,Name'")
    addr = _numeric(df, "Address", path).astype(int)
    val = _numeric(df, "Value", path)
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
        raise InputError(f"{where(path)}no inertial rate register (Name "
                         "'InertialAndMagneticDataRate', address 69; 54 on old firmware); "
                         "give the rate with --rate / rate_hz=")
    fs = math.floor(2.0 ** (value - 1))
    if fs <= 0:
        raise InputError(f"{where(path, key='InertialAndMagneticDataRate')}value {value:g} means "
                         "the inertial data were disabled; give the rate with --rate / rate_hz=")
    return float(fs)


def _ximu_full_scale_g(regs_path: Path) -> float | None:
    # AccelerometerFullScale register: 0/1/2 -> +-2/4/8 g (x-IMU user manual).
    try:
        regs = read_ximu_registers(regs_path)
    except (InputError, OSError):
        return None
    v = regs.get("AccelerometerFullScale")
    return None if v is None else float(2 ** (int(v) + 1))


def _read_ximu_gui(path: Path, rate_hz: float | None, full_scale_g: float | None) -> ImuLog:
    name = path.name
    legacy = name.endswith("_CalInertialMagnetic.csv")
    suffix = "_CalInertialMagnetic.csv" if legacy else "_CalInertialAndMag.csv"
    regs = path.with_name(name[: -len(suffix)] + "_Registers.csv") if name.endswith(suffix) else None
    if rate_hz is None:
        if regs is None or not regs.is_file():
            raise InputError(f"{where(path)}no <base>_Registers.csv next to it to read the sample "
                             "rate from; give the rate with --rate / rate_hz=")
        rate_hz = ximu_rate_from_registers(regs, legacy=legacy)
    df = _read_csv(path)
    if "Packet number" not in df.columns:
        raise InputError(f"{where(path, 1)}missing column 'Packet number'; not an x-IMU GUI export")
    cols = _inertial_columns(df, path)
    gyro, acc = _stack(df, cols, path)
    pk = _numeric(df, "Packet number", path)
    # 16-bit packet counters wrap; unwrap before checking order.
    wrap = np.diff(pk) < -30000
    if wrap.any():
        pk = pk + 65536.0 * np.concatenate(([0], np.cumsum(wrap)))
    _check_increasing(pk, path, "Packet number")
    index, dropped = _ximu_sample_index(pk)
    if full_scale_g is None and regs is not None and regs.is_file():
        full_scale_g = _ximu_full_scale_g(regs)
    sat = _saturation(acc, full_scale_g)
    return ImuLog(index / rate_hz, gyro, acc, float(rate_hz), dropped, sat, str(path),
                  "ximu-gui", pk)


def _ximu_sample_index(pk: np.ndarray) -> tuple[np.ndarray, int]:
    """Sample index from packet numbers, skipping runs of lost packets.

    Normal gaps are the interleaving pattern (1-3 packets: quaternion,
    battery, date/time packets between inertial ones).  A gap larger than
    twice the largest common gap is a loss.  The index after a loss is the
    packet number measured against the local phase of the packet/sample line
    (mean of ``pk - per * index`` over the preceding 64 samples, ``per`` the
    mean packets per inertial sample on normal gaps), rounded: exact while
    the interleaving jitter stays within +-0.5 sample.
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
        index[g + 1:] += new - index[g + 1]
    return index, int(round(index[-1] - (n - 1)))


# --------------------------------------------------------------------------- x-IMU3
def _read_ximu3(path: Path, rate_hz: float | None, full_scale_g: float | None) -> ImuLog:
    df = _read_csv(path)
    tcol = "Timestamp (us)"
    if tcol not in df.columns:
        raise InputError(f"{where(path, 1)}missing column 'Timestamp (us)'; not an x-IMU3 Inertial.csv")
    cols = _inertial_columns(df, path)
    gyro, acc = _stack(df, cols, path)
    t = _numeric(df, tcol, path) * 1e-6
    _check_increasing(t, path, tcol)
    period = 1.0 / rate_hz if rate_hz else float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    dropped = _gap_drops(t, period)
    fs = XIMU3_FULL_SCALE_G if full_scale_g is None else full_scale_g
    sat = _saturation(acc, fs)
    n_hg = 0
    hg = path.with_name("HighGAccelerometer.csv")
    if sat.any() and hg.is_file():
        acc, n_hg = _merge_high_g(hg, t, acc, sat)
    return ImuLog(t, gyro, acc, 1.0 / period, dropped, sat, str(path), "ximu3", None, n_hg)


def _merge_high_g(hg: Path, t: np.ndarray, acc: np.ndarray, sat: np.ndarray):
    df = _read_csv(hg)
    need = ["Timestamp (us)", "X (g)", "Y (g)", "Z (g)"]
    miss = [c for c in need if c not in df.columns]
    if miss:
        raise InputError(f"{where(hg, 1)}missing columns {', '.join(miss)}; expected "
                         "'Timestamp (us),X (g),Y (g),Z (g)'")
    th = _numeric(df, need[0], hg) * 1e-6
    _check_increasing(th, hg, need[0])
    acc = acc.copy()
    idx = np.flatnonzero(sat)
    for k, c in enumerate(need[1:]):
        acc[idx, k] = np.interp(t[idx], th, _numeric(df, c, hg) * G)
    return acc, int(idx.size)


# --------------------------------------------------------------------------- generic
def _read_timed(path: Path, rate_hz, full_scale_g, mapping) -> ImuLog:
    df = _read_csv(path)
    if mapping:
        cols: dict[str, tuple[str, float]] = {}
        tcol, tf = None, 1.0
        for name, spec in mapping.items():
            role, _, unit = str(spec).partition(":")
            role, unit = role.strip().lower(), unit.strip().lower()
            if name not in df.columns:
                raise InputError(f"{where(path, 1, name)}mapped column not in the header "
                                 f"({', '.join(df.columns)}); fix the mapping")
            table = (_TIME_UNITS if role == "t" else _GYRO_UNITS if role.startswith("gyro_")
                     else _ACC_UNITS if role.startswith("acc_") else None)
            if table is None or (role != "t" and role not in _ROLES):
                raise InputError(f"mapping[{name!r}]: unknown role {role!r}; use t, "
                                 "gyro_x|y|z or acc_x|y|z as 'role:unit'")
            if unit not in table:
                raise InputError(f"mapping[{name!r}]: unknown unit {unit!r} for {role}; "
                                 f"use one of {', '.join(table)}")
            if role == "t":
                tcol, tf = name, table[unit]
            else:
                cols[role] = (name, table[unit])
        missing = [r for r in _ROLES if r not in cols]
        if missing:
            raise InputError(f"mapping: roles {', '.join(missing)} not mapped; map every "
                             "gyro_x|y|z and acc_x|y|z column")
        fmt = "mapped"
    else:
        cols = _inertial_columns(df, path)
        tcol = next((c for c in df.columns if c.lower() in ("time (s)", "t_s")), None)
        tf, fmt = 1.0, "fusion"
        if tcol is None and rate_hz is None:
            raise InputError(f"{where(path, 1)}no 'Time (s)' column and no rate; add the "
                             "column, pass a mapping, or give the rate with --rate / rate_hz=")
    gyro, acc = _stack(df, cols, path)
    if tcol is None:
        t = np.arange(len(df)) / float(rate_hz)
    else:
        t = _numeric(df, tcol, path) * tf
        _check_increasing(t, path, tcol)
    period = 1.0 / rate_hz if rate_hz else float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    return ImuLog(t, gyro, acc, 1.0 / period, _gap_drops(t, period),
                  _saturation(acc, full_scale_g), str(path), fmt)


def _resolve(path: Path) -> Path:
    """A log folder or base prefix -> the inertial CSV inside it."""
    if path.is_file():
        return path
    if path.is_dir():
        pats = ("*_CalInertialAndMag.csv", "*_CalInertialMagnetic.csv", "Inertial.csv",
                "*/Inertial.csv", "sensor_data.csv")
        for pat in pats:
            hits = sorted(path.glob(pat))
            if len(hits) == 1:
                return hits[0]
            if len(hits) > 1:
                raise InputError(f"{where(path)}{len(hits)} logs match {pat} "
                                 f"({hits[0].name}, {hits[1].name}, ...); give one file")
        csvs = sorted(path.glob("*.csv"))
        if len(csvs) == 1:
            return csvs[0]
        raise InputError(f"{where(path)}no IMU log found (looked for *_CalInertialAndMag.csv, "
                         "Inertial.csv, a single *.csv); give the file")
    for suffix in ("_CalInertialAndMag.csv", "_CalInertialMagnetic.csv"):
        cand = path.with_name(path.name + suffix)
        if cand.is_file():
            return cand
    raise FileNotFoundError(2, "no such file or folder", str(path))


def read_imu(path, rate_hz: float | None = None, mapping: dict | None = None,
             full_scale_g: float | None = None) -> ImuLog:
    """Read an IMU log into SI units.

    Parameters
    ----------
    path : str or Path
        An inertial CSV, a log folder (x-IMU GUI export, x-IMU3 device folder),
        or an x-IMU base prefix (``.../00000``).
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
    p = _resolve(Path(path))
    if rate_hz is not None and not (np.isfinite(rate_hz) and rate_hz > 0):
        raise InputError(f"rate_hz={rate_hz!r}: the sample rate must be a positive number of Hz")
    if mapping:
        return _read_timed(p, rate_hz, full_scale_g, mapping)
    if p.name.endswith(("_CalInertialAndMag.csv", "_CalInertialMagnetic.csv")):
        return _read_ximu_gui(p, rate_hz, full_scale_g)
    with open(p, encoding="utf-8", errors="replace") as fh:
        head = fh.readline()
    if "Timestamp (us)" in head:
        return _read_ximu3(p, rate_hz, full_scale_g)
    if "Packet number" in head:
        # A renamed x-IMU export: needs the rate from the user.
        if rate_hz is None:
            raise InputError(f"{where(p)}x-IMU 'Packet number' log without a "
                             "_CalInertialAndMag.csv name; give the rate with --rate / rate_hz=")
        return _read_ximu_gui(p, rate_hz, full_scale_g)
    return _read_timed(p, rate_hz, full_scale_g, None)
