"""The Overturning Acceleration Spectrum of a multi-block column under a record (thesis Fig. 43).

The single-block OAS (:func:`~rocklab.models.overturning_spectrum`) extended to a column of
``n`` equal blocks stacked to the total slenderness H/B, with ``n_impacts`` consecutive impacts
per closing (1 = Housner, 2 = the thesis's recommended model, 10 = practically no dissipation:
the blocks "roll"). The plane is the single block's, so the spectra compare directly:

- the size is the whole column's: R = half its diagonal, p = sqrt(g / (alpha_I R)) with the
  solid block's alpha_I = 4/3 (Eq. 13), alpha = atan(B/H);
- the level is a_p/a_p,min with a_p,min = g tan(alpha), the acceleration that lifts the whole
  column off its base (the upper joints, narrower in angle, lift later);
- a run overturns when the centre of mass above an open joint passes its pivot
  (:func:`~rocklab.models.simulate_column`); for one block that is |theta| >= alpha, the single
  block's ``criterion="angle"``;
- a run the model terminates because a joint would take tension or slide counts as unsafe: the
  column may disintegrate, and the thesis stops there too (§3.3); ``options["n_terminated"]``
  counts these runs;
- after the record the column rocks freely for ``free_pt / p`` seconds (or until every joint has
  closed and stays closed): unlike the single block there is no closed-form energy verdict.

Every grid point is a :func:`~rocklab.models.simulate_column` run (Newmark steps with the exact
opening and impact events), so a column OAS costs far more than a block's: the grid is coarser by
default, and each level is simulated from the largest block down to its first unsafe size only
(``grid="top-down"``), which gives the scan boundary of the dense grid without the small blocks'
short steps.
"""

from __future__ import annotations

import math

import numpy as np

from ..._errors import InputError
from ...blocks import G
from ...series import BaseMotion
from ..column import Column, simulate_column
from ._oas import OASResult, check_opts, first_unsafe, oas_result
from ._oas_grid import adaptive_verdicts

__all__ = ["column_overturning_spectrum"]

#: The solid rectangle's I_O / (m R^2): the p of the column as one block (thesis Eq. 13).
ALPHA_I_SOLID = 4.0 / 3.0


def _column_of(R_m: float, alpha: float, n_blocks: int) -> Column:
    return Column.uniform(2.0 * R_m * math.sin(alpha), 2.0 * R_m * math.cos(alpha), n_blocks, mass_kg=1.0)


def _overturns(base, scale, R_m, alpha, n_blocks, n_impacts, max_p_dt, free_pt, rest_pt, velocity_terms) -> str:
    col = _column_of(R_m, alpha, n_blocks)
    p_col = math.sqrt(G / (ALPHA_I_SOLID * R_m))
    # the step follows the fastest block (the top block of a tall column is the shortest)
    dt = max_p_dt / max(b.p_rad_s for b in col.blocks)
    # a step whose fixed-point iteration fails (a near-singular mass matrix as a joint opens) is
    # taken again with a half and a quarter of it, as the failure's own message advises; only a
    # run that fails at all three steps has no verdict (El Centro, 3 blocks, 10 impacts: one cell
    # of thesis Fig. 43's grid fails at 0.005/p and rocks at 0.0025/p and 0.00125/p)
    for shrink in (1.0, 0.5, 0.25):
        r = simulate_column(
            col,
            base.scaled(scale),
            duration_s=base.duration_s + free_pt / p_col,
            dt_s=dt * shrink,
            n_impacts=n_impacts,
            velocity_terms=velocity_terms,
            rest_omega_rad_s=rest_pt * p_col,
            output_dt_s=math.inf,
        )
        if r.status not in ("capacity", "numerical"):
            return r.status
    raise InputError(
        f"column OAS: a run failed '{r.status}' ({r.message}) at R = {R_m:.4g} m, scale {scale:.4g}, also with "
        "a quarter of the step; the column model gives no verdict there: narrow the size range (R_min_m, "
        "R_max_m) or the levels"
    )


def _top_down(run, n_rows, n_cols):
    """Each row simulated from the largest size down to its first unsafe one; the rest drawn unsafe.

    The first unsafe size from the top is exactly what ``search="scan"`` takes from a dense
    grid, and the small blocks below it, the costly runs (short steps), are never simulated.
    """
    over = np.zeros((n_rows, n_cols), bool)
    evaluated = np.zeros_like(over)
    for i in range(n_rows):
        for j in range(n_cols):
            evaluated[i, j] = True
            if run([i], [j])[0]:
                over[i, j:] = True
                break
    return over, evaluated


