"""Markerless blocks: the outline against a contrasting background.

Per frame, inside a window around the predicted outline: threshold (Otsu or
``targets.edge_threshold``), take the block's connected region, get a first
rectangle from ``cv2.minAreaRect``, then locate each side to sub-pixel
precision from grey-level profiles across it (the crossing of the level midway
between block and background) and fit a robust (Huber) line per side. The four
line intersections are the corners handed to the rigid fit. Binary contours
alone would quantise a near-vertical side to a pixel column and bias θ by up
to 1 px / side length.

``table`` objects in this style are followed with the region tracker
(:mod:`._region`): give their ``roi`` on the textured table edge.
"""

from __future__ import annotations

import numpy as np

from ._detection import Detection
from ._region import RegionTracker

__all__ = ["EdgeDetector", "refine_rectangle"]

_NEXT = np.array([1, 2, 3, 0])
_PREV = np.array([3, 0, 1, 2])
_SIGNS = np.array([[-1, 1], [1, 1], [1, -1], [-1, -1]], float)  # TL, TR, BR, BL (y up)


def refine_rectangle(gray, corners, half=6.0, step=2.0, trim=0.15):
    """Sub-pixel quadrilateral (rectangle, marker square) from an approximate one.

    Grey profiles across each side (bicubic samples every 0.5 px over
    ``±half``) give the crossing of the level midway between the inside and
    outside grey; a total-least-squares line per side (one re-fit without
    points beyond 3 rms) and the line intersections give the corners.

    Parameters
    ----------
    gray : ndarray (H, W) uint8
    corners : ndarray (4, 2)
        Approximate corners (px) in order around the outline.
    half : float
        Half-length of each grey profile across a side (px).
    step : float
        Spacing of profiles along a side (px).
    trim : float
        Fraction of each side ignored at both ends (corners are rounded by blur).

    Returns
    -------
    corners : ndarray (4, 2) or None
    rms_px : float
        RMS distance of the edge points from their fitted lines.
    n_points : int
    sigma_theta_rad : float
        1-σ uncertainty of the quadrilateral's orientation (mean of the four
        side directions), from each line fit's scatter: ``σ_k = rms_k /
        sqrt(Σ(s - s̄)²)`` along the side (inflated by ``2 px / step`` for
        profiles correlated by the blur), combined as ``sqrt(Σ σ_k²) / 4``.
    """
    import cv2

    fail = (None, np.inf, 0, np.inf)
    c = np.asarray(corners, float)
    b = c[_NEXT]
    L = np.hypot(*(b - c).T)
    if L.min() < 8:
        return fail
    d = (b - c) / L[:, None]
    nrm = np.column_stack((-d[:, 1], d[:, 0]))
    inward = np.einsum("ij,ij->i", c.mean(0) - c, nrm) > 0
    nrm[inward] *= -1.0  # outward normals
    m = max(5, int((1 - 2 * trim) * L.max() / step))
    frac = np.linspace(trim, 1 - trim, m)
    offs = np.arange(-half, half + 0.25, 0.5)
    base = c[:, None, :] + (frac[None, :, None] * L[:, None, None]) * d[:, None, :]  # (4, m, 2)
    pts = base[:, :, None, :] + offs[None, None, :, None] * nrm[:, None, None, :]  # (4, m, p, 2)
    # Work on a float crop: remap of uint8 would round the profiles to whole grey levels.
    H, W = gray.shape[:2]
    x0 = int(max(np.floor(pts[..., 0].min()) - 3, 0))
    y0 = int(max(np.floor(pts[..., 1].min()) - 3, 0))
    x1 = int(min(np.ceil(pts[..., 0].max()) + 4, W))
    y1 = int(min(np.ceil(pts[..., 1].max()) + 4, H))
    if x1 - x0 < 4 or y1 - y0 < 4:
        return fail
    img = gray[y0:y1, x0:x1].astype(np.float32)
    p = len(offs)
    mx = (pts[..., 0] - x0).reshape(4 * m, p).astype(np.float32)
    my = (pts[..., 1] - y0).reshape(4 * m, p).astype(np.float32)
    # bicubic: linear interpolation "pixel-locks" the crossings of near-axis edges
    prof = cv2.remap(img, mx, my, cv2.INTER_CUBIC, borderMode=cv2.BORDER_REPLICATE).astype(float)
    inside = (prof[:, 0] + prof[:, 1] + prof[:, 2]) / 3.0
    contrast = (prof[:, -1] + prof[:, -2] + prof[:, -3]) / 3.0 - inside
    ok = np.abs(contrast) > 15
    f = (prof - inside[:, None]) / np.where(ok, contrast, 1.0)[:, None]  # 0 inside .. 1 outside
    above = f >= 0.5
    j = np.argmax(above, axis=1)
    ok &= above.any(axis=1) & (j > 0)
    j = np.clip(j, 1, p - 1)
    r = np.arange(len(j))
    f0, f1 = f[r, j - 1], f[r, j]
    den = f1 - f0
    t = np.divide(0.5 - f0, den, out=np.full_like(den, 0.5), where=den != 0)
    off = (offs[j - 1] + t * 0.5).reshape(4, m)
    edge = base + off[..., None] * nrm[:, None, :]  # (4, m, 2)
    w = ok.reshape(4, m).astype(float)
    for it in range(2):
        sw = w.sum(1)
        if np.any(sw < 5):
            return fail
        mean = np.einsum("km,kmi->ki", w, edge) / sw[:, None]
        e = edge - mean[:, None, :]
        sxx = np.einsum("km,km->k", w, e[..., 0] ** 2)
        syy = np.einsum("km,km->k", w, e[..., 1] ** 2)
        sxy = np.einsum("km,km->k", w, e[..., 0] * e[..., 1])
        phi = 0.5 * np.arctan2(2 * sxy, sxx - syy)
        dv = np.column_stack((np.cos(phi), np.sin(phi)))
        nv = np.column_stack((-dv[:, 1], dv[:, 0]))
        dist = np.einsum("kmi,ki->km", e, nv)
        if it == 0:
            # drop outliers (a notch, a neighbouring edge): beyond 3 rms of the first fit
            rms_k = np.sqrt(np.einsum("km,km->k", w, dist**2) / sw)
            w = w * (np.abs(dist) <= np.maximum(3 * rms_k, 0.05)[:, None])
    sw = w.sum(1)
    along = np.einsum("kmi,ki->km", e, dv)
    a_mean = np.einsum("km,km->k", w, along) / sw
    s_along = np.einsum("km,km->k", w, (along - a_mean[:, None]) ** 2)
    ss = np.einsum("km,km->k", w, dist**2)
    # profiles closer than ~2 px share their noise through the blur: one sample per 2 px
    spacing = (1 - 2 * trim) * L / max(m - 1, 1)
    corr = np.maximum(1.0, 2.0 / spacing)
    var_phi = corr * ss / np.maximum(sw - 2, 1) / np.maximum(s_along, 1e-12)
    # corner k = side (k - 1) ∩ side k
    p1, d1 = mean[_PREV], dv[_PREV]
    det = d1[:, 0] * (-dv[:, 1]) - d1[:, 1] * (-dv[:, 0])
    if np.any(np.abs(det) < 1e-9):
        return fail
    rhs = mean - p1
    t1 = (rhs[:, 0] * (-dv[:, 1]) - rhs[:, 1] * (-dv[:, 0])) / det
    out = p1 + t1[:, None] * d1
    n_pts = int(sw.sum())
    return out, float(np.sqrt(ss.sum() / n_pts)), n_pts, float(np.sqrt(var_phi.sum()) / 4)


