"""Tracking configuration (``track.toml``): the schema, its reader and its writer.

The file is TOML read with :mod:`tomllib`; every table maps onto one frozen
dataclass below. Lengths are metres, angles radians, image coordinates pixels
(``u`` right, ``v`` down, origin at the top-left pixel centre). Example::

    [video]
    fps = 50                     # optional when the container has it
    [targets]
    style = "aruco"              # aruco | apriltag | dots | edges | region | markerless
    dictionary = "DICT_4X4_50"   # aruco/apriltag
    marker_size_m = 0.03         # side length of the printed marker (gives the scale)
    [reference]
    level = "table"              # "table" | "none" | "value" (then level_rad = ...)
    [[objects]]
    id = "block_1"
    kind = "block"               # block | table | point (a position only: theta_rad NaN)
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

import dataclasses
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

from .._errors import InputError
from ._toml import TomlDoc, default_of, dumps_toml

__all__ = [
    "TrackConfig",
    "VideoConfig",
    "TargetsConfig",
    "ReferenceConfig",
    "BoardConfig",
    "MotionConfig",
    "ObjectConfig",
    "load_track_config",
    "FPS_PLACEHOLDER_NOTE",
    "schema_markdown",
    "TARGET_STYLES",
    "MARKER_STYLES",
    "REGION_STYLES",
    "OBJECT_KINDS",
    "LEVEL_MODES",
    "CORNER_REFINEMENTS",
    "DOT_COLORS",
    "PLANE_MODES",
    "BOARD_KINDS",
]

#: Target styles: printed markers, dot targets, the block's outline, a region, markerless.
TARGET_STYLES = ("aruco", "apriltag", "dots", "edges", "region", "markerless")
#: The styles that follow printed fiducials (an object lists its ``markers``).
MARKER_STYLES = ("aruco", "apriltag")
#: The styles that follow a region of the first frame (an object gives its ``roi``).
REGION_STYLES = ("edges", "region", "markerless")
OBJECT_KINDS = ("block", "table", "point")
LEVEL_MODES = ("table", "none", "value", "rest", "line")
CORNER_REFINEMENTS = ("edges", "subpix", "contour", "apriltag", "none")
DOT_COLORS = ("dark", "light")
PLANE_MODES = ("auto", "table", "image")
BOARD_KINDS = ("checkerboard", "charuco")
#: The dictionary of ``apriltag`` targets when ``targets.dictionary`` is not given.
APRILTAG_DICTIONARY = "DICT_APRILTAG_36h11"
#: ``level = "line"``: the two points at least this far apart (px).
LEVEL_LINE_MIN_PX = 20.0


@dataclass(frozen=True)
class VideoConfig:
    """``[video]``: frame rate, frame range and (optional) lens model.

    Attributes
    ----------
    fps : float or None
        Frames per second; overrides the container's own frame times (t_s = frame / fps;
        W-VIDEO-FPS when they disagree). Required when the container has none (else the CLI
        asks for ``--fps``).
    start_frame, stop_frame : int, int or None
        Half-open range of frames to track (``stop_frame=None``: to the end).
    camera_matrix : tuple of 3 tuples of 3 floats, or None
        Pinhole intrinsics ``K`` (px). With ``dist_coeffs`` detected image
        points are undistorted before any geometry.
    dist_coeffs : tuple of float, or None
        OpenCV distortion coefficients ``(k1, k2, p1, p2[, k3, ...])``.
    calibration : str or None
        Path (relative to the TOML file) of a lens file (``lens.json`` from ``rocklab calibrate
        FILM_OR_FOLDER --board ...``, calibrated at the film's size) or of a ``.npz`` with
        ``camera_matrix`` and ``dist_coeffs`` (:func:`rocklab.tracking.calibrate_camera`); replaces
        ``camera_matrix`` and ``dist_coeffs``.
    corrections : str or None
        Path (relative to the TOML file) of a corrections file (CSV or TOML: per object and frame
        or time range, ``drop`` or set ``x_m``/``y_m``/``theta_rad``/``theta_deg``), applied after
        tracking; the frames it changes have status ``corrected`` or ``dropped``.
    """

    fps: float | None = None
    start_frame: int = 0
    stop_frame: int | None = None
    camera_matrix: tuple | None = None
    dist_coeffs: tuple | None = None
    calibration: str | None = None
    corrections: str | None = None


@dataclass(frozen=True)
class TargetsConfig:
    """``[targets]``: what is tracked and how it is detected.

    Attributes
    ----------
    style : {"aruco", "apriltag", "dots", "edges", "region", "markerless"}
        How every object is followed unless it names its own ``style``: printed
        markers, dot targets, the block's outline, optical flow in a region, or
        ``markerless`` (the region's own texture and edges registered against a
        keyframe; see "Markers or none" in the lab guide).
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
    level : {"table", "none", "value", "rest", "line"}
        Where the horizontal comes from: ``"table"``: the table object's median
        angle (markers, or a markerless table's top edge); ``"rest"``: the
        block's final rest (free rocking ends upright; ``level_object``, default
        the first block); ``"line"``: ``level_line_px``, a line the user marked
        on a horizontal edge of the first frame; ``"value"``: ``level_rad``;
        ``"none"``: the image rows are horizontal (say so only when the camera is
        known to be level). The source and its uncertainty are in the result.
    level_rad : float
        Camera roll (rad, counter-clockwise) removed when ``level = "value"``.
    level_line_px : ((u0, v0), (u1, v1)) or None
        Two pixels of the first frame on a horizontal line, for ``level = "line"``.
    level_object : str or None
        The block whose final rest is upright, for ``level = "rest"``.
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
    level_line_px: tuple | None = None
    level_object: str | None = None
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
    kind : {"block", "table", "point"}
        ``"point"``: a position only (a ball, a target on a string): ``theta_rad`` is NaN with
        the reason in the track, ``x``/``y`` are measured. A markerless block whose appearance
        does not tell its angle (a disk, a plain ball) is tracked the same way, with warning
        W-TRACK-THETA.
    markers : tuple of int
        ArUco/AprilTag ids on this object.
    marker_positions_m : tuple of (x, y) or None
        Marker centres in the object frame (m), same order as ``markers``;
        default: the first marker centre is the origin and the layout is
        learnt from the first frame that shows every marker.
    dots : tuple of (x, y)
        Dot centres in the object frame (m), at least two (``dots`` style).
    roi : (u, v, w, h) or None
        Region in the first tracked frame (px), for ``edges``/``region``/``markerless``.
    size_m : (b, h) or None
        Block outline width and height (m), for ``edges`` (gives the scale).
    theta0_rad : float or None
        ``region`` and ``markerless`` blocks: the object's angle at the first frame, rad,
        counter-clockwise, in the levelled frame: these trackers measure the rotation since the
        first frame and add it. Not given: upright, unless the block ends at rest away from
        upright, when that rest sets it (free rocking ends upright; warning W-THETA0-REST);
        ``edges``: a hint (default 0) to tell the outline's top from its side.
    marker_size_m : float or None
        This object's marker side (m) when it differs from ``targets.marker_size_m``.
    style : str or None
        This object's target style when it differs from ``targets.style`` (mixed styles:
        e.g. a block with ArUco markers on a markerless table).
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
    style: str | None = None


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
        return _read(TomlDoc(d, text, source))

    @property
    def table(self) -> ObjectConfig | None:
        """The first object of kind ``"table"`` (or None)."""
        return next((o for o in self.objects if o.kind == "table"), None)

    @property
    def named_files(self) -> tuple[Path, ...]:
        """The files the config names, which a tracking run reads (its lens calibration)."""
        v = self.video
        return tuple(Path(f) for f in (v.calibration, v.corrections) if f is not None)

    def object(self, oid: str) -> ObjectConfig:
        for o in self.objects:
            if o.id == oid:
                return o
        raise InputError(f"no object '{oid}' in the tracking config; known: {', '.join(o.id for o in self.objects)}")

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        return {
            "video": _prune(asdict(self.video)),
            "targets": _prune(asdict(self.targets)),
            "reference": _prune(asdict(self.reference)),
            "motion": _prune(asdict(self.motion)),
            "objects": [_prune(asdict(o)) for o in self.objects],
        }

    def to_toml(self, header=()) -> str:
        """Render as TOML text that :func:`load_track_config` reads back unchanged (``header``:
        comment lines written first)."""
        return dumps_toml(self.to_dict(), header)