def _check_column_options(n_blocks, n_impacts, max_p_dt, rest_pt, free_pt, search, grid) -> tuple[int, int]:
    """The column-specific options of :func:`column_overturning_spectrum`, checked (one-line
    :class:`InputError` naming the option); returns (n_blocks, n_impacts) as integers."""
    if int(n_blocks) != n_blocks or int(n_blocks) < 1:
        raise InputError(f"n_blocks={n_blocks!r}: a column has a whole number of blocks >= 1 (e.g. 2)")
    if int(n_impacts) != n_impacts or int(n_impacts) < 1:
        raise InputError(f"n_impacts={n_impacts!r}: consecutive impacts per closing must be a whole number >= 1")
    if not (math.isfinite(max_p_dt) and 0 < max_p_dt <= 0.01):
        raise InputError(f"max_p_dt={max_p_dt!r}: step times p must be in (0, 0.01] (converged impacts)")
    if not (math.isfinite(rest_pt) and 0 < rest_pt <= 0.01):
        raise InputError(f"rest_pt={rest_pt!r}: the rest threshold, in units of p, must be in (0, 0.01]")
    if not (math.isfinite(free_pt) and free_pt >= 0):
        raise InputError(f"free_pt={free_pt!r}: free rocking after the record, in units of 1/p, must be >= 0")
    if search not in ("scan", "contiguous"):
        raise InputError(f"search={search!r}: use 'scan' or 'contiguous'")
    if grid not in ("top-down", "adaptive", "dense"):
        raise InputError(f"grid={grid!r}: use 'top-down', 'adaptive' (refined where verdicts change) or 'dense'")
    if grid == "top-down" and search != "scan":
        raise InputError("grid='top-down' finds the scan boundary only; give search='scan' or another grid")
    return int(n_blocks), int(n_impacts)


def _bisect(p_hi, p_lo, unsafe, refine: int) -> None:
    """Geometric bisection of each level's boundary between ``p_lo`` (safe) and ``p_hi``
    (unsafe), in place, ``refine`` halvings; ``unsafe(level index, p)`` runs one column."""
    for i in np.flatnonzero(np.isfinite(p_hi) & np.isfinite(p_lo)):
        for _ in range(refine):
            pm = math.sqrt(p_hi[i] * p_lo[i])
            if unsafe(i, pm):
                p_hi[i] = pm
            else:
                p_lo[i] = pm


def _column_result(base, alpha, lv, R, p, over, evaluated, p_hi, opts) -> OASResult:
    """The :class:`OASResult` of a column's verdict grid and boundary (``p_hi`` per level), read
    as a monolithic block's (alpha_I 4/3, eta NaN); runs stopped with the column coming apart
    are said (W-COLUMN-APART)."""
    if opts["n_terminated"]:
        from ..._diagnostics import warn

        warn(
            "W-COLUMN-APART",
            f"{opts['n_terminated']} column runs stopped with a joint in tension or sliding "
            "(the column comes apart): counted as unsafe (options['n_terminated'])",
        )
    return oas_result(base.name, lv, R, p, over, evaluated, p_hi, (alpha, ALPHA_I_SOLID, float("nan")), opts)


