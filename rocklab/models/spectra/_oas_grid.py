"""The OAS verdict grid computed adaptively: coarse first, refined only where verdicts change.

Most of an OAS grid is uniform (large blocks safe, small blocks overturned);
the verdicts change along a chaotic band of bays and islands a few sizes
wide. :func:`adaptive_verdicts` simulates every ``coarse``-th level and size,
then halves the spacing inside the cells whose corners disagree (and their
neighbours, ``dilate`` cells around) until the full resolution is reached;
uniform cells take their corners' verdict. The cost follows the length of the
boundary, not the area of the grid. Each row's first unsafe size (which sets
the boundary, hence t_I) gets a last check of the ``frontier`` sizes before it.

Measured against the dense grid (every point simulated) on the 44 FEMA P695
far-field records at H/B = 12 with the Taylor runs (the default since session 13;
``benchmarks/oas_fema44.py --grid``): 99.92 % of the 422 400 verdicts identical (worst
record 99.77 %), t_I identical on 43/44 records and t'_I on 42/44, 19.8 % of the grid
simulated, 3.47x less time than the dense grid (191.6 s against 665.1 s on one thread of a
machine loaded by other work). With the Newmark runs before: 99.93 % (worst 99.78 %), t_I
44/44, t'_I 42/44, 25 s against 63 s on 2 idle cores. What it can miss: islands smaller
than a coarse cell that touch no coarse point and lie away from the boundary. The one
record whose t_I differs is such a case: FF-10's dense t_I (0.560 s against 0.516 s) comes
from one unsafe cell (a_p/a_p,min 1.68, R 6.53 m) 12 sizes before its row's first unsafe
size, beyond the frontier of 8, inside a cell whose corners are safe; that cell is chaotic
(safe at 1 -/+ 1e-4 times its amplitude), so neither value is the more converged.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["adaptive_verdicts", "boundary_verdicts", "ADAPTIVE_COARSE", "ADAPTIVE_DILATE", "ADAPTIVE_FRONTIER"]

#: Spacing (grid steps) of the first pass.
ADAPTIVE_COARSE = 8
#: Cells around a mixed cell that are refined too.
ADAPTIVE_DILATE = 1
#: Grid steps before each level's first unsafe size that are always simulated.
ADAPTIVE_FRONTIER = 8


def _lines(n: int, step: int) -> np.ndarray:
    return np.unique(np.r_[np.arange(0, n, step), n - 1])


def _cells(idx: np.ndarray, lines: np.ndarray):
    """Cell of each index and the other cell it touches when it lies on a grid line."""
    lo = np.clip(np.searchsorted(lines, idx, side="right") - 1, 0, lines.size - 2)
    on_line = np.isin(idx, lines) & (lo > 0) & (idx != lines[-1])
    return lo, np.where(on_line, lo - 1, lo)


def adaptive_verdicts(
    run: Callable[[np.ndarray, np.ndarray], np.ndarray],
    n_rows: int,
    n_cols: int,
    *,
    coarse: int = ADAPTIVE_COARSE,
    dilate: int = ADAPTIVE_DILATE,
    frontier: int = ADAPTIVE_FRONTIER,
) -> tuple[np.ndarray, np.ndarray]:
    """Boolean verdict grid from as few calls of ``run`` as the boundary needs.

    Parameters
    ----------
    run : callable
        ``run(rows, cols) -> bool array`` of the same shape: the verdicts of the
        grid points (rows[k], cols[k]), all computed in one call (one parallel batch).
    n_rows, n_cols : int
        Grid shape (levels, sizes).
    coarse : int
        First-pass spacing in grid steps (>= 1; 1 is the dense grid).
    dilate : int
        Mixed cells grow by this many cells before refining (>= 0).
    frontier : int
        Then the ``frontier`` points before each row's first unsafe point are
        simulated (again after every newly found unsafe point): that point sets
        the row's boundary and hence t_I, and a lone unsafe island just outside
        the refined band would otherwise be missed.

    Returns
    -------
    over : ndarray of bool, shape (n_rows, n_cols)
        Verdicts: simulated where ``evaluated``, else the verdict of the uniform
        cell the point lies in.
    evaluated : ndarray of bool, shape (n_rows, n_cols)
        Points that were simulated.
    """
    from scipy.ndimage import binary_dilation

    coarse = max(1, int(coarse))
    over = np.zeros((n_rows, n_cols), bool)
    known = np.zeros_like(over)
    rows, cols = _lines(n_rows, coarse), _lines(n_cols, coarse)
    ii, jj = np.meshgrid(rows, cols, indexing="ij")
    over[ii, jj] = np.asarray(run(ii.ravel(), jj.ravel()), bool).reshape(ii.shape)
    known[ii, jj] = True
    step = coarse
    while step > 1 and rows.size > 1 and cols.size > 1:
        v = over[np.ix_(rows, cols)]
        c = v[:-1, :-1]
        mixed = (c != v[1:, :-1]) | (c != v[:-1, 1:]) | (c != v[1:, 1:])
        if dilate > 0 and mixed.any():
            mixed = binary_dilation(mixed, iterations=int(dilate))
        step = max(1, step // 2)
        fine_r, fine_c = _lines(n_rows, step), _lines(n_cols, step)
        a, a2 = _cells(fine_r, rows)
        b, b2 = _cells(fine_c, cols)
        A, B = np.meshgrid(a, b, indexing="ij")
        A2, B2 = np.meshgrid(a2, b2, indexing="ij")
        touch_mixed = mixed[A, B] | mixed[A2, B] | mixed[A, B2] | mixed[A2, B2]
        fi, fj = np.meshgrid(fine_r, fine_c, indexing="ij")
        todo = touch_mixed & ~known[fi, fj]
        if todo.any():
            ri, cj = fi[todo], fj[todo]
            over[ri, cj] = np.asarray(run(ri, cj), bool)
            known[ri, cj] = True
        rows, cols = fine_r, fine_c
        # points of uniform cells take the cells' verdict (every corner agrees)
        fill = ~touch_mixed & ~known[fi, fj]
        over[fi[fill], fj[fill]] = c[A[fill], B[fill]]
    if frontier > 0:
        _check_frontier(run, over, known, int(frontier))
    if rows.size <= 1 or cols.size <= 1:  # degenerate grid: simulate every point
        ii, jj = np.nonzero(~known)
        if ii.size:
            over[ii, jj] = np.asarray(run(ii, jj), bool)
            known[ii, jj] = True
    return over, known


def _check_frontier(run, over, known, width, only=None):
    """Simulate the ``width`` points before each row's first unsafe one until none turns unsafe (rows in
    the mask ``only``, all by default)."""
    while True:
        has = over.any(axis=1) if only is None else over.any(axis=1) & only
        rows = np.flatnonzero(has)  # rows without an unsafe point have no boundary
        j = over[rows].argmax(axis=1)[:, None] - np.arange(1, width + 1)[None, :]
        i = np.broadcast_to(rows[:, None], j.shape)
        ok = j >= 0
        i, j = i[ok], j[ok]
        todo = ~known[i, j]
        if not todo.any():
            return
        i, j = i[todo], j[todo]
        v = np.asarray(run(i, j), bool)
        over[i, j] = v
        known[i, j] = True
        if not v.any():
            return


def _simulate(run, over, known, lo, hi, rows):
    """Simulate the columns [lo[r], hi[r]) of each row r in ``rows`` that are not known yet."""
    if not rows.size:
        return
    i = np.concatenate([np.full(max(0, hi[r] - lo[r]), r) for r in rows]).astype(int)
    j = np.concatenate([np.arange(lo[r], hi[r]) for r in rows]).astype(int)
    todo = ~known[i, j]
    if todo.any():
        over[i[todo], j[todo]] = np.asarray(run(i[todo], j[todo]), bool)
        known[i[todo], j[todo]] = True


def _windows(run, over, known, lo, hi, frontier, mid=None):
    """Simulate each row's window [lo, hi); rows with no unsafe point there move on to the right in steps of
    ``frontier`` until one is found or the row ends (``lo``, ``hi`` updated in place). With ``mid``: [lo, mid)
    first and [mid, hi) only for the rows with no unsafe point yet; the later windows likewise in pieces of 2, 2
    and the rest (the first unsafe point is the same; the points after it are not needed)."""
    n_cols = over.shape[1]
    active = hi > lo
    if mid is not None:
        mid = np.clip(mid, lo, hi)
        _simulate(run, over, known, lo, mid, np.flatnonzero(active))
        rest = active & ~over.any(axis=1)
        _simulate(run, over, known, mid, hi, np.flatnonzero(rest))
        active = rest & ~over.any(axis=1) & (hi < n_cols)
        lo[active] = hi[active]
        hi[active] = np.minimum(hi[active] + max(1, int(frontier)), n_cols)
    while active.any():
        # left to right in pieces of 2, 2 and the rest, each for the rows with no unsafe point yet
        for a, b in ((lo, np.minimum(lo + 2, hi)), (np.minimum(lo + 2, hi), np.minimum(lo + 4, hi)), (lo + 4, hi)):
            _simulate(run, over, known, a, b, np.flatnonzero(active & ~over.any(axis=1)))
        active = ~over.any(axis=1) & (hi < n_cols) & (hi > lo)
        lo[active] = hi[active]
        hi[active] = np.minimum(hi[active] + max(1, int(frontier)), n_cols)


def boundary_verdicts(
    run: Callable[[np.ndarray, np.ndarray], np.ndarray],
    n_rows: int,
    n_cols: int,
    first_guess: np.ndarray,
    *,
    frontier: int = ADAPTIVE_FRONTIER,
    ahead: int = 2,
    key: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Each row's first unsafe point, searched near a guess (a neighbouring OAS's boundary).

    Per row, the points from ``first_guess - frontier`` to ``first_guess + ahead``
    are simulated (those after the guess only where none before it is unsafe: the row's first
    unsafe point is all that is used); a row with no unsafe point there moves on to the right in
    steps of ``frontier`` until one is found or the row ends; then the frontier
    check of :func:`adaptive_verdicts` runs. Only the boundary (and hence t_I,
    t'_I and beta) is resolved: the map elsewhere is filled, safe before each
    row's first unsafe point and unsafe after the simulated window.

    Parameters
    ----------
    run : callable
        As in :func:`adaptive_verdicts`.
    n_rows, n_cols : int
        Grid shape.
    first_guess : ndarray of int, shape (n_rows,)
        Expected first unsafe column per row; ``n_cols`` or more for a row
        expected to hold no unsafe point.
    frontier, ahead : int
        Columns simulated before and after the guess.
    key : ndarray, shape (n_rows, n_cols), optional
        Only the smallest ``key`` at a row's first unsafe point is wanted (t_I: key = f = level p):
        only the rows whose window start has a key below the smallest found so far are searched
        (first those below the smallest key at the windows' ends), until no other row has. The rows
        left out could not have held the minimum, as no row's point before its window is looked at;
        they stay safe (no boundary) in the map.

    Returns
    -------
    over, evaluated : ndarray of bool, shape (n_rows, n_cols)
    """
    over = np.zeros((n_rows, n_cols), bool)
    known = np.zeros_like(over)
    g = np.clip(np.asarray(first_guess, int), 0, n_cols)
    lo = np.clip(g - int(frontier), 0, n_cols)
    hi = np.clip(g + int(ahead) + 1, 0, n_cols)
    # rows expected to stay safe get their last `frontier` columns, the smallest blocks
    none = g >= n_cols
    lo[none] = max(0, n_cols - int(frontier))
    hi[none] = n_cols
    done = np.zeros(n_rows, bool)
    todo = np.ones(n_rows, bool)
    if key is not None:  # the rows whose window could reach below the smallest key the guess expects
        rows = np.arange(n_rows)
        bound = key[rows, np.minimum(lo, n_cols - 1)]
        todo = bound < np.min(key[rows, np.maximum(hi, 1) - 1])
    while todo.any():
        # up to the guess first: a row whose first unsafe point lies there needs none of the points after it
        _windows(run, over, known, np.where(todo, lo, hi), hi, frontier, mid=np.where(none, hi, g + 1))
        done |= todo
        if frontier > 0:
            _check_frontier(run, over, known, int(frontier), done)
        if key is None:
            break
        has = over.any(axis=1) & done
        best = np.min(key[has, over[has].argmax(axis=1)]) if has.any() else np.inf
        todo = ~done & (bound < best)
    # fill: unsafe after each row's simulated window (rows with an unsafe point only)
    for r in np.flatnonzero(over.any(axis=1)):
        last = np.flatnonzero(known[r]).max()
        over[r, last + 1 :] = True
    return over, known
