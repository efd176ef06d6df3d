"""Does a pose from points (region features, an outline's corners, dots, markers) re-explain the image?

A point detector reports where it found points; a wrong match (a second marker with the same id,
features that followed an occluder, the corners of another rectangle) is a well-fitted pose of the
wrong thing. Every detection of the ``region``, ``edges``, ``dots``, ``aruco`` and ``apriltag``
styles is checked against the object's first detection:

* **appearance** (``mismatch``): the frame, warped back onto the first detection's image by the
  pose (the image similarity from the first detection's points to this one's), correlates with
  the first detection's patch (or the last verified keyframe) at least as the object's own
  verified frames do (the limits of :class:`._verify.PoseVerifier`);
* **forward-backward** (``misaligned``): the first patch's corners, registered again onto the
  warped-back frame by optical flow (kept only where the flow back returns them to their start),
  must stay where they were: the pose must be the one that maps the first detection onto this
  frame, within the verified frames' median misalignment plus :data:`FB_MADS` robust deviations
  (at least :data:`FB_MIN_PX` plus :data:`FB_MIN_FRAC` of the patch);
* **motion** (``jump``): the constant-velocity and turn limits of :class:`._verify.PoseVerifier`;
  after lost frames, no farther from the last verified pose than its residual limit plus the
  fastest believable motion times the frames since, nor turned by more than one frame's limit
  plus three times the fastest verified turn rate times the frames since.

A plain face (an outline's block) is compared with its border, where its contrast is. Only
verified frames teach the limits.
"""

from __future__ import annotations

import cmath
import collections
import math

import numpy as np

from ._verify import MAX_STEP_RAD, PoseVerifier

__all__ = ["PointPoseVerifier", "VerifiedDetector"]

#: Grey-level spread below which a face is plain: compared with its border grown by
#: :data:`BORDER_FRAC` of the patch's larger side instead.
TEXTURE_MIN = 4.0
BORDER_FRAC = 0.15
#: Smallest patch side checked, px: a smaller hull (two dots, a far marker) has too few pixels to
#: correlate, and only the motion checks apply.
MIN_SIDE_PX = 8
#: Forward-backward limit: robust deviations above the verified frames' median misalignment, and
#: its floor, px plus a fraction of the patch's larger side (a rendered block realigns to 0.03 px).
FB_MADS = 8.0
FB_MIN_PX = 1.0
FB_MIN_FRAC = 0.01
#: Flow points whose flow back misses their start by more than this (px) are not used.
FB_ROUNDTRIP_PX = 1.0
#: Largest side of the grid the checks sample the patch on, and the corners registered on it.
GRID_PX = 64
N_FEATURES = 8
LK_WIN = (9, 9)
_LK_STOP = (3, 10, 0.03)  # cv2.TERM_CRITERIA_EPS + COUNT: 10 iterations or 0.03 px
#: Verified frames between two renewals of the keyframe.
KEY_EVERY = 25


def _fit(a, b):
    """Complex similarity ``b ≈ z a + t`` (a, b complex (n,)): (z, t, rms residual)."""
    am, bm = a.mean(), b.mean()
    A, B = a - am, b - bm
    den = float(np.sum(np.abs(A) ** 2))
    z = complex(np.sum(B * np.conj(A)) / den) if den > 1e-18 else 1.0 + 0j
    t = bm - z * am
    return z, t, float(np.sqrt(np.mean(np.abs(z * a + t - b) ** 2)))


def _unit(v):
    """``v`` less its mean, scaled to unit length: the dot product of two is their correlation."""
    v = v - v.mean()
    return v / (float(np.sqrt(v @ v)) + 1e-9)


def _cplx(p):
    p = np.asarray(p, float)
    return p[:, 0] + 1j * p[:, 1]


