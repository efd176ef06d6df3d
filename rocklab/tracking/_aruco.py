"""ArUco / AprilTag fiducials: windowed detection around the predicted pose.

The full frame is searched only at the start and while an object is lost;
otherwise each object is searched in a window around its constant-velocity
prediction, which keeps 1080p tracking well above 100 frames/s.
"""

from __future__ import annotations

import numpy as np

from .._errors import InputError
from ._geometry import fit_similarity

__all__ = ["ArucoDetector", "Detection"]

_REFINE = {"none": "CORNER_REFINE_NONE", "subpix": "CORNER_REFINE_SUBPIX",
           "contour": "CORNER_REFINE_CONTOUR", "apriltag": "CORNER_REFINE_APRILTAG"}
# Object-frame corner offsets (y up) in OpenCV's order TL, TR, BR, BL, unit side.
_UNIT_CORNERS = np.array([[-0.5, 0.5], [0.5, 0.5], [0.5, -0.5], [-0.5, -0.5]])


class Detection:
    """One object's points in one frame.

    Attributes
    ----------
    img_pts : ndarray (n, 2)
        Measured image positions (px, distorted as in the video).
    obj_pts : ndarray (n, 2)
        Matching object-frame positions (m if ``metric`` else object units).
    metric : bool
    n_expected : int
        Points a complete detection would have (quality = n / n_expected ...).
    """

    __slots__ = ("img_pts", "obj_pts", "metric", "n_expected")

    def __init__(self, img_pts, obj_pts, metric, n_expected):
        self.img_pts = np.asarray(img_pts, float).reshape(-1, 2)
        self.obj_pts = np.asarray(obj_pts, float).reshape(-1, 2)
        self.metric = bool(metric)
        self.n_expected = int(n_expected)


def make_cv_detector(targets, win: int | None = None):
    """OpenCV detector; ``win`` fixes a single adaptive-threshold window (px), as used in
    the tracking windows where the marker size is known (one pass instead of three)."""
    import cv2

    d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, targets.dictionary))
    p = cv2.aruco.DetectorParameters()
    p.cornerRefinementMethod = getattr(cv2.aruco, _REFINE[targets.corner_refinement])
    p.cornerRefinementWinSize = 5
    p.cornerRefinementMaxIterations = 50
    p.cornerRefinementMinAccuracy = 0.005
    if win is not None:
        p.adaptiveThreshWinSizeMin = win
        p.adaptiveThreshWinSizeMax = win
    return cv2.aruco.ArucoDetector(d, p), d


