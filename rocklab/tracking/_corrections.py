"""Manual corrections of a track: a file that drops frames of an object or sets its x, y or θ there.

A tracker can lock onto the wrong thing for a few frames (a hand over the block, a reflection);
Tracker, Kinovea and DLTdv users fix those frames by hand. rocklab reads the fixes from a file
(``--corrections FILE``, ``[video] corrections`` in ``track.toml`` or ``[sources.video] corrections``
in ``experiment.toml``) and applies them after tracking, marking every frame it changed (status
``corrected`` or ``dropped``) and listing each correction in the result, so no hand-made number
passes for a measured one.

The file is CSV (one correction per row) or TOML (one ``[[corrections]]`` table each), with these
columns / keys:

- ``object``: the object's id (required);
- where: ``frame`` (and optionally ``to_frame``, inclusive) or ``t_s`` (and optionally ``to_t_s``,
  inclusive; a single time is the frame nearest to it, within half a frame);
- ``action``: ``drop`` (the frames' values become NaN) or ``set`` (default when a value is given);
- values for ``set``: any of ``x_m``, ``y_m``, ``theta_rad`` or ``theta_deg`` (units in the
  name: a bare ``x``, ``y`` or ``theta`` is an error). Values not given keep what was measured
  there (NaN where nothing was).

A hand-set angle has no measured uncertainty: ``sigma_theta_rad`` and ``quality`` are NaN on
corrected frames.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .._errors import InputError
from ..series import CORRECTION_STATUSES

__all__ = ["Correction", "load_corrections", "apply_corrections", "CORRECTION_STATUSES"]

_WHERE = ("frame", "to_frame", "t_s", "to_t_s")
_VALUES = ("x_m", "y_m", "theta_rad", "theta_deg")
_KEYS = ("object", "action", *_WHERE, *_VALUES)
_UNITLESS = {"x": "x_m", "y": "y_m", "theta": "theta_rad or theta_deg", "angle": "theta_rad or theta_deg"}


@dataclass(frozen=True)
class Correction:
    """One correction: an object, a frame or time range, and what to do there.

    Attributes
    ----------
    object : str
    frames : (int, int) or None
        First and last frame (inclusive), or None when given by time.
    times_s : (float, float) or None
        First and last time (inclusive), s, or None when given by frame.
    action : {"drop", "set"}
    x_m, y_m, theta_rad : float or None
        Values set (None: keep the measured one).
    where : str
        File and line (or table) it came from, for messages.
    """

    object: str
    frames: tuple | None
    times_s: tuple | None
    action: str
    x_m: float | None
    y_m: float | None
    theta_rad: float | None
    where: str

    def to_dict(self) -> dict:
        """JSON-ready summary (units in the keys)."""
        d = {"object": self.object, "action": self.action, "where": self.where}
        if self.frames is not None:
            d["frames"] = list(self.frames)
        if self.times_s is not None:
            d["t_s"] = list(self.times_s)
        d.update({k: getattr(self, k) for k in ("x_m", "y_m", "theta_rad") if getattr(self, k) is not None})
        return d


def _num(v, where: str, key: str, integer: bool = False):
    if v is None or (isinstance(v, float) and math.isnan(v)) or (isinstance(v, str) and not v.strip()):
        return None
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise InputError(f"{where}: {key} = {v!r} is not a number; give {key} as a number") from None
    if not math.isfinite(x) or (integer and x != int(x)):
        raise InputError(f"{where}: {key} = {v!r} must be a finite {'whole ' if integer else ''}number")
    return int(x) if integer else x


def _one(row: dict, where: str) -> Correction:
    for k in row:
        if k in _UNITLESS:
            raise InputError(f"{where}: {k!r} has no unit; name it {_UNITLESS[k]}")
        if k not in _KEYS:
            raise InputError(f"{where}: unknown column {k!r}; use {', '.join(_KEYS)}")
    obj = str(row.get("object") or "").strip()
    if not obj:
        raise InputError(f"{where}: no object; give the object's id (as in track.toml)")
    f0, f1 = _num(row.get("frame"), where, "frame", True), _num(row.get("to_frame"), where, "to_frame", True)
    t0, t1 = _num(row.get("t_s"), where, "t_s"), _num(row.get("to_t_s"), where, "to_t_s")
    if (f0 is None) == (t0 is None) or (f1 is not None and f0 is None) or (t1 is not None and t0 is None):
        raise InputError(f"{where}: give either frame (and to_frame) or t_s (and to_t_s), not both or neither")
    frames = None if f0 is None else (f0, f0 if f1 is None else f1)
    times = None if t0 is None else (t0, t0 if t1 is None else t1)
    if (frames and frames[1] < frames[0]) or (times and times[1] < times[0]):
        raise InputError(f"{where}: the range ends before it starts; give to_frame/to_t_s after frame/t_s")
    vals = {k: _num(row.get(k), where, k) for k in _VALUES}
    if vals["theta_rad"] is not None and vals["theta_deg"] is not None:
        raise InputError(f"{where}: theta_rad and theta_deg both given; give one")
    th = vals["theta_rad"] if vals["theta_deg"] is None else math.radians(vals["theta_deg"])
    given = any(v is not None for v in vals.values())
    action = str(row.get("action") or ("set" if given else "")).strip().lower()
    if action not in ("drop", "set"):
        raise InputError(f"{where}: action {action!r}; use drop, or set with x_m, y_m, theta_rad or theta_deg")
    if action == "set" and not given:
        raise InputError(f"{where}: action set without a value; give x_m, y_m, theta_rad or theta_deg")
    if action == "drop" and given:
        raise InputError(f"{where}: action drop with values; drop the values or use action set")
    return Correction(obj, frames, times, action, vals["x_m"], vals["y_m"], th, where)


def load_corrections(path, objects=None) -> tuple[Correction, ...]:
    """Read a corrections file (CSV or TOML, see the module's doc).

    ``objects`` (ids), when given, are the objects there are: a correction naming another is an
    error before any tracking.

    Raises
    ------
    InputError
        Missing or unreadable file, an unknown column, a value without units, an action without
        values, a range that ends before it starts.
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: corrections file not found; check the path")
    if p.suffix.lower() == ".toml":
        from ..config import TomlDoc

        doc = TomlDoc.read(p, "corrections file")
        d = doc.data
        rows = d.get("corrections")
        extra = sorted(set(d) - {"corrections"})
        if not isinstance(rows, list) or extra:
            raise InputError(f"{p}: give each correction as a [[corrections]] table (found {extra or 'none'})")
        out = tuple(
            _one(r, f"{p}, line {doc.line_of(('corrections', k - 1))}, correction {k}")
            for k, r in enumerate(rows, start=1)
        )
    else:
        out = _read_csv(p)
    for c in out:
        if objects is not None and c.object not in objects:
            raise InputError(
                f"{c.where}: object {c.object!r} is not tracked (objects: {', '.join(objects)}); fix the name"
            )
    return out


def _read_csv(p: Path) -> tuple[Correction, ...]:
    import csv

    try:
        lines = p.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(f"{p}: cannot read the corrections ({type(e).__name__}); give a CSV text file") from None
    rows = [(k, ln) for k, ln in enumerate(lines, start=1) if ln.strip() and not ln.lstrip().startswith("#")]
    if not rows:
        raise InputError(f"{p}: no header; the first line names the columns (object, frame or t_s, action, ...)")
    parsed = list(csv.reader([ln for _, ln in rows], skipinitialspace=True))
    head = [h.strip() for h in parsed[0]]
    out = []
    for (k, _), vals in zip(rows[1:], parsed[1:]):
        if len(vals) > len(head):
            raise InputError(f"{p}, line {k}: {len(vals)} values for {len(head)} columns; fix the row")
        out.append(_one({h: v.strip() for h, v in zip(head, vals)}, f"{p}, line {k}"))
    return tuple(out)


def _rows(c: Correction, frame: np.ndarray, t_s: np.ndarray, partial: bool = False) -> np.ndarray:
    """Indices of the track's samples the correction covers (an error when it reaches outside them,
    unless ``partial``: then the samples it covers, maybe none)."""
    if partial:
        if c.frames is not None:
            return np.flatnonzero((frame >= c.frames[0]) & (frame <= c.frames[1]))
        step = float(np.median(np.diff(t_s))) if len(t_s) > 1 else 0.0
        a, b = c.times_s
        return np.flatnonzero((t_s >= a - 0.5 * step) & (t_s <= b + 0.5 * step))
    if c.frames is not None:
        a, b = c.frames
        if a < frame.min() or b > frame.max():
            raise InputError(
                f"{c.where}: frames {a}..{b} are outside the film (frames {frame.min()}..{frame.max()} tracked); "
                "fix the frame numbers"
            )
        return np.flatnonzero((frame >= a) & (frame <= b))
    a, b = c.times_s
    step = float(np.median(np.diff(t_s))) if len(t_s) > 1 else 0.0
    if a == b:
        k = int(np.argmin(np.abs(t_s - a)))
        if abs(t_s[k] - a) > 0.5 * step + 1e-9:
            raise InputError(
                f"{c.where}: t_s = {a:g} s is outside the film ({t_s[0]:g}..{t_s[-1]:g} s tracked); fix the time"
            )
        return np.array([k])
    hit = np.flatnonzero((t_s >= a - 1e-9) & (t_s <= b + 1e-9))
    if not hit.size or a < t_s[0] - 0.5 * step or b > t_s[-1] + 0.5 * step:
        raise InputError(
            f"{c.where}: t_s {a:g}..{b:g} s is outside the film ({t_s[0]:g}..{t_s[-1]:g} s tracked); fix the times"
        )
    return hit


def apply_corrections(res, corrections, partial: bool = False):
    """The tracking result with ``corrections`` applied (a new result; ``res`` is not changed).

    Parameters
    ----------
    res : rocklab.tracking.TrackResult
    corrections : path-like or sequence of Correction
        A corrections file, or corrections already read.
    partial : bool
        ``res`` tracks part of the film (a preview): corrections outside it are left out instead
        of being an error.

    Returns
    -------
    TrackResult
        Its ``corrections`` lists each one applied (``to_dict()``, with ``n_frames``); the frames
        changed have status ``corrected`` or ``dropped``.

    Raises
    ------
    InputError
        A correction naming an object that is not tracked, or frames / times outside the film.
    """
    if isinstance(corrections, (str, Path)):
        corrections = load_corrections(corrections)
    tracks = {t.object: t for t in res.tracks}
    arrays = {}
    done = []
    for c in corrections:
        if c.object not in tracks:
            raise InputError(
                f"{c.where}: object {c.object!r} is not tracked (objects: {', '.join(tracks)}); fix the name"
            )
        t = tracks[c.object]
        a = arrays.setdefault(
            c.object,
            {
                k: np.array(getattr(t, k), dtype=object if k == "status" else float)
                for k in ("x_m", "y_m", "theta_rad", "sigma_theta_rad", "quality", "status", "x_px", "y_px")
                if getattr(t, k) is not None
            },
        )
        i = _rows(c, np.asarray(t.frame), np.asarray(t.t_s, float), partial)
        if not i.size:
            continue
        if c.action == "drop":
            for k in a:
                if k != "status":
                    a[k][i] = np.nan
            a["status"][i] = "dropped"
        else:
            for k in ("x_m", "y_m", "theta_rad"):
                v = getattr(c, k)
                if v is not None:
                    a[k][i] = v
            if c.x_m is not None or c.y_m is not None:
                for k in ("x_px", "y_px"):  # the image point no longer matches the position set
                    if k in a:
                        a[k][i] = np.nan
            if c.theta_rad is not None:
                a["sigma_theta_rad"][i] = np.nan
            a["quality"][i] = np.nan
            a["status"][i] = "corrected"
        done.append({**c.to_dict(), "n_frames": int(i.size)})
    new = tuple(
        replace(t, **{k: (v.astype(str) if k == "status" else v) for k, v in arrays[t.object].items()})
        if t.object in arrays
        else t
        for t in res.tracks
    )
    return replace(res, tracks=new, corrections=tuple(res.corrections) + tuple(done))
