"""Independent references for the real pendulum films: the ball's silhouette, its blue half.

Used only by tests and benchmarks, never by the package. :func:`silhouette_track` is the
reference the checks use: the ball's whole silhouette against the film's temporal median, in
colour, and the smallest circle round it. Checked by hand on film1 (the other take, 550x310):
nine frames labelled from 6x crops (the ball's left, right, top and bottom edges read off a
pixel grid), the circle's centre within 2.2 px of every label (RMS 1.2 px); the blue-half blob
below was 2.5-3.9 px off on five of them (the ball tilts, and the blue half with it).

:func:`blob_track`, the older reference: an HSV threshold on the ball's blue
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


#: Colour difference from the film's median (largest of B, G, R, after a 5x5 blur) above which a
#: pixel is the ball, tried in turn until the circle has the ball's radius (a shadow band that
#: joins the ball at the lowest threshold is dropped by the next).
SIL_THRESHOLDS = (20, 30, 45)
#: The circle's radius may differ from the film's median radius by this fraction.
SIL_RADIUS_TOL = 0.12


def _silhouette_circle(img, med, thr):
    """(u, v, r) px of the smallest circle round the largest blob differing from ``med`` by more
    than ``thr``; NaN without a blob of 200 px."""
    # |img - med| per channel, then the largest of B, G, R (OpenCV's per-channel calls: numpy's
    # max over the 3-long last axis took half of the reference's time)
    b, g, r = cv2.split(cv2.absdiff(img, med))
    d = cv2.GaussianBlur(cv2.max(cv2.max(b, g), r), (5, 5), 0)
    m = (d > thr).astype(np.uint8)
    m = cv2.morphologyEx(m, cv2.MORPH_CLOSE, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (11, 11)))
    m = cv2.morphologyEx(m, cv2.MORPH_OPEN, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (5, 5)))
    cs, _ = cv2.findContours(m, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    if not cs or cv2.contourArea(max(cs, key=cv2.contourArea)) < 200:
        return (np.nan, np.nan, np.nan)
    (u, v), r = cv2.minEnclosingCircle(max(cs, key=cv2.contourArea))
    return (u, v, r)


def silhouette_track(path, scale=1.0):
    """The ball's centre from its silhouette, px (u, v) per frame; NaN where none has its radius.

    The background is the film's temporal median (every fourth frame: the ball swings through);
    the ball is the largest blob differing from it in colour, its centre the centre of the
    smallest circle round the blob (the ball's clear upper half and its blue lower half alike).
    Frames are reduced by ``scale`` (< 1 for large films) and the centres given at full size.

    Returns
    -------
    uv : ndarray (n, 2)
    radius_px : float
        The median radius.
    """
    frames = _read_frames(
        path,
        lambda img: img if scale == 1.0 else cv2.resize(img, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA),
    )
    med = np.median(np.asarray(frames[::4]), axis=0).astype(np.uint8)  # truncated, as before: same pixels
    first = np.array([_silhouette_circle(f, med, SIL_THRESHOLDS[0]) for f in frames])
    r0 = float(np.nanmedian(first[:, 2]))
    out = []
    for f, c in zip(frames, first):
        for thr in SIL_THRESHOLDS:
            if thr != SIL_THRESHOLDS[0]:
                c = _silhouette_circle(f, med, thr)
            if abs(c[2] - r0) <= SIL_RADIUS_TOL * r0:
                break
        else:
            c = (np.nan, np.nan, np.nan)
        out.append(c[:2])
    return np.array(out, float).reshape(-1, 2) / scale, r0 / scale


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

    best = None
    for ph in (0.0, 0.5 * np.pi, np.pi, 1.5 * np.pi):  # a start whose phase is far off may not converge
        try:
            popt, _ = curve_fit(damped, t_s[m], s, p0=(np.std(s) * 1.4, 30.0, T0, ph, 0.0), maxfev=20000)
        except RuntimeError:
            continue
        cost = float(np.sum((damped(t_s[m], *popt) - s) ** 2))
        if best is None or cost < best[0]:
            best = (cost, float(popt[2]))
    if best is None:
        raise RuntimeError("no damped sine fits the swing")
    return best[1]


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


def moved_box(box, dx=0.0, dy=0.0, scale=1.0):
    """``box`` = (x, y, w, h) with its centre moved by (``dx``, ``dy``) of its sides and scaled by
    ``scale`` about that centre: [x, y, w, h], int px."""
    x, y, w, h = box
    cx, cy = x + w / 2 + dx * w, y + h / 2 + dy * h
    return [round(cx - scale * w / 2), round(cy - scale * h / 2), round(scale * w), round(scale * h)]


def ball_config(box, **video):
    """A markerless :class:`~rocklab.config.TrackConfig` of one object ``ball`` in ``box``, no
    levelling, ``video`` the [video] table (start_frame, stop_frame)."""
    from rocklab.config import TrackConfig

    return TrackConfig.from_dict(
        {
            "video": video,
            "targets": {"style": "markerless"},
            "reference": {"level": "none"},
            "objects": [{"id": "ball", "roi": list(box)}],
        }
    )


def bright_blob_track(path, start_uv, thr=50, area_px=(12, 400), max_step_px=80.0):
    """A small bright object on a dark background (a bob in front of black cloth), px (u, v) per
    frame; NaN where none is found.

    Independent of the tracker: per frame, the pixels brighter or darker than the film's temporal
    median (every second frame) by more than ``thr`` grey levels, their compact blobs of
    ``area_px`` pixels, and of those the one nearest the last found (from ``start_uv`` in the first
    frame, within ``max_step_px``). The median is the background where the object moves most of
    the film.
    """
    frames = _read_frames(path, lambda img: cv2.cvtColor(img, cv2.COLOR_BGR2GRAY))
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


def _read_frames(path, each) -> list:
    """Every frame of a film (OpenCV BGR), each passed through ``each``."""
    cap = cv2.VideoCapture(str(path))
    frames = []
    while True:
        ok, img = cap.read()
        if not ok:
            break
        frames.append(each(img))
    cap.release()
    return frames
