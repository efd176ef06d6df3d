"""ArUco / AprilTag fiducials: windowed detection around the predicted pose.

The full frame is searched only at the start and while an object is lost;
otherwise each object is searched in a window around its constant-velocity
prediction, which keeps 1080p tracking well above 100 frames/s.

A small marker (a few pixels per cell) that compression has blurred is missed
one frame in four; the object's angle would then come from the four corners of
its other marker alone, several times less precise than from the pair. So a
missed marker is searched again where a found sibling marker and the object's
layout put it, and a small one is decoded from a cubic-upscaled window
(:data:`UPSCALE_BELOW_PX`).
"""

from __future__ import annotations

import numpy as np

from ...._errors import InputError
from ._detection import Detection
from ._edges import refine_rectangle
from .._camera_model import fit_similarity

__all__ = ["ArucoDetector", "Detection"]

_REFINE = {
    "none": "CORNER_REFINE_NONE",
    "subpix": "CORNER_REFINE_SUBPIX",
    "contour": "CORNER_REFINE_CONTOUR",
    "apriltag": "CORNER_REFINE_APRILTAG",
    "edges": "CORNER_REFINE_NONE",
}
#: A marker smaller than this (px, its bounding box) that the tracking window misses is decoded
#: again from a cubic-upscaled window: at 2 px per cell, H.264 blurs the bits below the
#: detector's reach (the demo's B9M markers, 13 px: one of its two markers was missed on 56 of
#: 200 frames, the angle then came from one marker, 1.5-2.5 deg off), while the upscaled
#: window decodes them (56 of 56).
UPSCALE_BELOW_PX = 40.0
UPSCALE = 3
#: An object of several markers seen through one marker smaller than this (px) gives no pose
#: (``one_marker``): the angle from one small marker's four corners is several times less
#: precise than from the pair (the demo's 13 px B9M markers: 0.95 deg RMS, 1.7 deg off among
#: poses the verifier let through, against 0.1 deg RMS from two).
ONE_MARKER_MIN_PX = 40.0
# Object-frame corner offsets (y up) in OpenCV's order TL, TR, BR, BL, unit side.
UNIT_CORNERS = np.array([[-0.5, 0.5], [0.5, 0.5], [0.5, -0.5], [-0.5, -0.5]])


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


