"""Validation of ``track.toml`` mappings into :class:`~rocklab.tracking.TrackConfig`.

Errors name the key path (``objects[1].markers``) and, when the TOML text is
known, its line; every message is one line with the rule and the fix.
"""

from __future__ import annotations

import math
import re
from dataclasses import fields

import numpy as np

from ..._errors import InputError, where
from ._config import (
    CORNER_REFINEMENTS,
    LEVEL_MODES,
    OBJECT_KINDS,
    TARGET_STYLES,
    BoardConfig,
    MotionConfig,
    ObjectConfig,
    ReferenceConfig,
    TargetsConfig,
    TrackConfig,
    VideoConfig,
)

__all__ = ["ConfigParser"]


class ConfigParser:
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
            hdr = re.compile(
                r"^\s*\[\[\s*%s\s*\]\]" % re.escape(section)
                if index is not None
                else r"^\s*\[\s*%s\s*\]" % re.escape(section)
            )
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
            self.err(section, None, "must be a table; see docs/track-toml.md", index)
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
            self.err(section, key, f"must be {'an integer' if integer else 'a finite number'}, got {v!r}", index)
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
        if (
            len(rows) != shape[0]
            or any(len(r) != shape[1] for r in rows)
            or not all(math.isfinite(x) for r in rows for x in r)
        ):
            self.err(section, key, f"must be a {shape[0]}x{shape[1]} array of numbers", index)
        return rows

    def _homography(self, v, section):
        H = self.matrix(v, (3, 3), section, "homography")
        if H is not None:
            c = float(np.linalg.cond(np.asarray(H, float)))
            if not math.isfinite(c) or c > 1e12:
                self.err(
                    section,
                    "homography",
                    f"is singular (condition number {c:.3g}): it maps the image "
                    "to a line or a point; fix it or drop it",
                )
        return H

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
                    self.err(
                        "objects",
                        "markers",
                        f"marker {m} already belongs to {seen_markers[m]!r}; each marker id belongs to one object",
                        i,
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
            source=None if self.source is None else str(self.source),
        )

    def video(self, d):
        s = "video"
        self._take(d, s, VideoConfig)
        fps = self.num(d.get("fps"), s, "fps", positive=True)
        start = self.num(d.get("start_frame", 0), s, "start_frame", integer=True, allow_none=False)
        stop = self.num(d.get("stop_frame"), s, "stop_frame", integer=True)
        if start < 0 or (stop is not None and stop <= start):
            self.err(
                s,
                "stop_frame" if stop is not None and stop <= start else "start_frame",
                "need 0 <= start_frame < stop_frame",
            )
        K = self.matrix(d.get("camera_matrix"), (3, 3), s, "camera_matrix")
        if K is not None:
            fx, fy, k22 = K[0][0], K[1][1], K[2][2]
            if not (fx > 0 and fy > 0 and abs(K[1][0]) + abs(K[2][0]) + abs(K[2][1]) == 0 and k22 == 1):
                self.err(
                    s,
                    "camera_matrix",
                    "must be [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] with fx, fy > 0 (pixels); fix it or drop it",
                )
        dist = self.vector(d.get("dist_coeffs"), s, "dist_coeffs")
        if dist is not None and len(dist) not in (4, 5, 8, 12, 14):
            self.err(s, "dist_coeffs", "must have 4, 5, 8, 12 or 14 coefficients")
        if dist is not None and K is None:
            self.err(s, "camera_matrix", "dist_coeffs need a camera_matrix too")
        cal, fix = d.get("calibration"), d.get("corrections")
        for key, v in (("calibration", cal), ("corrections", fix)):
            if v is not None and not isinstance(v, str):
                self.err(s, key, "must be a path string")
        return VideoConfig(fps, start, stop, K, dist, cal, fix)

    def targets(self, d):
        s = "targets"
        self._take(d, s, TargetsConfig)
        style = self.choice(d.get("style", "aruco"), TARGET_STYLES, s, "style")
        default_dict = "DICT_APRILTAG_36h11" if style == "apriltag" else "DICT_4X4_50"
        dictionary = d.get("dictionary", default_dict)
        import cv2

        if not isinstance(dictionary, str) or not dictionary.startswith("DICT_") or not hasattr(cv2.aruco, dictionary):
            self.err(
                s,
                "dictionary",
                f"unknown dictionary {dictionary!r}; use an OpenCV name such as DICT_4X4_50 or DICT_APRILTAG_36h11",
            )
        return TargetsConfig(
            style=style,
            dictionary=dictionary,
            marker_size_m=self.num(d.get("marker_size_m"), s, "marker_size_m", positive=True),
            corner_refinement=self.choice(
                d.get("corner_refinement", "edges"), CORNER_REFINEMENTS, s, "corner_refinement"
            ),
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
                frame=self.num(b.get("frame", 0), bs, "frame", integer=True, allow_none=False),
            )
        line = self.matrix(d.get("level_line_px"), (2, 2), s, "level_line_px")
        if level == "line" and (line is None or (line[0][0] - line[1][0]) ** 2 + (line[0][1] - line[1][1]) ** 2 < 400):
            self.err(
                s,
                "level_line_px",
                "level = 'line' needs level_line_px = [[u0, v0], [u1, v1]] (px, first "
                "frame), at least 20 px apart along a horizontal edge",
            )
        lobj = d.get("level_object")
        if lobj is not None and not isinstance(lobj, str):
            self.err(s, "level_object", "must be an object id (string)")
        return ReferenceConfig(
            level=level,
            level_rad=self.num(d.get("level_rad", 0.0), s, "level_rad", allow_none=False),
            level_line_px=line,
            level_object=lobj,
            m_per_px=self.num(d.get("m_per_px"), s, "m_per_px", positive=True),
            homography=self._homography(d.get("homography"), s),
            board=board,
            plane=self.choice(d.get("plane", "auto"), ("auto", "table", "image"), s, "plane"),
        )

    def motion(self, d):
        s = "motion"
        self._take(d, s, MotionConfig)
        order = self.num(d.get("sg_polyorder"), s, "sg_polyorder", integer=True)
        if order is not None and order < 2:
            self.err(s, "sg_polyorder", "must be >= 2 so acceleration is defined")
        gap = self.num(
            d.get("interpolate_max_gap_frames", 0), s, "interpolate_max_gap_frames", integer=True, allow_none=False
        )
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
        dots = self.matrix(dots, (len(dots) if isinstance(dots, list) else -1, 2), s, "dots", i) if dots else ()
        roi = self.vector(d.get("roi"), s, "roi", i, n=4)
        if roi is not None and (roi[2] <= 0 or roi[3] <= 0):
            self.err(s, "roi", "must be [u, v, width, height] with positive size (px)", i)
        size = self.vector(d.get("size_m"), s, "size_m", i, n=2)
        if size is not None and min(size) <= 0:
            self.err(s, "size_m", "must be [b_m, h_m] > 0", i)
        own = d.get("style")
        if own is not None:
            own = self.choice(own, TARGET_STYLES, s, "style", i)
        style = own or targets.style
        if style in ("aruco", "apriltag") and not markers:
            self.err(s, "markers", f"style {style!r} needs the marker ids on this object, e.g. markers = [1]", i)
        if style == "dots" and len(dots) < 2:
            self.err(s, "dots", "style 'dots' needs at least two dot centres [[x_m, y_m], ...]", i)
        if style in ("edges", "region", "markerless") and roi is None:
            self.err(s, "roi", f"style {style!r} needs roi = [u, v, width, height] (px, first frame)", i)
        return ObjectConfig(
            id=oid,
            kind=kind,
            markers=markers,
            marker_positions_m=mpos,
            dots=dots,
            roi=roi,
            size_m=size,
            theta0_rad=self.num(d.get("theta0_rad"), s, "theta0_rad", i),
            marker_size_m=self.num(d.get("marker_size_m"), s, "marker_size_m", i, positive=True),
            style=own,
        )