def load_track_config(path) -> TrackConfig:
    """Read and validate ``track.toml``.

    Raises
    ------
    InputError
        Missing file, unreadable TOML (with its line), an unknown key, a wrong type or value;
        the message names the file, line (where found) and key.
    """
    path = Path(path)
    cfg = _read(TomlDoc.read(path, "tracking config"))
    v = cfg.video

    def near(f: str | None) -> str | None:  # paths relative to the TOML file
        return f if f is None or Path(f).is_absolute() else str(path.parent / f)

    if (near(v.calibration), near(v.corrections)) != (v.calibration, v.corrections):
        v = dataclasses.replace(v, calibration=near(v.calibration), corrections=near(v.corrections))
        cfg = dataclasses.replace(cfg, video=v)
    return cfg


def _prune(d: dict) -> dict:
    return {k: (_prune(v) if isinstance(v, dict) else v) for k, v in d.items() if v is not None and k != "source"}


def _known(cls) -> set:
    return {f.name for f in dataclasses.fields(cls)} - {"source"}


#: The note under which 'rocklab track init' (up to session 18) wrote ``fps = 50`` for a film with
#: no frame rate: a guess, not a rate, so such a config is read as giving none.
FPS_PLACEHOLDER_NOTE = "the film has no frame rate: fps = 50 written; correct it (or give --fps)"


