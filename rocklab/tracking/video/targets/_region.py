"""Generic region tracker: features of a user-given region followed with
pyramidal Lucas-Kanade optical flow, against the *first* frame (no drift).
Each frame is first resampled onto the reference grid with the predicted
pose (constant velocity), so LK only sees the small prediction error and
large rotations are tracked.

The object points are the features' plane positions in the first frame
(relative to the roi centre, rotated by ``-theta0_rad``), so the rigid fit
returns the rotation since the first frame plus ``theta0_rad`` and the scale
in plane units per first-frame plane unit (metres then come from
``reference.m_per_px`` or the other objects' scale).
"""

from __future__ import annotations

import numpy as np

from ._detection import Detection

__all__ = ["RegionTracker", "RegionDetector"]


class RegionTracker:
    """One region's feature tracker.

    Parameters
    ----------
    obj : ObjectConfig
        Needs ``roi = (u, v, w, h)`` px in the first frame.
    plane_map : PlaneMap
    first_gray : ndarray (H, W) uint8
    """

    def __init__(self, obj, plane_map, first_gray, max_features=150):
        import cv2

        self.obj = obj
        self.pm = plane_map
        u, v, w, h = (int(round(x)) for x in obj.roi)
        mask = np.zeros_like(first_gray)
        mask[max(v, 0) : v + h, max(u, 0) : u + w] = 255
        f = cv2.goodFeaturesToTrack(first_gray, max_features, 0.01, 5, mask=mask, blockSize=7)
        self.ref = first_gray
        self.p_ref = np.zeros((0, 2), np.float32) if f is None else f.reshape(-1, 2).astype(np.float32)
        if len(self.p_ref):
            self.p_ref = cv2.cornerSubPix(
                first_gray,
                self.p_ref.reshape(-1, 1, 2),
                (5, 5),
                (-1, -1),
                (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 30, 0.01),
            ).reshape(-1, 2)
        q = plane_map.to_plane(self.p_ref) if len(self.p_ref) else np.zeros((0, 2))
        cu, cv_ = obj.roi[0] + obj.roi[2] / 2, obj.roi[1] + obj.roi[3] / 2
        centre = plane_map.to_plane(np.array([[cu, cv_]]))[0]
        th0 = obj.theta0_rad or 0.0
        c, s = np.cos(-th0), np.sin(-th0)
        self.obj_pts = (q - centre) @ np.array([[c, -s], [s, c]]).T
        self.A_last = None  # 2x3 affine ref px -> current px
        self.A_prev = None
        self.win = (21, 21)
        H, W = first_gray.shape[:2]
        if len(self.p_ref):
            m = 24
            self.box = (
                int(max(self.p_ref[:, 0].min() - m, 0)),
                int(max(self.p_ref[:, 1].min() - m, 0)),
                int(min(self.p_ref[:, 0].max() + m + 1, W)),
                int(min(self.p_ref[:, 1].max() + m + 1, H)),
            )
            x0, y0, x1, y1 = self.box
            self.ref_crop = first_gray[y0:y1, x0:x1].copy()

    def detect(self, gray, frame):
        """The region's features in ``gray``: a :class:`Detection` or None (lost)."""
        import cv2

        if len(self.p_ref) < 3:
            return None
        A = np.array([[1.0, 0, 0], [0, 1.0, 0]]) if self.A_last is None else self.A_last.copy()
        if self.A_prev is not None:
            A = A + (A - self.A_prev)  # constant-velocity prediction of the pose
        # Undo the predicted rotation/translation first (the current frame resampled onto
        # the reference grid), so LK only sees the small prediction error and large
        # rotations do not deform its windows.
        x0, y0, x1, y1 = self.box
        T = np.array([[1.0, 0, x0], [0, 1.0, y0], [0, 0, 1.0]])
        M = A @ T
        warped = cv2.warpAffine(
            gray, M, (x1 - x0, y1 - y0), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP, borderMode=cv2.BORDER_REPLICATE
        )
        p0 = (self.p_ref - (x0, y0)).astype(np.float32).reshape(-1, 1, 2)
        pw, st, err = cv2.calcOpticalFlowPyrLK(
            self.ref_crop,
            warped,
            p0,
            p0.copy(),
            winSize=self.win,
            maxLevel=2,
            flags=cv2.OPTFLOW_USE_INITIAL_FLOW,
            criteria=(cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 40, 0.005),
        )
        pr = pw.reshape(-1, 2).astype(float) + (x0, y0)  # in reference coordinates
        p = pr @ A[:, :2].T + A[:, 2]  # in the current frame
        ok = st.ravel() == 1
        if ok.sum() < 3:
            self.A_last = self.A_prev = None
            return None
        A_new, inl = cv2.estimateAffinePartial2D(
            self.p_ref[ok], p[ok].astype(np.float32), method=cv2.RANSAC, ransacReprojThreshold=1.0
        )
        if A_new is None:
            return None
        idx = np.flatnonzero(ok)[inl.ravel() == 1]
        if len(idx) < 3 or len(idx) < 0.3 * len(self.p_ref):
            self.A_last = self.A_prev = None
            return None
        self.A_prev, self.A_last = self.A_last, A_new
        return Detection(p[idx], self.obj_pts[idx], False, len(self.p_ref))


class RegionDetector:
    """Detector for the ``region`` style: one :class:`RegionTracker` per object."""

    def __init__(self, config, plane_map, first_gray):
        self.trackers = {o.id: RegionTracker(o, plane_map, first_gray) for o in config.objects}

    def detect(self, gray, frame):
        return {oid: t.detect(gray, frame) for oid, t in self.trackers.items()}
