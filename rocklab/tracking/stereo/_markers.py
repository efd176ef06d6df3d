"""ArUco markers in two films: corners found by id in each frame, so identity needs no tracking.

Every corner of every marker seen is a target labelled ``M<id>c<k>`` (k = 0..3,
OpenCV's corner order). The films share labels, so matching is by name; the clock
offset and the triangulation are those of the dot tracker
(:func:`~rocklab.tracking.stereo.sync_offset_stereo`,
:func:`~rocklab.tracking.stereo.triangulate_tracks`).
"""

from __future__ import annotations

import numpy as np

from ..._errors import InputError, where
from ._calib import StereoRig
from ._setup import check_depth_in_front, check_film_order, check_unsynchronised
from ._dots3d import DotTracks2D, StereoPoints, check_films, sync_offset_stereo, triangulate_tracks

__all__ = ["track_markers_2d", "track_markers_stereo"]


def track_markers_2d(frames, dictionary: str = "DICT_4X4_50", source: str = ""):
    """``({label: (n, 2) px}, n_frames)`` of every ArUco corner in ``frames`` (NaN where not seen)."""
    import cv2

    if not hasattr(cv2.aruco, dictionary):
        raise InputError(f"--dictionary {dictionary!r}: not an ArUco dictionary; e.g. DICT_4X4_50, DICT_5X5_100")
    params = cv2.aruco.DetectorParameters()
    params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    det = cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, dictionary)), params)
    seen: dict = {}
    n = 0
    for i, gray in enumerate(frames):
        corners, ids, _ = det.detectMarkers(gray)
        if ids is not None:
            for c, mid in zip(corners, ids.ravel()):
                for k in range(4):
                    seen.setdefault(f"M{int(mid)}c{k}", {})[i] = c.reshape(4, 2)[k]
        n = i + 1
    if not seen:
        raise InputError(
            f"{where(source)}no {dictionary} marker found in {n} frames; check the dictionary "
            "(--dictionary) and that the markers are in view and sharp"
        )
    out = {}
    for lab, d in seen.items():
        a = np.full((n, 2), np.nan)
        idx = np.fromiter(d.keys(), int)
        a[idx] = np.array([d[j] for j in idx])
        out[lab] = a
    return out, n


def _sort_key(label: str):
    mid, k = label[1:].split("c")
    return int(mid), int(k)


def track_markers_stereo(
    film1, film2, rig: StereoRig, dictionary: str = "DICT_4X4_50", fps: float | None = None, sync: bool = True
) -> StereoPoints:
    """ArUco corners of two films to 3D points in camera 1's axes (labels in ``StereoPoints.labels``)."""
    from ._calib import frames_by_index, warn_lost

    rate = check_films(film1, film2, rig, fps)
    lost: list = []
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(max_workers=2) as ex:
        jobs = [ex.submit(track_markers_2d, frames_by_index(f, lost), dictionary, str(f)) for f in (film1, film2)]
        (m1, n1), (m2, n2) = (j.result() for j in jobs)
    warn_lost(lost)
    labels = sorted(set(m1) & set(m2), key=_sort_key)
    if len(labels) < 3:
        raise InputError(
            f"{where(film1)}{len(labels)} marker corner(s) seen by both cameras; need markers both "
            f"cameras see (camera 1: {len(m1) // 4} markers, camera 2: {len(m2) // 4})"
        )
    t1 = DotTracks2D(np.stack([m1[lab] for lab in labels], axis=1), str(film1))
    t2 = DotTracks2D(np.stack([m2[lab] for lab in labels], axis=1), str(film2))
    pairs = np.column_stack([np.arange(len(labels)), np.arange(len(labels))])
    check_film_order(rig, t1.uv_px, t2.uv_px, film1, film2)
    so = sync_offset_stereo(rig, t1, t2, pairs, rate)
    if not sync:
        check_unsynchronised(so, film1, film2)
        so = None
    lag = so.offset_frames if so is not None else 0.0
    pts = triangulate_tracks(rig, t1, t2, pairs, lag, rate)
    check_depth_in_front(pts.xyz_m, film1, film2)
    return StereoPoints(pts.t_s, pts.xyz_m, pts.reproj_px, pairs, so, pts.notes, tuple(labels))