class PointPoseVerifier:
    """One object's checks (see the module's description); built from its first detection.

    Parameters
    ----------
    gray : ndarray (H, W) uint8
        The frame of the first detection.
    det : Detection
        The first detection (at least two points).
    """

    def __init__(self, gray, det):
        import cv2

        obj, img = _cplx(det.obj_pts), _cplx(det.img_pts)
        # object frames are y-up, images y-down: the object -> first image map may be a mirror
        z1, t1, r1 = _fit(obj, img)
        z2, t2, r2 = _fit(np.conj(obj), img)
        self.mirror = r2 < r1
        self.z0, self.t0 = (z2, t2) if self.mirror else (z1, t1)
        pts = det.img_pts.astype(np.float32)
        H, W = gray.shape[:2]
        span = max(float(np.ptp(pts[:, 0])), float(np.ptp(pts[:, 1])))
        self.centre0 = complex(img.mean())
        hull = cv2.convexHull(pts).astype(np.int32)
        m = int(math.ceil(BORDER_FRAC * span)) + 2
        x0, y0 = int(max(pts[:, 0].min() - m, 0)), int(max(pts[:, 1].min() - m, 0))
        x1, y1 = int(min(pts[:, 0].max() + m + 1, W)), int(min(pts[:, 1].max() + m + 1, H))
        self.origin, self.size = (x0, y0), (x1 - x0, y1 - y0)
        # the checks sample the patch on a grid of at most GRID_PX a side: a 1080p marker's
        # 200 px patch would cost more than finding the marker
        self.step = max(1.0, max(self.size) / GRID_PX)
        self.grid = (max(int(math.ceil(self.size[0] / self.step)), 1), max(int(math.ceil(self.size[1] / self.step)), 1))
        patch = self._warp_back(gray, 1.0 + 0j, 0j)
        mask = np.zeros(patch.shape, np.uint8)
        cv2.fillConvexPoly(mask, np.round((hull - (x0, y0)) / self.step).astype(np.int32), 255)
        if mask.any() and float(patch[mask > 0].std()) < TEXTURE_MIN:
            r = max(int(round(m / self.step)), 1)
            mask = cv2.dilate(mask, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * r + 1, 2 * r + 1)))
        self.mask = mask > 0
        vals = patch[self.mask].astype(np.float32)
        small = min(self.size) < MIN_SIDE_PX or self.mask.sum() < 64 or vals.std() < 1.0
        self.look = not small  # whether the appearance checks apply
        self.ref_img = patch
        self.ref = self.key = _unit(vals) if self.look else None
        f = None
        if self.look:
            f = cv2.goodFeaturesToTrack(patch, N_FEATURES, 0.05, 3, mask=mask, blockSize=5)
        self.feats = None if f is None or len(f) < 3 else f.reshape(-1, 1, 2).astype(np.float32)
        self.base = PoseVerifier(gray, (x0, y0, x1, y1), self.size)
        self.base.check_turn = True
        self.fb = []
        self.turn_rates = collections.deque(maxlen=300)
        self._fb_lim, self._fb_at = None, -1
        self.verified_since_key = 0

    def _pose(self, det):
        """Image similarity (z, t) from the first detection's image to this one's."""
        obj = _cplx(det.obj_pts)
        ref = self.z0 * (np.conj(obj) if self.mirror else obj) + self.t0
        z, t, _ = _fit(ref, _cplx(det.img_pts))
        return z, t

    def _warp_back(self, gray, z, t):
        import cv2

        x0, y0 = self.origin
        # grid (x, y) -> first image (x0 + step x, y0 + step y) -> this frame z (.) + t
        zs = z * self.step
        o = z * complex(x0, y0) + t
        M = np.array([[zs.real, -zs.imag, o.real], [zs.imag, zs.real, o.imag]])
        return cv2.warpAffine(
            gray, M, self.grid, flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP, borderMode=cv2.BORDER_REPLICATE
        )

    def _misalignment(self, back):
        """Median shift (px) of the first patch's corners registered onto ``back``, or None."""
        import cv2

        if self.feats is None:
            return None
        kw = {"winSize": LK_WIN, "maxLevel": 1, "criteria": _LK_STOP}
        fwd, st1, _ = cv2.calcOpticalFlowPyrLK(self.ref_img, back, self.feats, None, **kw)
        bwd, st2, _ = cv2.calcOpticalFlowPyrLK(back, self.ref_img, fwd, None, **kw)
        e = (bwd - self.feats).reshape(-1, 2)
        d = (fwd - self.feats).reshape(-1, 2)
        good = (st1.ravel() * st2.ravel() == 1) & (np.einsum("ij,ij->i", e, e) < (FB_ROUNDTRIP_PX / self.step) ** 2)
        if good.sum() < 3:
            return None
        return self.step * math.sqrt(float(np.median(np.einsum("ij,ij->i", d[good], d[good]))))

    def fb_limit(self):
        """Largest misalignment accepted now, px: the verified frames' median plus
        :data:`FB_MADS` robust deviations, at least :data:`FB_MIN_PX` plus :data:`FB_MIN_FRAC` of
        the patch. A median, not a high percentile: a slow slide accepted below the limit must not
        raise it."""
        floor = FB_MIN_PX + FB_MIN_FRAC * max(self.size)
        if len(self.fb) < 15:
            return floor
        if self._fb_lim is None or self.base.n_verified - self._fb_at >= 10:
            a = np.asarray(self.fb[-300:])
            med = float(np.median(a))
            self._fb_lim = max(floor, med + FB_MADS * 1.4826 * float(np.median(np.abs(a - med))))
            self._fb_at = self.base.n_verified
        return self._fb_lim

    def verify(self, gray, frame, det):
        """The reason ``det`` fails, or None when it is verified (and then learned from)."""
        z, t = self._pose(det)
        centre = z * self.centre0 + t
        c = np.array([centre.real, centre.imag])
        theta = cmath.phase(z)
        b = self.base
        last, gap, pred = b.motion_context(frame)
        last2 = None if last is None else last[:2]
        score, mis, back = 1.0, None, None
        if self.look:
            back = self._warp_back(gray, z, t)
            v = _unit(back[self.mask].astype(np.float32))
            score = float(v @ self.ref)
            if score < b.limits()[0] and self.key is not self.ref:
                score = max(score, float(v @ self.key))
        reason = b.check(score, c, theta, pred, last2, gap)
        if reason is None and last2 is not None and gap > 1:
            # points are found anew in every frame, so a wrong match can be anywhere: after lost
            # frames no farther than the fastest verified motion reaches (the markerless rule
            # also lets the residual limit grow with the gap, as its search does)
            _, lim, speed_lim = b.limits()
            turn = abs(math.remainder(theta - last2[1], 2 * math.pi))
            rate = 3.0 * max(self.turn_rates) if len(self.turn_rates) >= 15 else MAX_STEP_RAD
            if float(np.hypot(*(c - last2[0]))) > lim + speed_lim * gap or turn > MAX_STEP_RAD + rate * (gap - 1):
                reason = "jump"
        if reason is None and back is not None:
            mis = self._misalignment(back)
            if mis is not None and mis > self.fb_limit():
                reason = "misaligned"
        if reason is None:
            if last2 is not None and gap == 1:
                self.turn_rates.append(abs(math.remainder(theta - last2[1], 2 * math.pi)))
            b.accept(score, c, pred, last2, gap)
            b.recent = (b.recent + [(c, theta, frame)])[-2:]
            if mis is not None:
                self.fb.append(mis)
                del self.fb[:-300]
            self.verified_since_key += 1
            if back is not None and self.verified_since_key >= KEY_EVERY:
                self.key, self.verified_since_key = _unit(back[self.mask].astype(np.float32)), 0
        return reason


class VerifiedDetector:
    """A point detector whose detections are verified (:class:`PointPoseVerifier`) before use;
    a detection that fails is reported missing and :meth:`lost_reason` names why."""

    def __init__(self, inner):
        self.inner = inner
        self.verifiers = {}
        self.reasons = {}

    def detect(self, gray, frame):
        out = self.inner.detect(gray, frame)
        self.reasons = {}
        for oid, d in out.items():
            if d is None or len(d.img_pts) < 2:
                continue
            v = self.verifiers.get(oid)
            if v is None:
                v = self.verifiers[oid] = PointPoseVerifier(gray, d)
            why = v.verify(gray, frame, d)
            if why is not None:
                out[oid] = None
                self.reasons[oid] = why
        return out

    def lost_reason(self, oid):
        """Why object ``oid``'s last detection was refused (by the verifier, or by the detector
        itself), or None (not found at all)."""
        why = self.reasons.get(oid)
        if why is None and hasattr(self.inner, "lost_reason"):
            why = self.inner.lost_reason(oid)
        return why

    def theta_note(self, oid):
        return self.inner.theta_note(oid) if hasattr(self.inner, "theta_note") else None
