"""t_I as a distribution over the open choices of its computation (thesis Eq. 20, §5).

One t_I is a minimum over a chaotic boundary: where the grids fall, the step
and the restitution move it by 10-20 % on some records. :func:`t_I_band`
computes the OAS for a documented ensemble of those choices and reports the
median, the 5th-95th percentile band and the grid point behind each member.

The ensemble (:data:`BAND_ENSEMBLE`), each member changing one choice of the default:

- ``default``: 80 levels x 120 sizes, step p*dt <= 0.001, Housner eta, scan;
- ``level+1/2``, ``size+1/2``, ``both+1/2``: the level grid, the size grid, or
  both shifted by half a step (same resolution, different placement);
- ``coarse``: 60 levels x 90 sizes (three quarters of the resolution);
- ``step x2``: Newmark steps of p*dt <= 0.002 instead of the converged Taylor runs (the
  default's integrator before session 13, at twice its step);
- ``eta -1%``: restitution 1 % below Housner's (Čeh's eta_mat = 0.989 says
  real impacts lose slightly more than Housner's model);
- ``contiguous``: the unsafe band counted from the smallest blocks up to the
  first safe size (islands of overturning above it ignored).

The first member's grid is computed in full (adaptive); members on the same
grid reuse its verdicts, the others search each level's first unsafe size near
its boundary only (``grid="boundary"``; on 12 FEMA records x 5 members t_I,
t'_I and beta equal their own full adaptive grid's in 60/60). The first member
is bisected on the levels behind its t_I and line and elsewhere only as far as
the others' search windows need (:func:`~rocklab.models.spectra._oas.settle_guide`).
The members after the first bisect only the levels that can set t_I or touch the inclined line
(``refine_where="fit"``: the same t_I, t'_I and beta; on 6 FEMA records 27.3 ->
15.5 CPU-s, one thread, loaded machine; 44 records 127 CPU-s at load 44-53 against
306 CPU-s in session 15 at load 2-7). With ``lines=False`` they compute t_I alone
(``refine_where="t_I"``): each searches only the levels whose window could hold a
smaller f than found so far and bisects only those that can set f_min, so the t'_I
and beta bands are the first member's values; 44 records 67 CPU-s (same load), one
member's t_I of 352 differs from the default mode's, no band does; Table 4 inside the
band 30/44, median half-width 9.3 % in both modes, as before. Since session 17 the runs stop
once the rest of the record cannot lift the block to alpha (the Taylor and Newmark kernels' safe stop), a
member's search window simulates the points after its guess only where none before it is
unsafe, and the guide's settling check is vectorised: every member's t_I, t'_I and beta are
unchanged (11 of the records, every 4th from FF-1), with 1.21x less CPU for the default bands
and 1.28x for ``lines=False`` (one thread, same process as the session-16 code, load 22-28).

Measured with the Taylor runs (the default since session 13) on the 44 FEMA P695 far-field
records at H/B = 12 against Table 4 (``benchmarks/oas_fema44.py --bands``): Table 4's t_I lies
inside the 5-95 % band for 30/44, median half-width 9.3 % (with the Newmark runs before: 29/44,
8.8 %, 136 s on 2 idle cores; the Taylor time is not yet measured on an idle machine). More
members do not close the gap honestly (measured with the Newmark runs): 18 members (adding grid-only and contiguous grid-only search,
eta -2/-3/-5 %, quarter-step level offsets, p h <= 0.005/0.01/0.02) cover at most
33/44; FF-11, -17, -20 and -37 sit 3-41 % below every member and FF-21, -26, -27,
-29, -42 and -43 1-43 % above, so those Table 4 rows were computed some way
none of these choices reproduces.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._oas import OAS_DEFAULTS, OASResult, grid_axes, overturning_spectrum, settle_guide

__all__ = ["BAND_ENSEMBLE", "TIBand", "t_I_band"]

#: Ensemble members: name -> options of :func:`overturning_spectrum` changed from the default.
BAND_ENSEMBLE: dict[str, dict] = {
    "default": {},
    "level+1/2": {"level_offset": 0.5},
    "size+1/2": {"size_offset": 0.5},
    "both+1/2": {"level_offset": 0.5, "size_offset": 0.5},
    "coarse": {"levels": 60, "sizes": 90},
    "step x2": {"method": "newmark", "max_p_dt": 0.002},
    "eta -1%": {"eta_factor": 0.99},
    "contiguous": {"search": "contiguous"},
}


@dataclass(frozen=True)
class TIBand:
    """t_I, t'_I and beta over an ensemble of OAS computations.

    Attributes
    ----------
    t_I_s, t_I_p05_s, t_I_p95_s : float
        Median and 5th / 95th percentiles of t_I over the members, s.
    t_I_prime_s, t_I_prime_p05_s, t_I_prime_p95_s : float
        The same for t'_I, s (``inf`` members count as the largest).
    beta, beta_p05, beta_p95 : float
    members : tuple of dict
        Per member: ``name, t_I_s, t_I_prime_s, beta, f_min_level, f_min_R_m`` (the grid
        point behind its t_I).
    """

    t_I_s: float
    t_I_p05_s: float
    t_I_p95_s: float
    t_I_prime_s: float
    t_I_prime_p05_s: float
    t_I_prime_p95_s: float
    beta: float
    beta_p05: float
    beta_p95: float
    members: tuple

    @property
    def half_width_rel(self) -> float:
        """Half the 90 % band over the median t_I (-)."""
        return 0.5 * (self.t_I_p95_s - self.t_I_p05_s) / self.t_I_s if self.t_I_s > 0 else float("nan")

    def to_dict(self) -> dict:
        """Numbers and members (SI units)."""
        d = {
            k: getattr(self, k)
            for k in (
                "t_I_s",
                "t_I_p05_s",
                "t_I_p95_s",
                "t_I_prime_s",
                "t_I_prime_p05_s",
                "t_I_prime_p95_s",
                "beta",
                "beta_p05",
                "beta_p95",
            )
        }
        d["members"] = list(self.members)
        return d


#: Grid options :func:`grid_axes` reads, at the defaults of :func:`overturning_spectrum`.
_AXES = {k: v for k, v in OAS_DEFAULTS.items() if k in ("levels", "level_max", "sizes", "R_max_m", "R_min_m")} | {
    "level_offset": 0.0,
    "size_offset": 0.0,
}


def _grid_key(kw):
    """What makes two members' grids and runs the same (all options but the boundary search's)."""
    return tuple(sorted((k, repr(v)) for k, v in kw.items() if k not in ("search", "refine", "refine_where")))


def _member_options(ensemble, options, slenderness, lines):
    """(name, options of :func:`overturning_spectrum`) of each member (``eta_factor`` applied)."""
    out = []
    for k, (name, change) in enumerate(ensemble.items()):
        kw = dict(options)
        kw.update({key: v for key, v in change.items() if key != "eta_factor"})
        if "eta_factor" in change:
            alpha_I = kw.get("alpha_I", 4.0 / 3.0)
            alpha = math.atan(1.0 / slenderness)
            eta0 = kw.get("eta") if kw.get("eta") is not None else 1.0 - 2.0 * math.sin(alpha) ** 2 / alpha_I
            kw["eta"] = eta0 * change["eta_factor"]
        if k:  # only the guide's boundary is used whole (it places the others' search)
            kw.setdefault("refine_where", "fit" if lines else "t_I")
        out.append((name, kw))
    return out


def _stats(v):
    v = np.asarray(v, float)
    v = v[~np.isnan(v)]
    if not v.size:
        return (float("nan"),) * 3
    # an infinite member (no inclined line) interpolates to inf, not to inf - inf = NaN
    q = np.percentile(np.where(np.isinf(v), 1e300, v), [50, 5, 95])
    return tuple(math.inf if x > 1e290 else float(x) for x in q)


def t_I_band(base, slenderness: float = 12.0, ensemble: dict | None = None, *, lines: bool = True, **options) -> TIBand:
    """t_I over the :data:`BAND_ENSEMBLE` (or ``ensemble``) of OAS choices.

    Parameters
    ----------
    base : BaseMotion
    slenderness : float
        Block h/b.
    ensemble : dict, optional
        Name -> options changed from ``options`` (``eta_factor`` scales the
        restitution the base options use, Housner's by default).
    lines : bool
        ``False``: the members after the first compute t_I only (``refine_where="t_I"``: their
        boundary searched and bisected only on the levels that can set it), so the t'_I and beta
        bands are the first member's values; about 2x faster.
    **options
        Options of :func:`overturning_spectrum` shared by every member.

    Returns
    -------
    TIBand
    """
    members = []
    grids: dict[tuple, OASResult] = {}  # members that differ only in search/refine share one grid's runs
    guide: OASResult | None = None
    todo = _member_options(ensemble or BAND_ENSEMBLE, options, slenderness, lines)
    keys = [_grid_key(kw) for _, kw in todo]
    # the grids whose search the first member's boundary places: it is bisected only as far as they need
    places = [
        grid_axes(dict(_AXES, **kw), kw.get("alpha_I", 4.0 / 3.0))[::2]
        for k, (_, kw) in enumerate(todo)
        if k and keys[k] not in keys[:k] and kw.get("search", "scan") == "scan"
    ]
    for (name, kw), key in zip(todo, keys):
        if key in grids:
            o = overturning_spectrum(base, slenderness, verdicts=grids[key], **kw)
        elif guide is not None and kw.get("search", "scan") == "scan":
            # the first member's boundary guides the others' search (t_I, t'_I, beta as from full grids)
            o = overturning_spectrum(base, slenderness, grid="boundary", guide=guide, **kw)
        elif guide is None:
            o = overturning_spectrum(base, slenderness, **dict(kw, refine=0))
            o = guide = settle_guide(base, o, places, kw.get("refine", 10))
        else:
            o = overturning_spectrum(base, slenderness, **kw)
        grids.setdefault(key, o)
        lv, R = o.f_min_at
        members.append(
            {
                "name": name,
                "t_I_s": o.t_I_s,
                "t_I_prime_s": o.t_I_prime_s,
                "beta": o.beta,
                "f_min_level": float(lv),
                "f_min_R_m": float(R),
            }
        )
    ti = _stats([m["t_I_s"] for m in members])
    tp = _stats([m["t_I_prime_s"] for m in members])
    be = _stats([m["beta"] for m in members])
    return TIBand(ti[0], ti[1], ti[2], tp[0], tp[1], tp[2], be[0], be[1], be[2], tuple(members))
