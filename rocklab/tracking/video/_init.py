"""A tracking config from the first frame: markers found by trying the common dictionaries,
objects grouped from them, or user-given regions followed markerless.

Pure functions on images and configs; the ``rocklab track init`` command writes the
result as a commented ``track.toml`` and draws the preview.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._errors import InputError
from ._checks import region_leaves, region_overlap
from .targets._markerless import MIN_TEXTURE_STD, texture_std
from ...config import ObjectConfig, ReferenceConfig, TargetsConfig, TrackConfig, VideoConfig

__all__ = [
    "DICTIONARIES",
    "MarkerFinding",
    "find_markers",
    "suggest_config",
    "parse_region",
    "texture_std",
    "MIN_TEXTURE_STD",
]

#: Dictionaries tried, most common first (ArUco 4x4..6x6, AprilTag 36h11, original ArUco).
DICTIONARIES = (
    "DICT_4X4_50",
    "DICT_5X5_100",
    "DICT_6X6_250",
    "DICT_APRILTAG_36h11",
    "DICT_ARUCO_ORIGINAL",
    "DICT_4X4_1000",
    "DICT_5X5_1000",
    "DICT_6X6_1000",
    "DICT_7X7_1000",
    "DICT_APRILTAG_25h9",
)


@dataclass(frozen=True)
class MarkerFinding:
    """Markers found in one frame with one dictionary.

    Attributes
    ----------
    dictionary : str
        OpenCV dictionary name.
    ids : tuple of int
    corners_px : ndarray (n, 4, 2)
        Corner pixels (u right, v down), OpenCV order.
    """

    dictionary: str
    ids: tuple
    corners_px: np.ndarray = field(repr=False)

    @property
    def centres_px(self) -> np.ndarray:
        """Marker centres, px, shape (n, 2)."""
        return self.corners_px.mean(axis=1)

    @property
    def sizes_px(self) -> np.ndarray:
        """Mean side length of each marker, px, shape (n,)."""
        c = self.corners_px
        return np.mean(np.linalg.norm(c - np.roll(c, 1, axis=1), axis=2), axis=1)


def find_markers(gray) -> MarkerFinding | None:
    """The dictionary that finds the most markers in ``gray`` (ties: the earlier in
    :data:`DICTIONARIES`), or None when none finds any."""
    import cv2

    best = None
    for name in DICTIONARIES:
        d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, name))
        det = cv2.aruco.ArucoDetector(d, cv2.aruco.DetectorParameters())
        corners, ids, _ = det.detectMarkers(gray)
        if ids is None or not len(ids):
            continue
        f = MarkerFinding(name, tuple(int(i) for i in ids.ravel()), np.asarray(corners, float).reshape(-1, 4, 2))
        if best is None or len(f.ids) > len(best.ids):
            best = f
    return best


def parse_region(text: str, option: str) -> tuple:
    """``"x,y,w,h"`` (px) as a 4-tuple of floats, or a one-line :class:`InputError`."""
    try:
        v = tuple(float(x) for x in str(text).split(","))
    except ValueError:
        v = ()
    if len(v) != 4 or v[2] <= 0 or v[3] <= 0 or not all(np.isfinite(v)):
        raise InputError(f"{option} {text!r}: give x,y,w,h in pixels of the first frame (w, h > 0)")
    return v


def _group_markers(f: MarkerFinding):
    """Table = markers on the lowest row spread over more than 3 marker sizes; blocks = the rest,
    grouped by horizontal proximity (a column of markers on one block), left to right."""
    c, s = f.centres_px, f.sizes_px
    ids = np.array(f.ids)
    size = float(np.median(s))
    low = c[:, 1] >= c[:, 1].max() - 1.0 * size
    table = []
    if low.sum() >= 2 and np.ptp(c[low, 0]) > 3 * size:
        table = sorted(int(i) for i in ids[low])
    rest = [k for k in range(len(ids)) if int(ids[k]) not in table]
    groups: list[list[int]] = []
    for k in sorted(rest, key=lambda k: c[k, 0]):
        if groups and abs(c[k, 0] - np.mean([c[j, 0] for j in groups[-1]])) < 1.5 * size:
            groups[-1].append(k)
        else:
            groups.append([k])
    blocks = [sorted(int(ids[k]) for k in g) for g in groups]
    return table, blocks


def suggest_config(
    first_gray,
    *,
    regions: dict | None = None,
    table_roi=None,
    fps: float | None = None,
    marker_size_m: float | None = None,
    found: MarkerFinding | None = None,
    level_line_px=None,
    start_frame: int = 0,
    rest_check=None,
) -> tuple[TrackConfig, list[str], MarkerFinding | None]:
    """A tracking config for a video from its first frame.

    Parameters
    ----------
    first_gray : ndarray (H, W) uint8
    regions : dict name -> (x, y, w, h), optional
        User-given objects (px, first frame), followed markerless; with them no marker search.
    table_roi : (x, y, w, h), optional
        A markerless table (levelling comes from its top edge).
    fps : float, optional
        Written when the container has no frame rate.
    marker_size_m : float, optional
        Marker side, m (gives the metric scale of marker targets).
    found : MarkerFinding, optional
        The markers already found in ``first_gray`` (the search is not repeated).
    level_line_px : ((u0, v0), (u1, v1)), optional
        Without a table: a horizontal line of the first frame (px) that levels the angles.
    start_frame : int
        The frame ``first_gray`` is (``[video] start_frame``: tracking starts there).
    rest_check : callable, optional
        ``rest_check(box) -> (bool, str)``: whether the first block, at ``box`` (x, y, w, h px), is at
        rest at the end of the film, and what was measured
        (:func:`~rocklab.tracking.video._level.rests_at_end`). Without a table or a level line the
        level is ``"rest"`` when it is (or when not told), else ``"none"`` with a note: a pendulum or
        a ball never rests, and ``"rest"`` would warn on every run of the config.

    Returns
    -------
    (TrackConfig, notes, MarkerFinding or None)
        ``notes``: one line each, written as comments into the TOML.
    """
    notes: list[str] = []
    video = VideoConfig(fps=fps, start_frame=int(start_frame))
    H, W = first_gray.shape[:2]

    def inside(option, roi):
        if region_leaves(roi, W, H):
            raise InputError(f"{option}: region {list(roi)} leaves the {W}x{H} first frame; give it inside")
        return roi

    if regions or table_roi is not None:
        objs = [ObjectConfig(id=n, kind="block", roi=inside(f"--object {n}", r)) for n, r in (regions or {}).items()]
        if table_roi is not None:
            objs.append(ObjectConfig(id="table", kind="table", roi=inside("--table", table_roi)))
        _check_overlaps(objs)
        for o in objs:
            _check_texture(first_gray, "--table" if o.kind == "table" else f"--object {o.id}", o.roi)
        notes.append("objects followed markerless from the regions given (px, first frame)")
        notes.append(
            "a block's theta starts at its theta0_rad (not given: upright in the first frame, or "
            "from its final rest when it ends at rest tilted); set theta0_rad (rad, ccw) for a "
            "release from a tilt"
        )
        if level_line_px is not None and table_roi is None:
            level = "line"
        elif table_roi is None:
            first = next(iter(regions.values()), None) if regions else None
            level, note = _rest_or_none(rest_check, first)
            notes.append(note + "; a table levels instead: add --table x,y,w,h round its top edge")
        else:
            level = "table"
        if marker_size_m is None:
            notes.append("no metric scale: x_m, y_m stay empty; set reference.m_per_px (m per pixel)")
        cfg = TrackConfig(
            objects=tuple(objs),
            video=video,
            targets=TargetsConfig(style="markerless"),
            reference=ReferenceConfig(
                level=level,
                level_line_px=None if level != "line" else tuple(tuple(float(v) for v in p) for p in level_line_px),
            ),
        )
        return cfg, notes, None
    found = found if found is not None else find_markers(first_gray)
    if found is None:
        raise InputError(
            "no ArUco/AprilTag marker found in the first frame (tried "
            f"{', '.join(DICTIONARIES[:5])}, ...); give the objects as --object NAME=x,y,w,h "
            "(and --table x,y,w,h) to follow them markerless"
        )
    table, blocks = _group_markers(found)
    style = "apriltag" if "APRILTAG" in found.dictionary else "aruco"
    objs = []
    if table:
        objs.append(ObjectConfig(id="table", kind="table", markers=tuple(table)))
    for k, ms in enumerate(blocks, start=1):
        objs.append(ObjectConfig(id=f"block_{k}", kind="block", markers=tuple(ms)))
    notes.append(f"{len(found.ids)} markers found with {found.dictionary}: ids {sorted(found.ids)}")
    notes.append(
        f"grouped as: table {table or '(none)'}; " + "; ".join(f"block_{k} {m}" for k, m in enumerate(blocks, start=1))
    )
    level = "table"
    if not table:
        level, note = _rest_or_none(rest_check, _marker_box(found, blocks[0]) if blocks else None)
        notes.append("no table found (markers spread along the lowest row): " + note)
    if marker_size_m is None:
        notes.append("marker size unknown: x_m, y_m stay empty; set targets.marker_size_m (m)")
    cfg = TrackConfig(
        objects=tuple(objs),
        video=video,
        targets=TargetsConfig(style=style, dictionary=found.dictionary, marker_size_m=marker_size_m),
        reference=ReferenceConfig(level=level),
    )
    return cfg, notes, found


#: What ``level = "rest"`` assumes, and what to do when it does not hold.
_REST_NOTE = (
    "level = \"rest\": the camera's roll is taken from the first block's final rest (free rocking "
    "ends upright; W-LEVEL-NONE when it does not come to rest in the film: then set reference.level "
    '= "line", "value" or "none")'
)


def _rest_or_none(rest_check, box) -> tuple[str, str]:
    """(level, its note) without a table or a line: ``"rest"`` when the first block (at ``box``)
    rests at the film's end by ``rest_check`` (or nothing says otherwise), else ``"none"``."""
    if rest_check is None or box is None:
        return "rest", _REST_NOTE
    rests, why = rest_check(box)
    if rests:
        return "rest", f"{_REST_NOTE}; the first block: {why}"
    return "none", (
        f'level = "none": the angles are not levelled (the camera\'s roll stays in them). No table edge was '
        f'found, and level = "rest" needs the first block at rest in view at the film\'s end (free rocking), '
        f"but {why}: a pendulum or a ball that never rests would warn W-LEVEL-NONE on every run; to level, "
        'add --table x,y,w,h round a horizontal edge or set reference.level = "line" with '
        "level_line_px = [[u0, v0], [u1, v1]] on one"
    )


