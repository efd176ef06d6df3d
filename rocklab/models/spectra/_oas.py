"""Overturning Acceleration Spectra (OAS) and the replacement impulse duration t_I.

Ther thesis §5.1.3 and §5.3: for a record, the OAS separates safe and unsafe
blocks in the plane (a_p/a_p,min, p), with a_p the scaled PGA,
a_p,min = g tan(alpha) (Eq. 3) and p = sqrt(g/(alpha_I R)) (Eq. 13). The
transformed OAS uses f = p a_p/a_p,min (Eq. 19); its leftmost point f_min gives
the replacement impulse duration t_I = i_cr / f_min (Eq. 20) with
i_cr = sqrt(2/(1+cos alpha)) (Eq. 18). The inclined-line fit f = 1/t'_I + A/beta
(Eq. 28, A = a_p/a_p,min) gives t'_I and beta.

Definition choices the thesis leaves open are options (defaults first):

- ``criterion``: ``"angle"`` (|theta| >= alpha counts as overturned) or
  ``"fall"`` (|theta| >= pi/2).
- ``free``: ``"energy"`` (after the record ends the block rocks freely; the
  exact energy verdict with the restitution decides), ``"none"`` (only what
  happens during the record counts) or a number of seconds to integrate with
  zero base motion.
- ``search``: ``"scan"`` (every grid size is simulated and the largest unsafe
  one is taken, so unsafe islands at large sizes are not missed) or
  ``"contiguous"`` (the unsafe region connected to the smallest size only, as a
  search from small blocks upward would find it).
- ``levels``, ``sizes``, ``refine``: grid density and bisection steps; ``refine_where``: which levels
  get all of them (``"curve"``: those behind t_I, t'_I and beta; the others to 1e-3 in p).
- ``eta``: restitution; ``None`` = Housner's 1 - 2 sin^2(alpha)/alpha_I.
- ``method``: the runs' integrator, ``"taylor"`` (a Taylor series per record interval, exact
  events: converged verdicts, see :func:`~rocklab.models.oas_reference`) or ``"newmark"``
  (trapezoidal steps of ``p h <= max_p_dt``, the default before session 13).

How much each choice moves t_I (H/B = 12; output of ``benchmarks/oas_sensitivity.py`` with the
Taylor runs, the default since session 13; thesis Table 4: FF-1 0.266 s, FF-2 0.360 s, FF-41 0.503 s)::

    variant              FF-1            FF-2            FF-41 (NGA-West2 file)
    defaults             0.336 (+26 %)   0.333 ( -7 %)   0.474 ( -6 %)
    search=contiguous    0.275 ( +3 %)   0.324 (-10 %)   0.378 (-25 %)
    criterion=fall, free=none or 10 s: no change
    refine=0             0.324 (+22 %)   0.323 (-10 %)   0.467 ( -7 %)
    levels=160           0.294 (+10 %)   0.365 ( +1 %)   0.469 ( -7 %)
    sizes=240            0.343 (+29 %)   0.333 ( -7 %)   0.474 ( -6 %)
    newmark, p h 0.001   0.336 (+26 %)   0.333 ( -7 %)   0.470 ( -7 %)
    newmark, p h 0.02    0.320 (+20 %)   0.327 ( -9 %)   0.512 ( +2 %)
    newmark, p h 0.005   0.329 (+24 %)   0.332 ( -8 %)   0.396 (-21 %)
    eta=0.95             0.289 ( +9 %)   0.321 (-11 %)   0.373 (-26 %)

Why not closer: t_I is the minimum of f over a boundary that is chaotic near
its edge (bays, islands; single verdicts flip with the integration step even
at p h = 0.001), so grid density and step alone move it by 10-20 %. For FF-1
the minimum comes from a_p/a_p,min = 1.34, where blocks up to R = 1.49 m
overturn (confirmed by an event-driven solve_ivp run), with single safe sizes
from R = 0.47 m up; the thesis's boundary there lies below R = 0.93 m. The
FF-41 file is the NGA-West2 processing, not the thesis's (its t_p is 0.293 s
against Table 4's 0.224 s). The overturning criterion and the free-rocking rule
do not matter for slender blocks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..._errors import InputError
from ...blocks import G, inertia_coefficient
from ..rocking import free_rocking_overturns, simulate_batch
from ._oas_grid import adaptive_verdicts, boundary_verdicts
from ...series import BaseMotion

__all__ = [
    "OASResult",
    "overturning_spectrum",
    "normalised_critical_impulse",
    "critical_impulse",
    "fit_inclined_line",
    "simplified_oas",
    "OAS_DEFAULTS",
]

#: Defaults of :func:`overturning_spectrum` (thesis §5.3: 80 levels 1..10, 120 sizes 1000..0.1 m).
OAS_DEFAULTS = dict(
    levels=80,
    level_max=10.0,
    sizes=120,
    R_max_m=1000.0,
    R_min_m=0.1,
    refine=10,
    refine_where="curve",
    criterion="angle",
    free="energy",
    search="scan",
    alpha_I=4.0 / 3.0,
    eta=None,
    max_p_dt=0.001,
    method="taylor",
)

CRIT = {"angle": 0, "fall": 1}
#: Integrators of the OAS runs (``method``).
METHODS_OAS = ("newmark", "taylor")
#: Largest p h of a Taylor step (``method="taylor"``): the order adapts to it.
TAYLOR_P_H = 0.25
_GOLDEN = 0.5 * (math.sqrt(5.0) - 1.0)
#: ``refine_where="curve"``: every level's boundary is bisected until its bracket spans at most this relative
#: width in p (6 of the 10 steps on the default grid, whose neighbouring sizes lie 3.9 % apart in p), the
#: amplitude step under which the converged reference calls a cell chaotic when its verdict flips. t_I, t'_I,
#: beta and the verdicts are those of ``"all"`` with 474 bisection runs instead of 770 on FF-1's default OAS
#: (44 FEMA records, H/B 12: bitwise the same, 18 % less CPU; the other levels' boundary at most 5.7e-4 above
#: the full bisection's).
CURVE_REL_P = 1e-3


def normalised_critical_impulse(alpha_rad: float) -> float:
    """i_cr = p I_cr / a_p,min = sqrt(2/(1+cos alpha)) >= 1 (thesis Eq. 18)."""
    return math.sqrt(2.0 / (1.0 + math.cos(alpha_rad)))


def critical_impulse(R_m: float, alpha_rad: float, alpha_I: float = 4.0 / 3.0) -> float:
    """Critical impulse of an infinitely short single-lobe pulse, m/s (thesis Eq. 17).

    I_cr = sqrt(2 alpha_I R g (1 - cos alpha)) / cos alpha.
    """
    return math.sqrt(2 * alpha_I * R_m * G * (1 - math.cos(alpha_rad))) / math.cos(alpha_rad)


def free_after_code(free):
    if isinstance(free, str):
        if free == "energy":
            return 1, 0.0
        if free == "none":
            return 0, 0.0
        raise InputError(f"free={free!r}: use 'energy', 'none' or a number of seconds")
    fs = float(free)
    if not (math.isfinite(fs) and fs >= 0):
        raise InputError(f"free={free!r}: seconds of free rocking must be >= 0")
    return 2, fs


@dataclass(frozen=True)
class OASResult:
    """An Overturning Acceleration Spectrum of one record.

    Attributes
    ----------
    levels : ndarray, shape (n_l,)
        a_p/a_p,min of each row.
    R_m, p_rad_s : ndarray, shape (n_s,)
        Grid block sizes (corner to centre of mass, m; descending) and p (ascending).
    overturned : ndarray of bool, shape (n_l, n_s)
        Grid verdicts (bays and islands are visible here).
    p_min_rad_s : ndarray, shape (n_l,)
        Refined boundary: smallest unsafe p (largest unsafe R) per level; NaN if none.
    R_unsafe_max_m : ndarray, shape (n_l,)
        The same as a size, m.
    f_rad_s : ndarray, shape (n_l,)
        Transformed OAS f = p_min a_p/a_p,min (Eq. 19), 1/s.
    f_min_rad_s, t_I_s, t_I_prime_s, beta : float
        Leftmost f, t_I = i_cr/f_min (Eq. 20), and the inclined-line fit (Eq. 28).
    i_cr : float
        Eq. 18 for the block's slenderness.
    alpha_rad, alpha_I, eta : float
        Block slenderness angle, inertia coefficient, restitution used.
    name : str
        Record label.
    options : dict
        All definition options used.
    evaluated : ndarray of bool, shape (n_l, n_s), optional
        Grid points simulated; the others took the verdict of the uniform
        cell around them (``grid="adaptive"``).
    """

    levels: np.ndarray
    R_m: np.ndarray
    p_rad_s: np.ndarray
    overturned: np.ndarray
    p_min_rad_s: np.ndarray
    R_unsafe_max_m: np.ndarray
    f_rad_s: np.ndarray
    f_min_rad_s: float
    t_I_s: float
    t_I_prime_s: float
    beta: float
    i_cr: float
    alpha_rad: float
    alpha_I: float
    eta: float
    name: str = ""
    options: dict = field(default_factory=dict)
    evaluated: np.ndarray | None = None

    @property
    def n_runs(self) -> int:
        """Grid points simulated (the bisection's runs not counted)."""
        return int(self.overturned.size if self.evaluated is None else np.count_nonzero(self.evaluated))

    def to_frame(self):
        """Boundary per level: ``level, p_min_rad_s, R_unsafe_max_m, f_rad_s``."""
        import pandas as pd

        return pd.DataFrame(
            {
                "level": self.levels,
                "p_min_rad_s": self.p_min_rad_s,
                "R_unsafe_max_m": self.R_unsafe_max_m,
                "f_rad_s": self.f_rad_s,
            }
        )

    @property
    def f_min_at(self) -> tuple[float, float]:
        """Where t_I comes from: (a_p/a_p,min, R m) of the leftmost transformed-OAS point.

        t_I rests on this one boundary point, so it is worth a look in the OAS plot
        (a single chaotic verdict there moves t_I); NaN, NaN without any unsafe level.
        """
        if not np.isfinite(self.f_rad_s).any():
            return float("nan"), float("nan")
        i = int(np.nanargmin(self.f_rad_s))
        return float(self.levels[i]), float(self.R_unsafe_max_m[i])

    def to_dict(self) -> dict:
        """Scalars and options (JSON-ready; arrays are in :meth:`to_frame`)."""
        lv, R = self.f_min_at
        return dict(
            name=self.name,
            t_I_s=self.t_I_s,
            t_I_prime_s=self.t_I_prime_s,
            beta=self.beta,
            f_min=self.f_min_rad_s,
            f_min_level=lv,
            f_min_R_m=R,
            i_cr=self.i_cr,
            alpha_rad=self.alpha_rad,
            slenderness=1.0 / math.tan(self.alpha_rad),
            alpha_I=self.alpha_I,
            eta=self.eta,
            options=dict(self.options),
        )


#: Largest h/b the OAS accepts: alpha = atan(b/h) >= 1 mrad.
MAX_SLENDERNESS = 1000.0


def check_opts(slenderness, levels, sizes, R_max_m, R_min_m, level_max, alpha_I):
    try:
        sl = float(slenderness)
    except (TypeError, ValueError):
        raise InputError(f"slenderness={slenderness!r}: must be a number h/b > 0") from None
    if not (math.isfinite(sl) and sl > 0):
        raise InputError(f"slenderness={slenderness!r}: h/b must be a positive number (e.g. 12)")
    if sl > MAX_SLENDERNESS:
        raise InputError(
            f"slenderness={sl:g}: h/b above {MAX_SLENDERNESS:g} (alpha below 1 mrad) is a needle that "
            "any imperfection topples, not a rocking block; give the block's h/b (e.g. 12)"
        )
    if int(levels) < 2 or int(sizes) < 2:
        raise InputError(f"levels={levels}, sizes={sizes}: need at least 2 of each")
    if not (R_max_m > R_min_m > 0):
        raise InputError(f"R_max_m={R_max_m}, R_min_m={R_min_m}: need R_max > R_min > 0 (m)")
    if not 1 < level_max <= 1000:
        raise InputError(
            f"level_max={level_max}: the a_p/a_p,min range must go above 1 and up to at most 1000 (default 10)"
        )
    inertia_coefficient(alpha_I)
    return sl


def overturning_spectrum(
    base: BaseMotion,
    slenderness: float = 12.0,
    *,
    levels: int = 80,
    level_max: float = 10.0,
    sizes: int = 120,
    R_max_m: float = 1000.0,
    R_min_m: float = 0.1,
    refine: int = 10,
    refine_where: str = "curve",
    criterion: str = "angle",
    free="energy",
    search: str = "scan",
    alpha_I: float = 4.0 / 3.0,
    eta: float | None = None,
    max_p_dt: float = 0.001,
    level_offset: float = 0.0,
    size_offset: float = 0.0,
    grid: str = "adaptive",
    verdicts: OASResult | None = None,
    guide: OASResult | None = None,
    method: str = "taylor",
) -> OASResult:
    """OAS, transformed OAS, t_I, t'_I and beta of a record for one block slenderness.

    Parameters
    ----------
    base : BaseMotion
        The record (SI). Only its shape matters: it is scaled to each level.
    slenderness : float
        h/b of the block (thesis uses 12); alpha = atan(1/slenderness).
    levels, level_max : int, float
        ``levels`` values of a_p/a_p,min evenly from 1 to ``level_max``.
    sizes, R_max_m, R_min_m : int, float, float
        ``sizes`` log-spaced R from ``R_max_m`` down to ``R_min_m``, m.
    refine : int
        Bisection steps (in log R) between the largest unsafe grid size and its safe neighbour; 10 steps
        resolve the boundary to ~0.01 % in p.
    refine_where : {"curve", "all", "fit", "t_I"}
        ``"all"``: every level ``refine`` steps; ``"fit"``: only the levels that can set t_I or touch the
        inclined line (:func:`_bisect`; t_I, t'_I, beta as with ``"all"``); ``"curve"``: those, and the
        others to :data:`CURVE_REL_P` (1e-3) in p; ``"t_I"``: t_I only (t'_I, beta NaN), and
        ``grid="boundary"`` searches only the levels that can set it.
    criterion, free, search, eta : see the module docstring.
    alpha_I : float
        Inertia coefficient I_O/(m R^2) (thesis Eq. 22).
    max_p_dt : float
        For ``method="newmark"``: largest step times p (against p h = 0.00025 the grid at 0.001 keeps
        99.82 % of the verdicts on FF-1, 96.02 % on FF-9: long rocking amplifies step errors).
    level_offset, size_offset : float
        Shift of the level grid and of the (log) size grid by this fraction of one step, in [0, 1):
        the same resolution placed elsewhere, to see how much t_I owes to where the grid falls.
    grid : {"adaptive", "dense", "boundary"}
        ``"adaptive"`` simulates a coarse grid and refines only where verdicts change
        (:func:`~rocklab.models.spectra._oas_grid.adaptive_verdicts`); ``"dense"`` simulates every grid
        point; ``"boundary"`` (needs ``guide``) only searches each level's first unsafe size near the guide's
        boundary (:func:`~rocklab.models.spectra._oas_grid.boundary_verdicts`): t_I, t'_I and beta come out
        as from a full grid, the map away from the boundary is a fill.
    verdicts : OASResult, optional
        An earlier result on the same grid and runs (every option equal but ``search`` and
        ``refine``): its verdicts are reused and only the boundary is searched and bisected again.
    guide : OASResult, optional
        For ``grid="boundary"``: an OAS of the same record whose boundary is close to this
        one's (e.g. the default grid for a shifted or coarser one).
    method : {"taylor", "newmark"}
        Integrator of the runs (:func:`~rocklab.models.simulate_batch`): ``"taylor"`` a Taylor
        step per record interval (``p h <= 0.25``, order from ``p h``, truncation below 1e-16),
        exact events: converged verdicts (:func:`~rocklab.models.oas_reference`; on the 44 FEMA
        far-field records >= 99.9 % of the cells that are not chaotic, the Newmark grid at p h =
        0.001 98.8 %); ``"newmark"`` trapezoidal steps of ``p h <= max_p_dt`` (before session 13).

    Returns
    -------
    OASResult

    Examples
    --------
    A one-cycle sine pulse (peak 0.5 m/s², period 2 s) on a coarse 20 × 30 grid, H/B = 5:

    >>> from rocklab.models import overturning_spectrum, pulse_motion
    >>> o = overturning_spectrum(pulse_motion("sine", 0.5, 2.0), 5.0, levels=20, sizes=30)
    >>> o.n_runs, round(o.t_I_s, 2)
    (313, 0.36)
    """
    sl = check_opts(slenderness, levels, sizes, R_max_m, R_min_m, level_max, alpha_I)
    base = _checked_record(base, levels, sizes)
    _check_choices(criterion, search, grid, guide, method, refine_where)
    _check_steps(level_offset, size_offset, max_p_dt)
    free_code, free_s = free_after_code(free)
    alpha, eta_v = _block_restitution(sl, alpha_I, eta)
    opts = dict(
        levels=int(levels),
        level_max=float(level_max),
        sizes=int(sizes),
        R_max_m=float(R_max_m),
        R_min_m=float(R_min_m),
        refine=int(refine),
        refine_where=refine_where,
        criterion=criterion,
        free=free,
        search=search,
        max_p_dt=float(max_p_dt),
        level_offset=float(level_offset),
        size_offset=float(size_offset),
        grid=grid,
        method=method,
    )
    lv, R, p = grid_axes(opts, alpha_I)
    scales = lv * math.tan(alpha) * G / base.pga_m_s2  # record scaled to a_p = level g tan(alpha)
    args = (alpha, eta_v, CRIT[criterion], free_code, free_s, max_p_dt if method == "newmark" else TAYLOR_P_H, method)
    if verdicts is not None:
        over, evaluated = _reused_verdicts(verdicts, opts, (eta_v, alpha, float(alpha_I)), base.name)
    else:
        run = lambda i, j: batch_runs(base, scales[i], p[j], args)  # noqa: E731
        over, evaluated = _grid_verdicts(grid, run, lv, p, guide, refine_where == "t_I")

    p_hi, p_lo = first_unsafe(over, p, search)
    p_hi, p_lo = _bisect(base, scales, p_hi, p_lo, refine, args, None if refine_where == "all" else lv, refine_where)
    return oas_result(base.name, lv, R, p, over, evaluated, p_hi, (alpha, float(alpha_I), eta_v), opts)


def _checked_record(base, levels, sizes):
    """The record checked (enough samples, not all zeros), and the grid's size checked against memory."""
    if not isinstance(base, BaseMotion):
        raise InputError(f"base={type(base).__name__}: expected a BaseMotion (load_base_motion)")
    from ..._errors import check_memory
    from ._pulses import check_record

    base = check_record(base)
    if int(levels) < 1 or int(sizes) < 2:
        raise InputError(f"levels={levels!r}, sizes={sizes!r}: need at least 1 level and 2 sizes")
    check_memory(
        80.0 * int(levels) * int(sizes),
        f"an OAS grid of {int(levels)} x {int(sizes)} runs",
        "reduce --levels/--sizes (the defaults 80 x 120 resolve t_I)",
    )
    return base


def _check_steps(level_offset, size_offset, max_p_dt):
    """Grid offsets are fractions of a step and the Newmark step is in range."""
    if not (0.0 <= float(level_offset) < 1.0 and 0.0 <= float(size_offset) < 1.0):
        raise InputError(f"level_offset={level_offset!r}, size_offset={size_offset!r}: fractions of a step in [0, 1)")
    if not (math.isfinite(max_p_dt) and 0 < max_p_dt <= 0.5):
        raise InputError(f"max_p_dt={max_p_dt!r}: step times p must be in (0, 0.5]")


def _check_choices(criterion, search, grid, guide, method="newmark", refine_where="curve"):
    """The OAS's definition choices are among the known ones (module docstring)."""
    if refine_where not in ("curve", "all", "fit", "t_I"):
        raise InputError(
            f"refine_where={refine_where!r}: use 'curve' (every level to 1e-3 in p, t_I, t'_I, beta in full), "
            "'all' (every level in full), 'fit' (t_I, t'_I, beta) or 't_I'"
        )
    if method not in METHODS_OAS:
        raise InputError(
            f"method={method!r}: use 'newmark' (trapezoidal steps) or 'taylor' (series per record interval)"
        )
    if criterion not in CRIT:
        raise InputError(f"criterion={criterion!r}: use 'angle' (|theta|>=alpha) or 'fall' (|theta|>=pi/2)")
    if search not in ("scan", "contiguous"):
        raise InputError(f"search={search!r}: use 'scan' or 'contiguous'")
    if grid not in ("adaptive", "dense", "boundary"):
        raise InputError(f"grid={grid!r}: use 'adaptive' (refined where verdicts change), 'dense' or 'boundary'")
    if (grid == "boundary") != (guide is not None):
        raise InputError("grid='boundary' and guide=<an OAS of the same record> go together")


def _block_restitution(sl, alpha_I, eta):
    """(alpha rad, eta): the block's angle and its restitution, Housner's when ``eta`` is None."""
    alpha = math.atan(1.0 / sl)
    eta_v = 1.0 - 2.0 * math.sin(alpha) ** 2 / alpha_I if eta is None else float(eta)
    if eta is not None and not (0.0 <= eta_v <= 1.0):
        raise InputError(f"eta={eta!r}: restitution omega+/omega- must be in [0, 1] (1: no energy lost); fix it")
    if eta is None and sl < 1.0:
        raise InputError(
            f"slenderness={sl:g}: Housner's restitution 1 - 2 sin^2(alpha)/alpha_I = {eta_v:.3g} "
            "holds for slender blocks (h/b >= 1); give h/b >= 1, or the block's restitution eta"
        )
    return alpha, eta_v


def grid_axes(opts, alpha_I):
    """(levels a_p/a_p,min, R m, p rad/s) of the grid ``opts`` describes, each shifted by its offset."""
    step = (opts["level_max"] - 1.0) / (opts["levels"] - 1)
    lv = 1.0 + (np.arange(opts["levels"]) + opts["level_offset"]) * step
    R = opts["R_max_m"] * (opts["R_min_m"] / opts["R_max_m"]) ** (
        (np.arange(opts["sizes"]) + opts["size_offset"]) / (opts["sizes"] - 1)
    )
    return lv, R, np.sqrt(G / (alpha_I * R))


def _reused_verdicts(verdicts, opts, block, name):
    """(overturned, evaluated) of an earlier OAS on the same grid, runs and block (alpha, eta, alpha_I)."""

    def grid_of(o):
        return {k: v for k, v in o.items() if k not in ("search", "refine", "refine_where")}

    eta_v, alpha, alpha_I = block
    if (
        grid_of(verdicts.options) != grid_of(opts)
        or (verdicts.eta, verdicts.alpha_rad, verdicts.alpha_I) != (eta_v, alpha, alpha_I)
        or verdicts.name != name
    ):
        raise InputError("verdicts: the earlier OAS differs in more than search/refine; compute this one anew")
    return verdicts.overturned, verdicts.evaluated


def _grid_verdicts(grid, run, lv, p, guide, t_I_only=False):
    """(overturned, evaluated), each (levels, sizes): ``run(i, j)`` simulated where ``grid`` says."""
    if grid == "dense":
        i, j = np.repeat(np.arange(lv.size), p.size), np.tile(np.arange(p.size), lv.size)
        over = run(i, j).reshape(lv.size, p.size)
        return over, np.ones_like(over)
    if grid == "boundary":
        key = lv[:, None] * p[None, :] if t_I_only else None  # f: only the rows that can set t_I
        return boundary_verdicts(run, lv.size, p.size, _guess_first(guide, lv, p), key=key)
    return adaptive_verdicts(run, lv.size, p.size)


def oas_result(name, lv, R, p, over, evaluated, p_hi, block, opts):
    """The OASResult of a grid's verdicts and boundary ``p_hi`` (rad/s), block = (alpha rad, alpha_I, eta)."""
    alpha, alpha_I, eta_v = block
    f = lv * p_hi
    icr = normalised_critical_impulse(alpha)
    f_min = float(np.nanmin(f)) if np.isfinite(f).any() else float("nan")
    t_I = icr / f_min if math.isfinite(f_min) else float("nan")
    tIp, beta = fit_inclined_line(f, lv) if opts.get("refine_where") != "t_I" else (math.nan, math.nan)
    return OASResult(
        levels=lv,
        R_m=R,
        p_rad_s=p,
        overturned=over,
        p_min_rad_s=p_hi,
        R_unsafe_max_m=G / (alpha_I * p_hi**2),
        f_rad_s=f,
        f_min_rad_s=f_min,
        t_I_s=t_I,
        t_I_prime_s=tIp,
        beta=beta,
        i_cr=icr,
        alpha_rad=alpha,
        alpha_I=alpha_I,
        eta=eta_v,
        name=name,
        options=opts,
        evaluated=evaluated,
    )


def first_unsafe(over, p, search):
    """Per level, p (rad/s) of the largest unsafe grid size and of its safe neighbour (NaN if none).

    ``search="scan"``: the first overturning size from the largest block down; ``"contiguous"``:
    the largest block of the run of overturning sizes that reaches the smallest block.
    """
    k = np.full(over.shape[0], -1)
    for i, row in enumerate(over):
        if search == "scan":
            hit = np.flatnonzero(row)
            if hit.size:
                k[i] = hit[0]
        elif row[-1]:
            safe = np.flatnonzero(~row)
            k[i] = safe[-1] + 1 if safe.size else 0
    p_hi = np.where(k >= 0, p[np.clip(k, 0, None)], np.nan)  # unsafe
    p_lo = np.where(k > 0, p[np.clip(k - 1, 0, None)], np.nan)  # safe neighbour (larger block)
    return p_hi, p_lo


def settle_guide(base, o, places, refine=10):
    """A guide OAS computed with ``refine=0``, bisected (``refine`` steps) on the levels that set its t_I
    and inclined line and, elsewhere, only as far as :func:`_guess_first` needs to place the windows of
    grids with the sizes ``places`` (each (levels, p) of a member grid): the guesses, t_I, t'_I and beta
    come out as from the guide bisected on every level, with a fraction of the runs."""
    opt = o.options
    free_code, free_s = free_after_code(opt["free"])
    args = (o.alpha_rad, o.eta, CRIT[opt["criterion"]], free_code, free_s)
    args += (opt["max_p_dt"] if opt["method"] == "newmark" else TAYLOR_P_H, opt["method"])
    scales = o.levels * math.tan(o.alpha_rad) * G / base.pga_m_s2
    p_hi, p_lo = first_unsafe(o.overturned, o.p_rad_s, opt["search"])
    m = np.isfinite(p_hi) & np.isfinite(p_lo)
    left = np.where(m, int(refine), 0)
    step = abs(o.levels[1] - o.levels[0]) if o.levels.size > 1 else 1.0

    # per member grid, which guide levels lie within one guide step of each of its levels (_guess_first)
    nears = [(np.abs(o.levels[None, :] - np.asarray(lv)[:, None]) <= step * (1 + 1e-9), p) for lv, p in places]

    def wanted():
        want = _fit_levels(o.levels, p_hi, p_lo, left, m)
        live = np.isfinite(p_hi)
        low = np.where(left > 0, p_lo, p_hi)  # the bisected value lies in (low, p_hi]
        for near0, p in nears:
            near = near0 & live[None, :]  # (member levels, guide levels)
            rows = near.any(axis=1)
            if not rows.any():
                continue
            near = near[rows]
            top = np.where(near, p_hi[None, :], np.inf).min(axis=1)
            bottom = np.where(near, low[None, :], np.inf).min(axis=1)
            ahead = np.searchsorted(p, bottom * (1 - 1e-12)) != np.searchsorted(p, top * (1 - 1e-12))
            # a grid point inside a bracket: that guess is not settled
            want |= (near[ahead] & (low[None, :] < top[ahead, None])).any(axis=0) & (left > 0)
        return want

    want = wanted()
    while want.any():
        _halve(base, scales, args, p_hi, p_lo, left, np.flatnonzero(want))
        want = wanted()
    opts = dict(opt, refine=int(refine), refine_where="fit")
    return oas_result(
        o.name, o.levels, o.R_m, o.p_rad_s, o.overturned, o.evaluated, p_hi, (o.alpha_rad, o.alpha_I, o.eta), opts
    )


def _guess_first(guide, lv, p):
    """First unsafe column of each level on this grid, from a guide OAS's refined boundary.

    Each level takes the lowest boundary p of the guide's levels within one guide
    step of it (chaotic boundaries jump between neighbouring levels: start left).
    """
    gl, gp = guide.levels, guide.p_min_rad_s
    step = abs(gl[1] - gl[0]) if gl.size > 1 else 1.0
    first = np.full(lv.size, p.size)
    for i, level in enumerate(lv):
        near = np.abs(gl - level) <= step * (1 + 1e-9)
        pm = gp[near]
        pm = pm[np.isfinite(pm)]
        if pm.size:
            first[i] = int(np.searchsorted(p, pm.min() * (1 - 1e-12)))
    return first


def batch_runs(base, scale, p, args):
    """Overturned flags of independent runs (``base`` times ``scale``, blocks ``p``) by ``simulate_batch``.

    ``args`` = (alpha rad, eta, criterion code, free code, free s, max p h[, method[, taylor_tol]]).
    """
    alpha, eta, crit, free_code, free_s, max_p_dt = args[:6]
    method = args[6] if len(args) > 6 else "newmark"
    tol = args[7] if len(args) > 7 else 1e-16
    # neighbouring grid points cost alike and the parallel loop hands each thread one contiguous
    # chunk: a golden-ratio interleave spreads the long runs over both (1.6x -> 1.9x on 2 cores)
    p = np.broadcast_to(np.asarray(p, float), np.shape(scale))
    order = np.argsort((np.arange(p.size) * _GOLDEN) % 1.0, kind="stable")
    b = simulate_batch(
        p[order],
        alpha,
        base=base,
        scale=np.asarray(scale, float)[order],
        eta=eta,
        dt_s=base.dt_s,
        free_after_s=free_s if free_code == 2 else 0.0,
        fall_rad=alpha if crit == 0 else None,
        max_p_dt=max_p_dt,
        method=method,
        taylor_tol=tol,
        stop_when_safe=True,  # verdicts only: a run stops once it cannot reach alpha
    )
    over = np.asarray(b.overturned, bool)
    rocking = b.status == 0
    if free_code == 1 and rocking.any():
        ends = (b.theta_end_rad[rocking], b.omega_end_rad_s[rocking], p[order][rocking])
        over[rocking] |= free_rocking_overturns(*ends, alpha, eta)
    out = np.empty_like(over)
    out[order] = over
    return out


def _halve(base, scales, args, p_hi, p_lo, left, idx) -> None:
    """One geometric bisection of the brackets ``idx``, in place: a run at sqrt(p_hi p_lo) of each
    level ``scales[idx]`` (:func:`batch_runs`); where its verdict is true ``p_hi`` moves to it,
    elsewhere ``p_lo``; one fewer bisection ``left``."""
    pm = np.sqrt(p_hi[idx] * p_lo[idx])
    v = batch_runs(base, scales[idx], pm, args)
    p_hi[idx] = np.where(v, pm, p_hi[idx])
    p_lo[idx] = np.where(v, p_lo[idx], pm)
    left[idx] -= 1


def _bisect(base, scales, p_hi, p_lo, n, args, lv=None, where="fit"):
    """Geometric bisection of every level's bracket [p_lo safe, p_hi unsafe] at once, ``n`` steps.

    With ``lv`` (the levels a_p/a_p,min): only the levels that can still set t_I or touch the inclined
    line. f = lv p lies in (lv p_lo, lv p_hi]; a level whose lower end is at or above the smallest upper
    end cannot hold f_min, and one whose lower end lies on or above the line fitted to the upper ends
    (the final f of the others) leaves that line feasible and hence optimal for the exact values too.
    The line is checked again once the others are done, and the levels below it bisected in turn;
    ``where="t_I"``: no line, only f_min; ``where="curve"``: first every level until its bracket spans
    :data:`CURVE_REL_P` in p (the first steps of every level's full bisection, so its end stays inside
    the bracket the full bisection ends in), then the levels behind t_I and the line as with ``"fit"``.
    """
    p_hi = p_hi.copy()
    p_lo = p_lo.copy()
    m = np.isfinite(p_hi) & np.isfinite(p_lo)
    if not m.any():
        return p_hi, p_lo
    left = np.where(m, int(n), 0)
    if lv is not None and where == "curve":
        with np.errstate(invalid="ignore", divide="ignore"):
            steps = np.ceil(np.log2(np.log(p_hi / p_lo) / math.log1p(CURVE_REL_P)))
        keep = int(n) - np.clip(np.where(m, steps, 0.0), 0, int(n)).astype(int)  # steps left after the curve's
        while (m & (left > keep)).any():
            _halve(base, scales, args, p_hi, p_lo, left, np.flatnonzero(m & (left > keep)))
    lines = where != "t_I"
    want = left > 0 if lv is None else _fit_levels(lv, p_hi, p_lo, left, m, lines)
    while want.any():
        _halve(base, scales, args, p_hi, p_lo, left, np.flatnonzero(want))
        want = left > 0 if lv is None else _fit_levels(lv, p_hi, p_lo, left, m, lines)
    return p_hi, p_lo


def _fit_levels(lv, p_hi, p_lo, left, m, lines=True):
    """Levels still to bisect for t_I and the inclined line (see :func:`_bisect`)."""
    f_hi, f_lo = lv * p_hi, lv * p_lo
    todo = m & (left > 0)
    need = f_lo < np.nanmin(f_hi)
    if (todo & need).any() or not lines:
        return todo & need  # f_min first: its level is a point of the line too
    c, s = _line_of(f_hi, lv)
    return todo & (f_lo < c + s * lv)


def _line_of(f, lv):
    """(c, s) of the inclined line f = c + s A of :func:`fit_inclined_line` (zeros when undefined), without
    the LP solver: maximising the line's integral over [A_min, A_max] is maximising its height at the
    range's middle, so the optimum is the lower convex hull's edge over the middle (from the end of the
    lowest chord there), or one of the lines c = 0, s = 0 where that edge leaves c, s >= 0."""
    ok = np.isfinite(f)
    if ok.sum() < 2:
        return 0.0, 0.0
    A, y = lv[ok], f[ok]
    mid = 0.5 * (A.min() + A.max())
    left, right = A <= mid, A > mid
    al, yl, ar, yr = A[left][:, None], y[left][:, None], A[right][None, :], y[right][None, :]
    sl = (yr - yl) / (ar - al)
    i = np.unravel_index(np.argmin(yl + sl * (mid - al)), sl.shape)[0]  # a hull vertex at or left of mid
    s_i = np.min(sl[i])  # the hull's edge to its right (supporting even when the vertex sits at mid)
    c = np.array([yl[i, 0] - s_i * al[i, 0], y.min(), 0.0])
    s = np.array([s_i, 0.0, np.min(y / A)])
    tol = 1e-12 * max(1.0, float(np.abs(y).max()))
    feasible = (c >= -tol) & (s >= -tol) & np.all(c[:, None] + s[:, None] * A[None, :] <= y[None, :] + tol, axis=1)
    best = int(np.argmax(np.where(feasible, c + s * mid, -np.inf)))
    return max(float(c[best]), 0.0), max(float(s[best]), 0.0)


def fit_inclined_line(f, levels):
    """t'_I and beta of the inclined line f = 1/t'_I + A/beta (thesis Eq. 28).

    The thesis does not say how the line was fitted; here it is the
    conservative line (left of every transformed-OAS point, like the vertical
    line of Eq. 20) that is closest to the points on average over the level
    range: maximise the integral of ``c + s A`` over [A_min, A_max] subject to
    ``c + s A_i <= f_i``, ``c >= 0``, ``s >= 0`` (a linear programme; the
    optimum touches the convex hull of the points, thesis Fig. 48).

    Eight candidate rules were tried against all 44 Table 4 rows
    (``benchmarks/oas_fema44.py``, Taylor runs; rank correlation, rows within 20 %):
    this one t'_I 0.748, 28/44 and beta 0.774, 24/44, both within 20 % for 19/44,
    tied with a 10 % quantile line (19/44) and ahead of least squares in f over all
    points (3/44), in p against 1/A (3/44), on the running-minimum envelope
    (13/44) or in p on it (17/44), a 25 % quantile line (11/44) and least squares
    over A <= 5 (1/44); with the Newmark runs before, 20/44 tied with the quantile
    line. It stays: it is the conservative one.

    Returns
    -------
    (t_I_prime_s, beta) : floats; ``inf`` when c or s is 0, NaN with < 2 points.
    """
    from scipy.optimize import linprog

    f = np.asarray(f, float)
    A = np.asarray(levels, float)
    ok = np.isfinite(f)
    if ok.sum() < 2:
        return float("nan"), float("nan")
    f, A = f[ok], A[ok]
    a_lo, a_hi = A.min(), A.max()
    # maximise (a_hi - a_lo) c + (a_hi^2 - a_lo^2)/2 s  -> minimise the negative
    cost = -np.array([a_hi - a_lo, 0.5 * (a_hi**2 - a_lo**2)])
    res = linprog(cost, A_ub=np.c_[np.ones_like(A), A], b_ub=f, bounds=[(0, None), (0, None)], method="highs")
    if res.status != 0:
        return float("nan"), float("nan")
    c, s = res.x
    tol = 1e-12 * max(1.0, float(f.max()))
    return (1.0 / c if c > tol else math.inf), (1.0 / s if s > tol else math.inf)


def simplified_oas(
    p_rad_s,
    t_I_s: float,
    t_I_prime_s: float | None = None,
    beta: float | None = None,
    i_cr: float = 1.0,
    kind: str = "eq21",
):
    """Simplified OAS a_p/a_p,min as a function of p (thesis Eq. 21, 29, 30).

    Parameters
    ----------
    p_rad_s : array_like
        Frequency parameter, rad/s.
    t_I_s : float
        Replacement impulse duration (Eq. 21, 30), s.
    t_I_prime_s, beta : float
        Inclined-line parameters (Eq. 29, 30).
    i_cr : float
        Normalised critical impulse (Eq. 18); the thesis's "≈" form uses 1.
    kind : {"eq21", "eq29", "eq30"}
        Eq. 21: max(i_cr/(t_I p), 1); Eq. 29: max(1/(t'_I (p - 1/beta)), 1)
        (inf for p <= 1/beta); Eq. 30: the larger of the two.

    Returns
    -------
    ndarray
        Smallest a_p/a_p,min that overturns a block of each p.
    """
    p = np.asarray(p_rad_s, float)
    with np.errstate(divide="ignore"):
        a21 = np.maximum(i_cr / (t_I_s * p), 1.0)
        if kind == "eq21":
            return a21
        if t_I_prime_s is None or beta is None:
            raise InputError(f"kind={kind!r} needs t_I_prime_s and beta")
        d = p - 1.0 / beta
        a29 = np.where(d > 0, 1.0 / (t_I_prime_s * np.where(d > 0, d, 1.0)), np.inf)
        a29 = np.maximum(a29, 1.0)
    if kind == "eq29":
        return a29
    if kind == "eq30":
        return np.maximum(a21, a29)
    raise InputError(f"kind={kind!r}: use eq21, eq29 or eq30")
