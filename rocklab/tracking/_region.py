"""Generic region tracker: features of a user-given region followed with
pyramidal Lucas-Kanade optical flow, against the *first* frame (no drift),
seeded with the previous pose so rotation and translation are tracked.

The object points are the features' plane positions in the first frame
(relative to the roi centre, rotated by ``-theta0_rad``), so the rigid fit
returns the rotation since the first frame plus ``theta0_rad`` and the scale
in plane units per first-frame plane unit (metres then come from
``reference.m_per_px`` or the other objects' scale).
"""

from __future__ import annotations

import numpy as np

from ._aruco import Detection

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
        mask[max(v, 0):v + h, max(u, 0):u + w] = 255
        f = cv2.goodFeaturesToTrack(first_gray, max_features, 0.01, 5, mask=mask, blockSize=7)
        self.ref = first_gray
        self.p_ref = np.zeros((0, 2), np.float32) if f is None else f.reshape(-1, 2).astype(np.float32)
        if len(self.p_ref):
            self.p_ref = cv2.cornerSubPix(first_gray, self.p_ref.reshape(-1, 1, 2), (5, 5), (-1, -1),
                                          (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 30, 0.01)
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

    def detect(self, gray, frame):
        import cv2

        if len(self.p_ref) < 3:
            return None
        if self.A_last is None:
            guess = self.p_ref.copy()
        else:
            A = self.A_last
            if self.A_prev is not None:
                A = A + (A - self.A_prev)  # constant-velocity prediction of the pose
            guess = (self.p_ref @ A[:, :2].T + A[:, 2]).astype(np.float32)
        p, st, err = cv2.calcOpticalFlowPyrLK(
            self.ref, gray, self.p_ref.reshape(-1, 1, 2), guess.reshape(-1, 1, 2).copy(),
            winSize=self.win, maxLevel=3, flags=cv2.OPTFLOW_USE_INITIAL_FLOW,
            criteria=(cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 40, 0.005))
        p = p.reshape(-1, 2)
        ok = st.ravel() == 1
        if ok.sum() < 3:
            self.A_last = self.A_prev = None
            return None
        A, inl = cv2.estimateAffinePartial2D(self.p_ref[ok], p[ok], method=cv2.RANSAC,
                                             ransacReprojThreshold=1.0)
        if A is None:
            return None
        idx = np.flatnonzero(ok)[inl.ravel() == 1]
        if len(idx) < 3 or len(idx) < 0.3 * len(self.p_ref):
            self.A_last = self.A_prev = None
            return None
        self.A_prev, self.A_last = self.A_last, A
        return Detection(p[idx], self.obj_pts[idx], False, len(self.p_ref))


class RegionDetector:
    """Detector for the ``region`` style: one :class:`RegionTracker` per object."""

    def __init__(self, config, plane_map, first_gray):
        self.trackers = {o.id: RegionTracker(o, plane_map, first_gray) for o in config.objects}

    def detect(self, gray, frame):
        return {oid: t.detect(gray, frame) for oid, t in self.trackers.items()}
