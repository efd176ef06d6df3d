"""Kinovea exports of trajectories: the spreadsheet (``.xml``) and the Gnuplot text (``.txt``).

- *Export to spreadsheet, Microsoft Excel (.xml)* (SpreadsheetML): one ``Track`` block per
  trajectory, ``Label :`` its name, ``Coords (x,y:UNIT; t:time)`` the calibration's unit, then
  rows ``x, y, t`` with ``t`` a time code ``h:mm:ss:cc`` (hundredths of a second);
- *Gnuplot (.txt)*: ``#Kinovea Trajectory data export``, ``#T X Y``, then per trajectory a
  ``# name`` line and rows ``t x y`` (``t`` in s; ``x, y`` in the calibration's unit, which the
  file does not name, with the decimal separator of the PC's locale).

Both hold calibrated coordinates (y up), never pixels, so :class:`PlanePoints` carries ``xy_m``
only. Times are those of the export (0.01 s or 1 ms resolution); ``fps`` snaps them to frames
(each within the export's resolution of a frame, and two times never on one frame, else an error). A trajectory with two rows at one time keeps neither
(``lost`` there, warning ``W-IMPORT-TIME``): which one is the film's is not in the file.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..._errors import InputError, where
from ._plane_points import PlanePoints

__all__ = ["read_kinovea", "KINOVEA_UNITS_M"]

#: Calibration units of Kinovea's exports, in metres.
KINOVEA_UNITS_M = {"m": 1.0, "cm": 0.01, "mm": 0.001}
_SS = "{urn:schemas-microsoft-com:office:spreadsheet}"
_TIMECODE = re.compile(r"^(\d+):(\d\d):(\d\d):(\d\d)$")
_COORDS = re.compile(r"^Coords \(x,y:\s*([^;]+);\s*t:\s*([^)]+)\)$")


def _sheet_rows(path: Path) -> list:
    import xml.etree.ElementTree as ET

    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        line = exc.position[0] if exc.position else None
        raise InputError(f"{where(path, line)}not valid XML ({exc.msg}); export the spreadsheet again") from None
    rows = []
    for row in root.iter(f"{_SS}Row"):
        cells = []
        for cell in row.findall(f"{_SS}Cell"):
            data = cell.find(f"{_SS}Data")
            cells.append((data.text or "").strip() if data is not None and data.text else "")
        rows.append(cells)
    return rows


def _timecode(text: str, path: Path, label: str) -> float:
    m = _TIMECODE.match(text)
    if m is None:
        raise InputError(
            f"{where(path, key=label)}time {text!r} is not Kinovea's h:mm:ss:cc time code; set Kinovea's "
            "time format to the classic time code and export again"
        )
    h, mi, s, cc = (int(g) for g in m.groups())
    return h * 3600.0 + mi * 60.0 + s + cc / 100.0


def _read_sheet(path: Path) -> tuple[dict, str]:
    """``{label: (t_s, xy)}`` and the unit from a SpreadsheetML export."""
    rows = _sheet_rows(path)
    tracks: dict = {}
    units = set()
    i = 0
    while i < len(rows):
        r = rows[i]
        if r[:1] == ["Label :"] and i + 2 < len(rows) and rows[i + 1] and _COORDS.match(rows[i + 1][0]):
            label = r[1] if len(r) > 1 else f"track {len(tracks) + 1}"
            units.add(_COORDS.match(rows[i + 1][0]).group(1).strip())
            i += 3  # the x, y, t header
            t, xy = [], []
            while i < len(rows) and len(rows[i]) >= 3 and rows[i][2]:
                try:
                    xy.append((float(rows[i][0]), float(rows[i][1])))
                except ValueError:
                    raise InputError(
                        f"{where(path, key=label)}row {len(t) + 1}: x, y {rows[i][:2]} are not numbers; "
                        "export the spreadsheet again"
                    ) from None
                t.append(_timecode(rows[i][2], path, label))
                i += 1
            if label in tracks:
                raise InputError(f"{where(path, key=label)}two trajectories named {label!r}; rename one in Kinovea")
            tracks[label] = (np.array(t), np.array(xy, dtype=float).reshape(-1, 2))
            continue
        i += 1
    if not tracks:
        raise InputError(f"{where(path)}no trajectory (Track with Label and Coords) in this Kinovea spreadsheet")
    if len(units) != 1:
        raise InputError(f"{where(path)}trajectories in several units {sorted(units)}; export them in one unit")
    return tracks, units.pop()


def _read_gnuplot(path: Path) -> dict:
    """``{label: (t_s, xy)}`` from a Gnuplot trajectory export."""
    tracks: dict = {}
    label = None
    with open(path, encoding="utf-8", errors="replace") as fh:
        for n, line in enumerate(fh, start=1):
            s = line.strip()
            if not s or s.startswith("#Kinovea") or s.replace(" ", "") == "#TXY":
                continue
            if s.startswith("#"):
                label = s[1:].strip()
                if label in tracks:
                    raise InputError(f"{where(path, n)}two trajectories named {label!r}; rename one in Kinovea")
                tracks[label] = ([], [])
                continue
            parts = s.replace(",", ".").split()
            if label is None or len(parts) != 3:
                raise InputError(f"{where(path, n)}expected '# name' then rows 't x y'; got {s[:40]!r}")
            try:
                t, x, y = (float(p) for p in parts)
            except ValueError:
                raise InputError(f"{where(path, n)}not numbers ({s[:40]!r}); export the trajectory again") from None
            tracks[label][0].append(t)
            tracks[label][1].append((x, y))
    if not tracks:
        raise InputError(f"{where(path)}no trajectory in this Kinovea text export")
    return {k: (np.array(t), np.array(xy, dtype=float).reshape(-1, 2)) for k, (t, xy) in tracks.items()}


def _frames(t: np.ndarray, fps: float | None, path: Path, resolution_s: float) -> np.ndarray:
    """Integer keys of the sample times: frames with ``fps``, else the times on the export's grid."""
    if fps is None:
        return np.round(t / resolution_s).astype(np.int64)
    k = np.round(t * fps).astype(np.int64)
    off = np.abs(t - k / fps)
    # the export rounds (or cuts) times to its resolution: a true frame rate puts every time
    # within that of a frame, and never two different times on one frame
    if np.unique(k).size < np.unique(t).size:
        raise InputError(
            f"{where(path)}two different times fall on one frame at --fps {fps:g}; give the film's frame rate"
        )
    if off.max() > resolution_s + 1e-9:
        bad = int(np.argmax(off))
        raise InputError(
            f"{where(path)}time {t[bad]:.6g} s is {off[bad] * 1e3:.3g} ms from any frame at --fps {fps:g}; "
            "give the film's frame rate"
        )
    return k


