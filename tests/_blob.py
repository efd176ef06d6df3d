"""Independent reference for the real pendulum films: the ball's blue half by colour.

Used only by tests and benchmarks, never by the package: an HSV threshold on the ball's blue
lower half and the largest blob. The ball turns about its string, so its blue half stays at the
bottom: the ball's centre is the middle of the blob's width, one half-width above its lowest
pixel (closer to the tracked point than the blob's centroid, which moves with the equator's
tilt: 3.1 px against 3.7 px largest spread on the development film). A tracker's reference point
is compared after removing the median offset between the two.
"""

from __future__ import annotations

import cv2
import numpy as np

#: HSV range of the ball's blue half (OpenCV hue 0..180); the beige wall and its shadow are far out.
BLUE_LO, BLUE_HI = (95, 80, 40), (130, 255, 255)


def blob_track(path, max_frames=None):
    """The ball's centre from the largest blue blob per frame, px (u, v); NaN where there is none.

    Returns
    -------
    uv : ndarray (n, 2)
    fps : float
    width_px : int
    """
    cap = cv2.VideoCapture(str(path))
    fps = cap.get(cv2.CAP_PROP_FPS)
    width = int(cap.get(cv2.CAP_PROP_FRAME_WIDTH))
    out = []
    while max_frames is None or len(out) < max_frames:
        ok, img = cap.read()
        if not ok:
            break
        m = cv2.inRange(cv2.cvtColor(img, cv2.COLOR_BGR2HSV), BLUE_LO, BLUE_HI)
        # smallest blob worth calling the ball: 0.02 % of the frame
        n, _, stats, _ = cv2.connectedComponentsWithStats(m)
        if n > 1:
            i = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
            if stats[i, cv2.CC_STAT_AREA] >= 2e-4 * m.size:
                x, y, w, h = stats[i, :4]
                out.append((x + 0.5 * w, y + h - 0.5 * w))
                continue
        out.append((np.nan, np.nan))
    cap.release()
    return np.array(out, float).reshape(-1, 2), float(fps), width


def wrong_ok(x_px, y_px, ok, ref_uv, width_px, tol_frac=0.01):
    """Frames reported ok whose point is off the reference by more than ``tol_frac`` of the width.

    The offset between the tracked point and the blob's centroid is the median over the frames
    both see (a box drawn elsewhere on the ball moves the tracked point, not the track).

    Returns
    -------
    wrong : ndarray (n,) bool
        Ok frames off by more than the tolerance, or ok where the reference sees no ball.
    offset : ndarray (2,)
    """
    n = min(len(x_px), len(ref_uv))
    p = np.column_stack((x_px[:n], y_px[:n]))
    ok = np.asarray(ok[:n], bool)
    r = ref_uv[:n]
    both = ok & np.all(np.isfinite(r), axis=1)
    off = np.median(p[both] - r[both], axis=0) if both.any() else np.zeros(2)
    d = np.hypot(*(p - r - off).T)
    wrong = ok & ~(d <= tol_frac * width_px)
    return wrong, off


def swing_period_s(t_s, x):
    """Period of a damped swing ``x(t)`` (NaN where not measured): FFT peak, then a damped-sine
    least-squares fit, s."""
    from scipy.optimize import curve_fit

    t_s, x = np.asarray(t_s, float), np.asarray(x, float)
    m = np.isfinite(x)
    s = x[m] - x[m].mean()
    dt = float(np.median(np.diff(t_s)))
    f = np.fft.rfftfreq(m.sum(), dt)[1:]
    T0 = 1 / f[np.argmax(np.abs(np.fft.rfft(s))[1:])]

    def damped(t, a, tau, T, ph, c):
        return a * np.exp(-t / tau) * np.cos(2 * np.pi * t / T + ph) + c

    popt, _ = curve_fit(damped, t_s[m], s, p0=(np.std(s) * 1.4, 30.0, T0, 0.0, 0.0), maxfev=20000)
    return float(popt[2])


def perturbed_boxes(box, n, seed=0, size_frac=0.2, pos_frac=0.1):
    """``n`` boxes round ``box`` = (x, y, w, h): each side scaled by up to ``size_frac`` and the
    centre moved by up to ``pos_frac`` of the side, uniformly at random (seeded); int px."""
    rng = np.random.default_rng(seed)
    x, y, w, h = box
    cx, cy = x + w / 2, y + h / 2
    out = []
    for _ in range(n):
        sw, sh = w * (1 + rng.uniform(-size_frac, size_frac)), h * (1 + rng.uniform(-size_frac, size_frac))
        ux, uy = cx + rng.uniform(-pos_frac, pos_frac) * w, cy + rng.uniform(-pos_frac, pos_frac) * h
        out.append((int(round(ux - sw / 2)), int(round(uy - sh / 2)), int(round(sw)), int(round(sh))))
    return out


def bright_blob_track(path, start_uv, thr=50, area_px=(12, 400), max_step_px=80.0):
    """A small bright object on a dark background (a bob in front of black cloth), px (u, v) per
    frame; NaN where none is found.

    Independent of the tracker: per frame, the pixels brighter or darker than the film's temporal
    median (every second frame) by more than ``thr`` grey levels, their compact blobs of
    ``area_px`` pixels, and of those the one nearest the last found (from ``start_uv`` in the first
    frame, within ``max_step_px``). The median is the background where the object moves most of
    the film.
    """
    cap = cv2.VideoCapture(str(path))
    frames = []
    while True:
        ok, img = cap.read()
        if not ok:
            break
        frames.append(cv2.cvtColor(img, cv2.COLOR_BGR2GRAY))
    cap.release()
    g = np.asarray(frames, np.int16)
    med = np.median(g[::2], axis=0).astype(np.int16)
    last, out = np.asarray(start_uv, float), []
    for f in g:
        n, _, st, cen = cv2.connectedComponentsWithStats((np.abs(f - med) > thr).astype(np.uint8))
        best = None
        for i in range(1, n):
            w, h = st[i, 2], st[i, 3]
            if not area_px[0] <= st[i, cv2.CC_STAT_AREA] <= area_px[1] or max(w, h) > 3 * min(w, h) + 3:
                continue
            d = float(np.hypot(*(cen[i] - last)))
            if d <= max_step_px and (best is None or d < best[0]):
                best = (d, cen[i])
        out.append((np.nan, np.nan) if best is None else tuple(best[1]))
        if best is not None:
            last = best[1]
    return np.array(out, float).reshape(-1, 2)
