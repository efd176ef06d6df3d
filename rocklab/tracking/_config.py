"""Tracking configuration (``track.toml``): the authoritative schema.

The file is TOML read with :mod:`tomllib`; every table maps onto one frozen
dataclass below. Lengths are metres, angles radians, image coordinates pixels
(``u`` right, ``v`` down, origin at the top-left pixel centre). Example::

    [video]
    fps = 50                     # optional when the container has it
    [targets]
    style = "aruco"              # aruco | apriltag | dots | edges | region
    dictionary = "DICT_4X4_50"   # aruco/apriltag
    marker_size_m = 0.03         # side length of the printed marker (gives the scale)
    [reference]
    level = "table"              # "table" | "none" | "value" (then level_rad = ...)
    [[objects]]
    id = "block_1"
    kind = "block"               # block | table
    markers = [1]                # aruco ids; for dots: dots = [[x_m, y_m], ...]
    [[objects]]
    id = "table"
    kind = "table"
    markers = [0]

Conventions used by the tracker (documented here because ``synth`` writes
matching truth):

* World frame: the rocking plane, ``x`` right, ``y`` up, metres. With
  ``reference.homography`` (image px -> plane m) positions are absolute in
  that plane; otherwise ``x = s (u - cx)``, ``y = -s (v - cy)`` about the
  image centre ``(cx, cy)`` with the scale ``s`` (m/px) from the marker size,
  the dot layout, ``reference.m_per_px`` or ``reference.board``, then rotated
  by the levelling angle. Compare positions as displacements unless a
  homography is given.
* Object frame: ``x`` right, ``y`` up when the object is upright. Its origin is
  the point reported as ``x_m, y_m``: for ``markers`` the centre of the first
  marker unless ``marker_positions_m`` (marker centres in the object frame)
  says otherwise; for ``dots`` the origin of the ``dots`` coordinates; for
  ``edges`` the centre of the block outline; for ``region`` the centre of
  ``roi`` in the first frame.
* ``theta_rad``: counter-clockwise rotation of the object frame relative to
  the world frame as seen by the camera (levelled). A marker printed upright
  reads 0; ``dots`` read 0 when laid out as given; ``edges`` read 0 when the
  outline's sides are vertical/horizontal; ``region`` reads ``theta0_rad``
  (default 0) at the first frame. In the ``edges`` style a ``table`` object is
  followed by the region tracker and its angle is the image angle of the
  strongest near-horizontal edge in its ``roi`` (the table top), so levelling
  from the table works.
* ``roi = [u, v, w, h]`` is in continuous pixel coordinates (pixel centres at
  integers); its centre is ``(u + w/2, v + h/2)``.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path

from .._errors import InputError, where

__all__ = [
    "TrackConfig", "VideoConfig", "TargetsConfig", "ReferenceConfig", "BoardConfig",
    "MotionConfig", "ObjectConfig", "load_track_config", "TARGET_STYLES", "OBJECT_KINDS",
]

TARGET_STYLES = ("aruco", "apriltag", "dots", "edges", "region")
OBJECT_KINDS = ("block", "table")
LEVEL_MODES = ("table", "none", "value")
CORNER_REFINEMENTS = ("edges", "subpix", "contour", "apriltag", "none")


@dataclass(frozen=True)
class VideoConfig:
    """``[video]``: frame rate, frame range and (optional) lens model.

    Attributes
    ----------
    fps : float or None
        Frames per second; overrides the container's rate. Required when the
        container has none (else the CLI asks for ``--fps``).
    start_frame, stop_frame : int, int or None
        Half-open range of frames to track (``stop_frame=None``: to the end).
    camera_matrix : tuple of 3 tuples of 3 floats, or None
        Pinhole intrinsics ``K`` (px). With ``dist_coeffs`` detected image
        points are undistorted before any geometry.
    dist_coeffs : tuple of float, or None
        OpenCV distortion coefficients ``(k1, k2, p1, p2[, k3, ...])``.
    calibration : str or None
        Path (relative to the TOML file) of a ``.npz`` with ``camera_matrix``
        and ``dist_coeffs`` (as written by :func:`rocklab.tracking.calibrate_camera`).
    """

    fps: float | None = None
    start_frame: int = 0
    stop_frame: int | None = None
    camera_matrix: tuple | None = None
    dist_coeffs: tuple | None = None
    calibration: str | None = None


@dataclass(frozen=True)
class TargetsConfig:
    """``[targets]``: what is tracked and how it is detected.

    Attributes
    ----------
    style : {"aruco", "apriltag", "dots", "edges", "region"}
    dictionary : str
        OpenCV predefined dictionary name (``DICT_4X4_50``, ``DICT_APRILTAG_36h11``...).
    marker_size_m : float or None
        Printed marker side (black border included), m. Gives the scale.
    corner_refinement : {"edges", "subpix", "contour", "apriltag", "none"}
        ArUco corner refinement: ``"edges"`` (default) intersects sub-pixel lines
        fitted to the marker's outer edges (unbiased under blur); the others
        are OpenCV's methods (``"subpix"`` shrinks blurred markers by ~1 %).
    search_margin : float
        Around the predicted pose, search a window this many object sizes wide
        on each side before falling back to the full frame.
    dot_diameter_m : float or None
        Printed dot diameter (m); filters blobs by size once the scale is known.
    dot_color : {"dark", "light"}
        Dots darker or lighter than the surface they are printed on.
    edge_threshold : float or None
        Grey level (0-255) separating block from background for ``edges``;
        ``None``: Otsu per frame inside the search window.
    min_quality : float
        Samples with a quality below this (0..1) are reported as ``"low_quality"``.
    """

    style: str = "aruco"
    dictionary: str = "DICT_4X4_50"
    marker_size_m: float | None = None
    corner_refinement: str = "edges"
    search_margin: float = 0.5
    dot_diameter_m: float | None = None
    dot_color: str = "dark"
    edge_threshold: float | None = None
    min_quality: float = 0.0


@dataclass(frozen=True)
class BoardConfig:
    """``[reference.board]``: a checkerboard/ChArUco board seen in the video, for scale.

    The board lies in the rocking plane; its pose gives the homography image ->
    plane (m). The plane origin is then the board's top-left inner corner as
    seen in the image (checkerboard; for ChArUco OpenCV's board origin), x to
    the right, y up.

    Attributes
    ----------
    kind : {"checkerboard", "charuco"}
    squares_x, squares_y : int
        Number of squares along the board's x and y.
    square_m : float
        Square side, m.
    marker_m : float or None
        ChArUco marker side, m.
    dictionary : str
        ChArUco dictionary name.
    frame : int
        Video frame index showing the board.
    """

    kind: str = "checkerboard"
    squares_x: int = 9
    squares_y: int = 6
    square_m: float = 0.025
    marker_m: float | None = None
    dictionary: str = "DICT_4X4_50"
    frame: int = 0


@dataclass(frozen=True)
class ReferenceConfig:
    """``[reference]``: levelling and the pixel -> metre mapping.

    Attributes
    ----------
    level : {"table", "none", "value"}
        ``"table"``: the table object's median image angle is the horizontal
        (so a slightly rotated camera does not bias θ); ``"value"``: use
        ``level_rad``; ``"none"``: the image rows are horizontal.
    level_rad : float
        Camera roll (rad, counter-clockwise) removed when ``level = "value"``.
    m_per_px : float or None
        Explicit scale (m per px); otherwise from markers/dots/board.
    homography : 3x3 tuple or None
        Image (px) -> plane (m, y up) homography; overrides the scale.
    board : BoardConfig or None
    plane : {"auto", "table", "image"}
        Where the image -> plane homography comes from when neither
        ``homography`` nor ``board`` is given. ``"table"``: from the table's
        markers in the first frame (their corners are known in the table frame:
        with ``video.camera_matrix`` by a planar PnP pose, else a homography
        fit, which needs two or more markers); positions are then metres in the
        table frame at the first frame. ``"image"``: centred pixels times the
        measured scale. ``"auto"``: ``"table"`` when possible with a camera
        matrix (aruco/apriltag, a table with known marker layout and size),
        else ``"image"`` (a free homography from markers along one table edge
        is poorly conditioned; force it with ``"table"``).
    """

    level: str = "table"
    level_rad: float = 0.0
    m_per_px: float | None = None
    homography: tuple | None = None
    board: BoardConfig | None = None
    plane: str = "auto"


@dataclass(frozen=True)
class MotionConfig:
    """``[motion]``: table velocity/acceleration and gap handling.

    Attributes
    ----------
    sg_window_s : float or None
        Savitzky-Golay window (s); ``None`` chooses it from the noise.
    sg_polyorder : int or None
        Savitzky-Golay polynomial order (>= 2 for acceleration); ``None``
        chooses it with the window (3 when only the window is given).
    interpolate_max_gap_frames : int
        Fill NaN gaps up to this many frames by interpolation (status
        ``"interpolated"``); 0 (default) never invents samples.
    """

    sg_window_s: float | None = None
    sg_polyorder: int | None = None
    interpolate_max_gap_frames: int = 0


@dataclass(frozen=True)
class ObjectConfig:
    """``[[objects]]``: one tracked body.

    Attributes
    ----------
    id : str
        Name used in ``tracks.csv``'s ``object`` column.
    kind : {"block", "table"}
    markers : tuple of int
        ArUco/AprilTag ids on this object.
    marker_positions_m : tuple of (x, y) or None
        Marker centres in the object frame (m), same order as ``markers``;
        default: the first marker centre is the origin and the layout is
        learnt from the first frame that shows every marker.
    dots : tuple of (x, y)
        Dot centres in the object frame (m), at least two (``dots`` style).
    roi : (u, v, w, h) or None
        Region in the first tracked frame (px), for ``edges``/``region``.
    size_m : (b, h) or None
        Block outline width and height (m), for ``edges`` (gives the scale).
    theta0_rad : float or None
        ``region``: the object's angle at the first frame (default 0);
        ``edges``: a hint (default 0) to tell the outline's top from its side.
    marker_size_m : float or None
        This object's marker side (m) when it differs from ``targets.marker_size_m``.
    """

    id: str
    kind: str = "block"
    markers: tuple = ()
    marker_positions_m: tuple | None = None
    dots: tuple = ()
    roi: tuple | None = None
    size_m: tuple | None = None
    theta0_rad: float | None = None
    marker_size_m: float | None = None


@dataclass(frozen=True)
class TrackConfig:
    """The whole ``track.toml``. Build with :func:`load_track_config` or
    :meth:`from_dict`; write with :meth:`to_toml`."""

    objects: tuple[ObjectConfig, ...]
    video: VideoConfig = field(default_factory=VideoConfig)
    targets: TargetsConfig = field(default_factory=TargetsConfig)
    reference: ReferenceConfig = field(default_factory=ReferenceConfig)
    motion: MotionConfig = field(default_factory=MotionConfig)
    source: str | None = None

    # ------------------------------------------------------------------ build
    @classmethod
    def from_dict(cls, d: dict, source=None, text: str | None = None) -> "TrackConfig":
        """Validate a parsed TOML mapping; errors name the key (and line when ``text`` is given)."""
        return _Parser(source, text).config(d)

    @property
    def table(self) -> ObjectConfig | None:
        """The first object of kind ``"table"`` (or None)."""
        return next((o for o in self.objects if o.kind == "table"), None)

    def object(self, oid: str) -> ObjectConfig:
        for o in self.objects:
            if o.id == oid:
                return o
        raise InputError(f"no object '{oid}' in the tracking config; known: "
                         f"{', '.join(o.id for o in self.objects)}")

    def to_dict(self) -> dict:
        d = {"video": _prune(asdict(self.video)), "targets": _prune(asdict(self.targets)),
             "reference": _prune(asdict(self.reference)), "motion": _prune(asdict(self.motion)),
             "objects": [_prune(asdict(o)) for o in self.objects]}
        return d

    def to_toml(self) -> str:
        """Render as TOML text that :func:`load_track_config` reads back unchanged."""
        d = self.to_dict()
        out = []
        for sec in ("video", "targets", "reference", "motion"):
            sub = {k: v for k, v in d[sec].items() if not isinstance(v, dict)}
            out.append(f"[{sec}]")
            out += [f"{k} = {_toml_value(v)}" for k, v in sub.items()]
            for k, v in d[sec].items():
                if isinstance(v, dict):
                    out.append(f"[{sec}.{k}]")
                    out += [f"{kk} = {_toml_value(vv)}" for kk, vv in v.items()]
            out.append("")
        for o in d["objects"]:
            out.append("[[objects]]")
            out += [f"{k} = {_toml_value(v)}" for k, v in o.items()]
            out.append("")
        return "\n".join(out)


def load_track_config(path) -> TrackConfig:
    """Read and validate ``track.toml``.

    Raises
    ------
    InputError
        Unreadable TOML (with its line), an unknown key, a wrong type or value;
        the message names the file, line (where found) and key.
    """
    path = Path(path)
    text = path.read_text(encoding="utf-8")
    try:
        d = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise InputError(f"{path}: not valid TOML ({e}); fix the syntax") from None
    cfg = TrackConfig.from_dict(d, source=path, text=text)
    v = cfg.video
    if v.calibration is not None and not Path(v.calibration).is_absolute():
        import dataclasses
        cfg = dataclasses.replace(cfg, video=dataclasses.replace(
            v, calibration=str(path.parent / v.calibration)))
    return cfg


# ------------------------------------------------------------------ internals
def _prune(d: dict) -> dict:
    return {k: (_prune(v) if isinstance(v, dict) else v) for k, v in d.items()
            if v is not None and k != "source"}


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ("nan" if v != v else ("inf" if v > 0 else "-inf"))
    if isinstance(v, int):
        return str(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


class _Parser:
    """Validation with key paths (``objects[1].markers``) and best-effort line numbers."""

    def __init__(self, source, text):
        self.source, self.text = source, text

    # -- errors
    def _line(self, section: str, key: str | None, index: int | None) -> int | None:
        if self.text is None:
            return None
        lines = self.text.splitlines()
        start, count = 0, -1
        if section:
            hdr = re.compile(r"^\s*\[\[\s*%s\s*\]\]" % re.escape(section) if index is not None
                             else r"^\s*\[\s*%s\s*\]" % re.escape(section))
            found = None
            for i, ln in enumerate(lines):
                if hdr.match(ln):
                    count += 1
                    if index is None or count == index:
                        found = i
                        break
            if found is None:
                return None
            start = found
            if key is None:
                return start + 1
        pat = re.compile(r"^\s*%s\s*=" % re.escape(key))
        for i in range(start, len(lines)):
            if i > start and section and re.match(r"^\s*\[", lines[i]):
                break
            if pat.match(lines[i]):
                return i + 1
        return start + 1 if section else None

    def err(self, section, key, msg, index=None):
        name = section + (f"[{index}]" if index is not None else "") + (f".{key}" if key else "")
        raise InputError(where(self.source, self._line(section, key, index), name) + msg)

    # -- typed getters
    def _take(self, d, section, cls, index=None, skip=()):
        if not isinstance(d, dict):
            self.err(section, None, "must be a table; see rocklab/tracking/_config.py", index)
        names = {f.name for f in fields(cls)} - {"source"}
        for k in d:
            if k not in names and k not in skip:
                self.err(section, k, f"unknown key; allowed: {', '.join(sorted(names))}", index)
        return d

    def num(self, v, section, key, index=None, positive=False, allow_none=True, integer=False):
        if v is None and allow_none:
            return None
        ok = isinstance(v, int) if integer else isinstance(v, (int, float))
        if isinstance(v, bool) or not ok or not math.isfinite(v):
            self.err(section, key, f"must be {'an integer' if integer else 'a finite number'}"
                     f", got {v!r}", index)
        if positive and v <= 0:
            self.err(section, key, f"must be > 0, got {v!r}", index)
        return int(v) if integer else float(v)

    def choice(self, v, options, section, key, index=None):
        if v not in options:
            self.err(section, key, f"must be one of {', '.join(options)}; got {v!r}", index)
        return v

    def matrix(self, v, shape, section, key, index=None):
        if v is None:
            return None
        try:
            rows = tuple(tuple(float(x) for x in r) for r in v)
        except TypeError:
            rows = ()
        if len(rows) != shape[0] or any(len(r) != shape[1] for r in rows) or not all(
                math.isfinite(x) for r in rows for x in r):
            self.err(section, key, f"must be a {shape[0]}x{shape[1]} array of numbers", index)
        return rows

    def vector(self, v, section, key, index=None, n=None, integer=False):
        if v is None:
            return None
        if not isinstance(v, (list, tuple)):
            self.err(section, key, "must be an array", index)
        out = tuple(self.num(x, section, key, index, allow_none=False, integer=integer) for x in v)
        if n is not None and len(out) != n:
            self.err(section, key, f"must have {n} elements, got {len(out)}", index)
        return out

    # -- sections
    def config(self, d) -> TrackConfig:
        allowed = {"video", "targets", "reference", "motion", "objects"}
        for k in d:
            if k not in allowed:
                self.err(k, None, f"unknown table; allowed: {', '.join(sorted(allowed))}")
        video = self.video(d.get("video", {}))
        targets = self.targets(d.get("targets", {}))
        reference = self.reference(d.get("reference", {}))
        motion = self.motion(d.get("motion", {}))
        objs = d.get("objects")
        if not objs or not isinstance(objs, list):
            self.err("objects", None, "at least one [[objects]] entry is required (id, kind, markers/dots/roi)")
        objects = tuple(self.obj(o, i, targets) for i, o in enumerate(objs))
        seen, seen_markers = set(), {}
        for i, o in enumerate(objects):
            if o.id in seen:
                self.err("objects", "id", f"duplicate object id {o.id!r}; ids must be unique", i)
            seen.add(o.id)
            for m in o.markers:
                if m in seen_markers:
                    self.err("objects", "markers", f"marker {m} already belongs to "
                             f"{seen_markers[m]!r}; each marker id belongs to one object", i)
                seen_markers[m] = o.id
        if reference.level == "table" and not any(o.kind == "table" for o in objects):
            import dataclasses
            # No table to level from: fall back to the image rows (documented).
            reference = dataclasses.replace(reference, level="none")
        if targets.style in ("aruco", "apriltag") and targets.marker_size_m is None and \
                any(o.marker_size_m is None for o in objects) and reference.m_per_px is None and reference.homography is None and reference.board is None:
            self.err("targets", "marker_size_m", "needed for the scale (or give reference.m_per_px, "
                     "reference.homography or [reference.board])")
        return TrackConfig(objects=objects, video=video, targets=targets, reference=reference,
                           motion=motion, source=None if self.source is None else str(self.source))

    def video(self, d):
        s = "video"
        self._take(d, s, VideoConfig)
        fps = self.num(d.get("fps"), s, "fps", positive=True)
        start = self.num(d.get("start_frame", 0), s, "start_frame", integer=True, allow_none=False)
        stop = self.num(d.get("stop_frame"), s, "stop_frame", integer=True)
        if start < 0 or (stop is not None and stop <= start):
            self.err(s, "stop_frame" if stop is not None and stop <= start else "start_frame",
                     "need 0 <= start_frame < stop_frame")
        K = self.matrix(d.get("camera_matrix"), (3, 3), s, "camera_matrix")
        dist = self.vector(d.get("dist_coeffs"), s, "dist_coeffs")
        if dist is not None and len(dist) not in (4, 5, 8, 12, 14):
            self.err(s, "dist_coeffs", "must have 4, 5, 8, 12 or 14 coefficients")
        if dist is not None and K is None:
            self.err(s, "camera_matrix", "dist_coeffs need a camera_matrix too")
        cal = d.get("calibration")
        if cal is not None and not isinstance(cal, str):
            self.err(s, "calibration", "must be a path string")
        return VideoConfig(fps, start, stop, K, dist, cal)

    def targets(self, d):
        s = "targets"
        self._take(d, s, TargetsConfig)
        style = self.choice(d.get("style", "aruco"), TARGET_STYLES, s, "style")
        default_dict = "DICT_APRILTAG_36h11" if style == "apriltag" else "DICT_4X4_50"
        dictionary = d.get("dictionary", default_dict)
        import cv2

        if not isinstance(dictionary, str) or not dictionary.startswith("DICT_") or \
                not hasattr(cv2.aruco, dictionary):
            self.err(s, "dictionary", f"unknown dictionary {dictionary!r}; use an OpenCV name "
                     "such as DICT_4X4_50 or DICT_APRILTAG_36h11")
        return TargetsConfig(
            style=style, dictionary=dictionary,
            marker_size_m=self.num(d.get("marker_size_m"), s, "marker_size_m", positive=True),
            corner_refinement=self.choice(d.get("corner_refinement", "edges"), CORNER_REFINEMENTS,
                                          s, "corner_refinement"),
            search_margin=self.num(d.get("search_margin", 0.5), s, "search_margin", positive=True),
            dot_diameter_m=self.num(d.get("dot_diameter_m"), s, "dot_diameter_m", positive=True),
            dot_color=self.choice(d.get("dot_color", "dark"), ("dark", "light"), s, "dot_color"),
            edge_threshold=self.num(d.get("edge_threshold"), s, "edge_threshold"),
            min_quality=self.num(d.get("min_quality", 0.0), s, "min_quality", allow_none=False),
        )

    def reference(self, d):
        s = "reference"
        self._take(d, s, ReferenceConfig)
        level = d.get("level", "value" if "level_rad" in d else "table")
        level = self.choice(level, LEVEL_MODES, s, "level")
        board = None
        if "board" in d:
            b = self._take(d["board"], "reference.board", BoardConfig)
        if "board" in d:
            bs = "reference.board"
            board = BoardConfig(
                kind=self.choice(b.get("kind", "checkerboard"), ("checkerboard", "charuco"), bs, "kind"),
                squares_x=self.num(b.get("squares_x", 9), bs, "squares_x", integer=True, positive=True),
                squares_y=self.num(b.get("squares_y", 6), bs, "squares_y", integer=True, positive=True),
                square_m=self.num(b.get("square_m", 0.025), bs, "square_m", positive=True),
                marker_m=self.num(b.get("marker_m"), bs, "marker_m", positive=True),
                dictionary=str(b.get("dictionary", "DICT_4X4_50")),
                frame=self.num(b.get("frame", 0), bs, "frame", integer=True, allow_none=False))
        return ReferenceConfig(
            level=level,
            level_rad=self.num(d.get("level_rad", 0.0), s, "level_rad", allow_none=False),
            m_per_px=self.num(d.get("m_per_px"), s, "m_per_px", positive=True),
            homography=self.matrix(d.get("homography"), (3, 3), s, "homography"),
            board=board,
            plane=self.choice(d.get("plane", "auto"), ("auto", "table", "image"), s, "plane"))

    def motion(self, d):
        s = "motion"
        self._take(d, s, MotionConfig)
        order = self.num(d.get("sg_polyorder"), s, "sg_polyorder", integer=True)
        if order is not None and order < 2:
            self.err(s, "sg_polyorder", "must be >= 2 so acceleration is defined")
        gap = self.num(d.get("interpolate_max_gap_frames", 0), s, "interpolate_max_gap_frames",
                       integer=True, allow_none=False)
        if gap < 0:
            self.err(s, "interpolate_max_gap_frames", "must be >= 0")
        return MotionConfig(self.num(d.get("sg_window_s"), s, "sg_window_s", positive=True), order, gap)

    def obj(self, d, i, targets):
        s = "objects"
        self._take(d, s, ObjectConfig, i)
        oid = d.get("id")
        if not isinstance(oid, str) or not oid or "," in oid:
            self.err(s, "id", "a non-empty name without commas is required", i)
        kind = self.choice(d.get("kind", "block"), OBJECT_KINDS, s, "kind", i)
        markers = self.vector(d.get("markers", []), s, "markers", i, integer=True)
        if any(m < 0 for m in markers):
            self.err(s, "markers", "marker ids must be >= 0", i)
        mpos = d.get("marker_positions_m")
        if mpos is not None:
            mpos = self.matrix(mpos, (len(markers), 2), s, "marker_positions_m", i)
        dots = d.get("dots", [])
        dots = self.matrix(dots, (len(dots) if isinstance(dots, list) else -1, 2), s, "dots", i) \
            if dots else ()
        roi = self.vector(d.get("roi"), s, "roi", i, n=4)
        if roi is not None and (roi[2] <= 0 or roi[3] <= 0):
            self.err(s, "roi", "must be [u, v, width, height] with positive size (px)", i)
        size = self.vector(d.get("size_m"), s, "size_m", i, n=2)
        if size is not None and min(size) <= 0:
            self.err(s, "size_m", "must be [b_m, h_m] > 0", i)
        style = targets.style
        if style in ("aruco", "apriltag") and not markers:
            self.err(s, "markers", f"style {style!r} needs the marker ids on this object, "
                     "e.g. markers = [1]", i)
        if style == "dots" and len(dots) < 2:
            self.err(s, "dots", "style 'dots' needs at least two dot centres [[x_m, y_m], ...]", i)
        if style in ("edges", "region") and roi is None:
            self.err(s, "roi", f"style {style!r} needs roi = [u, v, width, height] (px, first frame)", i)
        return ObjectConfig(id=oid, kind=kind, markers=markers, marker_positions_m=mpos, dots=dots,
                            roi=roi, size_m=size,
                            theta0_rad=self.num(d.get("theta0_rad"), s, "theta0_rad", i),
                            marker_size_m=self.num(d.get("marker_size_m"), s, "marker_size_m", i,
                                                   positive=True))