# ---------------------------------------------------------------------- reading
def _read(doc: TomlDoc) -> TrackConfig:
    d = doc.data
    doc.reject_unknown((), d, ("video", "targets", "reference", "motion", "objects"))
    video = _video(doc, doc.table(("video",), d.get("video")))
    targets = _targets(doc, doc.table(("targets",), d.get("targets")))
    reference = _reference(doc, doc.table(("reference",), d.get("reference")))
    motion = _motion(doc, doc.table(("motion",), d.get("motion")))
    objs = d.get("objects")
    if not objs or not isinstance(objs, list):
        doc.fail(("objects",), "needs at least one [[objects]] entry (id, kind, markers/dots/roi)")
    objects = tuple(_object(doc, o, i, targets) for i, o in enumerate(objs))
    seen: set[str] = set()
    seen_markers: dict[int, str] = {}
    for i, o in enumerate(objects):
        if o.id in seen:
            doc.fail(("objects", i, "id"), f"= {o.id!r} is a duplicate object id; ids must be unique")
        seen.add(o.id)
        for m in o.markers:
            if m in seen_markers:
                doc.fail(
                    ("objects", i, "markers"),
                    f"has marker {m}, which already belongs to {seen_markers[m]!r}; "
                    "each marker id belongs to one object",
                )
            seen_markers[m] = o.id
    # level = "table" without a table object stays as written: tracking then warns W-LEVEL-NONE.
    # Markers of unknown size are tracked in marker units: x_m, y_m stay empty (W-TRACK-NOSCALE).
    return TrackConfig(
        objects=objects,
        video=video,
        targets=targets,
        reference=reference,
        motion=motion,
        source=None if doc.source is None else str(doc.source),
    )


def _get(doc, d, key, cls, name, **kw):
    """A number of table ``d`` (at path ``key``), the field's default when absent."""
    kw.setdefault("allow_none", default_of(cls, name) is None)
    return doc.number(key + (name,), d.get(name, default_of(cls, name)), **kw)


def _choice(doc, d, key, cls, name, choices):
    return doc.string(key + (name,), d.get(name, default_of(cls, name)), choices)


def _video(doc, d) -> VideoConfig:
    s = ("video",)
    doc.reject_unknown(s, d, _known(VideoConfig))
    fps = _get(doc, d, s, VideoConfig, "fps", positive=True)
    if fps == 50.0 and doc.text is not None and FPS_PLACEHOLDER_NOTE in doc.text:
        fps = None  # the placeholder: tracking asks for --fps unless the film has its own rate
    start = _get(doc, d, s, VideoConfig, "start_frame", integer=True)
    stop = _get(doc, d, s, VideoConfig, "stop_frame", integer=True)
    if start < 0 or (stop is not None and stop <= start):
        bad = "stop_frame" if stop is not None and stop <= start else "start_frame"
        doc.fail(s + (bad,), "must satisfy 0 <= start_frame < stop_frame")
    K = doc.matrix(s + ("camera_matrix",), d.get("camera_matrix"), (3, 3))
    if K is not None:
        fx, fy, k22 = K[0][0], K[1][1], K[2][2]
        if not (fx > 0 and fy > 0 and abs(K[1][0]) + abs(K[2][0]) + abs(K[2][1]) == 0 and k22 == 1):
            doc.fail(
                s + ("camera_matrix",),
                "must be [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] with fx, fy > 0 (pixels); fix it or drop it",
            )
    dist = doc.vector(s + ("dist_coeffs",), d.get("dist_coeffs"))
    if dist is not None and len(dist) not in (4, 5, 8, 12, 14):
        doc.fail(s + ("dist_coeffs",), "must have 4, 5, 8, 12 or 14 coefficients")
    if dist is not None and K is None:
        doc.fail(s + ("camera_matrix",), "is missing: dist_coeffs need a camera_matrix too")
    cal, fix = d.get("calibration"), d.get("corrections")
    for name, v in (("calibration", cal), ("corrections", fix)):
        if v is not None and not isinstance(v, str):
            doc.fail(s + (name,), "must be a path string")
    return VideoConfig(fps, start, stop, K, dist, cal, fix)


