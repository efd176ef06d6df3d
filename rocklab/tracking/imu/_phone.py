"""Phone IMU exports: the accelerometer and the gyroscope in one CSV each, on their own clocks.

Two apps a lab reaches for, each a folder (or the ``.zip`` the app shares):

``phyphox`` (RWTH Aachen)
    ``Accelerometer.csv`` (``"Time (s)","Acceleration x (m/s^2)",...``, gravity included:
    "Acceleration with g") and ``Gyroscope.csv`` (``"Time (s)","Gyroscope x (rad/s)",...``).
    ``Linear Acceleration`` (gravity taken out by the phone) gives no tilt and is not read.
``sensor-logger`` (Sensor Logger, Kelvin Choi)
    ``TotalAcceleration.csv`` (gravity included) and ``Gyroscope.csv``, each
    ``time,seconds_elapsed,z,y,x`` (epoch ns, s, m/s^2 or rad/s). Its ``Accelerometer.csv``
    has gravity taken out: a folder with only that one is refused.

The two sensors are sampled by separate clocks of the same phone; their times share one
origin. The sensor with the higher rate sets the sample times (the gyroscope on a tie: it
carries the rotation history), the other is interpolated linearly onto them, over the span
both cover. Linear interpolation of a 100 Hz signal onto 400 Hz times adds no information:
an impact's jump in the slower sensor is spread over one of its own periods.
"""

from __future__ import annotations

import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..._errors import InputError, where
from ._csv import check_increasing, gap_drops, numeric_column, read_csv, saturation
from ._log import ImuLog

__all__ = ["PHONE_LAYOUTS", "phone_layout", "phone_files", "read_phone"]


@dataclass(frozen=True)
class PhoneLayout:
    """Where a phone app puts each sensor and what it calls the columns.

    Attributes
    ----------
    acc_file, gyro_file : str
        The accelerometer's (gravity included) and the gyroscope's CSV names.
    time_col : str
        Time column, s.
    acc_cols, gyro_cols : tuple of str
        x, y, z columns, m/s^2 and rad/s.
    """

    acc_file: str
    gyro_file: str
    time_col: str
    acc_cols: tuple[str, str, str]
    gyro_cols: tuple[str, str, str]


#: The phone apps read, by the name :class:`~rocklab.tracking.ImuLog` gives their format.
PHONE_LAYOUTS = {
    "phyphox": PhoneLayout(
        "Accelerometer.csv",
        "Gyroscope.csv",
        "Time (s)",
        ("Acceleration x (m/s^2)", "Acceleration y (m/s^2)", "Acceleration z (m/s^2)"),
        ("Gyroscope x (rad/s)", "Gyroscope y (rad/s)", "Gyroscope z (rad/s)"),
    ),
    "sensor-logger": PhoneLayout(
        "TotalAcceleration.csv", "Gyroscope.csv", "seconds_elapsed", ("x", "y", "z"), ("x", "y", "z")
    ),
}

#: The slower sensor's samples must reach this share of the faster one's rate; below it the
#: interpolated axes are too coarse to be mixed in silently.
MIN_RATE_SHARE = 0.25


def _header(text: bytes) -> list[str]:
    import csv

    line = text.decode("utf-8", "replace").splitlines()[0] if text else ""
    return [c.strip() for c in next(csv.reader([line]), [])]


def _members(names: list[str]) -> dict[str, str]:
    """``{base name: member}`` for the CSVs found anywhere in a zip (the first of each name)."""
    found: dict[str, str] = {}
    for name in names:
        found.setdefault(name.rsplit("/", 1)[-1], name)
    return found


def _first_bytes(path: Path, name: str) -> bytes | None:
    """The first 4 kB of ``name`` in the folder or zip ``path``, or None."""
    if path.is_dir():
        p = path / name
        if not p.is_file():
            return None
        with open(p, "rb") as fh:
            return fh.read(4096)
    with zipfile.ZipFile(path) as zf:
        member = _members(zf.namelist()).get(name)
        if member is None:
            return None
        with zf.open(member) as fh:
            return fh.read(4096)


def phone_layout(path: Path) -> str | None:
    """The phone app whose export ``path`` (a folder or a zip) is, or None.

    Raises
    ------
    InputError
        A Sensor Logger export without ``TotalAcceleration.csv`` (its ``Accelerometer.csv``
        has gravity taken out).
    """
    if not (path.is_dir() or (path.is_file() and path.suffix.lower() == ".zip" and zipfile.is_zipfile(path))):
        return None
    gyro = _first_bytes(path, "Gyroscope.csv")
    if gyro is None:
        return None
    if "seconds_elapsed" in _header(gyro):
        if _first_bytes(path, "TotalAcceleration.csv") is None:
            raise InputError(
                f"{path}: a Sensor Logger export without TotalAcceleration.csv: its Accelerometer.csv has "
                "gravity taken out, which gives no tilt; record 'Total Acceleration' with the gyroscope"
            )
        return "sensor-logger"
    return "phyphox" if _first_bytes(path, "Accelerometer.csv") is not None else None


def phone_files(path: Path, layout: str) -> list[Path]:
    """The input files read for a phone export (the two CSVs, or the zip)."""
    lay = PHONE_LAYOUTS[layout]
    return [path / lay.acc_file, path / lay.gyro_file] if path.is_dir() else [path]