def column_overturning_spectrum(
    base: BaseMotion,
    slenderness: float = 12.0,
    n_blocks: int = 2,
    *,
    n_impacts: int = 1,
    levels: int = 19,
    level_max: float = 10.0,
    sizes: int = 49,
    R_max_m: float = 1000.0,
    R_min_m: float = 0.1,
    refine: int = 6,
    max_p_dt: float = 0.003,
    free_pt: float = 10.0,
    rest_pt: float = 1e-4,
    search: str = "scan",
    velocity_terms: bool = True,
    grid: str = "top-down",
) -> OASResult:
    """OAS, transformed OAS and t_I of a column of ``n_blocks`` equal blocks under a record.

    Parameters
    ----------
    base : BaseMotion
        The record (SI); scaled to each level (a_p = level g tan(alpha)).
    slenderness : float
        H/B of the whole column; alpha = atan(B/H).
    n_blocks : int
        Equal blocks stacked to height H (1 gives the single block's OAS).
    n_impacts : int
        Consecutive impacts per closing (1 Housner; 2 the thesis's model; 10 "rolling").
    levels, level_max, sizes, R_max_m, R_min_m, refine, search :
        As :func:`~rocklab.models.overturning_spectrum` (R the column's half-diagonal, m; the same
        size range, 1000 m to 0.1 m), on a coarser default grid, each point being a column run.
        A level whose largest size already overturns has its boundary beyond the grid (no
        bisection there): give a larger ``R_max_m``.
    max_p_dt : float
        Step times the largest block p of the run (the top block's).
    free_pt : float
        Free rocking after the record, in units of 1/p of the column (dimensionless time).
    rest_pt : float
        A joint whose rate after an impact is below ``rest_pt * p`` closes (the column's
        ``rest_omega_rad_s``): with little dissipation (10 impacts) the joints otherwise chatter
        through 10^5 ever smaller impacts per run. Verdicts near the boundary are chaotic and
        move with it, as they move with the step (see :func:`~rocklab.models.overturning_spectrum`).
    velocity_terms : bool
        Passed to :func:`~rocklab.models.simulate_column`.
    grid : {"top-down", "adaptive", "dense"}
        ``"top-down"``: each level from the largest size down to its first unsafe one (the
        ``search="scan"`` boundary exactly, without the costly small blocks below it; the map
        below the boundary is drawn unsafe, ``evaluated`` says what ran); ``"adaptive"``: refine
        where verdicts change; ``"dense"``: every grid point.

    Returns
    -------
    OASResult
        ``eta`` is NaN (the restitution follows from the impacts), ``alpha_I`` 4/3, ``i_cr`` the
        monolithic block's (Eq. 18), so ``t_I_s`` is the column's replacement impulse duration
        read as a single block's; ``options`` carries ``n_blocks`` and ``n_impacts``.

    Examples
    --------
    A two-block column, H/B = 6, under a one-cycle sine (t_p = 2 s), on a 4 x 8 grid:

    >>> from rocklab.models import column_overturning_spectrum, pulse_motion
    >>> o = column_overturning_spectrum(pulse_motion("sine", 2.0, 1.0), 6.0, 2, levels=4, sizes=8, R_max_m=1000.0)
    >>> o.options["n_blocks"], round(o.t_I_s, 2)
    (2, 0.96)
    """
    sl = check_opts(slenderness, levels, sizes, R_max_m, R_min_m, level_max, ALPHA_I_SOLID)
    from ._pulses import check_record

    base = check_record(base)
    n_blocks, n_impacts = _check_column_options(n_blocks, n_impacts, max_p_dt, rest_pt, free_pt, search, grid)
    alpha = math.atan(1.0 / sl)
    lv = np.linspace(1.0, float(level_max), int(levels))
    R = float(R_max_m) * (float(R_min_m) / float(R_max_m)) ** (np.arange(int(sizes)) / (int(sizes) - 1))
    p = np.sqrt(G / (ALPHA_I_SOLID * R))
    scales = lv * math.tan(alpha) * G / base.pga_m_s2

    terminated = []  # runs stopped by tension or sliding at a joint: counted unsafe

    def one(scale, p_rad_s):
        R_m = G / (ALPHA_I_SOLID * p_rad_s**2)  # the column's half-diagonal at this p
        status = _overturns(base, scale, R_m, alpha, n_blocks, n_impacts, max_p_dt, free_pt, rest_pt, velocity_terms)
        terminated.extend([status] if status in ("tension", "sliding") else [])
        return status in ("overturned", "tension", "sliding")

    def run(rows, cols):
        return np.array([one(scales[i], p[j]) for i, j in zip(rows, cols)], bool)

    if grid == "dense":
        ii, jj = np.meshgrid(np.arange(lv.size), np.arange(p.size), indexing="ij")
        over = run(ii.ravel(), jj.ravel()).reshape(ii.shape)
        evaluated = np.ones_like(over)
    elif grid == "adaptive":
        over, evaluated = adaptive_verdicts(run, lv.size, p.size)
    else:
        over, evaluated = _top_down(run, lv.size, p.size)
    p_hi, p_lo = first_unsafe(over, p, search)
    _bisect(p_hi, p_lo, lambda i, pm: one(scales[i], pm), int(refine))
    opts = dict(
        n_blocks=n_blocks,
        n_impacts=n_impacts,
        levels=int(levels),
        level_max=float(level_max),
        sizes=int(sizes),
        R_max_m=float(R_max_m),
        R_min_m=float(R_min_m),
        refine=int(refine),
        criterion="column",
        free=f"{free_pt:g}/p",
        rest_pt=float(rest_pt),
        search=search,
        max_p_dt=float(max_p_dt),
        velocity_terms=bool(velocity_terms),
        grid=grid,
        n_terminated=len(terminated),
    )
    return _column_result(base, alpha, lv, R, p, over, evaluated, p_hi, opts)
