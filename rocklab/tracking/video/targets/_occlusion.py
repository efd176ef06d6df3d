"""Which part of the frame is the markerless object: a part covered, and its outline.

**Covered** (a hand, the thread): the registered template is cut into ``GRID x GRID`` cells
and each cell's correlation with the frame, warped back by the pose, is measured. When most
cells match and some do not, something covers part of the object: the keyframe is not renewed
from that frame (it would learn the occluder), and the pose is fitted again on the matching
cells alone, so a hand over the top of a block neither biases its angle nor loses it while
enough of the face stays in view.

**Outline** (a check of the pose that the object's texture cannot fool): a texture registration follows the texture: on a ball that spins while it swings the texture
slides across the ball, and the pose slides with it while every correlation stays high. The
object's outline against the background does not slide. Once the background behind the user's
region is known, the object's *silhouette* there (how far each pixel stands out of the
background, :func:`silhouette`) is the reference; in every frame the silhouette round the pose is
registered against it by normalised cross-correlation over a window grown round the template
(the reference itself grown round the user's region, so a box drawn smaller than the object
does not cut the object's outline).
The shift found is how far the pose has slid off the object; the pose moved by it is where the
outline puts the object (a start for re-acquisition, verified like any other pose, never
reported as it is).

The registration is made in the pose's frame and, when the pose has turned, in the image's
(the object as it stood), and both must agree: a spinning ball's texture can turn the pose about
a point off the ball, and in the turned frame the ball's silhouette then matches. (For an object
that does turn, the image's frame places the pose within ``2 sin(turn / 2)`` times the distance
from the template's centre to the silhouette's, a few percent of the object for a box drawn
round it.)

**Disk**: a round outline's centre (:func:`disk`: the smallest circle round the blob standing out
of the background, its pale parts included; a disk of the object's radius matched to the window
where a change of the wall joins the blob) is the position of a ball, whose texture slides. A first
frame that shows the disk joined by what held it, or not round at all, is corrected by the
tracked frames (:class:`SeenDisk`): once several verified frames in a row show one round blob
whose edge circle (:func:`edge_circle`: OpenCV's Hough transform on the frame itself, refined on
the edge) keeps one radius at one place under the pose, that circle is the disk.
"""

from __future__ import annotations

import functools
import math

import numpy as np

__all__ = [
    "GRID",
    "cell_correlations",
    "partly_covered",
    "cell_pixels",
    "masked_fit",
    "OutlineRef",
    "silhouette",
    "roundness",
    "disk",
    "stable_disk",
    "SeenDisk",
    "edge_circle",
    "warp_grown",
    "pair",
    "subpixel_peak",
]

#: Cells per side of the grid laid over the template.
GRID = 4
#: A cell below this correlation is covered.
CELL_CC = 0.4
#: The median cell at or above this: the object as a whole still matches (an object whose look
#: changes as a whole, a spinning ball or the lighting, lowers every cell instead).
MEDIAN_CC = 0.95
#: Cells that must stay in view for a fit on the visible part, and the correlation it must reach.
MIN_VISIBLE = 4
VISIBLE_CC = 0.8
MASKED_CC = 0.95


def _edges(n: int) -> np.ndarray:
    return np.linspace(0, n, GRID + 1).astype(int)


def cell_correlations(tmpl: np.ndarray, back: np.ndarray) -> np.ndarray:
    """Correlation coefficient of each cell of ``tmpl`` with ``back`` (the frame warped back onto
    the template's grid), shape (GRID, GRID); 1 for a cell without contrast."""
    h, w = tmpl.shape
    ys, xs = _edges(h), _edges(w)
    out = np.ones((GRID, GRID))
    for i in range(GRID):
        for j in range(GRID):
            a = tmpl[ys[i] : ys[i + 1], xs[j] : xs[j + 1]]
            b = back[ys[i] : ys[i + 1], xs[j] : xs[j + 1]]
            a = a - a.mean()
            b = b - b.mean()
            den = math.sqrt(float((a * a).sum()) * float((b * b).sum()))
            out[i, j] = float((a * b).sum()) / den if den > 0 else 1.0
    return out


def partly_covered(ccs: np.ndarray) -> bool:
    """Whether the cell correlations ``ccs`` show part of the object covered and the rest matching."""
    return bool(np.median(ccs) >= MEDIAN_CC and ccs.min() < CELL_CC)


def cell_pixels(shape, cells: np.ndarray) -> np.ndarray:
    """Template-pixel mask (``shape``) of the cells that ``cells`` (GRID, GRID) keeps."""
    h, w = shape
    rows = np.repeat(np.arange(GRID), np.diff(_edges(h)))
    cols = np.repeat(np.arange(GRID), np.diff(_edges(w)))
    return cells[rows[:, None], cols[None, :]]


