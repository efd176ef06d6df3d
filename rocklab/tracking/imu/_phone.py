"""Phone IMU exports: the accelerometer and the gyroscope in one CSV each, on their own clocks.

Two apps a lab reaches for, each a folder (or the ``.zip`` the app shares):

``phyphox`` (RWTH Aachen)
    ``Accelerometer.csv`` (gravity included: "Acceleration with g") and ``Gyroscope.csv``, each
    ``"Time (s)"`` then the axes, named ``"Acceleration x (m/s^2)"`` / ``"Gyroscope x (rad/s)"``
    or, in other app versions, ``"X (m/s^2)"`` / ``"X (rad/s)"``; separated by commas, tabs or
    semicolons, with a decimal point or comma (the app's export options). ``Linear
    Acceleration`` (gravity taken out by the phone) gives no tilt and is refused.
``sensor-logger`` (Sensor Logger, Kelvin Choi)
    ``TotalAcceleration.csv`` (gravity included; Android) or ``Accelerometer.csv`` +
    ``Gravity.csv`` (iOS: CoreMotion's user acceleration and its gravity estimate, summed back
    into the accelerometer's reading), and ``Gyroscope.csv``, each ``time,seconds_elapsed,z,y,x``
    (epoch ns, s, m/s^2 or rad/s). ``Accelerometer.csv`` alone has gravity taken out: refused.

The two sensors are sampled by separate clocks of the same phone; their times share one
origin. The sensor with the higher rate sets the sample times (the gyroscope on a tie: it
carries the rotation history), the other is interpolated linearly onto them, over the span
both cover. Linear interpolation of a 100 Hz signal onto 400 Hz times adds no information:
an impact's jump in the slower sensor is spread over one of its own periods. Sensors whose
spans share less than :data:`MIN_SPAN_SHARE` of the longer one are ``W-IMU-CLOCK`` (a paused
recording exports one sensor longer than the other).
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
    format : str
        The :attr:`ImuLog.format` of its logs.
    acc_files : tuple of str
        The accelerometer's CSV, or CSVs whose axes add up to it (gravity included), m/s^2.
    gyro_file : str
        The gyroscope's CSV, rad/s.
    time_col : str
        Time column, s.
    acc_cols, gyro_cols : tuple of (str, str, str)
        x, y, z column names, each triple one naming the app uses (the first found is read).
    """

    format: str
    acc_files: tuple[str, ...]
    gyro_file: str
    time_col: str
    acc_cols: tuple[tuple[str, str, str], ...]
    gyro_cols: tuple[tuple[str, str, str], ...]


_XYZ = (("x", "y", "z"),)

#: The phone export layouts read, by name.
PHONE_LAYOUTS = {
    "phyphox": PhoneLayout(
        "phyphox",
        ("Accelerometer.csv",),
        "Gyroscope.csv",
        "Time (s)",
        (
            ("Acceleration x (m/s^2)", "Acceleration y (m/s^2)", "Acceleration z (m/s^2)"),
            ("X (m/s^2)", "Y (m/s^2)", "Z (m/s^2)"),
        ),
        (
            ("Gyroscope x (rad/s)", "Gyroscope y (rad/s)", "Gyroscope z (rad/s)"),
            ("X (rad/s)", "Y (rad/s)", "Z (rad/s)"),
        ),
    ),
    "sensor-logger": PhoneLayout(
        "sensor-logger", ("TotalAcceleration.csv",), "Gyroscope.csv", "seconds_elapsed", _XYZ, _XYZ
    ),
    "sensor-logger-ios": PhoneLayout(
        "sensor-logger", ("Accelerometer.csv", "Gravity.csv"), "Gyroscope.csv", "seconds_elapsed", _XYZ, _XYZ
    ),
}

#: The slower sensor's samples must reach this share of the faster one's rate; below it the
#: interpolated axes are too coarse to be mixed in silently.
MIN_RATE_SHARE = 0.25

#: The span both sensors cover, as a share of the longer sensor's span, below which the export
#: is ``W-IMU-CLOCK``.
MIN_SPAN_SHARE = 0.8

#: Names a phone app gives its gravity-free acceleration (no tilt in it).
_LINEAR = ("Linear Acceleration.csv", "Linear Accelerometer.csv", "LinearAcceleration.csv")


def _separator(line: str) -> str:
    """The field separator of a CSV whose first line is ``line``: phyphox's export options write
    commas, tabs or semicolons (the latter two with a decimal point or comma)."""
    return ";" if line.count(";") > line.count(",") else "\t" if "\t" in line else ","


