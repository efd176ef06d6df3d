"""A table's top edge as a level reference: followed beyond the user's region, fitted in the plane.

The level of a markerless table comes from the angle of its top edge. Found only inside the
region a user draws (often a short stretch at one end), the angle is limited by the table's own
texture: the grain just below the edge moves each column's sub-pixel edge row by hundredths of
a pixel, and over 170 px (a 960x540 render) that leaves 0.02-0.04 deg. The edge is therefore
followed along its own line, left and right of the region, as far as it keeps its polarity,
contrast and straightness (a block standing on the table, the table's end or a shadow stops it),
and the line is fitted to the undistorted points in plane coordinates. Its 1-sigma comes from
the scatter about the line, counted as one independent sample per smoothing length.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["TopEdge", "table_top_edge", "BLUR_PX"]

#: Smoothing of the vertical gradient along the edge, px: the face's grain averages out, the edge not.
BLUR_PX = 15
#: Half-height of the band searched round the line when following it, px.
BAND_PX = 4
#: A column outside the region joins when its edge keeps the region's polarity and its strength
#: stays within these factors of the region's median.
CONTRAST_RANGE = (0.6, 1.6)
#: ... and lies within this many px of the line so far.
MAX_OFF_PX = 1.0
#: Following stops after this many columns in a row that do not join.
MAX_GAP_PX = 2 * BLUR_PX
#: The scatter-based sigma is multiplied by this: on 12 renders (960x540, six scenes, lossless
#: and H.264, seeds 0-5) the angle errors were 2.2 times the bare sigma (RMS); the grain of a
#: face is correlated over more than the smoothing length.
SIGMA_INFLATION = 2.0


@dataclass(frozen=True)
class TopEdge:
    """A table's top edge in one frame.

    Attributes
    ----------
    angle_rad : float
        The edge's angle in the plane (counter-clockwise from the plane's x axis), rad.
    sigma_rad : float
        Its 1-sigma, rad.
    u_span_px : tuple of float
        First and last image column used, px (the region's own, or wider when followed).
    ends_px : ndarray, shape (2, 2)
        The fitted line's image points at those columns (u, v), px: for drawing.
    n_columns : int
        Columns used.
    """

    angle_rad: float
    sigma_rad: float
    u_span_px: tuple
    ends_px: np.ndarray
    n_columns: int


def _sub_row(g, rows, cols):
    """Sub-pixel peak rows of ``g`` (columns ``cols``) by a parabola through each peak row."""
    rows = np.clip(rows, 1, g.shape[0] - 2)
    g0, g1, g2 = g[rows - 1, cols], g[rows, cols], g[rows + 1, cols]
    den = g0 - 2 * g1 + g2
    return rows + np.divide(0.5 * (g0 - g2), den, out=np.zeros_like(den), where=den < 0), g1


def _robust_line(u, v):
    """(a, b) of v = a + b u by least squares with points beyond 3 robust sigma left out (twice)."""
    keep = np.ones(u.size, bool)
    a = b = 0.0
    for _ in range(3):
        b, a = np.polyfit(u[keep], v[keep], 1)
        r = v - (a + b * u)
        s = 1.4826 * float(np.median(np.abs(r[keep] - np.median(r[keep])))) + 1e-3
        nxt = np.abs(r) <= 3 * s
        if nxt.sum() < 2:  # points on no line at all: keep the last fit rather than none
            break
        keep = nxt
    return a, b, keep


def table_top_edge(gray, roi, plane_map, follow: bool = True) -> TopEdge | None:
    """The top edge of a table seen in ``roi``, followed along its line with ``follow``.

    Parameters
    ----------
    gray : ndarray (H, W), uint8
    roi : (u, v, w, h)
        The table's region, px; its top edge must cross it from side to side.
    plane_map : PlaneMap
        Image -> plane (undistortion, homography).
    follow : bool
        Follow the edge beyond the region's columns.

    Returns
    -------
    TopEdge or None
        None when the region holds no usable edge (fewer than 5 columns).
    """
    import cv2

    H, W = gray.shape[:2]
    u0, v0, w, h = (int(round(x)) for x in roi)
    u0, v0 = max(u0, 0), max(v0, 0)
    u1, v1 = min(u0 + w, W), min(v0 + h, H)
    if u1 - u0 < 5 or v1 - v0 < 5:
        return None
    # signed vertical gradient, smoothed along the rows, on the region's rows plus a margin (the
    # edge may climb or fall across the frame)
    margin = max(int(0.02 * W) + BAND_PX + 2, 8)
    r0, r1 = max(v0 - margin, 0), min(v1 + margin, H)
    gy = cv2.blur(cv2.Sobel(gray[r0:r1].astype(np.float32), cv2.CV_32F, 0, 1, ksize=3), (BLUR_PX, 1))
    cols = np.arange(u0, u1)
    inner = np.abs(gy[v0 - r0 + 1 : v1 - r0 - 1, u0:u1])
    if inner.shape[0] < 3:
        return None
    # per column the first row reaching half the column's strongest (the top edge, not the
    # stronger edges of markers or of the table's bottom), climbed to its local peak
    rows = np.argmax(inner >= 0.5 * inner.max(axis=0, keepdims=True), axis=0)
    for _ in range(3):
        nxt = np.minimum(rows + 1, inner.shape[0] - 1)
        up = inner[nxt, np.arange(inner.shape[1])] > inner[rows, np.arange(inner.shape[1])]
        rows = np.where(up, nxt, rows)
    rows = rows + (v0 - r0 + 1)
    sign = 1.0 if float(np.median(gy[rows, cols])) >= 0 else -1.0
    g = sign * gy
    sub, peak = _sub_row(g, rows, cols)
    strong = peak > 0.5 * np.median(peak)
    u_pts, v_pts = cols[strong].astype(float), sub[strong].astype(float) + r0
    if u_pts.size < 5:
        return None
    a, b, keep = _robust_line(u_pts, v_pts)
    u_pts, v_pts = u_pts[keep], v_pts[keep]
    strength = float(np.median(peak[strong][keep]))
    if follow:
        (ul, vl), (ur, vr) = (_follow(g, a, b, u, step, strength, r0, W) for u, step in ((u0 - 1, -1), (u1, 1)))
        u_pts, v_pts = np.concatenate((ul, u_pts, ur)), np.concatenate((vl, v_pts, vr))
    # the line in the plane, from the undistorted points
    q = plane_map.to_plane(np.column_stack((u_pts, v_pts)))
    x, y = q[:, 0], q[:, 1]
    a_p, b_p, _ = _robust_line(x, y)
    r = y - (a_p + b_p * x)
    s = 1.4826 * float(np.median(np.abs(r - np.median(r))))
    sxx = float(np.sum((x - x.mean()) ** 2))
    # neighbouring columns share the smoothing: one independent sample per BLUR_PX columns
    sigma = SIGMA_INFLATION * s * math.sqrt(BLUR_PX / sxx) / (1.0 + b_p * b_p) if sxx > 0 else math.inf
    ang = math.atan(b_p)
    us = (float(u_pts.min()), float(u_pts.max()))
    ends = np.array([[us[0], a + b * us[0]], [us[1], a + b * us[1]]])
    return TopEdge(ang, float(sigma), us, ends, int(u_pts.size))


def _follow(g, a, b, u_start, step, strength, r0, W):
    """Columns beyond the region that continue the edge v = a + b u: (u, v) arrays, px."""
    us, vs = [], []
    u, gap = u_start, 0
    while 0 <= u < W and gap < MAX_GAP_PX:
        pred = a + b * u - r0
        lo, hi = int(math.floor(pred)) - BAND_PX, int(math.ceil(pred)) + BAND_PX + 1
        ok = False
        if lo >= 1 and hi <= g.shape[0] - 1:
            band = g[lo:hi, u]
            k = int(np.argmax(band))
            lo_c, hi_c = CONTRAST_RANGE
            # the strongest row, in the band's inside, as strong as the region's edge, and the
            # topmost edge there (nothing half as strong above it: a block's top, a marker)
            if (
                0 < k < band.size - 1
                and lo_c * strength <= band[k] <= hi_c * strength
                and not np.any(band[: max(k - 1, 0)] >= 0.5 * band[k])
            ):
                sub, _ = _sub_row(g, np.array([lo + k]), np.array([u]))
                v = float(sub[0]) + r0
                if abs(v - (a + b * u)) <= MAX_OFF_PX:
                    us.append(float(u))
                    vs.append(v)
                    ok = True
        gap = 0 if ok else gap + 1
        # the line refitted to the last 4 BLUR_PX points every 2 BLUR_PX new ones: a lens bends a
        # long straight edge by a pixel or two, so the slope is kept local
        if ok and len(us) >= 4 * BLUR_PX and (len(us) - 4 * BLUR_PX) % (2 * BLUR_PX) == 0:
            b, a = np.polyfit(np.array(us[-4 * BLUR_PX :]), np.array(vs[-4 * BLUR_PX :]), 1)
        u += step
    if step < 0:
        us.reverse()
        vs.reverse()
    return np.asarray(us, float), np.asarray(vs, float)
