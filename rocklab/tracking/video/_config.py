"""Tracking configuration (``track.toml``): the authoritative schema.

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

import math
import tomllib
from dataclasses import asdict, dataclass, field
from pathlib import Path

from ..._errors import InputError

__all__ = [
    "TrackConfig",
    "VideoConfig",
    "TargetsConfig",
    "ReferenceConfig",
    "BoardConfig",
    "MotionConfig",
    "ObjectConfig",
    "load_track_config",
    "TARGET_STYLES",
    "OBJECT_KINDS",
]

TARGET_STYLES = ("aruco", "apriltag", "dots", "edges", "region", "markerless")
OBJECT_KINDS = ("block", "table", "point")
LEVEL_MODES = ("table", "none", "value", "rest", "line")
CORNER_REFINEMENTS = ("edges", "subpix", "contour", "apriltag", "none")


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
        from ._config_parse import ConfigParser

        return ConfigParser(source, text).config(d)

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
        d = {
            "video": _prune(asdict(self.video)),
            "targets": _prune(asdict(self.targets)),
            "reference": _prune(asdict(self.reference)),
            "motion": _prune(asdict(self.motion)),
            "objects": [_prune(asdict(o)) for o in self.objects],
        }
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
    import dataclasses

    for key in ("calibration", "corrections"):  # paths relative to the TOML file
        f = getattr(cfg.video, key)
        if f is not None and not Path(f).is_absolute():
            cfg = dataclasses.replace(cfg, video=dataclasses.replace(cfg.video, **{key: str(path.parent / f)}))
    return cfg


# ------------------------------------------------------------------ internals
def _prune(d: dict) -> dict:
    return {k: (_prune(v) if isinstance(v, dict) else v) for k, v in d.items() if v is not None and k != "source"}


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


def schema_markdown() -> str:
    """The ``track.toml`` reference (every table, key, default and meaning) as Markdown, from
    the dataclasses' fields and their numpydoc ``Attributes`` (``docs/track-toml.md``)."""
    import dataclasses
    import inspect
    import re

    def attr_docs(cls) -> dict:
        doc = inspect.getdoc(cls) or ""
        body = doc.split("Attributes\n----------\n", 1)[-1] if "Attributes" in doc else ""
        out, key = {}, None
        for ln in body.splitlines():
            m = re.match(r"^(\w+(?:, \w+)*)\s*:\s*(.*)$", ln)
            if m and not ln.startswith(" "):
                names = [n.strip() for n in m.group(1).split(",")]
                key = names
                for n in names:
                    out[n] = [f"*{m.group(2).strip()}*:"]
            elif key and ln.strip():
                for n in key:
                    out[n].append(ln.strip())
        return {k: " ".join(v) for k, v in out.items()}

    sections = [
        ("[video]", VideoConfig),
        ("[targets]", TargetsConfig),
        ("[reference]", ReferenceConfig),
        ("[reference.board]", BoardConfig),
        ("[motion]", MotionConfig),
        ("[[objects]] (one per object)", ObjectConfig),
    ]
    lines = []
    for title, cls in sections:
        first = (inspect.getdoc(cls) or "").splitlines()[0]
        lines += [f"## `{title}`", "", first, "", "| key | default | type and meaning |", "| --- | --- | --- |"]
        docs = attr_docs(cls)
        for f in dataclasses.fields(cls):
            if f.default is not dataclasses.MISSING:
                dflt = f"`{f.default!r}`"
            elif f.default_factory is not dataclasses.MISSING:  # type: ignore[misc]
                dflt = f"`{f.default_factory()!r}`"  # type: ignore[misc]
            else:
                dflt = "required"
            text = docs.get(f.name, "").replace("|", "/")
            lines.append(f"| `{f.name}` | {dflt} | {text} |")
        lines.append("")
    return "\n".join(lines)
