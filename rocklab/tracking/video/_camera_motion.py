"""Whether the camera moves: the background's motion between frames, and the warning a track gets
when its positions carry the camera's motion.

Between two frames, corners tracked by optical flow (Lucas-Kanade) over the whole picture, or
outside the tracked objects' regions, are fitted with one similarity transform (RANSAC). Two
rules keep a large moving object from passing for the camera: the transform counts only when its
inliers spread over at least :data:`CAMERA_SPREAD` of the frame's width and height, and a still
background wins over any moving majority: when at least :data:`STILL_SHARE` of the tracked
corners, spread as widely, moved less than :data:`STILL_PX`, the camera stood still in that pair
(a model building that fills two thirds of the picture moves 3-8 px between frames while the
wall round it stays within 0.1 px; the RANSAC threshold, 1 px at the compared width, is loose
enough to take both for one motion).

``rocklab track init`` without regions refuses a film whose camera moves (:func:`camera_motion`);
with regions, and ``rocklab track`` on any film, say so as ``W-VIDEO-CAMERA``
(:func:`check_camera`): positions in image pixels then include the pan.
"""

from __future__ import annotations

import numpy as np

from ..._diagnostics import warn

#: The camera moves when, between consecutive frames compared, one similarity transform carries
#: features spread over at least ``CAMERA_SPREAD`` of the frame's width and height (RANSAC
#: inliers; the whole scene, not an object) by at least ``CAMERA_PX`` px at a frame corner, in at
#: least ``CAMERA_SHARE`` of the pairs. Measured on real films: a hand-held pan moves 31 of 36
#: pairs (median 9.4 px); 18 films from a tripod 0-3 of 20-51 (median 0.0-1.0 px; a plain wall's only
#: features on the swinging ball move 25 px but span a tenth of the frame).
CAMERA_PX = 2.0
CAMERA_SPREAD = 0.5
CAMERA_SHARE = 0.3
#: Frames are compared for camera motion at this width at most (px).
CAMERA_WIDTH_PX = 320
#: A pair's corners that moved less than this (px, full frame) are still; when at least
#: ``STILL_SHARE`` of them are, spread over ``STILL_SPREAD`` of the frame's width and height, the
#: camera stood still whatever moved with the rest (kx_pendulum's hand-held pan: 0 of ~45 corners
#: still in 26 of its 30 pairs; chulminy's building on a tripod: 12-34 % still while it sways,
#: spread over 0.40-0.61 of the frame: the wall beside it).
STILL_PX = 1.0
STILL_SHARE = 0.1
STILL_SPREAD = 0.3
#: Corners followed between two frames (spread over the picture: see :func:`pair_motion`).
CORNERS = 320
#: A corner followed from one frame to the next and back must return within this (px, compared width).
FB_PX = 0.5
#: ``rocklab track`` compares this many frames spread over the frames tracked (at most).
TRACK_SAMPLES = 80
#: A track is warned (``W-VIDEO-CAMERA``) when the background outside the objects' regions moves
#: this far (px, at the objects' first regions' centres, from the first frame tracked) in at least
#: ``DRIFT_SHARE`` of the frames where it could be measured, those at least ``DRIFT_KNOWN`` of the
#: frames compared (a plain wall has no background to measure).
DRIFT_PX = 3.0
DRIFT_SHARE = 0.25
DRIFT_KNOWN = 0.2


def _spread(pts, W: int, H: int) -> float:
    return float(min(np.ptp(pts[:, 0]) / W, np.ptp(pts[:, 1]) / H)) if len(pts) else 0.0