def _marker_box(found: MarkerFinding, ids) -> tuple:
    """(x, y, w, h) px round the markers ``ids`` of ``found``."""
    c = found.corners_px[[found.ids.index(i) for i in ids]].reshape(-1, 2)
    lo, hi = c.min(axis=0), c.max(axis=0)
    return (float(lo[0]), float(lo[1]), float(hi[0] - lo[0]), float(hi[1] - lo[1]))


def _check_texture(first_gray, option: str, roi) -> None:
    """A one-line :class:`InputError` for a region the markerless tracker would refuse at its first
    frame (grey std below :data:`MIN_TEXTURE_STD`), before a config is written."""
    std = texture_std(first_gray, roi)
    if not std >= MIN_TEXTURE_STD:
        raise InputError(
            f"{option}: region {list(roi)} holds no texture (grey std {std:.3g} < {MIN_TEXTURE_STD:g}); "
            "draw it round the object's edges or surface detail"
        )


def _check_overlaps(objs) -> None:
    """Two objects' regions may touch but not overlap by more than 20 % of the smaller
    (:func:`region_overlap`): a tracker would latch onto the other object."""
    for i, a in enumerate(objs):
        for b in objs[i + 1 :]:
            area, too_much = region_overlap(a.roi, b.roi)
            if too_much:
                raise InputError(
                    f"objects {a.id!r} and {b.id!r}: their regions overlap by {area:.0f} px^2; "
                    "draw each round its own object only"
                )
