"""Dot targets: blob detection, sub-pixel centroids, identification against the
known dot layout, rigid fit (done by the core).

Acquisition (first frame, or after a loss) finds candidate blobs with an
adaptive threshold and identifies each object's dots by hypothesising
similarities from blob pairs (near-upright, consistent dot size) and counting
the layout dots they predict. Tracking then searches a small window around
each dot's constant-velocity prediction.

Centroids weight each pixel by ``max(thr - I, 0)`` with ``thr`` midway between
dot and surface grey: for a symmetric (anti-aliased, blurred) disk the weights
are symmetric about its centre, and pure-surface pixels (and their noise) get
no weight, so the centroid is unbiased.
"""

from __future__ import annotations

import numpy as np

from ._detection import Detection

__all__ = ["DotDetector", "dot_centroid"]


def dot_centroid(gray, c, r, dark=True):
    """Sub-pixel centre of the dot near ``c`` (px) within a window of half-size ``r`` (px).

    Returns ``(u, v, diameter_px, contrast)`` or None when no dot is there.
    """
    import cv2

    H, W = gray.shape
    x0, y0 = int(max(c[0] - r, 0)), int(max(c[1] - r, 0))
    x1, y1 = int(min(c[0] + r + 1, W)), int(min(c[1] + r + 1, H))
    if x1 - x0 < 5 or y1 - y0 < 5:
        return None
    patch = gray[y0:y1, x0:x1].astype(np.float32)
    if not dark:
        patch = 255.0 - patch
    lo, hi = np.percentile(patch, (2, 98))
    contrast = hi - lo
    if contrast < 20:
        return None
    thr = 0.5 * (lo + hi)
    mask = (patch < thr).astype(np.uint8)
    n, lab, stats, cents = cv2.connectedComponentsWithStats(mask, connectivity=8)
    if n < 2:
        return None
    # the component nearest the prediction
    d2 = np.sum((cents[1:] - (c[0] - x0, c[1] - y0)) ** 2, axis=1)
    k = 1 + int(np.argmin(d2))
    bx, by, bw, bh, area = stats[k]
    if area < 6 or bx == 0 or by == 0 or bx + bw >= patch.shape[1] or by + bh >= patch.shape[0]:
        return None  # touching the window: not a whole dot
    ys, xs = slice(max(by - 2, 0), by + bh + 2), slice(max(bx - 2, 0), bx + bw + 2)
    w = np.maximum(thr - patch[ys, xs], 0.0)
    lk = lab[ys, xs]
    w[(lk != 0) & (lk != k)] = 0.0  # other blobs in the window
    s = w.sum()
    if s <= 0:
        return None
    yy, xx = np.mgrid[ys, xs]
    u = float((w * xx).sum() / s) + x0
    v = float((w * yy).sum() / s) + y0
    return u, v, 2.0 * np.sqrt(area / np.pi), float(contrast)


