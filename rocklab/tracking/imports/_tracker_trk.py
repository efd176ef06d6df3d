"""Tracker (Open Source Physics) project files: ``.trk`` (XML) and ``.trz`` (a zip holding them).

A ``.trk`` keeps every point-mass track as image positions per frame (px, y down), the
coordinate system that maps them to the world (per key frame: origin px, angle deg, scale px per
unit; Tracker's ``ImageCoordSystem``: ``x_img = sx cos a x - sx sin a y + x0``,
``y_img = -sy sin a x - sy cos a y + y0``), the length unit and the clip's time base (Tracker's
``VideoPlayer.getFrameTime``: start time + (frame - start frame) x frame duration, in ms). The reader converts at this boundary: times to s, world
positions to m (y up). Model tracks (``DynamicParticle``...) are simulations, not measurements,
and are not read.
"""

from __future__ import annotations

import re
import zipfile
from pathlib import Path

import numpy as np

from ..._errors import InputError, where
from ._plane_points import PlanePoints

__all__ = ["read_trk", "TRACKER_LENGTH_UNITS_M"]

#: Tracker's length units, in metres.
TRACKER_LENGTH_UNITS_M = {"m": 1.0, "cm": 0.01, "mm": 0.001, "km": 1000.0, "in": 0.0254, "ft": 0.3048}
_POINT_MASS = "org.opensourcephysics.cabrillo.tracker.PointMass"


def _props(obj) -> dict:
    return {p.get("name"): p for p in obj.findall("property")}


def _value(prop):
    kind, text = prop.get("type"), prop.text
    if kind == "double":
        return float(text)
    if kind == "int":
        return int(text)
    if kind == "boolean":
        return text == "true"
    if kind == "object":
        return prop.find("object")
    return text


def _scalars(obj) -> dict:
    return {k: _value(v) for k, v in _props(obj).items() if v.get("type") in ("double", "int", "boolean", "string")}


def _indexed(array_prop) -> dict:
    """``{index: <object>}`` of an OSP array property (``[0]``, ``[5]``...: key frames)."""
    out = {}
    for item in array_prop.findall("property"):
        obj = item.find("object")
        if obj is not None:
            out[int(item.get("name").strip("[]"))] = obj
    return out


def _xml_text(path: Path, member: str | None) -> tuple[bytes, str]:
    if path.suffix.lower() != ".trz":
        return path.read_bytes(), str(path)
    try:
        z = zipfile.ZipFile(path)
    except zipfile.BadZipFile:
        raise InputError(f"{where(path)}not a zip file; a .trz is Tracker's zipped project (re-save it)") from None
    with z:
        names = [n for n in z.namelist() if n.lower().endswith(".trk")]
        if member is not None:
            hits = [n for n in names if n == member or Path(n).name == member]
            if not hits:
                raise InputError(f"{where(path)}no {member!r} inside (it holds {names}); fix --trk")
            names = hits[:1]
        if len(names) != 1:
            raise InputError(
                f"{where(path)}{len(names)} .trk files inside {names}; choose one with --trk NAME"
                if names
                else f"{where(path)}no .trk inside; not a Tracker project"
            )
        return z.read(names[0]), f"{path}:{names[0]}"


_DECLARATION = re.compile(r"^\s*<\?xml[^>]*\?>")
_DECLARED = re.compile(rb"""^\s*<\?xml[^>]*?encoding\s*=\s*["']([A-Za-z0-9._-]+)["']""")


def _encoding(raw: bytes, source: str) -> tuple[str, str | None]:
    """(the encoding to parse ``raw`` with, a note when it is not the one the file declares).

    The XML declaration's encoding (UTF-8 when it names none) is used when the bytes are valid in
    it. Tracker writes the declaration ``encoding="UTF-8"`` but, on some systems, the text in the
    platform's 8-bit encoding (an author ``Jal\xf3n`` as one Latin-1 byte): such a file is read as
    Windows-1252 (Java's default on Windows; ISO-8859-1 where Windows-1252 leaves a byte undefined),
    and the note says so. Only text (names, author, notes) depends on it, never a number.
    """
    import codecs

    if raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        return "utf-16", None
    m = _DECLARED.match(raw[:400])
    declared = m.group(1).decode("ascii") if m else "utf-8"
    try:
        codecs.lookup(declared)
    except LookupError:
        raise InputError(
            f"{where(source)}the XML declaration names the encoding {declared!r}, which Python does not know; "
            "save the project again in Tracker"
        ) from None
    try:
        raw.decode(declared)
        return declared, None
    except UnicodeDecodeError as exc:
        bad, line = raw[exc.start], raw.count(b"\n", 0, exc.start) + 1
    for fallback in ("cp1252", "latin-1"):
        try:
            raw.decode(fallback)
            break
        except UnicodeDecodeError:
            continue
    note = (
        f"the project declares {declared} but byte 0x{bad:02x} at line {line} is not {declared}: its text read "
        f"as {'Windows-1252' if fallback == 'cp1252' else 'ISO-8859-1'} (Tracker saved it in the platform's "
        "encoding); names and notes with accented letters depend on this, positions and times do not"
    )
    return fallback, note