def _members(names: list[str]) -> dict[str, str]:
    """``{base name: member}`` for the CSVs found anywhere in a zip (the first of each name)."""
    found: dict[str, str] = {}
    for name in names:
        found.setdefault(name.rsplit("/", 1)[-1], name)
    return found


def _files(path: Path) -> dict[str, str]:
    """``{base name: member}`` of the files in the folder or zip ``path`` (one listing)."""
    if path.is_dir():
        return {p.name: p.name for p in path.iterdir() if p.is_file()}
    with zipfile.ZipFile(path) as zf:
        return _members(zf.namelist())


def _header(path: Path, member: str) -> list[str]:
    """The column names on the first line of ``member`` in the folder or zip ``path``."""
    import csv

    if path.is_dir():
        with open(path / member, "rb") as fh:
            text = fh.read(4096)
    else:
        with zipfile.ZipFile(path) as zf, zf.open(member) as fh:
            text = fh.read(4096)
    line = text.decode("utf-8", "replace").splitlines()[0] if text else ""
    return [c.strip() for c in next(csv.reader([line], delimiter=_separator(line)), [])]


def phone_layout(path: Path) -> str | None:
    """The phone export layout (a key of :data:`PHONE_LAYOUTS`) of the folder or zip ``path``, or None.

    Raises
    ------
    InputError
        A phone export that cannot give a tilt and a rotation: no gyroscope file beside an
        accelerometer's, or only a gravity-free acceleration (one line saying which and the fix).
    """
    if not (path.is_dir() or (path.is_file() and path.suffix.lower() == ".zip" and zipfile.is_zipfile(path))):
        return None
    files = _files(path)
    has = {n: n in files for n in ("Accelerometer.csv", "TotalAcceleration.csv", "Gravity.csv")}
    linear = next((n for n in _LINEAR if n in files), None)
    if "Gyroscope.csv" not in files:
        if any(has.values()) or linear:
            raise InputError(
                f"{path}: a phone export (phyphox, Sensor Logger) without Gyroscope.csv: rocklab needs the "
                "gyroscope with the accelerometer; record both in one session"
            )
        return None
    if "seconds_elapsed" in _header(path, files["Gyroscope.csv"]):
        if has["TotalAcceleration.csv"]:
            return "sensor-logger"
        if has["Accelerometer.csv"] and has["Gravity.csv"]:
            return "sensor-logger-ios"
        what = (
            "its Accelerometer.csv has gravity taken out and no Gravity.csv"
            if has["Accelerometer.csv"]
            else ("no accelerometer file")
        )
        raise InputError(
            f"{path}: a Sensor Logger export without TotalAcceleration.csv ({what}), so no tilt; record "
            "'Total Acceleration' (or Accelerometer with Gravity) with the gyroscope"
        )
    if has["Accelerometer.csv"]:
        return "phyphox"
    if linear:
        raise InputError(
            f"{path}: a phyphox export with {linear} but no Accelerometer.csv: linear acceleration has gravity "
            "taken out, which gives no tilt; record 'Acceleration with g' with the gyroscope"
        )
    raise InputError(
        f"{path}: a phyphox export without Accelerometer.csv; record 'Acceleration with g' with the gyroscope"
    )


def phone_files(path: Path, layout: str) -> list[Path]:
    """The input files read for a phone export (its CSVs, or the zip)."""
    lay = PHONE_LAYOUTS[layout]
    return [path / f for f in (*lay.acc_files, lay.gyro_file)] if path.is_dir() else [path]


def _frame(path: Path):
    """The CSV as a DataFrame: comma files through rocklab's reader, tab- and semicolon-separated
    ones (phyphox's other export options, perhaps with a decimal comma) through pandas."""
    import pandas as pd

    with open(path, "rb") as fh:
        head = fh.read(4096).decode("utf-8", "replace").splitlines()
    sep = _separator(head[0] if head else "")
    if sep == ",":
        return read_csv(path)
    data = head[1] if len(head) > 1 else ""
    decimal = "," if "," in data else "."
    df = pd.read_csv(path, sep=sep, decimal=decimal)
    df.columns = [str(c).strip() for c in df.columns]
    return df


