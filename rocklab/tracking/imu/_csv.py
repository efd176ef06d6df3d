"""CSV helpers shared by the IMU readers: parsing, unit headers, validation.

Unit factors convert to SI at the file boundary (deg/s -> rad/s, g -> m/s^2).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from ..._errors import InputError, where
from ...blocks import G

__all__ = []

GYRO_UNITS = {"deg/s": math.pi / 180.0, "dps": math.pi / 180.0, "°/s": math.pi / 180.0, "rad/s": 1.0}
ACC_UNITS = {"g": G, "m/s2": 1.0, "m/s^2": 1.0, "m/s²": 1.0}
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6}
ROLES = ("gyro_x", "gyro_y", "gyro_z", "acc_x", "acc_y", "acc_z")
# "Acceleration x (m/s^2)" is phyphox's accelerometer with gravity; its "Linear Acceleration"
# (gravity taken out) does not match: it gives no tilt
_HEAD = re.compile(r"^\s*(gyroscope|accelerometer|acceleration)\s+([xyz])\s*\(([^)]*)\)\s*$", re.I)

#: Full scale of the x-IMU3 main accelerometer, g (HighGAccelerometer covers impacts).
XIMU3_FULL_SCALE_G = 16.0


def _skip_mag(col: str) -> bool:
    return not str(col).strip().lower().startswith("magnetometer")


#: First bytes of the files an IMU log is most often mistaken for (named in the error).
_MAGIC = (
    (b"\x89PNG", "a PNG image"),
    (b"\xff\xd8\xff", "a JPEG image"),
    (b"GIF8", "a GIF image"),
    (b"%PDF", "a PDF document"),
    (b"PK\x03\x04", "a ZIP archive (or an .xlsx workbook) holding no phone export (phyphox, Sensor Logger)"),
    (b"\x1f\x8b", "a gzip archive"),
    (b"\x1a\x45\xdf\xa3", "a Matroska/WebM film"),
    (b"RIFF", "a RIFF file (AVI, WAV)"),
)


def _require_text(path: Path) -> None:
    """:class:`InputError` naming ``path`` unless it starts as UTF-8 text (its first 64 kB): a
    picture or a film given for a log is refused before any reading (a missing final newline
    in an image is no truncated log)."""
    import codecs

    try:
        with open(path, "rb") as fh:
            head = fh.read(1 << 16)
    except OSError:
        return  # the reader reports a missing or unreadable file itself
    if head.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise InputError(f'{where(path)}UTF-16 text; an IMU log is read as UTF-8: save it as UTF-8 ("CSV UTF-8")')
    kind = next((k for magic, k in _MAGIC if head.startswith(magic)), None)
    if kind is None and head[4:8] == b"ftyp":
        kind = "an MP4/MOV film"
    if kind is None and b"\x00" in head:
        kind = "binary data"
    if kind is None:
        try:
            codecs.getincrementaldecoder("utf-8")().decode(head, final=False)
            return
        except UnicodeDecodeError as e:
            raise InputError(
                f"{where(path)}not UTF-8 text (byte 0x{head[e.start]:02x} at offset {e.start}); an IMU log is "
                "a CSV text file: save it as UTF-8"
            ) from None
    raise InputError(
        f"{where(path)}{kind}, not a text file; an IMU log is a CSV text file (x-io exports: "
        "<base>_CalInertialAndMag.csv, Inertial.csv, sensor_data.csv): give the log"
    )


def read_csv(path: Path):
    """Parse a CSV with pandas' C parser; numeric errors name the first bad line.

    All-numeric files go through the numba scanner (``_imu_fastcsv``); the
    rest (text, NaN, malformed rows) through pandas.  Magnetometer columns
    are dropped (unused). A file that is not text is refused first (:func:`_require_text`).
    """
    import pandas as pd

    from ._fastcsv import parse_numeric_csv

    _require_text(path)
    nrows = _complete_rows(path)
    fast = parse_numeric_csv(path) if path.is_file() and nrows is None else None
    if fast is not None:
        names, values = fast
        keep = [i for i, c in enumerate(names) if _skip_mag(c)]
        return pd.DataFrame(values[:, keep], columns=[names[i] for i in keep], copy=False)
    try:
        df = pd.read_csv(path, engine="c", usecols=_skip_mag, nrows=nrows)
    except pd.errors.EmptyDataError:
        raise InputError(f"{where(path)}empty file; an IMU CSV needs a header and data rows") from None
    if len(df) == 0:
        raise InputError(f"{where(path, 2)}no data rows after the header; log some samples or pick another file")
    df.columns = [str(c).strip() for c in df.columns]
    return df


def _complete_rows(path: Path) -> int | None:
    """Data rows to read when the file's last line is incomplete (a logger stopped mid-write:
    no final newline and fewer fields than the header, or an empty last field), else None. The
    cut line is dropped with ``W-IMU-TRUNCATED``; a whole last line that only lacks its newline
    (as phyphox writes its exports) is kept."""
    import csv

    try:
        with open(path, "rb") as fh:
            fh.seek(0, 2)
            size = fh.tell()
            if size == 0:
                return None
            fh.seek(size - 1)
            if fh.read(1) in (b"\n", b"\r"):
                return None
            fh.seek(0)
            data = fh.read()
    except OSError:
        return None
    n_lines = data.count(b"\n")  # complete lines, header included
    if n_lines < 2:
        return None
    head = data[: data.index(b"\n")].decode("utf-8", "replace").rstrip("\r")
    last = data[data.rindex(b"\n") + 1 :].decode("utf-8", "replace")
    names, fields = next(csv.reader([head]), []), next(csv.reader([last]), [])
    if len(fields) == len(names) and (fields[-1].strip() or not names[-1].strip()):
        return None
    from ..._diagnostics import warn

    warn(
        "W-IMU-TRUNCATED",
        f"{path}, line {n_lines + 1}: last line cut short ({len(fields)} of {len(names)} fields, no newline) dropped",
    )
    return n_lines - 1


def numeric_column(df, col, path: Path) -> np.ndarray:
    v = df[col].to_numpy()
    if v.dtype.kind not in "fiu":
        import pandas as pd

        num = pd.to_numeric(df[col], errors="coerce").to_numpy(dtype=float)
        bad = np.flatnonzero(~np.isfinite(num))
        line = int(bad[0]) + 2 if bad.size else None
        raise InputError(
            f"{where(path, line, col)}value {df[col].iloc[bad[0]]!r} is not a number; fix or delete that row"
        )
    v = v.astype(float, copy=False)
    bad = np.flatnonzero(~np.isfinite(v))
    if bad.size:
        raise InputError(f"{where(path, int(bad[0]) + 2, col)}missing or non-finite value; fix or delete that row")
    return v


def inertial_columns(df, path: Path) -> dict[str, tuple[str, float]]:
    """Find ``Gyroscope X (deg/s)`` ... ``Accelerometer Z (g)`` columns and unit factors."""
    found: dict[str, tuple[str, float]] = {}
    for col in df.columns:
        m = _HEAD.match(col)
        if not m:
            continue
        kind, ax, unit = m.group(1).lower(), m.group(2).lower(), m.group(3).strip().lower()
        table = GYRO_UNITS if kind == "gyroscope" else ACC_UNITS
        if unit not in table:
            raise InputError(f"{where(path, 1, col)}unknown unit {unit!r}; use one of {', '.join(table)} in the header")
        role = ("gyro_" if kind == "gyroscope" else "acc_") + ax
        found[role] = (col, table[unit])
    missing = [r for r in ROLES if r not in found]
    if missing:
        raise InputError(_missing_message(path, found, missing, df.columns))
    return found


def _missing_message(path: Path, found: dict, missing: list, columns=()) -> str:
    """The one-line error for an inertial CSV without all six gyroscope/accelerometer columns."""
    linear = [c for c in columns if str(c).strip().lower().startswith("linear acceleration")]
    if linear and any(r.startswith("acc_") for r in missing):
        return (
            f"{where(path, 1)}'{linear[0]}' is an acceleration with gravity taken out (phyphox's Linear "
            "Acceleration), which gives no tilt; record the accelerometer with gravity ('Acceleration with g')"
        )
    if all(r.startswith("acc_") for r in missing) and len(missing) == 3:
        units = sorted({c.partition("(")[2].rstrip(") ") for c, _ in (found[f"gyro_{a}"] for a in "xyz")})
        return (
            f"{where(path, 1)}gyroscope only ({', '.join(units)}), no accelerometer column: rocklab reads no "
            "gyroscope-only log, since a block's tilt and the gravity reference (a table's acceleration too) "
            "come from a 3-axis accelerometer; record the accelerometer with the gyroscope in the same log"
        )
    names = ", ".join(("Gyroscope " if r.startswith("gyro") else "Accelerometer ") + r[-1].upper() for r in missing)
    return (
        f"{where(path, 1)}missing columns {names}; name the header's columns 'Gyroscope X (rad/s)' "
        "(or '(deg/s)') ... 'Accelerometer Z (m/s^2)' (or '(g)'), each with the unit its values are in, "
        "and 'Time (s)', or from Python read it with rocklab.tracking.imu.read_imu(path, "
        "mapping={column: 'role:unit'})"
    )


def stack(df, cols, path) -> tuple[np.ndarray, np.ndarray]:
    gyro = np.empty((len(df), 3))
    acc = np.empty((len(df), 3))
    for i, ax in enumerate("xyz"):
        c, f = cols["gyro_" + ax]
        gyro[:, i] = numeric_column(df, c, path) * f
        c, f = cols["acc_" + ax]
        acc[:, i] = numeric_column(df, c, path) * f
    return gyro, acc


def check_increasing(t: np.ndarray, path: Path, col: str) -> None:
    d = np.diff(t)
    bad = np.flatnonzero(d <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        what = "duplicate" if d[bad[0]] == 0 else "decreasing"
        raise InputError(
            f"{where(path, i + 2, col)}{what} time ({t[i]!r} after {t[i - 1]!r}); "
            "times must increase strictly: remove repeated rows or split the log"
        )


def gap_drops(t: np.ndarray, period: float) -> int:
    """Samples missing from gaps longer than 1.5 nominal periods."""
    d = np.diff(t)
    big = d > 1.5 * period
    return int(np.sum(np.rint(d[big] / period) - 1)) if big.any() else 0


def saturation(acc_m_s2: np.ndarray, full_scale_g: float | None) -> np.ndarray:
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