def masked_fit(tracker, tmpl, gray, W0):
    """The pose fitted on the cells of ``tmpl`` still in view, from the pose ``W0``.

    Twice: cells matching loosely at ``W0`` (it may be a pixel off), then cells matching at
    :data:`VISIBLE_CC` at the first fit's pose.

    Parameters
    ----------
    tracker : MarkerlessTracker
    tmpl : ndarray (h, w), float32
        The template (first frame's or the keyframe).
    gray : ndarray (H, W), uint8
    W0 : ndarray (2, 3)
        Starting pose, first-frame px -> image px.

    Returns
    -------
    (W, cc, mask, visible) or None
        The pose, its correlation on the visible cells, their pixel mask (h, w) and the share of
        cells in view; None when fewer than :data:`MIN_VISIBLE` cells are, or the fit fails.
    """
    import cv2

    rigid, _ = tracker._ic_for(tmpl)
    W, r, mask, cells = W0, None, None, None
    for thr, blur in ((0.5 * VISIBLE_CC, 3.0), (VISIBLE_CC, 0.0)):
        back = tracker._warp_back(gray, W)
        if back is None:
            return None
        if blur:  # the start may be pixels off: compare the coarse pattern first
            t, back = (cv2.GaussianBlur(x, (0, 0), blur) for x in (tmpl, back))
        else:
            t = tmpl
        cells = cell_correlations(t, back) >= thr
        if int(cells.sum()) < MIN_VISIBLE:
            return None
        mask = cell_pixels(tmpl.shape, cells)

        def fit(window, Ww, mask=mask):
            got = rigid.refine(window, tracker._to_tmpl(Ww), mask=mask)
            return None if got is None else (tracker._from_tmpl(got[0]), got[1])

        r = tracker.fit_near(gray, W, fit)
        if r is None:
            return None
        W = r[0]
    if r is None or r[1] < MASKED_CC:
        return None
    return W, float(r[1]), mask, float(cells.mean())


# -- the outline ---------------------------------------------------------------------------


#: A grey difference below this is "unchanged", grey levels.
BG_TOL = 10.0
#: A pixel starts to stand out where it differs from the background by this fraction of the
#: window's strongest differences (their 98th percentile), and fully at that percentile: a soft
#: shadow or a change of exposure darkens the wall by a fraction of what the object does.
FG_REL = 0.4
#: Least fraction of the user's region standing out of the background for an outline to exist.
MIN_FG = 0.05
#: Largest slide of the pose off the outline, as a fraction of the template's larger side.
DRIFT_FRAC = 0.075
#: Lowest silhouette correlation at which the outline is where the pose puts it.
MIN_SIL_CC = 0.5
#: Margin round the template searched for the outline, as a fraction of its larger side: a box
#: drawn smaller than the object, or a pose slid off it, still sees the whole outline.
OUTLINE_MARGIN_FRAC = 0.2
#: Larger side of the template at which the outline is registered, px (a larger object is
#: registered on a reduced copy: a pixel there is at most 1/40 of it, and sub-pixel peaks).
OUTLINE_SIDE_PX = 40.0
#: An outline at least this round (circularity of its hull: a disk 1, an ellipse of axes 3:2
#: 0.93, 2:1 0.83, a square 0.785) is a disk: it tells no angle, and its centre is its position.
ROUND_MIN = 0.9
#: Largest change of a disk's radius from its first frame's for its centre to be taken, as a
#: fraction of it (more, or a blob less round than :data:`ROUND_MIN`: a shadow, a hand or a
#: change of the background joined it, and the texture's pose stands).
DISK_RADIUS_TOL = 0.15
#: The disk's blob (:func:`disk`) gives its centre when its circle lies within this fraction of the
#: radius of the disk matched to the window (:func:`_disk_match`), which gives it otherwise.
DISK_AGREE = 0.05
#: Larger side of the window in which a disk's centre is measured, px (a larger window is reduced).
DISK_SIDE_PX = 100.0
#: Turns smaller than this leave the image's frame and the pose's nearly the same, rad: the
#: silhouette's place moves by under 0.15 of its distance from the template's centre.
TURN_SAME_RAD = 0.15


def silhouette(patch, bg):
    """How far each pixel of ``patch`` stands out of ``bg``: 0 below :data:`FG_REL` of the
    strongest differences (at least :data:`BG_TOL`), 1 at their 98th percentile (float32, the
    shape of ``patch``); None when nothing stands out."""
    import cv2

    d = cv2.absdiff(np.asarray(patch, np.float32), np.asarray(bg, np.float32))
    flat = d[::2, ::2].ravel()  # a quarter of the pixels tell the percentile
    k = int(0.98 * (flat.size - 1))
    hi = float(np.partition(flat, k)[k])
    lo = max(BG_TOL, FG_REL * hi)
    if hi <= lo:
        return None
    return _ramp(d, lo, hi)