def _sensor(path: Path, lay: PhoneLayout, cands, shown: str) -> tuple[np.ndarray, np.ndarray]:
    """Times (s) and the three axes (SI as the app writes them) of one sensor's CSV."""
    df = _frame(path)
    lower = {str(c).lower(): c for c in df.columns}
    tcol = lower.get(lay.time_col.lower())
    cols = next(
        (tuple(lower[c.lower()] for c in trio) for trio in cands if all(c.lower() in lower for c in trio)), None
    )
    if tcol is None or cols is None:
        missing = [lay.time_col] if tcol is None else []
        missing += [c for c in cands[0] if c.lower() not in lower] if cols is None else []
        linear = any(str(c).lower().startswith("linear acceleration") for c in df.columns)
        hint = (
            "this is phyphox's 'Linear Acceleration' (gravity taken out by the phone), which gives no tilt: "
            "record 'Acceleration with g' (Accelerometer.csv)"
            if linear
            else "expected the header " + " or ".join(", ".join(repr(c) for c in (lay.time_col, *t)) for t in cands)
        )
        raise InputError(f"{where(shown, 1)}missing columns {', '.join(missing)}; {hint}")
    t = numeric_column(df, tcol, path)
    check_increasing(t, path, tcol)
    return t, np.column_stack([numeric_column(df, c, path) for c in cols])


def _read_pair(paths: list[Path], shown: tuple[str, ...], source: str, layout: str, full_scale_g) -> ImuLog:
    """One log from an export's accelerometer CSV(s) (``paths[:-1]``, summed) and gyroscope CSV (``paths[-1]``)."""
    from ..._diagnostics import warn

    lay = PHONE_LAYOUTS[layout]
    t_a, acc = _sensor(paths[0], lay, lay.acc_cols, shown[0])
    for p, sh in zip(paths[1:-1], shown[1:-1]):  # iOS: user acceleration + gravity
        t_x, extra = _sensor(p, lay, lay.acc_cols, sh)
        acc = acc + np.column_stack([np.interp(t_a, t_x, extra[:, k]) for k in range(3)])
    t_g, gyro = _sensor(paths[-1], lay, lay.gyro_cols, shown[-1])
    if len(t_a) < 2 or len(t_g) < 2:
        raise InputError(f"{source}: fewer than 2 samples of a sensor; record longer")
    rate_a, rate_g = 1.0 / float(np.median(np.diff(t_a))), 1.0 / float(np.median(np.diff(t_g)))
    lo, hi = max(t_a[0], t_g[0]), min(t_a[-1], t_g[-1])
    if hi <= lo:
        raise InputError(
            f"{source}: the accelerometer ({t_a[0]:.4g}-{t_a[-1]:.4g} s) and the gyroscope "
            f"({t_g[0]:.4g}-{t_g[-1]:.4g} s) share no time span; export both sensors of one recording"
        )
    longer = max(t_a[-1] - t_a[0], t_g[-1] - t_g[0])
    if hi - lo < MIN_SPAN_SHARE * longer:
        warn(
            "W-IMU-CLOCK",
            f"{source}: the accelerometer covers {t_a[0]:.4g}-{t_a[-1]:.4g} s and the gyroscope "
            f"{t_g[0]:.4g}-{t_g[-1]:.4g} s; only the {hi - lo:.4g} s both cover is read (a paused recording "
            "or files from two recordings: export both sensors of one)",
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
        keep = (t_g >= lo) & (t_g <= hi)
        t, gyro, rate = t_g[keep], gyro[keep], rate_g
        acc = np.column_stack([np.interp(t, t_a, acc[:, k]) for k in range(3)])
    else:
        keep = (t_a >= lo) & (t_a <= hi)
        t, acc, rate = t_a[keep], acc[keep], rate_a
        gyro = np.column_stack([np.interp(t, t_g, gyro[:, k]) for k in range(3)])
    return ImuLog(t, gyro, acc, rate, gap_drops(t, 1.0 / rate), saturation(acc, full_scale_g), source, lay.format)


def read_phone(path: Path, layout: str, full_scale_g: float | None = None) -> ImuLog:
    """Read a phone app's export (folder or zip) into one :class:`ImuLog` in SI units.

    Parameters
    ----------
    path : Path
        The export's folder, or the ``.zip`` the app shares.
    layout : str
        A key of :data:`PHONE_LAYOUTS` (:func:`phone_layout` tells it).
    full_scale_g : float, optional
        The phone accelerometer's full scale, g, for saturation flags (else a clipping plateau).

    Returns
    -------
    ImuLog
        ``format`` the app's name; times of the faster sensor within the span both cover, s;
        gyroscope rad/s; accelerometer m/s^2 (gravity included).

    Raises
    ------
    InputError
        A missing column (``Linear Acceleration`` named as such), non-numeric values,
        non-increasing times, sensors without a common time span.
    """
    lay = PHONE_LAYOUTS[layout]
    names = (*lay.acc_files, lay.gyro_file)
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
