"""Readers for 3D point exports: a long CSV (``t_s, point, x_m, y_m, z_m``) and C3D.

Both give a :class:`PointSeries`: one time base, one label per point and the
positions in metres with NaN where a point was not seen. C3D is read with
``ezc3d`` (the maintained reader of the motion-capture standard); its units come
from the file's ``POINT:UNITS`` parameter, and samples the system marked invalid
(negative residual) become NaN.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..._errors import InputError, where

__all__ = ["PointSeries", "read_points", "read_points_csv", "read_c3d", "write_points_csv", "write_c3d"]

#: Length units a C3D file or a CSV column suffix may carry, in metres.
LENGTH_UNITS_M = {"m": 1.0, "cm": 0.01, "mm": 0.001}


@dataclass(frozen=True)
class PointSeries:
    """3D positions of labelled points over time.

    Attributes
    ----------
    t_s : ndarray, shape (n,)
        Sample times, s, strictly increasing.
    labels : tuple of str, length p
        Point names (C3D ``POINT:LABELS``, the CSV's ``point`` column).
    xyz_m : ndarray, shape (n, p, 3)
        Positions in the rig's axes, m; NaN where the point was not seen.
    source : str
        The file read (for messages).
    notes : tuple of str
        What the reader changed (units converted, invalid samples blanked).
    """

    t_s: np.ndarray
    labels: tuple
    xyz_m: np.ndarray
    source: str = ""
    notes: tuple = field(default=())

    @property
    def rate_hz(self) -> float:
        """Median sample rate, Hz (NaN for fewer than two samples)."""
        if self.t_s.size < 2:
            return float("nan")
        return float(1.0 / np.median(np.diff(self.t_s)))

    def select(self, labels) -> "PointSeries":
        """The series restricted to ``labels`` (in that order); :class:`InputError` names a missing one."""
        labels = list(labels)
        missing = [lab for lab in labels if lab not in self.labels]
        if missing:
            raise InputError(
                f"{where(self.source)}point(s) {missing} not in the file (it has "
                f"{list(self.labels)[:12]}{' ...' if len(self.labels) > 12 else ''}); "
                "fix the --body list"
            )
        idx = [self.labels.index(lab) for lab in labels]
        return PointSeries(self.t_s, tuple(labels), self.xyz_m[:, idx, :], self.source, self.notes)

    def to_frame(self):
        """Long table ``t_s, point, x_m, y_m, z_m`` (the CSV layout), seen samples only."""
        import pandas as pd

        n, p, _ = self.xyz_m.shape
        ok = np.isfinite(self.xyz_m).all(axis=2)
        ti, pi = np.nonzero(ok)
        return pd.DataFrame(
            {
                "t_s": self.t_s[ti],
                "point": np.asarray(self.labels, dtype=object)[pi],
                "x_m": self.xyz_m[ti, pi, 0],
                "y_m": self.xyz_m[ti, pi, 1],
                "z_m": self.xyz_m[ti, pi, 2],
            }
        )


def read_points(path) -> PointSeries:
    """Read a 3D point export by its suffix: ``.c3d`` with :func:`read_c3d`, anything else as CSV."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{where(path)}not found; give a .c3d file or a CSV with t_s, point, x_m, y_m, z_m")
    if path.suffix.lower() == ".c3d":
        return read_c3d(path)
    return read_points_csv(path)


def _coordinate_columns(columns, path):
    """(names of the x, y, z columns, scale to metres) from ``x_m``/``x_mm``/``x_cm`` headers."""
    for unit, scale in LENGTH_UNITS_M.items():
        names = [f"{a}_{unit}" for a in "xyz"]
        if all(n in columns for n in names):
            return names, scale
    raise InputError(
        f"{where(path)}no coordinate columns (has {list(columns)}); need x_m, y_m, z_m "
        "(or x_mm/x_cm with the unit in the name)"
    )