class ArucoDetector:
    """Stateful per-video detector for the ``aruco``/``apriltag`` styles.

    Parameters
    ----------
    config : TrackConfig
    plane_map : PlaneMap
        Used only to learn an unknown multi-marker layout.
    """

    def __init__(self, config, plane_map):
        self.cfg = config
        self.pm = plane_map
        self.det, dictionary = make_cv_detector(config.targets)
        self._win_dets = {}
        self.cells = int(dictionary.markerSize) + 2  # bits plus the black border
        n_dict = int(dictionary.bytesList.shape[0])
        for i, o in enumerate(config.objects):
            bad = [m for m in o.markers if m >= n_dict]
            if bad:
                raise InputError(f"{config.source or 'config'}: 'objects[{i}].markers': id {bad[0]} "
                                 f"is not in {config.targets.dictionary} (ids 0..{n_dict - 1}); "
                                 "fix the id or the dictionary")
        self.size = {o.id: o.marker_size_m or config.targets.marker_size_m for o in config.objects}
        self.owner = {m: o.id for o in config.objects for m in o.markers}
        self.layout = {}
        for o in config.objects:
            if o.marker_positions_m is not None:
                self.layout[o.id] = {m: np.asarray(c, float) for m, c in zip(o.markers, o.marker_positions_m)}
            elif len(o.markers) == 1:
                self.layout[o.id] = {o.markers[0]: np.zeros(2)}
        self.last = {}   # marker id -> (frame, corners (4,2))
        self.prev = {}
        self.margin = config.targets.search_margin
        self.ever_seen = set()

    # ---------------------------------------------------------------- search
    def _windowed(self, side_px):
        """Detector with one threshold window of ~1.5 marker cells (cached per size)."""
        cell = side_px / self.cells
        win = int(np.clip(2 * round(0.75 * cell) + 1, 5, 61))
        det = self._win_dets.get(win)
        if det is None:
            det = self._win_dets[win] = make_cv_detector(self.cfg.targets, win)[0]
        return det

    def _detect(self, gray, x0=0, y0=0, det=None):
        corners, ids, _ = (det or self.det).detectMarkers(gray)
        out = {}
        if ids is None:
            return out
        for c, i in zip(corners, ids.ravel()):
            i = int(i)
            if i in self.owner:
                out[i] = c.reshape(4, 2).astype(float) + (x0, y0)
        return out

    def _predict(self, m, frame):
        f1, c1 = self.last[m]
        if m in self.prev and frame - f1 <= 2:
            f0, c0 = self.prev[m]
            return c1 + (c1 - c0) * (frame - f1) / max(f1 - f0, 1)
        return c1

    def find(self, gray, frame):
        """Detect this object's markers: ``{marker id: corners (4, 2) px}``."""
        H, W = gray.shape[:2]
        found = {}
        need_full = False
        for o in self.cfg.objects:
            ms = [m for m in o.markers if m in self.last and frame - self.last[m][0] <= 2]
            if not ms:
                need_full = True
                continue
            pts = np.vstack([self._predict(m, frame) for m in ms])
            side = max(np.ptp(pts[:4, 0]), np.ptp(pts[:4, 1]), 8.0)
            pad = self.margin * side
            x0 = int(max(np.floor(pts[:, 0].min() - pad), 0))
            y0 = int(max(np.floor(pts[:, 1].min() - pad), 0))
            x1 = int(min(np.ceil(pts[:, 0].max() + pad), W))
            y1 = int(min(np.ceil(pts[:, 1].max() + pad), H))
            if x1 - x0 < 16 or y1 - y0 < 16:
                need_full = True
                continue
            got = self._detect(gray[y0:y1, x0:x1], x0, y0, self._windowed(side))
            found.update({k: v for k, v in got.items() if k not in found})
            if not any(m in found for m in o.markers):
                need_full = True
        if need_full:
            for k, v in self._detect(gray).items():
                found.setdefault(k, v)
        for m, c in found.items():
            if m in self.last:
                self.prev[m] = self.last[m]
            self.last[m] = (frame, c)
            self.ever_seen.add(m)
        return found

    # ---------------------------------------------------------------- points
    def _learn_layout(self, o, found):
        """Marker centres in the object frame from a frame showing all of ``o``'s markers."""
        fits = {}
        for m in o.markers:
            q = self.pm.to_plane(found[m])
            fits[m] = fit_similarity(_UNIT_CORNERS * (self.size[o.id] or 1.0), q)
        f0 = fits[o.markers[0]]
        rot = np.array([[np.cos(-f0.theta_rad), -np.sin(-f0.theta_rad)],
                        [np.sin(-f0.theta_rad), np.cos(-f0.theta_rad)]])
        k = np.mean([f.scale for f in fits.values()])
        return {m: rot @ (fits[m].t - f0.t) / k for m in o.markers}

    def detect(self, gray, frame):
        """Per object: a :class:`Detection` or None (not seen)."""
        found = self.find(gray, frame)
        out = {}
        for o in self.cfg.objects:
            have = [m for m in o.markers if m in found]
            if not have:
                out[o.id] = None
                continue
            lay = self.layout.get(o.id)
            if lay is None:
                if len(have) < len(o.markers):
                    out[o.id] = None  # layout unknown until every marker was seen once
                    continue
                lay = self.layout[o.id] = self._learn_layout(o, found)
            s = self.size[o.id] or 1.0
            img = np.vstack([found[m] for m in have])
            obj = np.vstack([lay[m] + _UNIT_CORNERS * s for m in have])
            out[o.id] = Detection(img, obj, self.size[o.id] is not None, 4 * len(o.markers))
        return out