class DotDetector:
    """Stateful detector for the ``dots`` style.

    Parameters
    ----------
    config : TrackConfig
    plane_map : PlaneMap
    first_gray : ndarray
        Unused (the first call to :meth:`detect` acquires).
    """

    def __init__(self, config, plane_map, first_gray=None):
        self.cfg = config
        self.pm = plane_map
        self.dark = config.targets.dot_color == "dark"
        self.layout = {o.id: np.asarray(o.dots, float) for o in config.objects}
        self.last = {}  # object id -> (frame, pts (n,2) with NaN rows for missing dots)
        self.prev = {}
        self.diam = {}  # object id -> dot diameter, px

    # ------------------------------------------------------------ acquisition
    def _blobs(self, gray, roi=None):
        import cv2

        H, W = gray.shape
        x0, y0, x1, y1 = 0, 0, W, H
        if roi is not None:
            x0, y0 = int(max(roi[0], 0)), int(max(roi[1], 0))
            x1, y1 = int(min(roi[0] + roi[2], W)), int(min(roi[1] + roi[3], H))
        img = gray[y0:y1, x0:x1]
        block = int(max(51, min(img.shape) // 8)) | 1
        mode = cv2.THRESH_BINARY_INV if self.dark else cv2.THRESH_BINARY
        binary = cv2.adaptiveThreshold(img, 255, cv2.ADAPTIVE_THRESH_MEAN_C, mode, block, -10 if not self.dark else 10)
        n, lab, stats, cents = cv2.connectedComponentsWithStats(binary, connectivity=8)
        out = []
        for k in range(1, n):
            bx, by, bw, bh, area = stats[k]
            if area < 12 or not (0.6 < bw / bh < 1.6) or not (0.55 < area / (bw * bh) < 0.95):
                continue
            out.append((cents[k][0] + x0, cents[k][1] + y0, 2.0 * np.sqrt(area / np.pi)))
        return np.array(out).reshape(-1, 3)

    def _acquire(self, gray, o, taken):
        lay = self.layout[o.id]
        blobs = self._blobs(gray, o.roi)
        if len(blobs) and taken:
            keep = [i for i, b in enumerate(blobs) if min(np.hypot(b[0] - t[0], b[1] - t[1]) for t in taken) > 1.0]
            blobs = blobs[keep]
        if len(blobs) < 2:
            return None
        q = self.pm.to_plane(blobs[:, :2])
        qc = q[:, 0] + 1j * q[:, 1]
        # blob diameters in plane units (the plane may be metric, the blobs are in px)
        half = np.column_stack((blobs[:, 2] / 2, np.zeros(len(blobs))))
        d_plane = np.hypot(*(self.pm.to_plane(blobs[:, :2] + half) - self.pm.to_plane(blobs[:, :2] - half)).T)
        pc = lay[:, 0] + 1j * lay[:, 1]
        j = int(np.argmax(np.abs(pc - pc[0])))
        dmed = np.median(blobs[:, 2])
        dot_d = self.cfg.targets.dot_diameter_m
        best, best_key = None, None
        for a in range(len(qc)):
            for b in range(len(qc)):
                if a == b:
                    continue
                z = (qc[b] - qc[a]) / (pc[j] - pc[0])
                if abs(np.angle(z)) > 0.6:
                    continue  # the block starts near upright
                if dot_d is not None and not 0.6 < d_plane[a] / (abs(z) * dot_d) < 1.6:
                    continue
                pred = z * (pc - pc[0]) + qc[a]
                dist = np.abs(pred[:, None] - qc[None, :])
                idx = np.argmin(dist, axis=1)
                tol = 0.5 * max(blobs[a, 2], 2.0)
                hit = dist[np.arange(len(pc)), idx] < tol
                key = (int(hit.sum()), -float(np.sum(dist[np.arange(len(pc)), idx][hit])))
                if best_key is None or key > best_key:
                    best_key, best = key, (idx, hit)
        if best is None or best_key[0] < 2:
            return None
        idx, hit = best
        pts = np.full((len(pc), 2), np.nan)
        pts[hit] = blobs[idx[hit], :2]
        self.diam[o.id] = float(np.median(blobs[idx[hit], 2])) if np.any(hit) else dmed
        return pts

    # --------------------------------------------------------------- tracking
    def _predict(self, oid, frame):
        f1, p1 = self.last[oid]
        if oid in self.prev and frame - f1 <= 2:
            f0, p0 = self.prev[oid]
            v = (p1 - p0) / max(f1 - f0, 1)
            return np.where(np.isfinite(v), p1 + v * (frame - f1), p1)
        return p1

    def detect(self, gray, frame):
        out = {}
        taken = []
        for o in self.cfg.objects:
            pts = None
            if o.id in self.last and frame - self.last[o.id][0] <= 2:
                pred = self._predict(o.id, frame)
                r = 1.5 * self.diam[o.id] + 4
                pts = np.full_like(pred, np.nan)
                for i, c in enumerate(pred):
                    if np.all(np.isfinite(c)):
                        got = dot_centroid(gray, c, r, self.dark)
                        if got is not None and np.hypot(got[0] - c[0], got[1] - c[1]) < r:
                            pts[i] = got[:2]
                if np.sum(np.isfinite(pts[:, 0])) < 2:
                    pts = None
            if pts is None or np.any(~np.isfinite(pts[:, 0])):
                acq = self._acquire(gray, o, taken)
                if acq is not None:
                    r = 0.75 * self.diam[o.id] + 4
                    for i, c in enumerate(acq):
                        if np.all(np.isfinite(c)):
                            got = dot_centroid(gray, c, r, self.dark)
                            acq[i] = got[:2] if got is not None else np.nan
                    if pts is None or np.sum(np.isfinite(acq[:, 0])) > np.sum(np.isfinite(pts[:, 0])):
                        pts = acq
            good = None if pts is None else np.isfinite(pts[:, 0])
            if pts is None or good.sum() < 2:
                out[o.id] = None
                continue
            if o.id in self.last:
                self.prev[o.id] = self.last[o.id]
            self.last[o.id] = (frame, pts.copy())
            taken += [tuple(p) for p in pts[good]]
            out[o.id] = Detection(pts[good], self.layout[o.id][good], True, len(pts))
        return out
