"""The image -> rocking-plane mapping a tracking config asks for.

Order of precedence: ``reference.homography``; ``reference.board`` (seen in
one frame); the table's own markers (``reference.plane``); centred pixels.
The lens model (``video.camera_matrix``/``dist_coeffs``/``calibration``)
applies to all of them.
"""

from __future__ import annotations

import numpy as np

from ..._errors import InputError
from ...config import MARKER_STYLES, TrackConfig
from ._camera_model import PlaneMap, board_homography, load_calibration, plane_homography_from_points

__all__ = ["make_plane_map"]


def make_plane_map(config: TrackConfig, width_px: int, height_px: int, first_gray=None) -> PlaneMap:
    """The image -> plane mapping the config asks for: lens model, then a given homography,
    a board, the table's markers (``reference.plane``), or centred pixels."""
    v = config.video
    K, dist = v.camera_matrix, v.dist_coeffs
    if v.calibration:
        K, dist = load_calibration(v.calibration, (width_px, height_px))
    ref = config.reference
    pm = PlaneMap(width_px, height_px, K, dist, ref.homography)
    if ref.homography is not None:
        pm.source = "homography"
        return pm
    if ref.board is not None:
        if first_gray is None:
            raise InputError("reference.board: needs the board frame; use track_video")
        pm = PlaneMap(width_px, height_px, K, dist, board_homography(first_gray, ref.board, pm))
        pm.source = "board"
        return pm
    H = _table_plane(config, pm, first_gray) if ref.plane != "image" else None
    if H is not None:
        pm = PlaneMap(width_px, height_px, K, dist, H)
        pm.source = "table"
    return pm


def _table_plane(config, pm, gray):
    """Homography from the table markers seen in ``gray``, or None (``plane = "auto"``)."""
    tab = config.table
    style = config.targets.style
    strict = config.reference.plane == "table"
    why = None
    if style not in MARKER_STYLES or tab is None:
        why = "needs the aruco/apriltag style and a table object"
    elif tab.marker_positions_m is None and len(tab.markers) > 1:
        why = "needs the table's marker_positions_m"
    elif (tab.marker_size_m or config.targets.marker_size_m) is None:
        why = "needs the marker size"
    elif pm.K is None and not strict:
        # Without intrinsics a free homography from markers along one table edge is poorly
        # conditioned across it (and lens distortion is not removed): centred pixels are
        # the safer default. plane = "table" still forces it (>= 2 markers).
        why = "needs video.camera_matrix"
    elif pm.K is None and len(tab.markers) < 2:
        why = "needs video.camera_matrix or two or more table markers"
    elif gray is None:
        why = "needs the first frame"
    if why is None:
        from .targets._aruco import UNIT_CORNERS, make_cv_detector, refine_marker_corners

        det, _ = make_cv_detector(config.targets)
        corners, ids, _ = det.detectMarkers(gray)
        size = tab.marker_size_m or config.targets.marker_size_m
        pos = tab.marker_positions_m or ((0.0, 0.0),)
        img, obj = [], []
        for c, i in zip(corners, [] if ids is None else ids.ravel()):
            if int(i) in tab.markers:
                k = tab.markers.index(int(i))
                c = c.reshape(4, 2).astype(float)
                if config.targets.corner_refinement == "edges":
                    c, _ = refine_marker_corners(gray, c)
                img.append(c)
                obj.append(np.asarray(pos[k], float) + UNIT_CORNERS * size)
        if len(img) == len(tab.markers):
            return plane_homography_from_points(np.vstack(img), np.vstack(obj), pm)
        why = "not every table marker is visible in the first frame"
    if strict:
        raise InputError(
            f'{config.source or "config"}: \'reference.plane\' = "table" {why}; fix it or use plane = "image"'
        )
    return None