def refine_marker_corners(gray, corners, cells=6):
    """Marker corners from sub-pixel lines fitted to the marker's four outer edges.

    OpenCV's ``cornerSubPix`` is made for X-junctions; on the outer corner of a
    black square it is pulled inwards by the blur (here about 0.25 px per
    corner at 0.8 px blur, a 1 % scale error on a 45 px marker). The outer
    edges are located as grey-level crossings across each side (profiles kept
    inside the black border cell and the white quiet zone) and intersected.
    Falls back to the input corners (and sigma NaN) when a side cannot be measured.

    Returns
    -------
    corners : ndarray (4, 2)
    sigma_theta_rad : float
        The marker's orientation uncertainty from the edge-line scatter.
    """

    side = float(np.mean(np.hypot(*(np.roll(corners, -1, axis=0) - corners).T)))
    half = float(np.clip(0.5 * side / cells, 1.5, 4.0))
    # One pass: a profile slightly off the normal still crosses the edge on the edge.
    # About 30 profiles per side: closer ones share their noise through the blur.
    out, _, _, sig = refine_rectangle(gray, corners, half=half, step=max(1.5, side / 38), trim=0.12)
    if out is None or np.max(np.abs(out - corners)) > 0.5 * half + 1.0:
        return corners, np.nan
    return out, sig


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
        self.edge_refine = config.targets.corner_refinement == "edges"
        self.sigma = {}  # marker id -> orientation sigma of its last detection (rad)
        n_dict = int(dictionary.bytesList.shape[0])
        for i, o in enumerate(config.objects):
            bad = [m for m in o.markers if m >= n_dict]
            if bad:
                raise InputError(
                    f"{config.source or 'config'}: 'objects[{i}].markers': id {bad[0]} "
                    f"is not in {config.targets.dictionary} (ids 0..{n_dict - 1}); "
                    "fix the id or the dictionary"
                )
        self.size = {o.id: o.marker_size_m or config.targets.marker_size_m for o in config.objects}
        self.owner = {m: o.id for o in config.objects for m in o.markers}
        self.layout = {}
        for o in config.objects:
            if o.marker_positions_m is not None:
                self.layout[o.id] = {m: np.asarray(c, float) for m, c in zip(o.markers, o.marker_positions_m)}
            elif len(o.markers) == 1:
                self.layout[o.id] = {o.markers[0]: np.zeros(2)}
        self.last = {}  # marker id -> (frame, corners (4,2))
        self.prev = {}
        self.margin = config.targets.search_margin
        self.ever_seen = set()
        self.refused = {}  # object id -> why its detection in the last frame was withheld

    # ---------------------------------------------------------------- search
    def _windowed(self, side_px):
        """Detector with one threshold window of ~1.5 marker cells (cached per size)."""
        cell = side_px / self.cells
        win = int(np.clip(2 * round(0.75 * cell) + 1, 5, 61))
        det = self._win_dets.get(win)
        if det is None:
            det = self._win_dets[win] = make_cv_detector(self.cfg.targets, win)[0]
        return det

    def _detect(self, gray, x0=0, y0=0, det=None, upscale=1):
        """Markers in ``gray`` (a crop at ``x0, y0``), corners in frame pixels; ``upscale`` > 1
        decodes a cubic-upscaled copy (corners mapped back, then refined on ``gray`` itself)."""
        import cv2

        img = gray if upscale == 1 else cv2.resize(gray, None, fx=upscale, fy=upscale, interpolation=cv2.INTER_CUBIC)
        corners, ids, _ = (det or self.det).detectMarkers(img)
        out = {}
        if ids is None:
            return out
        for c, i in zip(corners, ids.ravel()):
            i = int(i)
            if i in self.owner:
                # pixel centres: x in the upscaled image is (x + 0.5) * upscale - 0.5
                c = (c.reshape(4, 2).astype(float) + 0.5) / upscale - 0.5
                sig = np.nan
                if self.edge_refine:
                    c, sig = refine_marker_corners(gray, c)
                self.sigma[i] = sig
                out[i] = c + (x0, y0)
        return out

    def _predict(self, m, frame):
        f1, c1 = self.last[m]
        if m in self.prev and frame - f1 <= 2:
            f0, c0 = self.prev[m]
            return c1 + (c1 - c0) * (frame - f1) / max(f1 - f0, 1)
        return c1

    def _search_window(self, gray, m, pts, extra_px=0.0):
        """Markers found in a window round the predicted corners ``pts`` (4, 2) of marker ``m``:
        a threshold window matched to its size, then (e.g. under motion blur) the default
        three-window detector, then, for a small marker, the upscaled window."""
        H, W = gray.shape[:2]
        side = max(np.ptp(pts[:, 0]), np.ptp(pts[:, 1]), 8.0)
        pad = self.margin * side + 2 + extra_px
        x0 = int(max(np.floor(pts[:, 0].min() - pad), 0))
        y0 = int(max(np.floor(pts[:, 1].min() - pad), 0))
        x1 = int(min(np.ceil(pts[:, 0].max() + pad), W))
        y1 = int(min(np.ceil(pts[:, 1].max() + pad), H))
        if x1 - x0 < 16 or y1 - y0 < 16:
            return {}  # left the frame
        crop = gray[y0:y1, x0:x1]
        got = self._detect(crop, x0, y0, self._windowed(side))
        if m not in got:
            got = self._detect(crop, x0, y0)
        if m not in got and side < UPSCALE_BELOW_PX:
            got = self._detect(crop, x0, y0, upscale=UPSCALE)
        return got

    def _from_sibling(self, o, m, found):
        """Predicted corners (4, 2) px of ``o``'s marker ``m`` (not found in this frame) and the
        window's extra margin, px: ``m``'s place in the object's layout, carried by the pose of
        a sibling marker that was found (None without a layout or a sibling)."""
        lay = self.layout.get(o.id)
        sib = next((k for k in o.markers if k in found and k != m), None)
        if lay is None or sib is None or m not in lay:
            return None
        s = self.size[o.id] or 1.0
        f = fit_similarity(lay[sib] + UNIT_CORNERS * s, self.pm.to_plane(found[sib]))
        c, si = np.cos(f.theta_rad), np.sin(f.theta_rad)
        q = f.scale * (lay[m] + UNIT_CORNERS * s) @ np.array([[c, si], [-si, c]]) + f.t
        pts = np.asarray(self.pm.to_image(q), float)
        # one small marker's angle is known to a few degrees only: widen by 10 % of the distance
        return pts, 0.1 * float(np.hypot(*(pts.mean(axis=0) - found[sib].mean(axis=0))))

    def find(self, gray, frame):
        """Detect the configured markers: ``{marker id: corners (4, 2) px}``.

        Each recently seen marker is searched in a window around its predicted
        corners (:meth:`_search_window`); a marker of an object whose other
        marker was found, but not itself, is searched where that marker puts it
        (:meth:`_from_sibling`); the full frame is searched when an object has
        no recent marker, and every 25 frames while some configured marker is
        missing.
        """
        found = {}
        need_full = frame % 25 == 0 and any(m not in self.last or frame - self.last[m][0] > 2 for m in self.owner)
        for o in self.cfg.objects:
            ms = [m for m in o.markers if m in self.last and frame - self.last[m][0] <= 2]
            if not ms:
                need_full = True
                continue
            for m in ms:
                if m not in found:
                    for k, v in self._search_window(gray, m, self._predict(m, frame)).items():
                        found.setdefault(k, v)
            if not any(m in found for m in o.markers):
                need_full = True
        if need_full:
            for k, v in self._detect(gray).items():
                found.setdefault(k, v)
        for o in self.cfg.objects:
            for m in o.markers:
                pred = None if m in found else self._from_sibling(o, m, found)
                if pred is not None:
                    for k, v in self._search_window(gray, m, *pred).items():
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
            fits[m] = fit_similarity(UNIT_CORNERS * (self.size[o.id] or 1.0), q)
        f0 = fits[o.markers[0]]
        rot = np.array(
            [[np.cos(-f0.theta_rad), -np.sin(-f0.theta_rad)], [np.sin(-f0.theta_rad), np.cos(-f0.theta_rad)]]
        )
        k = np.mean([f.scale for f in fits.values()])
        return {m: rot @ (fits[m].t - f0.t) / k for m in o.markers}

    def detect(self, gray, frame):
        """Per object: a :class:`Detection` or None (not seen, or seen through one small marker
        of several: :meth:`lost_reason` says ``one_marker``)."""
        found = self.find(gray, frame)
        out = {}
        self.refused = {}
        for o in self.cfg.objects:
            have = [m for m in o.markers if m in found]
            if not have:
                out[o.id] = None
                continue
            if len(o.markers) > 1 and len(have) == 1 and np.ptp(found[have[0]], axis=0).max() < ONE_MARKER_MIN_PX:
                out[o.id], self.refused[o.id] = None, "one_marker"
                continue
            lay = self.layout.get(o.id)
            if lay is None:
                if len(have) < len(o.markers):
                    out[o.id] = None  # layout unknown until every marker was seen once
                    continue
                lay = self.layout[o.id] = self._learn_layout(o, found)
            s = self.size[o.id] or 1.0
            img = np.vstack([found[m] for m in have])
            obj = np.vstack([lay[m] + UNIT_CORNERS * s for m in have])
            sig = np.array([self.sigma.get(m, np.nan) for m in have])
            # markers are independent: the mean orientation's sigma shrinks with their number
            sig_mean = float(np.sqrt(np.nansum(sig**2)) / len(have)) if np.any(np.isfinite(sig)) else 0.0
            out[o.id] = Detection(img, obj, self.size[o.id] is not None, 4 * len(o.markers), sig_mean, len(have))
        return out

    def lost_reason(self, oid):
        """``"one_marker"`` when object ``oid``'s last frame showed only one of its small markers."""
        return self.refused.get(oid)