def horizontal_edge_angle(gray, roi, plane_map):
    """Plane angle (rad, ccw) of the strongest near-horizontal edge in ``roi`` (u, v, w, h px).

    Per column, the sub-pixel row of the largest vertical grey gradient
    (parabola through the peak), then a Huber line fit. (A markerless table's top edge,
    followed beyond its region, is :func:`._table_edge.table_top_edge`.)
    """
    import cv2

    u, v, w, h = (int(round(x)) for x in roi)
    crop = gray[max(v, 0) : v + h, max(u, 0) : u + w].astype(np.float32)
    gy = np.abs(cv2.Sobel(crop, cv2.CV_32F, 0, 1, ksize=3))
    rows = np.argmax(gy[1:-1], axis=0) + 1
    cols = np.arange(gy.shape[1])
    g0, g1, g2 = gy[rows - 1, cols], gy[rows, cols], gy[rows + 1, cols]
    den = g0 - 2 * g1 + g2
    sub = rows + np.divide(0.5 * (g0 - g2), den, out=np.zeros_like(den), where=den != 0)
    strong = g1 > 0.5 * np.median(g1)
    pts = np.column_stack((cols[strong] + max(u, 0), sub[strong] + max(v, 0))).astype(np.float32)
    if len(pts) < 5:
        return 0.0
    vx, vy, x0, y0 = cv2.fitLine(pts, cv2.DIST_HUBER, 0, 0.01, 0.01).ravel()
    q = plane_map.to_plane(np.array([[x0, y0], [x0 + 100 * vx, y0 + 100 * vy]]))
    d = q[1] - q[0]
    if d[0] < 0:
        d = -d
    return float(np.arctan2(d[1], d[0]))


