"""Part of a markerless object covered (a hand, the thread): which part, and a fit on the rest.

The registered template is cut into ``GRID x GRID`` cells and each cell's correlation with the
frame, warped back by the pose, is measured. When most cells match and some do not, something
covers part of the object: the keyframe is not renewed from that frame (it would learn the
occluder), and the pose is fitted again on the matching cells alone, so a hand over the top of a
block neither biases its angle nor loses it while enough of the face stays in view.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["GRID", "cell_correlations", "partly_covered", "cell_pixels", "masked_fit"]

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