def read_kinovea(path, units: str | None = None, fps: float | None = None) -> PlanePoints:
    """Read a Kinovea trajectory export (spreadsheet ``.xml`` or Gnuplot ``.txt``).

    Parameters
    ----------
    path : str or Path
    units : {"m", "cm", "mm"}, optional
        The calibration's unit: required for the text export (it names none); for the
        spreadsheet, which names it, only a matching value is accepted.
    fps : float, optional
        The film's frame rate: times snap to frames (``frame = round(t fps)``, ``t_s = frame /
        fps``); each time must lie within the export's resolution of its frame. Without it the export's times are kept (rounded to 0.01 s in the spreadsheet).

    Returns
    -------
    PlanePoints
        ``xy_m`` in m (y up as Kinovea's calibration has it), ``xy_px`` None.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{where(path)}not found; give Kinovea's trajectory export (.xml or .txt)")
    if fps is not None and not (np.isfinite(fps) and fps > 0):
        raise InputError(f"--fps {fps!r}: give the film's frame rate in Hz")
    with open(path, "rb") as fh:
        head = fh.read(512).decode("utf-8", "replace")
    if "<?xml" in head:
        tracks, named = _read_sheet(path)
        resolution = 0.01
    elif head.startswith("#Kinovea"):
        tracks, named, resolution = _read_gnuplot(path), None, 0.001
    else:
        raise InputError(f"{where(path)}not a Kinovea trajectory export (spreadsheet .xml or Gnuplot .txt)")
    unit = _unit(named, units, path)
    return _assemble(tracks, KINOVEA_UNITS_M[unit], unit, fps, path, resolution)


def _unit(named, units, path) -> str:
    if named is not None and named not in KINOVEA_UNITS_M:
        raise InputError(
            f"{where(path, key='Coords')}coordinates in {named!r}, not a length; calibrate in Kinovea "
            f"(a line of known length) and export again in one of {sorted(KINOVEA_UNITS_M)}"
        )
    if named is not None and units is not None and units != named:
        raise InputError(f"{where(path, key='Coords')}the file says {named!r}, --units says {units!r}; drop --units")
    unit = named or units
    if unit not in KINOVEA_UNITS_M:
        raise InputError(
            f"{where(path)}the text export names no unit; give --units m, cm or mm (Kinovea's calibration unit)"
        )
    return unit


def _assemble(tracks, scale, unit, fps, path, resolution) -> PlanePoints:
    from ..._diagnostics import warn

    keys = {lab: _frames(t, fps, path, resolution) for lab, (t, _) in tracks.items()}
    grid = np.unique(np.concatenate(list(keys.values())))
    labels = tuple(tracks)
    xy = np.full((grid.size, len(labels), 2), np.nan)
    dropped = {}
    for j, lab in enumerate(labels):
        k = keys[lab]
        uniq, counts = np.unique(k, return_counts=True)
        once = np.isin(k, uniq[counts == 1])
        xy[np.searchsorted(grid, k[once]), j] = tracks[lab][1][once] * scale
        if (~once).any():
            dropped[lab] = int((counts > 1).sum())
    if dropped:
        warn(
            "W-IMPORT-TIME",
            f"{path}: trajectories with two rows at one time {dropped}: that time is left out (lost) for "
            "them; the file does not say which row is the film's",
        )
    t_s = grid / fps if fps is not None else grid * resolution
    notes = [f"coordinates converted from {unit} to m"] if scale != 1.0 else []
    notes.append(
        f"times snapped to frames at {fps:g} fps"
        if fps
        else f"times as exported ({resolution:g} s steps); frame is the sample's index (--fps gives the film's)"
    )
    frame = grid if fps is not None else np.arange(grid.size)
    return PlanePoints(t_s, frame, labels, None, xy, str(path), tuple(notes))
