"""Tracker's exported data tables (*File → Export → Data*): delimited text.

The layout is Tracker's ``ExportDataDialog``: a ``#multi:`` line when several tracks are
exported; a row of track names, each over its first column (``<d>mass A<d><d>mass B<d><d>``);
a header row, the time column (``t``, s) then each track's columns (``x``, ``y``...); then one row
per frame, a cell empty where the track has no data. The delimiter is a tab, comma, semicolon or
space, and numbers use the PC's decimal separator (a comma when the delimiter is not one).
Positions are in the project's world (calibrated, y up) in a unit the table does not name: the
unit is required. Only each track's ``x`` and ``y`` are read.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..._errors import InputError, where
from ._plane_points import PlanePoints
from ._tracker_trk import TRACKER_LENGTH_UNITS_M

__all__ = ["read_tracker_table", "looks_like_tracker_table"]

_DELIMS = ("\t", ";", ",", " ")
_HEADER = re.compile(r"^(t|frame|step)([\t;, ])x\2y(\2|$)")


def _lines(path: Path) -> list:
    with open(path, encoding="utf-8", errors="replace") as fh:
        return [ln.rstrip("\r\n") for ln in fh]


def looks_like_tracker_table(head: str) -> bool:
    """Whether text starts like a Tracker data export (``#multi:``, a names row, a ``t x y`` header)."""
    lines = [ln for ln in head.splitlines() if ln.strip()][:3]
    if lines and lines[0].startswith("#multi:"):
        lines = lines[1:]
    return len(lines) >= 2 and lines[0][:1] in _DELIMS and bool(_HEADER.match(lines[1]))


def _number(cell: str, delim: str) -> float:
    cell = cell.strip()
    if not cell:
        return np.nan
    if delim != ",":
        cell = cell.replace(",", ".")
    return float(cell)


def read_tracker_table(path, units: str | None = None) -> PlanePoints:
    """Read a Tracker data export (one or several tracks' ``t, x, y``).

    Parameters
    ----------
    path : str or Path
    units : str
        The project's length unit (``m``, ``cm``, ``mm``, ``in``, ``ft``): the table names none.

    Returns
    -------
    PlanePoints
        ``xy_m`` in m (Tracker's world, y up), ``xy_px`` None, ``frame`` the row number.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{where(path)}not found; give Tracker's exported data (.txt or .csv)")
    if units not in TRACKER_LENGTH_UNITS_M:
        raise InputError(
            f"{where(path)}Tracker's data export names no length unit; give --units "
            f"({', '.join(sorted(TRACKER_LENGTH_UNITS_M))}: the project's length unit)"
        )
    lines = _lines(path)
    first = 1 if lines and lines[0].startswith("#multi:") else 0
    if len(lines) < first + 3 or not _HEADER.match(lines[first + 1]):
        raise InputError(
            f"{where(path, first + 2)}not Tracker's data export (a track-name row, then 't<delimiter>x<delimiter>y'); "
            "export the point masses' t, x, y from Tracker (File > Export > Data)"
        )
    delim = _HEADER.match(lines[first + 1]).group(2)
    names = lines[first].split(delim)
    header = lines[first + 1].split(delim)
    columns = {}  # track -> (x column, y column)
    track = None
    for j in range(1, len(header)):
        if j < len(names) and names[j].strip():
            track = names[j].strip()
        if track is not None and header[j].strip() in ("x", "y"):
            columns.setdefault(track, {})[header[j].strip()] = j
    tracks = {k: (v["x"], v["y"]) for k, v in columns.items() if set(v) == {"x", "y"}}
    if not tracks:
        raise InputError(f"{where(path, first + 2)}no track with both x and y columns; export x and y")
    rows = [(n, ln.split(delim)) for n, ln in enumerate(lines[first + 2 :], start=first + 3) if ln.strip()]
    t = np.empty(len(rows))
    xy = np.full((len(rows), len(tracks), 2), np.nan)
    for i, (n, cells) in enumerate(rows):
        try:
            t[i] = _number(cells[0], delim)
            for k, (cx, cy) in enumerate(tracks.values()):
                xy[i, k] = (
                    _number(cells[cx], delim) if cx < len(cells) else np.nan,
                    _number(cells[cy], delim) if cy < len(cells) else np.nan,
                )
        except ValueError:
            raise InputError(f"{where(path, n)}a cell is not a number ({delim.join(cells)[:60]!r})") from None
    if not np.isfinite(t).all() or (np.diff(t) <= 0).any():
        bad = int(np.flatnonzero(~np.isfinite(t) | np.r_[False, np.diff(t) <= 0])[0])
        raise InputError(f"{where(path, rows[bad][0], header[0])}times must increase; export the time column t")
    scale = TRACKER_LENGTH_UNITS_M[units]
    notes = [f"world coordinates converted from {units} to m"] if scale != 1.0 else []
    return PlanePoints(t, np.arange(t.size), tuple(tracks), None, xy * scale, str(path), tuple(notes))