def roundness(sil) -> float:
    """Circularity ``4 pi A / P^2`` of the convex hull of the largest blob where the silhouette
    ``sil`` (h, w, 0..1) stands out (above 0.2, gaps of a few pixels closed: a clear part
    of a ball stands out less than its coloured part): 1 for a disk, 0.785 for a square, 0.59
    for a 1:3 block; NaN without a blob of at least 20 px.

    >>> yy, xx = np.mgrid[0:60, 0:60]
    >>> round(roundness(((xx - 30) ** 2 + (yy - 28) ** 2 < 20**2).astype(np.float32)), 2) > 0.95
    True
    >>> sq = np.zeros((60, 60), np.float32); sq[10:50, 10:50] = 1
    >>> 0.75 < roundness(sq) < 0.82
    True
    """
    import cv2

    if sil is None:
        return float("nan")
    b = cv2.morphologyEx(
        (np.asarray(sil) > 0.2).astype(np.uint8), cv2.MORPH_CLOSE, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (5, 5))
    )
    cs, _ = cv2.findContours(b, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    if not cs:
        return float("nan")
    hull = cv2.convexHull(max(cs, key=cv2.contourArea)).astype(np.float32)
    area, per = cv2.contourArea(hull), cv2.arcLength(hull, True)
    return float(4 * math.pi * area / per**2) if area >= 20 else float("nan")


#: A pixel is part of a round object's disk where it differs from the background by this fraction
#: of the window's strongest differences (at least :data:`BG_TOL`): lower than :data:`FG_REL`, as a
#: ball's clear or pale half stands out less than its coloured half; holes inside are filled.
DISK_REL = 0.2
#: Thresholds tried in turn (as :data:`DISK_REL`) for a disk joined by something that stands out
#: less than it: a ball's soft shadow on the wall beside it stands out by a fifth of the ball's
#: strongest differences (development film: at the first threshold the first frame's disk has a
#: radius of 38.6-42.5 px and its centre 4.4 px off the ball's silhouette, at the next two 32.7-33.7
#: px and within 1 px; in later frames a blob of 46-57 px pulled the centre 6-8 px towards the
#: shadow), while the clear half, dropped by a higher one, leaves the enclosing circle's radius.
DISK_RELS = (DISK_REL, 0.25, 0.3)
#: The first frame's disk is taken at the lowest threshold whose radius the next one keeps to
#: this fraction (nothing that stands out less than the disk joined it).
DISK_STABLE = 0.05
#: The difference is smoothed first (px), and the mask closed (px: a clear half's pale gaps
#: between the parts that stand out, the beads in it) and opened (px: a string or a thread
#: hanging from the ball is no part of its disk), at the window's scale (:data:`DISK_SIDE_PX`).
DISK_SMOOTH_PX = 1.5
DISK_CLOSE_PX = 9
DISK_OPEN_PX = 5


def _ramp(d, lo, hi):
    """``(d - lo) / (hi - lo)`` clipped to 0..1 (float32, a new array; ``d`` is left as it is)."""
    out = np.subtract(d, np.float32(lo), dtype=np.float32)
    out *= np.float32(1.0 / (hi - lo))
    return np.clip(out, 0.0, 1.0, out=out)


def _disk_diff(patch, bg):
    """How far ``patch`` differs from ``bg``, smoothed by :data:`DISK_SMOOTH_PX` (float32), and the
    98th percentile of a quarter of it (grey levels): what :func:`disk` and :func:`_disk_match`
    threshold, computed once for both."""
    import cv2

    d = cv2.GaussianBlur(cv2.absdiff(np.asarray(patch, np.float32), np.asarray(bg, np.float32)), (0, 0), DISK_SMOOTH_PX)
    flat = d[::2, ::2].ravel()
    k = int(0.98 * (flat.size - 1))
    return d, float(np.partition(flat, k)[k])


def disk(patch, bg, rel=DISK_REL, diff=None):
    """The largest blob standing out of ``bg`` in ``patch`` (:data:`DISK_REL`, holes filled, thin
    parts opened away): its smallest enclosing circle's centre (x, y) px in ``patch``, radius px,
    and the circularity of its hull (:func:`roundness`); None when nothing stands out. ``diff``:
    :func:`_disk_diff` of the two, when already computed.

    A ball's outline does not slide as its texture does: the centre of its disk is the position
    it tells (its texture slides over it as it spins).

    >>> yy, xx = np.mgrid[0:80, 0:80]
    >>> ball = np.where((xx - 41.5) ** 2 + (yy - 37) ** 2 < 18**2, 60.0, 150.0).astype(np.float32)
    >>> ball[30:40, 30:50] = 148.0  # a clear part that hardly stands out
    >>> (c, r, circ) = disk(ball, np.full((80, 80), 150.0, np.float32))
    >>> bool(np.hypot(c[0] - 41.5, c[1] - 37) < 1.0 and abs(r - 18) < 1.5 and circ > 0.9)
    True
    """
    import cv2

    d, hi = _disk_diff(patch, bg) if diff is None else diff
    lo = max(BG_TOL, rel * hi)
    if hi <= lo:
        return None
    m = (d > lo).astype(np.uint8)
    for op, size in ((cv2.MORPH_CLOSE, DISK_CLOSE_PX), (cv2.MORPH_OPEN, DISK_OPEN_PX)):
        m = cv2.morphologyEx(m, op, _ellipse(size))
    cs, _ = cv2.findContours(m, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    if not cs:
        return None
    c = max(cs, key=cv2.contourArea)
    hull = cv2.convexHull(c).astype(np.float32)
    area, per = cv2.contourArea(hull), cv2.arcLength(hull, True)
    if area < 20:
        return None
    (x, y), r = cv2.minEnclosingCircle(c)
    return np.array([x, y]), float(r), float(4 * math.pi * area / per**2)


def stable_disk(patch, bg):
    """:func:`disk` at the lowest of :data:`DISK_RELS` whose radius the next threshold keeps to
    :data:`DISK_STABLE` (a shadow joined at a lower one), else at :data:`DISK_REL`.

    >>> yy, xx = np.mgrid[0:100, 0:100]
    >>> bg = np.full((100, 100), 150.0, np.float32)
    >>> img = np.where((xx - 45) ** 2 + (yy - 50) ** 2 < 20**2, 40.0, bg).astype(np.float32)
    >>> img[30:70, 65:90] -= 25.0  # a soft shadow beside it: a fifth of the ball's difference
    >>> (c, r, _), (c2, r2, _) = disk(img, bg), stable_disk(img, bg)
    >>> bool(np.hypot(c[0] - 45, c[1] - 50) > 5 and np.hypot(c2[0] - 45, c2[1] - 50) < 1 and abs(r2 - 20) < 2.5)
    True
    """
    found = [disk(patch, bg, rel) for rel in DISK_RELS]
    for d, nxt in zip(found, found[1:]):
        if d is not None and nxt is not None and abs(d[1] - nxt[1]) <= DISK_STABLE * nxt[1]:
            return d
    return found[0]


@functools.lru_cache(maxsize=8)
def _ellipse(size):
    """The elliptic structuring element of ``size`` px (read only)."""
    import cv2

    k = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (size, size))
    k.flags.writeable = False
    return k


@functools.lru_cache(maxsize=8)
def _disk_kernel(R):
    """A filled disk of radius ``R`` px in a (2R + 1)-px square, float32 (read only)."""
    import cv2

    kern = np.zeros((2 * R + 1, 2 * R + 1), np.float32)
    cv2.circle(kern, (R, R), R, 1.0, -1)
    kern.flags.writeable = False
    return kern


def _disk_match(patch, bg, r, rel=DISK_REL, diff=None):
    """Centre (x, y) px in ``patch`` of a disk of radius ``r`` px matched by normalised correlation
    to how far each pixel stands out of ``bg`` (0 below :data:`DISK_REL` of the strongest
    differences, 1 at them): a shadow or a change of the wall that joins the object's blob moves
    the match little; None when nothing stands out or the window is smaller than the disk.
    ``diff``: :func:`_disk_diff` of the two, when already computed."""
    import cv2

    d, hi = _disk_diff(patch, bg) if diff is None else diff
    lo = max(BG_TOL, rel * hi)
    R = int(round(r))
    if hi <= lo or R < 2 or min(d.shape) <= 2 * R + 1:
        return None
    res = cv2.matchTemplate(_ramp(d, lo, hi), _disk_kernel(R), cv2.TM_CCOEFF_NORMED)
    pk, val = subpixel_peak(res)
    return pk + R if math.isfinite(val) else None


def subpixel_peak(res):
    """Sub-pixel location (x, y) of the maximum of ``res`` and its value (parabola through the
    neighbours where the maximum is inside)."""
    import cv2

    _, val, _, (x, y) = cv2.minMaxLoc(res)
    out = [float(x), float(y)]
    for axis, (i, n) in enumerate(((x, res.shape[1]), (y, res.shape[0]))):
        if 0 < i < n - 1:
            a, b, c = (
                (res[y, i - 1], res[y, i], res[y, i + 1]) if axis == 0 else (res[i - 1, x], res[i, x], res[i + 1, x])
            )
            den = a - 2 * b + c
            if den < 0:
                out[axis] += float(min(max(0.5 * (a - c) / den, -0.5), 0.5))
    return np.array(out), float(val)


class OutlineRef:
    """One object's outline in its first frame, and its registration in later frames.

    Parameters
    ----------
    first, bg : ndarray (H, W) float32
        The first frame and the background behind it (known round the user's region).
    box : tuple of int
        The user's region, (u0, v0, u1, v1) px.

    Attributes
    ----------
    ref : ndarray float32 or None
        The silhouette over the user's region grown by :attr:`margin` (a box drawn smaller than
        the object does not cut its outline); None when the object does not stand out there.
    """

    def __init__(self, first, bg, box):
        u0, v0, u1, v1 = box
        self.size = (u1 - u0, v1 - v0)
        m = self.margin = int(math.ceil(OUTLINE_MARGIN_FRAC * max(self.size)))
        H, W = first.shape[:2]
        x0, y0, x1, y1 = max(u0 - m, 0), max(v0 - m, 0), min(u1 + m, W), min(v1 + m, H)
        s = silhouette(first[y0:y1, x0:x1], bg[y0:y1, x0:x1])
        fg = 0.0 if s is None else float(np.mean(s > 0.5))
        self.ref = s if MIN_FG <= fg <= 1.0 - MIN_FG and float(s.std()) > 0 else None
        #: where the reference lies in a window grown by twice the margin round the template
        self.at = np.array([x0 - (u0 - 2 * m), y0 - (v0 - 2 * m)], float)
        #: the scale the registration runs at (its cost grows as the fourth power of the size)
        self.scale = min(1.0, OUTLINE_SIDE_PX / max(self.size))
        if self.ref is not None and self.scale < 1.0:
            a, b = (_reduce(img[y0:y1, x0:x1], self.scale) for img in (first, bg))
            self.ref = silhouette(a, b)
        #: the outline's roundness (:func:`roundness`), NaN without an outline
        self.roundness = roundness(self.ref)
        #: the object's disk in the first frame (:func:`disk`): centre (first-frame px), radius px;
        #: None unless it is round (then its position is its disk's centre, not a texture point)
        self.disk0 = None
        d = stable_disk(first[y0:y1, x0:x1], bg[y0:y1, x0:x1]) if self.ref is not None else None
        if d is not None:
            # a pale part of a ball that the outline's threshold drops is part of its disk
            self.roundness = max(self.roundness, d[2]) if math.isfinite(self.roundness) else d[2]
            if d[2] >= ROUND_MIN:
                self.disk0 = (d[0] + (x0, y0), d[1])

    def locate(self, tr, frame, bg, W, grown=None):
        """Register the outline round the pose ``W`` (first-frame px -> image px).

        Parameters
        ----------
        tr : MarkerlessTracker
            Gives the template's place in the first frame (``origin``, ``centre0``) and windows.
        frame, bg : ndarray (H, W)
            The frame and the background.
        grown : ndarray (h, w, 2) float32, optional
            The frame and the background already resampled by ``W`` onto the template's grid
            grown by twice :attr:`margin`, stacked on the last axis (:func:`pair`).

        Returns
        -------
        (slide_px, cc, pose) or None
            How far the pose has slid off the outline, px (inf: beyond the margin searched), the
            silhouettes' correlation, and the pose moved towards the outline (float32 (2, 3)),
            from the frame (the pose's or the image's) that disagrees most. None without an
            outline to register.
        """
        import cv2

        if self.ref is None:
            return None
        Wd = np.asarray(W, float)
        A = Wd[:, :2]
        cands = [Wd]
        if abs(math.atan2(A[1, 0] - A[0, 1], A[0, 0] + A[1, 1])) > TURN_SAME_RAD:
            c = A @ tr.centre0 + Wd[:, 2]
            cands.append(np.column_stack((np.eye(2), c - tr.centre0)))
        worst = None
        m2 = 2 * self.margin
        for k, Wc in enumerate(cands):
            if k == 0 and grown is not None:
                both = grown
            else:
                both = pair(*warp_grown(tr, frame, Wc.astype(np.float32), m2, also=bg))
            if both is None:
                continue
            if self.scale < 1.0:
                both = _reduce(both, self.scale)  # both images in one pass, each as alone
            s = silhouette(both[..., 0], both[..., 1])
            if s is None:
                continue
            if s.shape[0] < self.ref.shape[0] or s.shape[1] < self.ref.shape[1]:
                continue
            res = cv2.matchTemplate(s, self.ref, cv2.TM_CCOEFF_NORMED)
            shift, cc = subpixel_peak(res)
            if not math.isfinite(cc):  # a window all one value
                continue
            # at the edge of the search: the outline lies farther than the margin
            edge = min(shift.min(), res.shape[1] - 1 - shift[0], res.shape[0] - 1 - shift[1]) < 0.5
            shift = shift / self.scale - self.at
            slide = math.inf if edge else float(np.hypot(*shift))
            # the pose must sit on the outline in its own frame and in the image's
            if worst is None or (slide, -cc) > (worst[0], -worst[1]):
                pose = Wc.copy()
                pose[:, 2] += Wc[:, :2] @ shift
                worst = (slide, cc, pose.astype(np.float32))
        return worst

    def disk_centre(self, tr, W, grown):
        """The object's disk centre in the image (px, (2,)) from ``grown`` (frame and background
        resampled by the pose ``W`` onto the template's grid grown by twice :attr:`margin`,
        stacked on the last axis: :func:`pair`); None for an object that is not a disk, or a disk
        whose size changed (a shadow or a hand joined it)."""
        if self.disk0 is None:
            return None
        f = min(1.0, DISK_SIDE_PX / max(grown.shape[:2]))
        if f < 1.0:
            grown = _reduce(grown, f)
        back, bgw = grown[..., 0], grown[..., 1]
        r0 = self.disk0[1] * f
        diff = _disk_diff(back, bgw)  # what every threshold below cuts
        found = []
        for rel in DISK_RELS:
            d = disk(back, bgw, rel, diff)
            found.append(d)
            if d is None or d[1] <= (1.0 + DISK_RADIUS_TOL) * r0:
                break  # no blob larger than the disk: nothing joined it at this threshold
        else:  # larger at every threshold (a hand joined it): as at the first
            rel, d = DISK_RELS[0], found[0]
        c = _disk_match(back, bgw, r0, rel, diff)
        if c is None:
            return None
        if d is not None and abs(d[1] - r0) <= DISK_RADIUS_TOL * r0 and np.hypot(*(d[0] - c)) <= DISK_AGREE * r0:
            c = d[0]  # the blob is the disk alone: its circle is finer than the match
        p = c / f - 2 * self.margin + tr.origin  # first-frame px under the pose
        Wd = np.asarray(W, float)
        return Wd[:, :2] @ p + Wd[:, 2]

    def moved(self, found):
        """Whether a :meth:`locate` result says the pose has left the object."""
        slide, cc, _ = found
        return slide > DRIFT_FRAC * max(self.size) or cc < MIN_SIL_CC


#: Verified frames looked at for the object's disk as the tracked frames show it (:class:`SeenDisk`):
#: this many in a row must show one round blob for the disk to be learned from them ...
SEEN_DISK_FRAMES = 10
#: ... of one radius (each within this fraction of their median) ...
SEEN_DISK_RADIUS = 0.05
#: ... at one place on the object under the pose (each within this fraction of the radius of
#: their median); and it is looked for on at most this many verified frames (a block's outline is
#: never round: the look costs a few morphology passes a frame).
SEEN_DISK_PLACE = 0.1
SEEN_DISK_LOOKS = 90
#: A disk learned under poses whose angle was mostly held, not measured, is placed in the first
#: frame by its edge circle there, of a radius within these fractions of the learned one (a held
#: pose puts the disk's first place 3 px off where the first frame shows its edge: PhysTrack
#: RollingCylinder, a 33 px box); under measured poses its place under them is kept (the first
#: frame's edge, a hand joining it, was 1 px off for a 37 px box, the poses' 0.7 px).
FIRST_EDGE_RADII = (0.9, 1.1)


#: The circle of a disk's edge (:func:`edge_circle`) is looked for with radii from this fraction of
#: its blob's enclosing circle's to a little over it: a shadow or a rim joined to the blob only
#: enlarges its enclosing circle (the development film's disc: 19.5 px blob, 15.2 px edge).
EDGE_RADIUS_RANGE = (0.6, 1.05)


def edge_circle(img, near, r_blob, radii=EDGE_RADIUS_RANGE):
    """The circle of the strongest round edge of ``img`` (float32 grey, h x w) within half of
    ``r_blob`` of ``near`` (x, y px), its radius within ``radii`` (fractions) of ``r_blob``
    (OpenCV's gradient Hough transform, the variant that scores each circle's completeness):
    centre (2,) px and radius px, or None. A disk's edge against its background places it where
    the blob standing out of the background does not: a soft shadow, or a hand holding it, joins
    the blob and not the edge."""
    import cv2

    u8 = np.clip(img, 0, 255).astype(np.uint8)
    lo, hi = (int(math.floor(k * r_blob)) for k in radii)
    if lo < 3:
        return None
    found = cv2.HoughCircles(
        cv2.GaussianBlur(u8, (0, 0), 1.0),
        cv2.HOUGH_GRADIENT_ALT,
        1,
        r_blob,
        param1=300,
        param2=0.7,
        minRadius=lo,
        maxRadius=hi + 1,
    )
    if found is None:
        return None
    for x, y, r in found[0]:  # strongest first
        if math.hypot(x - near[0], y - near[1]) <= 0.5 * r_blob:
            return _refine_circle(u8, np.array([x, y], float), float(r))
    return None


#: Rays cast from a circle's centre to refine it (:func:`_refine_circle`), the band searched along
#: each (px either side of the circle) and the residual beyond which an edge point is left out.
REFINE_RAYS = 48
REFINE_BAND_PX = 3.0
REFINE_OUT_PX = 1.5


def _refine_circle(u8, c, r):
    """The circle ``(c, r)`` (px; the Hough transform's, on whole pixels) fitted to the strongest
    edge along :data:`REFINE_RAYS` rays within :data:`REFINE_BAND_PX` of it (least squares, the
    points over :data:`REFINE_OUT_PX` off the first fit left out): to a tenth of a pixel where the
    edge is clear; the Hough circle where the fit moves it by over a pixel or half the band."""
    import cv2

    g = cv2.GaussianBlur(u8, (0, 0), 1.0).astype(np.float32)
    mag = cv2.magnitude(cv2.Sobel(g, cv2.CV_32F, 1, 0), cv2.Sobel(g, cv2.CV_32F, 0, 1))
    a = np.linspace(0.0, 2 * math.pi, REFINE_RAYS, endpoint=False)[:, None]
    rho = np.arange(r - REFINE_BAND_PX, r + REFINE_BAND_PX + 1e-9, 0.25)[None, :]
    mx, my = (c[0] + rho * np.cos(a)).astype(np.float32), (c[1] + rho * np.sin(a)).astype(np.float32)
    prof = cv2.remap(mag, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0.0)
    k = np.argmax(prof, axis=1)
    keep = prof[np.arange(len(k)), k] > 0
    pts = np.column_stack((mx[np.arange(len(k)), k], my[np.arange(len(k)), k]))[keep].astype(float)
    fit = None
    for _ in range(2):
        if len(pts) < REFINE_RAYS // 2:
            return c, r
        A = np.column_stack((2 * pts, np.ones(len(pts))))
        sol = np.linalg.lstsq(A, (pts**2).sum(1), rcond=None)[0]
        fit = (sol[:2], math.sqrt(max(sol[2] + sol[0] ** 2 + sol[1] ** 2, 0.0)))
        pts = pts[np.abs(np.hypot(*(pts - fit[0]).T) - fit[1]) <= REFINE_OUT_PX]
    if fit is None or np.hypot(*(fit[0] - c)) > 1.0 or abs(fit[1] - r) > 0.5 * REFINE_BAND_PX:
        return c, r
    return fit[0], fit[1]


class SeenDisk:
    """An object's disk as its own verified frames show it, where its first frame did not.

    The first frame may show a round object joined by what held it (a hand at the edge of a disc
    about to roll: a blob of radius 19.9 px for a 16 px disc, its centre 3 px towards the hand),
    or not round at all. Once :data:`SEEN_DISK_FRAMES` verified frames in a row show one round
    blob (circularity at least :data:`ROUND_MIN`, :func:`stable_disk`) of one radius at one place
    under the pose (first-frame px), that is the object's disk: its place under the pose is where
    the first frame would have shown it alone. A blob that slides under the pose (a spinning
    ball's texture carries the pose) or changes size (a hand, a shadow) teaches nothing.

    Attributes
    ----------
    disk : tuple or None
        ``(centre (2,) first-frame px, radius px, circularity)`` once learned.
    """

    def __init__(self):
        self.disk = None
        #: the learned disk's centre where the poses put it (first-frame px), before
        #: :meth:`place_first` moved it to the first frame's edge circle
        self.pose_c = None
        self.looks = 0
        #: frame -> (centre (2,) image px, radius px) of each verified frame's round look (:meth:`add`)
        self.seen_at: dict = {}
        #: whether the poses the looks are now taken under hold an angle they did not measure
        self.held = False
        self._held_share = 0.0
        self._run: list = []

    @property
    def done(self) -> bool:
        """Nothing more to look for: learned, or looked for on :data:`SEEN_DISK_LOOKS` frames."""
        return self.disk is not None or self.looks >= SEEN_DISK_LOOKS

    def look(self, tr, grown, margin2):
        """The round blob in ``grown`` (frame and background resampled by the pose onto the
        template's grid grown by ``margin2`` px, :func:`pair`): ``(centre first-frame px under the
        pose, radius px, circularity)``, or None when it is not round."""
        f = min(1.0, DISK_SIDE_PX / max(grown.shape[:2]))
        if f < 1.0:
            grown = _reduce(grown, f)
        d = stable_disk(grown[..., 0], grown[..., 1])
        if d is None or d[2] < ROUND_MIN:
            return None
        c = edge_circle(grown[..., 0], d[0], d[1])
        if c is None:
            return None
        return c[0] / f - margin2 + tr.origin, c[1] / f, d[2]

    def add(self, seen, frame=None, W=None) -> bool:
        """Count one verified frame's :meth:`look` (None: not round); True when the disk is
        learned with it. With the ``frame`` and the pose ``W`` (first-frame px -> image px) it was
        looked under, the look's circle is kept in :attr:`seen_at` (:meth:`measured`)."""
        self.looks += 1
        if seen is not None and frame is not None and W is not None:
            Wd = np.asarray(W, float)
            self.seen_at[frame] = (Wd[:, :2] @ np.asarray(seen[0], float) + Wd[:, 2], float(seen[1]))
        self._run = [] if seen is None else (self._run + [(*seen, self.held)])[-SEEN_DISK_FRAMES:]
        if len(self._run) < SEEN_DISK_FRAMES:
            return False
        c = np.array([s[0] for s in self._run])
        r = np.array([s[1] for s in self._run])
        cm, rm = np.median(c, axis=0), float(np.median(r))
        if np.all(np.abs(r - rm) <= SEEN_DISK_RADIUS * rm) and np.all(np.hypot(*(c - cm).T) <= SEEN_DISK_PLACE * rm):
            self.disk = (cm, rm, float(np.median([s[2] for s in self._run])))
            self._held_share = float(np.mean([s[3] for s in self._run]))
            return True
        return False

    def measured(self) -> dict:
        """frame -> the disk's centre (2,) image px, on the verified frames looked at whose edge
        circle has the learned disk's radius (within :data:`SEEN_DISK_RADIUS`): the place its own
        edge shows, which the poses of the frames before it was learned (their angle the
        texture's, turning as it rolls) do not give; empty before it is learned."""
        if self.disk is None:
            return {}
        r = self.disk[1]
        return {f: c for f, (c, rf) in self.seen_at.items() if abs(rf - r) <= SEEN_DISK_RADIUS * r}

    def place_first(self, first, at) -> None:
        """Move the learned disk's centre to its edge circle in ``first`` (the first frame's part
        whose corner is at ``at`` (x, y), first-frame px; float32), where one of its radius lies
        near (:data:`FIRST_EDGE_RADII`), when it was learned under poses mostly :attr:`held`;
        kept as learned otherwise."""
        if self.disk is None:
            return
        c, r, circ = self.disk
        self.pose_c = c
        if self._held_share <= 0.5:
            return
        e = edge_circle(first, c - np.asarray(at, float), r, FIRST_EDGE_RADII)
        if e is not None:
            self.disk = (e[0] + np.asarray(at, float), r, circ)

    def teach(self, ref) -> None:
        """Give the learned disk to the outline ``ref`` (an :class:`OutlineRef`) where its first
        frame's disk is missing or of another size (:data:`DISK_RADIUS_TOL`)."""
        if self.disk is None or ref is None:
            return
        c, r, circ = self.disk
        if ref.disk0 is None or abs(ref.disk0[1] - r) > DISK_RADIUS_TOL * r:
            ref.disk0 = (c, r)
            ref.roundness = max(ref.roundness, circ) if math.isfinite(ref.roundness) else circ


def _reduce(img, f):
    """``img`` reduced by the factor ``f`` < 1 (area averaging)."""
    import cv2

    return cv2.resize(img, None, fx=f, fy=f, interpolation=cv2.INTER_AREA)


def pair(a, b):
    """The images ``a`` and ``b`` of one shape (h, w) stacked on a last axis, (h, w, 2) float32;
    None when either is None. Reduced by :func:`_reduce` in one pass, each channel exactly as
    alone (the frame and its background are reduced together, twice a frame)."""
    import cv2

    if a is None or b is None:
        return None
    return cv2.merge((np.asarray(a, np.float32), np.asarray(b, np.float32)))


def warp_grown(tr, img, W, margin, also=None):
    """``img`` resampled by the pose ``W`` onto the template's grid grown by ``margin`` px on
    every side (float32), or None off the frame. ``also``: a second image of ``img``'s shape
    resampled the same way (the window placed once); then the pair, (None, None) off the frame."""
    import cv2

    crop, off = tr._window(img, W, margin + 4)
    if crop is None:
        return None if also is None else (None, None)
    Wd = np.asarray(W, np.float32).copy()
    Wd[:, 2] += (Wd[:, :2].astype(float) @ (tr.origin - margin)).astype(np.float32) - off
    w, h = tr.size
    crops = [crop]
    if also is not None:  # the same window of the second image (what tr._window cuts from it)
        x0, y0 = int(off[0]), int(off[1])
        crops.append(also[y0 : y0 + crop.shape[0], x0 : x0 + crop.shape[1]].astype(np.float32))
    out = [
        cv2.warpAffine(
            c,
            Wd,
            (w + 2 * margin, h + 2 * margin),
            flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
            borderMode=cv2.BORDER_REPLICATE,
        )
        for c in crops
    ]
    return out[0] if also is None else tuple(out)