def _sensor(path: Path, lay: PhoneLayout, cols: tuple[str, ...], shown: str) -> tuple[np.ndarray, np.ndarray]:
    """Times (s) and the three axes (SI as the app writes them) of one sensor's CSV."""
    df = read_csv(path)
    tcol = next((c for c in df.columns if c.lower() == lay.time_col.lower()), None)
    missing = [c for c in (tcol or lay.time_col,) + cols if c not in df.columns]
    if missing:
        linear = any(c.lower().startswith("linear acceleration") for c in df.columns)
        hint = (
            "this is phyphox's 'Linear Acceleration' (gravity taken out by the phone), which gives no tilt: "
            "record 'Acceleration with g' (Accelerometer.csv)"
            if linear
            else f"expected the header {', '.join(repr(c) for c in (lay.time_col,) + cols)}"
        )
        raise InputError(f"{where(shown, 1)}missing columns {', '.join(missing)}; {hint}")
    t = numeric_column(df, tcol, path)
    check_increasing(t, path, tcol)
    return t, np.column_stack([numeric_column(df, c, path) for c in cols])


def _read_pair(paths: list[Path], shown: tuple[str, ...], source: str, layout: str, full_scale_g) -> ImuLog:
    from ..._diagnostics import warn

    lay = PHONE_LAYOUTS[layout]
    t_a, acc = _sensor(paths[0], lay, lay.acc_cols, shown[0])
    t_g, gyro = _sensor(paths[1], lay, lay.gyro_cols, shown[1])
    if len(t_a) < 2 or len(t_g) < 2:
        raise InputError(f"{source}: fewer than 2 samples of a sensor; record longer")
    rate_a, rate_g = 1.0 / float(np.median(np.diff(t_a))), 1.0 / float(np.median(np.diff(t_g)))
    lo, hi = max(t_a[0], t_g[0]), min(t_a[-1], t_g[-1])
    if hi <= lo:
        raise InputError(
            f"{source}: the accelerometer ({t_a[0]:.4g}-{t_a[-1]:.4g} s) and the gyroscope "
            f"({t_g[0]:.4g}-{t_g[-1]:.4g} s) share no time span; export both sensors of one recording"
        )
    slow, fast = sorted((rate_a, rate_g))
    if slow < MIN_RATE_SHARE * fast:
        warn(
            "W-IMU-RATE",
            f"{source}: the {'accelerometer' if rate_a < rate_g else 'gyroscope'} runs at {slow:.4g} Hz, the "
            f"other sensor at {fast:.4g} Hz; the slower one is interpolated onto the faster one's times "
            "(set both sensors' rates alike in the app)",
        )
    if rate_g >= rate_a:
        t = t_g[(t_g >= lo) & (t_g <= hi)]
        gyro = gyro[(t_g >= lo) & (t_g <= hi)]
        acc = np.column_stack([np.interp(t, t_a, acc[:, k]) for k in range(3)])
        rate = rate_g
    else:
        t = t_a[(t_a >= lo) & (t_a <= hi)]
        acc = acc[(t_a >= lo) & (t_a <= hi)]
        gyro = np.column_stack([np.interp(t, t_g, gyro[:, k]) for k in range(3)])
        rate = rate_a
    return ImuLog(t, gyro, acc, rate, gap_drops(t, 1.0 / rate), saturation(acc, full_scale_g), source, layout)


def read_phone(path: Path, layout: str, full_scale_g: float | None = None) -> ImuLog:
    """Read a phone app's export (folder or zip) into one :class:`ImuLog` in SI units.

    Parameters
    ----------
    path : Path
        The export's folder, or the ``.zip`` the app shares.
    layout : {"phyphox", "sensor-logger"}
        The app (:func:`phone_layout` tells it).
    full_scale_g : float, optional
        The phone accelerometer's full scale, g, for saturation flags (else a clipping plateau).

    Returns
    -------
    ImuLog
        ``format = layout``; times of the faster sensor within the span both cover, s;
        gyroscope rad/s; accelerometer m/s^2 (gravity included).

    Raises
    ------
    InputError
        A missing column (``Linear Acceleration`` named as such), non-numeric values,
        non-increasing times, sensors without a common time span.
    """
    lay = PHONE_LAYOUTS[layout]
    names = (lay.acc_file, lay.gyro_file)
    if path.is_dir():
        paths = [path / f for f in names]
        return _read_pair(paths, tuple(str(p) for p in paths), str(path), layout, full_scale_g)
    with zipfile.ZipFile(path) as zf, tempfile.TemporaryDirectory(prefix="rocklab-phone-") as tmp:
        members = _members(zf.namelist())
        shown = tuple(f"{path}!{members[f]}" for f in names)
        out = []
        for f in names:
            p = Path(tmp) / f
            p.write_bytes(zf.read(members[f]))
            out.append(p)
        try:
            return _read_pair(out, shown, str(path), layout, full_scale_g)
        except InputError as e:  # name the member in the zip, not the temporary copy
            msg = str(e)
            for p, sh in zip(out, shown):
                msg = msg.replace(str(p), sh)
            raise InputError(msg) from None