def _targets(doc, d) -> TargetsConfig:
    s, T = ("targets",), TargetsConfig
    doc.reject_unknown(s, d, _known(T))
    style = _choice(doc, d, s, T, "style", TARGET_STYLES)
    dictionary = d.get("dictionary", APRILTAG_DICTIONARY if style == "apriltag" else default_of(T, "dictionary"))
    import cv2

    if not isinstance(dictionary, str) or not dictionary.startswith("DICT_") or not hasattr(cv2.aruco, dictionary):
        doc.fail(
            s + ("dictionary",),
            f"names an unknown dictionary {dictionary!r}; use an OpenCV name such as DICT_4X4_50 or "
            f"{APRILTAG_DICTIONARY}",
        )
    return TargetsConfig(
        style=style,
        dictionary=dictionary,
        marker_size_m=_get(doc, d, s, T, "marker_size_m", positive=True),
        corner_refinement=_choice(doc, d, s, T, "corner_refinement", CORNER_REFINEMENTS),
        search_margin=_get(doc, d, s, T, "search_margin", positive=True),
        dot_diameter_m=_get(doc, d, s, T, "dot_diameter_m", positive=True),
        dot_color=_choice(doc, d, s, T, "dot_color", DOT_COLORS),
        edge_threshold=_get(doc, d, s, T, "edge_threshold"),
        min_quality=_get(doc, d, s, T, "min_quality"),
    )


def _board(doc, b) -> BoardConfig:
    s, B = ("reference", "board"), BoardConfig
    b = doc.table(s, b)
    doc.reject_unknown(s, b, _known(B))
    return BoardConfig(
        kind=_choice(doc, b, s, B, "kind", BOARD_KINDS),
        squares_x=_get(doc, b, s, B, "squares_x", integer=True, positive=True),
        squares_y=_get(doc, b, s, B, "squares_y", integer=True, positive=True),
        square_m=_get(doc, b, s, B, "square_m", positive=True),
        marker_m=_get(doc, b, s, B, "marker_m", positive=True),
        dictionary=str(b.get("dictionary", default_of(B, "dictionary"))),
        frame=_get(doc, b, s, B, "frame", integer=True),
    )


def _reference(doc, d) -> ReferenceConfig:
    s, R = ("reference",), ReferenceConfig
    doc.reject_unknown(s, d, _known(R))
    level = doc.string(
        s + ("level",), d.get("level", "value" if "level_rad" in d else default_of(R, "level")), LEVEL_MODES
    )
    board = _board(doc, d["board"]) if "board" in d else None
    line = doc.matrix(s + ("level_line_px",), d.get("level_line_px"), (2, 2))
    if level == "line" and (
        line is None or math.hypot(line[0][0] - line[1][0], line[0][1] - line[1][1]) < LEVEL_LINE_MIN_PX
    ):
        doc.fail(
            s + ("level_line_px",),
            f"is needed with level = 'line': [[u0, v0], [u1, v1]] (px, first frame), at least "
            f"{LEVEL_LINE_MIN_PX:g} px apart along a horizontal edge",
        )
    lobj = d.get("level_object")
    if lobj is not None and not isinstance(lobj, str):
        doc.fail(s + ("level_object",), "must be an object id (string)")
    return ReferenceConfig(
        level=level,
        level_rad=_get(doc, d, s, R, "level_rad"),
        level_line_px=line,
        level_object=lobj,
        m_per_px=_get(doc, d, s, R, "m_per_px", positive=True),
        homography=_homography(doc, s + ("homography",), d.get("homography")),
        board=board,
        plane=_choice(doc, d, s, R, "plane", PLANE_MODES),
    )