def read_points_csv(path) -> PointSeries:
    """Read a long-format CSV of 3D points.

    Parameters
    ----------
    path : str or Path
        Columns ``t_s`` (s), ``point`` (a name) and ``x_m, y_m, z_m`` (m; ``_mm`` or
        ``_cm`` suffixes are converted); one row per point per sample; other columns
        are ignored. Empty coordinates mean the point was not seen.

    Returns
    -------
    PointSeries
    """
    import pandas as pd

    path = Path(path)
    try:
        df = pd.read_csv(path, comment="#", skipinitialspace=True)
    except pd.errors.EmptyDataError:
        raise InputError(f"{where(path)}empty file; need columns t_s, point, x_m, y_m, z_m") from None
    except (pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise InputError(
            f"{where(path)}not a CSV table ({str(exc).splitlines()[0]}); export t_s, point, x_m, y_m, z_m"
        ) from None
    df.columns = [str(c).strip() for c in df.columns]
    missing = [c for c in ("t_s", "point") if c not in df.columns]
    if missing:
        raise InputError(
            f"{where(path)}missing column(s) {missing} (has {list(df.columns)}); "
            "need t_s, point, x_m, y_m, z_m (long format, one row per point per sample)"
        )
    cols, scale = _coordinate_columns(df.columns, path)
    if df.empty:
        raise InputError(f"{where(path)}no data rows; need t_s, point, x_m, y_m, z_m rows")
    t = pd.to_numeric(df["t_s"], errors="coerce").to_numpy(float)
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise InputError(
            f"{where(path, int(bad[0]) + 2, 't_s')}not a number ({df['t_s'].iloc[bad[0]]!r}); "
            "every row needs its time in seconds"
        )
    xyz = np.empty((len(df), 3))
    for j, c in enumerate(cols):
        raw = df[c]
        val = pd.to_numeric(raw, errors="coerce").to_numpy(float)
        wrong = np.flatnonzero(np.isnan(val) & raw.notna().to_numpy() & (raw.astype(str).str.strip() != ""))
        if wrong.size:
            raise InputError(
                f"{where(path, int(wrong[0]) + 2, c)}not a number ({raw.iloc[wrong[0]]!r}); "
                "leave the cell empty for a point not seen"
            )
        xyz[:, j] = val * scale
    names = df["point"].astype(str).str.strip().to_numpy()
    labels = tuple(dict.fromkeys(names))
    times, ti = np.unique(t, return_inverse=True)
    if times.size < 2:
        raise InputError(f"{where(path)}only one sample time; need a time series")
    pi = pd.Index(labels).get_indexer(names)
    key = ti * len(labels) + pi
    _, first, counts = np.unique(key, return_index=True, return_counts=True)
    if (counts > 1).any():
        dup = int(np.sort(np.flatnonzero(np.isin(key, key[first[counts > 1]])))[1])
        raise InputError(
            f"{where(path, dup + 2)}point {names[dup]!r} appears twice at t_s={t[dup]:.6g}; each point once per sample"
        )
    out = np.full((times.size, len(labels), 3), np.nan)
    out[ti, pi] = xyz
    notes = () if scale == 1.0 else (f"coordinates converted from {cols[0].split('_')[1]} to m",)
    return PointSeries(times, labels, out, str(path), notes)


def read_c3d(path) -> PointSeries:
    """Read the 3D points of a C3D file (any vendor) with ``ezc3d``.

    Units come from ``POINT:UNITS`` (m, cm or mm; an unknown unit is an error),
    the time base from ``POINT:RATE`` and the header's first frame, and samples
    with a negative residual (the system's "invalid") or exact zeros become NaN.

    Returns
    -------
    PointSeries
    """
    path = Path(path)
    try:
        import ezc3d
    except ImportError:  # pragma: no cover - a declared dependency
        raise InputError("reading .c3d needs the ezc3d package; pip install ezc3d") from None
    try:
        c = ezc3d.c3d(str(path))
    except Exception as exc:  # ezc3d raises plain RuntimeError/IOError on a bad file
        raise InputError(
            f"{where(path)}not a readable C3D file ({str(exc).splitlines()[0] if str(exc) else type(exc).__name__}); "
            "export the 3D points again as C3D, or as CSV t_s, point, x_m, y_m, z_m"
        ) from None
    par = c["parameters"]["POINT"]
    labels = tuple(str(s).strip() for s in par["LABELS"]["value"])
    pts = np.asarray(c["data"]["points"], dtype=float)  # (4, p, n)
    if pts.shape[1] == 0 or pts.shape[2] == 0 or not labels:
        raise InputError(f"{where(path)}no 3D points in the file (only analog data?); export the markers")
    labels = labels[: pts.shape[1]]
    units = [str(u).strip().lower() for u in np.atleast_1d(par.get("UNITS", {}).get("value", ["mm"]))] or ["mm"]
    if len(set(units)) > 1:
        raise InputError(
            f"{where(path, key='POINT:UNITS')}mixed units {sorted(set(units))}; export all points in one unit"
        )
    unit = units[0]
    if unit not in LENGTH_UNITS_M:
        raise InputError(
            f"{where(path, key='POINT:UNITS')}unknown length unit {unit!r}; "
            "need m, cm or mm (re-export, or convert to CSV with x_m, y_m, z_m)"
        )
    rate = float(np.atleast_1d(par["RATE"]["value"])[0])
    if not np.isfinite(rate) or rate <= 0:
        raise InputError(f"{where(path, key='POINT:RATE')}rate {rate!r} is not positive; fix the file's point rate")
    xyz = np.moveaxis(pts[:3], 0, 2).transpose(1, 0, 2) * LENGTH_UNITS_M[unit]  # (n, p, 3)
    xyz = np.ascontiguousarray(xyz)
    resid = np.asarray(c["data"]["meta_points"]["residuals"], dtype=float)[0].T  # (n, p)
    invalid = (resid < 0) | (np.abs(xyz) == 0).all(axis=2)
    n_invalid = int((invalid & np.isfinite(xyz).all(axis=2)).sum())
    xyz[invalid] = np.nan
    first = int(c["header"]["points"]["first_frame"])
    t = (first + np.arange(xyz.shape[0])) / rate
    notes = [f"coordinates converted from {unit} to m"] if unit != "m" else []
    if n_invalid:
        notes.append(f"{n_invalid} sample(s) marked invalid by the system set to NaN")
    return PointSeries(t, labels, xyz, str(path), tuple(notes))


def exact_times(frame):
    """``frame`` with its ``t_s`` column as the shortest text that reads back to the same float.

    Coordinates are written to 9 digits (0.1 um at 100 m), but times may be absolute (epoch
    seconds, ~1.7e9): 9 digits would round them to 10 s and collapse every sample to one time.
    """
    out = frame.copy()
    out["t_s"] = [repr(float(v)) for v in out["t_s"].to_numpy(float)]
    return out


def write_points_csv(series: PointSeries, path, *, side: bool = False) -> Path:
    """Write ``series`` as the long CSV :func:`read_points_csv` reads (atomically; times exact;
    ``side``: a user's file there is kept, see :func:`rocklab._io.atomic_path`)."""
    from ..._io import write_frame_atomic

    return write_frame_atomic(path, exact_times(series.to_frame()), float_format="%.9g", side=side)


def write_c3d(series: PointSeries, path, unit: str = "mm") -> Path:
    """Write ``series`` as a C3D file with ``ezc3d`` (unit ``m``/``cm``/``mm``; NaN -> invalid).

    The time base must be uniform (C3D has one rate); the first frame is ``round(t0 * rate)``.
    """
    import ezc3d

    from ..._io import atomic_path

    dt = np.diff(series.t_s)
    rate = 1.0 / float(np.median(dt))
    if np.abs(dt * rate - 1.0).max() > 1e-3:
        raise InputError(
            f"{where(path)}C3D needs a uniform time base (steps vary by more than 0.1 %); write a CSV instead"
        )
    c = ezc3d.c3d()
    c["parameters"]["POINT"]["RATE"]["value"] = [rate]
    c["parameters"]["POINT"]["LABELS"]["value"] = list(series.labels)
    c["parameters"]["POINT"]["UNITS"]["value"] = [unit]
    xyz = series.xyz_m / LENGTH_UNITS_M[unit]
    n, p, _ = xyz.shape
    pts = np.ones((4, p, n))
    pts[:3] = np.transpose(xyz, (2, 1, 0))
    seen = np.isfinite(xyz).all(axis=2).T  # (p, n)
    pts[:3, ~seen] = 0.0
    c["data"]["points"] = pts
    c["data"]["meta_points"] = {
        "residuals": np.where(seen, 0.0, -1.0)[None].astype(float),
        "camera_masks": np.zeros((7, p, n), dtype=bool),
    }
    c["header"]["points"]["first_frame"] = int(round(series.t_s[0] * rate))
    path = Path(path)
    with atomic_path(path) as tmp:
        c.write(str(tmp))
    return path