def _parse(raw: bytes, source: str):
    """The root element of a Tracker project and the encoding note of :func:`_encoding` (or None)."""
    import xml.etree.ElementTree as ET

    encoding, note = _encoding(raw, source)
    try:
        # decoded here (the declaration, which would override the encoding, dropped) only when the
        # bytes are not in the declared encoding: expat reads every other file as it always did
        root = ET.fromstring(_DECLARATION.sub("", raw.decode(encoding), count=1) if note else raw)
    except ET.ParseError as exc:
        line = exc.position[0] if exc.position else None
        raise InputError(f"{where(source, line)}not valid XML ({exc.msg}); save the project again in Tracker") from None
    if root.tag != "object" or not str(root.get("class", "")).endswith("TrackerPanel"):
        raise InputError(f"{where(source)}not a Tracker project (root {root.get('class')!r}); give a .trk or .trz")
    return root, note


def _time_base(panel: dict, source: str) -> tuple[float, float, int]:
    """(start time ms, frame duration ms, start frame) of the clip."""
    clip = _scalars(_value(panel["videoclip"])) if "videoclip" in panel else {}
    dt = None
    if "clipcontrol" in panel:
        dt = _scalars(_value(panel["clipcontrol"])).get("delta_t")
    if dt is None and "videoclip" in panel:
        video = _props(_value(panel["videoclip"])).get("video")
        if video is not None and _value(video) is not None:
            dt = _scalars(_value(video)).get("delta_t")
    if dt is None or not np.isfinite(dt) or dt <= 0:
        raise InputError(
            f"{where(source, key='delta_t')}no frame duration in the project ({dt!r}); set the clip's "
            "frame rate in Tracker (Clip Settings) and save again"
        )
    return float(clip.get("starttime", 0.0)), float(dt), int(clip.get("startframe", 0))


def _coords(panel: dict, source: str):
    """Per key frame ``{frame: (x0, y0, angle rad, sx, sy)}`` of the image coordinate system."""
    if "coords" not in panel:
        return {0: (0.0, 0.0, 0.0, 1.0, 1.0)}
    fd = _props(_value(panel["coords"])).get("framedata")
    keys = {}
    for n, obj in (_indexed(fd) if fd is not None else {}).items():
        s = _scalars(obj)
        try:
            keys[n] = (s["xorigin"], s["yorigin"], np.radians(s["angle"]), s["xscale"], s["yscale"])
        except KeyError as exc:
            raise InputError(f"{where(source, key='coords')}frame {n} lacks {exc.args[0]}; save again") from None
        if not (s["xscale"] > 0 and s["yscale"] > 0):
            raise InputError(f"{where(source, key='coords')}frame {n}: scale not positive; recalibrate in Tracker")
    return keys or {0: (0.0, 0.0, 0.0, 1.0, 1.0)}


def _to_world(xy_px, frames, keys):
    """World coordinates (the tool's units, y up) of image points at ``frames``, shape (n, p, 2)."""
    kf = np.array(sorted(keys))
    out = np.empty_like(xy_px)
    which = np.clip(np.searchsorted(kf, frames, side="right") - 1, 0, None)
    for j in np.unique(which):
        x0, y0, a, sx, sy = keys[int(kf[j])]
        ca, sa = np.cos(a), np.sin(a)
        to_image = np.array([[sx * ca, -sx * sa], [-sy * sa, -sy * ca]])
        rows = which == j
        out[rows] = (xy_px[rows] - [x0, y0]) @ np.linalg.inv(to_image).T
    return out