class EdgeDetector:
    """Stateful detector for the ``edges`` style.

    Blocks: outline by threshold (Otsu or ``targets.edge_threshold``). Tables
    with ``size_m``: outline as the region whose grey stays near the table's
    own (measured in the middle of its ``roi`` in the first frame), so a
    brighter block standing on it and the darker surroundings are both
    excluded; their ends give the horizontal motion, their top the level.
    Tables without ``size_m``: :class:`RegionTracker`.
    """

    def __init__(self, config, plane_map, first_gray):
        self.cfg = config
        self.pm = plane_map
        self.thr = config.targets.edge_threshold
        self.state = {}
        self.regions = {}
        self.band = {}
        for o in config.objects:
            if o.kind == "table" and o.size_m is not None:
                u, v, w, h = (int(round(x)) for x in o.roi)
                crop = first_gray[max(v, 0) : v + h, max(u, 0) : u + w]
                hh, ww = crop.shape
                level = float(np.median(crop[hh // 3 : 2 * hh // 3, ww // 4 : 3 * ww // 4]))
                border = float(np.median(np.r_[crop[0], crop[-1]]))
                self.band[o.id] = (level, max(0.5 * abs(level - border), 8.0))
            elif o.kind == "table":
                if o.theta0_rad is None:
                    import dataclasses

                    # The table top's image angle, so that levelling from the table works.
                    o = dataclasses.replace(o, theta0_rad=horizontal_edge_angle(first_gray, o.roi, plane_map))
                self.regions[o.id] = RegionTracker(o, plane_map, first_gray)
        self.size = {o.id: o.size_m for o in config.objects}
        self.polarity = {}
        self.ref_px = {}

    def _outline(self, gray, box, oid):
        """Approximate corners (4, 2) of the block region inside ``box``."""
        import cv2

        H, W = gray.shape
        x0, y0, x1, y1 = (int(max(box[0], 0)), int(max(box[1], 0)), int(min(box[2], W)), int(min(box[3], H)))
        if x1 - x0 < 8 or y1 - y0 < 8:
            return None
        crop = gray[y0:y1, x0:x1]
        if oid in self.band:
            level, band = self.band[oid]
            binary = (np.abs(crop.astype(np.float32) - level) < band).astype(np.uint8) * 255
            binary = cv2.morphologyEx(binary, cv2.MORPH_OPEN, np.ones((3, 3), np.uint8))
            return self._largest_rect(binary, x0, y0)
        if oid not in self.polarity:
            h, w = crop.shape
            centre = np.median(crop[h // 3 : 2 * h // 3, w // 3 : 2 * w // 3])
            border = np.median(np.r_[crop[0], crop[-1], crop[:, 0], crop[:, -1]])
            self.polarity[oid] = centre > border
        if self.thr is None:
            _, binary = cv2.threshold(crop, 0, 255, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
        else:
            _, binary = cv2.threshold(crop, self.thr, 255, cv2.THRESH_BINARY)
        if not self.polarity[oid]:
            binary = 255 - binary
        return self._largest_rect(binary, x0, y0)

    @staticmethod
    def _largest_rect(binary, x0, y0):
        import cv2

        n, lab, stats, _ = cv2.connectedComponentsWithStats(binary, connectivity=4)
        if n < 2:
            return None
        k = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
        pts = np.column_stack(np.nonzero(lab == k)[::-1]).astype(np.float32)
        if len(pts) < 50:
            return None
        rect = cv2.minAreaRect(pts)
        return cv2.boxPoints(rect).astype(float) + (x0, y0)

    def _order(self, corners, theta_prev):
        """Corners as TL, TR, BR, BL of the object (plane y up), given the previous angle."""
        q = self.pm.to_plane(corners)
        cq = q - q.mean(0)
        c, s = np.cos(-theta_prev), np.sin(-theta_prev)
        rq = cq @ np.array([[c, s], [-s, c]])
        order = [int(np.argmax(rq @ sgn)) for sgn in _SIGNS]
        if len(set(order)) < 4:
            return None
        return corners[order]

    def detect(self, gray, frame):
        out = {}
        for o in self.cfg.objects:
            if o.id in self.regions:
                out[o.id] = self.regions[o.id].detect(gray, frame)
                continue
            st = self.state.get(o.id)
            if st is None:
                u, v, w, h = o.roi
                box = (u - 0.1 * w, v - 0.1 * h, u + 1.1 * w, v + 1.1 * h)
                theta_prev = o.theta0_rad or 0.0
            else:
                pc = st["corners"]
                span = np.ptp(pc, axis=0).max()
                m = 0.15 * span
                box = (pc[:, 0].min() - m, pc[:, 1].min() - m, pc[:, 0].max() + m, pc[:, 1].max() + m)
                theta_prev = st["theta"]
            approx = self._outline(gray, box, o.id)
            if approx is None:
                out[o.id] = None
                continue
            approx = self._order(approx, theta_prev)
            if approx is None:
                out[o.id] = None
                continue
            corners, rms, npts, sig = refine_rectangle(gray, approx)
            if corners is not None:
                corners2, rms2, npts2, sig2 = refine_rectangle(gray, corners, half=4.0)
                if corners2 is not None:
                    corners, sig = corners2, sig2
            if corners is None:
                out[o.id] = None
                continue
            q = self.pm.to_plane(corners)
            d = q[1] - q[0]
            theta = float(np.arctan2(d[1], d[0]))
            self.state[o.id] = {"corners": corners, "theta": theta}
            if self.size[o.id] is not None:
                b, h = self.size[o.id]
                obj = _SIGNS * (b / 2, h / 2)
                metric = True
            else:
                if o.id not in self.ref_px:
                    self.ref_px[o.id] = (
                        (np.hypot(*(q[1] - q[0])) + np.hypot(*(q[2] - q[3]))) / 2,
                        (np.hypot(*(q[0] - q[3])) + np.hypot(*(q[1] - q[2]))) / 2,
                    )
                bw, bh = self.ref_px[o.id]
                obj = _SIGNS * (bw / 2, bh / 2)
                metric = False
            out[o.id] = Detection(corners, obj, metric, 4, sig)
        return out