def pair_motion(a, b, sc: float, mask=None):
    """The background's motion from grey frame ``a`` to ``b`` (uint8, already scaled by ``sc``
    from the full frame): (2x3 similarity in ``a``'s pixels, spread of the corners that follow it
    (share of the frame's width and height, the smaller), whether the camera stood still by the
    still-background rule); None when too few corners are tracked. ``mask`` (uint8, nonzero where
    corners may be taken) leaves the objects out."""
    import cv2

    H, W = a.shape[:2]
    p = cv2.goodFeaturesToTrack(a, 4000, 0.01, 6, mask=mask)
    if p is None or len(p) < 10:
        return None
    # the strongest corners, at most a 16th of CORNERS in each cell of a 4x4 grid: a finely textured
    # object filling most of the picture would otherwise take every corner from the wall round it
    cell = (p[:, 0, 1] * 4 // H).astype(int) * 4 + (p[:, 0, 0] * 4 // W).astype(int)
    rank = np.zeros(len(p), int)
    for c in np.unique(cell):
        rank[cell == c] = np.arange(np.sum(cell == c))
    p = p[rank < CORNERS // 16]
    q, st, _ = cv2.calcOpticalFlowPyrLK(a, b, p, None, winSize=(21, 21), maxLevel=3)
    back, st2, _ = cv2.calcOpticalFlowPyrLK(b, a, q, None, winSize=(21, 21), maxLevel=3)
    # a corner that does not come back where it started was not followed (a plain wall, a blur)
    st = (st.ravel() == 1) & (st2.ravel() == 1) & (np.hypot(*(back - p).reshape(-1, 2).T) < FB_PX)
    if st.sum() < 10:
        return None
    P, Q = p[st].reshape(-1, 2), q[st].reshape(-1, 2)
    still = np.hypot(*(Q - P).T) < STILL_PX * sc
    if still.sum() >= max(10, STILL_SHARE * len(P)) and _spread(P[still], W, H) >= STILL_SPREAD:
        M, _ = cv2.estimateAffinePartial2D(P[still], Q[still], method=cv2.RANSAC, ransacReprojThreshold=1.0)
        return (np.eye(2, 3) if M is None else M), _spread(P[still], W, H), True
    M, inl = cv2.estimateAffinePartial2D(P, Q, method=cv2.RANSAC, ransacReprojThreshold=1.0)
    if M is None:
        return None
    return M, _spread(P[inl.ravel() == 1], W, H), False


def _corner_shift(M, W: int, H: int, sc: float, points=None) -> float:
    """Largest displacement of a frame corner (or of ``points``, (n, 2) scaled pixels) under ``M``
    (scaled pixels), px of the full frame."""
    pts = np.array([[0, 0], [W, 0], [0, H], [W, H]], np.float64) if points is None else np.asarray(points, float)
    return float(np.max(np.hypot(*(pts @ M[:, :2].T + M[:, 2] - pts).T))) / sc


def _small(frames, width_px: int = CAMERA_WIDTH_PX):
    import cv2

    sc = min(1.0, width_px / frames[0].shape[1])
    return [g if sc == 1.0 else cv2.resize(g, None, fx=sc, fy=sc, interpolation=cv2.INTER_AREA) for g in frames], sc


def camera_motion(frames) -> tuple[float, float]:
    """How the camera moves over ``frames`` (grey uint8, in time order): (share of the consecutive
    pairs in which the whole picture moves, median of that motion over the pairs, px at a frame
    corner of the full frame); see :data:`CAMERA_PX` and the module docstring."""
    if len(frames) < 2:
        return 0.0, 0.0
    small, sc = _small(frames)
    H, W = small[0].shape[:2]
    moved, shift = [], []
    for a, b in zip(small[:-1], small[1:]):
        found = pair_motion(a, b, sc)
        if found is None:
            continue
        M, spread, _ = found
        d = _corner_shift(M, W, H, sc)
        shift.append(d)
        moved.append(d >= CAMERA_PX and spread >= CAMERA_SPREAD)
    return float(np.sum(moved)) / (len(small) - 1), float(np.median(shift)) if shift else 0.0


def background_drift(frames, boxes=(), full_width_px: int | None = None) -> np.ndarray:
    """The background's displacement from the first of ``frames`` (grey uint8, in time order), px
    of the full frame at the centres of ``boxes`` (the largest; the frame's centre without boxes),
    per frame (shape (n,)): where the objects' positions carry it. The similarity transform of the
    corners outside ``boxes`` ((x, y, w, h) px, full frame; each left out with half its size round
    it) from the first frame, or chained from the frame before when that one was measured; NaN
    where neither spreads over the frame (no background to measure: a plain wall).
    ``full_width_px``: the frames are already scaled down from a frame this wide."""
    if len(frames) < 2:
        return np.zeros(len(frames))
    small, sc = (frames, frames[0].shape[1] / full_width_px) if full_width_px else _small(frames)
    H, W = small[0].shape[:2]
    mask = np.full((H, W), 255, np.uint8)
    for x, y, w, h in boxes:
        x0, y0 = int(max((x - 0.5 * w) * sc, 0)), int(max((y - 0.5 * h) * sc, 0))
        mask[y0 : int((y + 1.5 * h) * sc) + 1, x0 : int((x + 1.5 * w) * sc) + 1] = 0
    if mask.mean() < 0.1 * 255:  # the objects fill the picture: judged on all of it
        mask[:] = 255
    at = [((x + w / 2) * sc, (y + h / 2) * sc) for x, y, w, h in boxes] or [(W / 2, H / 2)]

    def counts(found) -> bool:  # the background's motion, not an object's
        return found is not None and (found[2] or found[1] >= CAMERA_SPREAD)

    out, total = [0.0], np.eye(3)
    for a, b in zip(small[:-1], small[1:]):
        # against the first frame: a misjudged frame (an arm filling the picture on a plain wall)
        # stays one frame; chained from the frame before only while that one was measured (a pan
        # that took the first frame's corners out of reach)
        found = pair_motion(small[0], b, sc, mask)
        if counts(found):
            total = np.vstack([found[0], [0, 0, 1]])
        elif total is not None and counts(step := pair_motion(a, b, sc, mask)):
            total = np.vstack([step[0], [0, 0, 1]]) @ total
        else:
            total = None
        out.append(np.nan if total is None else _corner_shift(total[:2], W, H, sc, at))
    return np.asarray(out)


class FrameSampler:
    """Keeps every ``step``-th grey frame of a ``(index, grey)`` stream it passes on, at
    :data:`CAMERA_WIDTH_PX` wide (for :func:`check_camera` after the track)."""

    def __init__(self, n_expected: int, n_samples: int = TRACK_SAMPLES):
        self.step = max(1, int(n_expected or 0) // n_samples)
        self.frames: list = []

    def wrap(self, frames):
        import cv2

        for k, item in enumerate(frames):
            if k % self.step == 0:
                g = item[1]
                g = cv2.cvtColor(g, cv2.COLOR_BGR2GRAY) if g.ndim == 3 else g
                self.frames.append(_small([g])[0][0])
            yield item


def check_camera(frames, boxes, path, full_width_px: int) -> tuple[float, bool]:
    """``W-VIDEO-CAMERA`` when the background outside the objects' first regions ``boxes`` moves
    more than :data:`DRIFT_PX` from the first of ``frames`` in :data:`DRIFT_SHARE` of them
    (:func:`background_drift`), sampled by :class:`FrameSampler`; returns (the largest drift, px of the full frame, whether
    it warned)."""
    if len(frames) < 3:
        return 0.0, False
    drift = background_drift(frames, boxes, full_width_px)
    known = drift[np.isfinite(drift)]
    if len(known) < max(3, DRIFT_KNOWN * len(drift)):
        return (float(known.max()) if len(known) else 0.0), False
    share = float(np.mean(known > DRIFT_PX))
    if share >= DRIFT_SHARE:
        warn(
            "W-VIDEO-CAMERA",
            f"{path}: the camera moves: the background outside the objects' regions shifts, where they are, by up to "
            f"{known.max():.3g} px (median {np.median(known):.3g} px) from the first frame tracked, beyond "
            f"{DRIFT_PX:g} px in {100 * share:.0f} % of {len(known)} frames compared; x_px, y_px (and x_m, y_m, "
            "theta) include the camera's motion: film from a fixed camera (a tripod)",
        )
    return float(known.max()), share >= DRIFT_SHARE