def _homography(doc, key, v):
    H = doc.matrix(key, v, (3, 3))
    if H is not None:
        import numpy as np

        c = float(np.linalg.cond(np.asarray(H, float)))
        if not math.isfinite(c) or c > 1e12:
            doc.fail(
                key,
                f"is singular (condition number {c:.3g}): it maps the image to a line or a point; fix it or drop it",
            )
    return H


def _motion(doc, d) -> MotionConfig:
    s, M = ("motion",), MotionConfig
    doc.reject_unknown(s, d, _known(M))
    order = _get(doc, d, s, M, "sg_polyorder", integer=True)
    if order is not None and order < 2:
        doc.fail(s + ("sg_polyorder",), "must be >= 2 so acceleration is defined")
    gap = _get(doc, d, s, M, "interpolate_max_gap_frames", integer=True)
    if gap < 0:
        doc.fail(s + ("interpolate_max_gap_frames",), "must be >= 0")
    return MotionConfig(_get(doc, d, s, M, "sg_window_s", positive=True), order, gap)


def _object(doc, d, i, targets) -> ObjectConfig:
    s, O = ("objects", i), ObjectConfig
    d = doc.table(s, d)
    doc.reject_unknown(s, d, _known(O))
    oid = d.get("id")
    if not isinstance(oid, str) or not oid or "," in oid:
        doc.fail(s + ("id",), "must be a non-empty name without commas (it is required)")
    kind = _choice(doc, d, s, O, "kind", OBJECT_KINDS)
    markers = doc.vector(s + ("markers",), d.get("markers", list(default_of(O, "markers"))), integer=True)
    if any(m < 0 for m in markers):
        doc.fail(s + ("markers",), "must hold marker ids >= 0")
    mpos = d.get("marker_positions_m")
    if mpos is not None:
        mpos = doc.matrix(s + ("marker_positions_m",), mpos, (len(markers), 2))
    dots = d.get("dots", [])
    dots = doc.matrix(s + ("dots",), dots, (len(dots) if isinstance(dots, list) else -1, 2)) if dots else ()
    roi = doc.vector(s + ("roi",), d.get("roi"), n=4)
    if roi is not None and (roi[2] <= 0 or roi[3] <= 0):
        doc.fail(s + ("roi",), "must be [u, v, width, height] with positive size (px)")
    size = doc.vector(s + ("size_m",), d.get("size_m"), n=2)
    if size is not None and min(size) <= 0:
        doc.fail(s + ("size_m",), "must be [b_m, h_m] > 0")
    own = doc.string(s + ("style",), d.get("style"), TARGET_STYLES)
    style = own or targets.style
    if style in MARKER_STYLES and not markers:
        doc.fail(s + ("markers",), f"is needed by style {style!r}: the marker ids on this object, e.g. markers = [1]")
    if style == "dots" and len(dots) < 2:
        doc.fail(s + ("dots",), "needs at least two dot centres [[x_m, y_m], ...] with style 'dots'")
    if style in REGION_STYLES and roi is None:
        doc.fail(s + ("roi",), f"is needed by style {style!r}: roi = [u, v, width, height] (px, first frame)")
    return ObjectConfig(
        id=oid,
        kind=kind,
        markers=markers,
        marker_positions_m=mpos,
        dots=dots,
        roi=roi,
        size_m=size,
        theta0_rad=_get(doc, d, s, O, "theta0_rad"),
        marker_size_m=_get(doc, d, s, O, "marker_size_m", positive=True),
        style=own,
    )


# ---------------------------------------------------------------------- the reference page
def schema_markdown() -> str:
    """The ``track.toml`` reference (every table, key, default and meaning) as Markdown, from
    the dataclasses' fields and their numpydoc ``Attributes`` (``docs/track-toml.md``)."""
    from ._schema_doc import tables_markdown

    return tables_markdown(
        [
            ("[video]", VideoConfig),
            ("[targets]", TargetsConfig),
            ("[reference]", ReferenceConfig),
            ("[reference.board]", BoardConfig),
            ("[motion]", MotionConfig),
            ("[[objects]] (one per object)", ObjectConfig),
        ]
    )