def _point_masses(panel: dict, source: str) -> dict:
    """``{name: {frame: (x_px, y_px)}}`` of every point-mass track."""
    out: dict = {}
    others: list = []
    tracks = panel.get("tracks")
    for item in tracks.findall("property") if tracks is not None else ():
        obj = item.find("object")
        if obj is None or obj.get("class") != _POINT_MASS:
            if obj is not None:
                others.append(str(obj.get("class", "")).rsplit(".", 1)[-1])
            continue
        p = _props(obj)
        name = str(_value(p["name"])) if "name" in p else f"track {len(out) + 1}"
        marks = {}
        for n, fobj in (_indexed(p["framedata"]) if "framedata" in p else {}).items():
            s = _scalars(fobj)
            if "x" in s and "y" in s:
                marks[n] = (s["x"], s["y"])
        if name in out:
            raise InputError(f"{where(source)}two point masses named {name!r}; rename one in Tracker")
        if marks:
            out[name] = marks
    if not out:
        held = f" (its tracks: {', '.join(others)}; a model track is Tracker's simulation, not marks)" if others else ""
        raise InputError(f"{where(source)}no point-mass track with marked frames{held}; mark the points in Tracker")
    return out


def read_trk(path, member: str | None = None, units: str | None = None) -> PlanePoints:
    """Read the point-mass tracks of a Tracker project.

    Parameters
    ----------
    path : str or Path
        A ``.trk`` file or a ``.trz`` (zip) holding one (``member`` chooses among several).
    member : str, optional
        The ``.trk`` inside a ``.trz`` (its name or path in the zip).
    units : str, optional
        The length unit of the calibration when the project names none (``m``, ``cm``, ``mm``,
        ``in``, ``ft``); a unit the project names wins only if equal (else an error).

    Returns
    -------
    PlanePoints
        Image positions (px) and, when the project is calibrated (a scale other than 1 px per
        unit), world positions in m (y up, Tracker's axes); ``t_s`` from the clip's start time
        and frame duration.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{where(path)}not found; give a Tracker .trk or .trz file")
    if path.stat().st_size == 0:
        raise InputError(f"{where(path)}empty file (0 bytes); a Tracker project is a .trk (XML) or a .trz (zip)")
    raw, source = _xml_text(path, member)
    root, encoding_note = _parse(raw, source)
    panel = _props(root)
    start_ms, dt_ms, start_frame = _time_base(panel, source)
    keys = _coords(panel, source)
    masses = _point_masses(panel, source)
    labels = tuple(masses)
    frames = np.array(sorted(set().union(*(m.keys() for m in masses.values()))), dtype=int)
    xy_px = np.full((frames.size, len(labels), 2), np.nan)
    row = {f: i for i, f in enumerate(frames)}
    for j, lab in enumerate(labels):
        for f, xy in masses[lab].items():
            xy_px[row[f], j] = xy
    t_s = (start_ms + (frames - start_frame) * dt_ms) / 1000.0
    notes = [f"times from the clip: start {start_ms:g} ms at frame {start_frame}, {dt_ms:g} ms a frame"]
    if encoding_note:
        notes.append(encoding_note)
    if "referenceframe" in panel:  # a moving origin Tracker derives for display; the marks are raw
        notes.append(
            f"Tracker's reference frame {_value(panel['referenceframe'])!r} is not applied: positions are "
            "in the project's fixed axes"
        )
    unit = _length_unit(panel, units, source)
    calibrated = any(abs(k[3] - 1.0) > 1e-12 or abs(k[4] - 1.0) > 1e-12 for k in keys.values())
    xy_m = None
    if calibrated and unit is not None:
        xy_m = _to_world(xy_px, frames, keys) * TRACKER_LENGTH_UNITS_M[unit]
        if unit != "m":
            notes.append(f"world coordinates converted from {unit} to m")
    else:
        from ..._diagnostics import warn

        why = "the project is not calibrated (1 px per unit)" if not calibrated else "it names no length unit"
        warn(
            "W-TRACK-NOSCALE",
            f"{source}: {why}: x_m, y_m left empty (x_px, y_px and theta_rad are measured); "
            "calibrate in Tracker" + ("" if not calibrated else " or give --units"),
        )
    return PlanePoints(t_s, frames, labels, xy_px, xy_m, source, tuple(notes))


def _length_unit(panel: dict, units: str | None, source: str) -> str | None:
    named = str(_value(panel["length_unit"])).strip() if "length_unit" in panel else None
    for u, what in ((named, "the project's length_unit"), (units, "--units")):
        if u is not None and u not in TRACKER_LENGTH_UNITS_M:
            raise InputError(
                f"{where(source, key='length_unit')}{what} {u!r} is not a length unit rocklab knows; "
                f"use one of {sorted(TRACKER_LENGTH_UNITS_M)}"
            )
    if named is not None and units is not None and named != units:
        raise InputError(
            f"{where(source, key='length_unit')}the project says {named!r}, --units says {units!r}; drop --units"
        )
    return named or units
