"""phyphox exports: a phone's accelerometer and gyroscope, one CSV per sensor.

phyphox (RWTH Aachen's phone app) exports each sensor of an experiment to its own CSV with
its own sample times: ``Accelerometer.csv`` (``"Time (s)","Acceleration x (m/s^2)",...``,
gravity included) and ``Gyroscope.csv`` (``"Time (s)","Gyroscope x (rad/s)",...``), in a
folder or in the ``.zip`` the app shares (beside ``meta/`` and the other sensors).
``Linear Acceleration`` (gravity taken out by the phone) cannot give a tilt and is not read.

The two sensors are sampled by separate clocks of the same phone; their times share one
origin. The sensor with the higher rate sets the sample times (the gyroscope on a tie: it
carries the rotation history), the other is interpolated linearly onto them, over the span
both cover. Linear interpolation of a 100 Hz signal onto 400 Hz times adds no information:
an impact's jump in the slower sensor is spread over one of its own periods.
"""

from __future__ import annotations

import tempfile
import zipfile
from pathlib import Path

import numpy as np

from ..._errors import InputError, where
from ._csv import check_increasing, gap_drops, numeric_column, read_csv, saturation
from ._log import ImuLog

__all__ = ["PHYPHOX_FILES", "is_phyphox", "phyphox_files", "read_phyphox"]

#: The two files of a phyphox export that rocklab reads (accelerometer with g, gyroscope).
PHYPHOX_FILES = ("Accelerometer.csv", "Gyroscope.csv")

#: Header names per role in phyphox's exports (units as phyphox writes them).
_ACC_COLS = tuple(f"Acceleration {a} (m/s^2)" for a in "xyz")
_GYRO_COLS = tuple(f"Gyroscope {a} (rad/s)" for a in "xyz")

#: The slower sensor's samples must reach this share of the faster one's rate; below it the
#: interpolated axes are too coarse to be mixed in silently.
MIN_RATE_SHARE = 0.25


def _members(zf: zipfile.ZipFile) -> dict[str, str]:
    """``{"Accelerometer.csv": member name, ...}`` for the files found anywhere in the zip."""
    found: dict[str, str] = {}
    for name in zf.namelist():
        base = name.rsplit("/", 1)[-1]
        if base in PHYPHOX_FILES and base not in found:
            found[base] = name
    return found


def is_phyphox(path: Path) -> bool:
    """True for a folder holding both phyphox CSVs, or a zip holding both."""
    if path.is_dir():
        return all((path / f).is_file() for f in PHYPHOX_FILES)
    if path.is_file() and path.suffix.lower() == ".zip" and zipfile.is_zipfile(path):
        with zipfile.ZipFile(path) as zf:
            return len(_members(zf)) == len(PHYPHOX_FILES)
    return False


def phyphox_files(path: Path) -> list[Path]:
    """The input files read for a phyphox export (the two CSVs, or the zip)."""
    return [path / f for f in PHYPHOX_FILES] if path.is_dir() else [path]


def _sensor(path: Path, cols: tuple[str, ...], shown: str) -> tuple[np.ndarray, np.ndarray]:
    """Times (s) and the three axes (SI as phyphox writes them) of one sensor's CSV."""
    df = read_csv(path)
    tcol = next((c for c in df.columns if c.lower() == "time (s)"), None)
    missing = [c for c in (tcol or "Time (s)",) + cols if c not in df.columns]
    if missing:
        linear = any(c.lower().startswith("linear acceleration") for c in df.columns)
        hint = (
            "this is phyphox's 'Linear Acceleration' (gravity taken out by the phone), which gives no tilt: "
            "record 'Acceleration with g' (Accelerometer.csv)"
            if linear
            else f"expected phyphox's header {', '.join(repr(c) for c in ('Time (s)',) + cols)}"
        )
        raise InputError(f"{where(shown, 1)}missing columns {', '.join(missing)}; {hint}")
    t = numeric_column(df, tcol, path)
    check_increasing(t, path, tcol)
    return t, np.column_stack([numeric_column(df, c, path) for c in cols])


def _read_pair(acc_path: Path, gyro_path: Path, shown: tuple[str, str], source: str, full_scale_g) -> ImuLog:
    from ..._diagnostics import warn

    t_a, acc = _sensor(acc_path, _ACC_COLS, shown[0])
    t_g, gyro = _sensor(gyro_path, _GYRO_COLS, shown[1])
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
            "(set both sensors' rates alike in phyphox)",
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
    return ImuLog(t, gyro, acc, rate, gap_drops(t, 1.0 / rate), saturation(acc, full_scale_g), source, "phyphox")


def read_phyphox(path: Path, full_scale_g: float | None = None) -> ImuLog:
    """Read a phyphox export (folder or zip) into one :class:`ImuLog` in SI units.

    Parameters
    ----------
    path : Path
        A folder with ``Accelerometer.csv`` and ``Gyroscope.csv``, or the ``.zip`` phyphox shares.
    full_scale_g : float, optional
        The phone accelerometer's full scale, g, for saturation flags (else a clipping plateau).

    Returns
    -------
    ImuLog
        ``format = "phyphox"``; times of the faster sensor within the span both cover, s;
        gyroscope rad/s; accelerometer m/s^2 (gravity included).

    Raises
    ------
    InputError
        A missing column (``Linear Acceleration`` named as such), non-numeric values,
        non-increasing times, sensors without a common time span.
    """
    if path.is_dir():
        a, g = (path / f for f in PHYPHOX_FILES)
        return _read_pair(a, g, (str(a), str(g)), str(path), full_scale_g)
    with zipfile.ZipFile(path) as zf, tempfile.TemporaryDirectory(prefix="rocklab-phyphox-") as tmp:
        names = _members(zf)
        shown = tuple(f"{path}!{names[f]}" for f in PHYPHOX_FILES)
        out = []
        for f in PHYPHOX_FILES:
            p = Path(tmp) / f
            p.write_bytes(zf.read(names[f]))
            out.append(p)
        try:
            return _read_pair(out[0], out[1], shown, str(path), full_scale_g)  # type: ignore[arg-type]
        except InputError as e:  # name the member in the zip, not the temporary copy
            msg = str(e)
            for p, s in zip(out, shown):
                msg = msg.replace(str(p), s)
            raise InputError(msg) from None
