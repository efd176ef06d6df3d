"""A record set's overturning spectra together (thesis §5.3: Figs. 44, 48-50, 53).

- :func:`characteristic_oas`: the OAS a set of records exceeds with a given probability (Fig. 44);
- :func:`oas_convex_hull`: the convex hull of a record's overturning region, in the OAS or the
  transformed OAS, optionally normalised by its lowest horizontal coordinate (Figs. 48-49);
- :func:`tI_tp_regression`: the least-squares line t_I = a t_p + b across records and its
  correlation coefficient (Fig. 53).

The thesis gives the characteristic OAS only as "a theoretical curve" (it does not state the
statistics); here it is the per-level quantile of the largest unsafe block size 1/p across the
records, so the chosen exceedance probability is the share of records whose OAS reaches past it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._errors import InputError

__all__ = ["CharacteristicOAS", "characteristic_oas", "oas_convex_hull", "TItpRegression", "tI_tp_regression"]


@dataclass(frozen=True)
class CharacteristicOAS:
    """The OAS that a share ``exceedance`` of the records reaches past, per level.

    Attributes
    ----------
    levels : ndarray, shape (n_l,)
        a_p/a_p,min, the records' common grid.
    p_min_rad_s : ndarray, shape (n_l,)
        Smallest unsafe p at each level (blocks with p above it, i.e. smaller, overturn), 1/s;
        NaN where fewer records than the quantile needs overturn anything.
    exceedance : float
        Probability that a record's unsafe size 1/p_min exceeds the characteristic one.
    n_records : int
    names : tuple of str
    """

    levels: np.ndarray
    p_min_rad_s: np.ndarray
    exceedance: float
    n_records: int
    names: tuple = ()

    def to_frame(self):
        """``level, p_min_rad_s``."""
        import pandas as pd

        return pd.DataFrame({"level": self.levels, "p_min_rad_s": self.p_min_rad_s})


def characteristic_oas(spectra, exceedance: float = 0.16) -> CharacteristicOAS:
    """Characteristic OAS of a record set (thesis Fig. 44b).

    Parameters
    ----------
    spectra : sequence of OASResult
        The records' spectra, on one level grid (the same ``levels`` and ``level_max``).
    exceedance : float
        Share of records allowed past the characteristic curve, 0 < q < 1 (0.16: mean plus one
        standard deviation of a normal spread; 0.5: the median).

    Returns
    -------
    CharacteristicOAS
    """
    q = float(exceedance)
    if not 0.0 < q < 1.0:
        raise InputError(f"exceedance={exceedance!r}: a probability strictly between 0 and 1 (e.g. 0.16)")
    spectra = list(spectra)
    if len(spectra) < 2:
        raise InputError(f"{len(spectra)} spectra: a characteristic OAS needs a set of records (2 or more)")
    lv = np.asarray(spectra[0].levels, float)
    for o in spectra[1:]:
        if np.asarray(o.levels).shape != lv.shape or not np.allclose(o.levels, lv):
            raise InputError(
                f"record {o.name!r}: its OAS levels differ from {spectra[0].name!r}'s; compute every OAS with the "
                "same levels and level_max"
            )
    # unsafe block size per level (1/p, s); a level where a record overturns nothing counts as size 0
    size = np.array(
        [np.where(np.isfinite(o.p_min_rad_s), 1.0 / np.asarray(o.p_min_rad_s, float), 0.0) for o in spectra]
    )
    s = np.quantile(size, 1.0 - q, axis=0, method="linear")
    with np.errstate(divide="ignore"):
        p = np.where(s > 0, 1.0 / s, np.nan)
    return CharacteristicOAS(lv, p, q, len(spectra), tuple(o.name for o in spectra))


def oas_convex_hull(o, transformed: bool = True, normalise: bool = True) -> np.ndarray:
    """Convex hull of a record's overturning region (thesis Figs. 48-49).

    Parameters
    ----------
    o : OASResult
    transformed : bool
        Hull in the transformed plane (f = p a_p/a_p,min, level) (True) or the OAS (p, level).
    normalise : bool
        Divide the horizontal coordinate by its smallest value on the boundary (Fig. 49), so
        records of different t_I compare.

    Returns
    -------
    ndarray, shape (k, 2)
        Hull vertices (x, level), counter-clockwise, the first not repeated.
    """
    from scipy.spatial import ConvexHull

    lv = np.asarray(o.levels, float)
    x = np.asarray(o.f_rad_s if transformed else o.p_min_rad_s, float)
    ok = np.isfinite(x)
    if ok.sum() < 3:
        raise InputError(f"{o.name or 'record'}: fewer than 3 levels overturn anything; no overturning region to hull")
    # the region right of the boundary (larger p, larger f overturns), closed at the grid's right edge
    right = float(np.nanmax(np.asarray(o.p_rad_s, float))) * (lv[ok] if transformed else 1.0)
    pts = np.r_[np.c_[x[ok], lv[ok]], np.c_[np.broadcast_to(right, lv[ok].shape), lv[ok]]]
    hull = pts[ConvexHull(pts).vertices]
    if normalise:
        hull = hull.copy()
        hull[:, 0] /= float(np.nanmin(x[ok]))
    return hull


@dataclass(frozen=True)
class TItpRegression:
    """Least-squares line t_I = slope t_p + intercept across records, and its correlation.

    Attributes
    ----------
    slope, intercept : float
        Line, intercept in s.
    r : float
        Pearson correlation coefficient of t_I and t_p.
    p_value : float
        Two-sided p-value of a zero slope.
    slope_stderr : float
    n : int
        Records used (finite t_I and t_p).
    """

    slope: float
    intercept: float
    r: float
    p_value: float
    slope_stderr: float
    n: int

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in ("slope", "intercept", "r", "p_value", "slope_stderr", "n")}


def tI_tp_regression(t_p_s, t_I_s) -> TItpRegression:
    """t_I against t_p across records (thesis Fig. 53): ``scipy.stats.linregress`` on finite pairs."""
    from scipy.stats import linregress

    tp = np.asarray(t_p_s, float).ravel()
    tI = np.asarray(t_I_s, float).ravel()
    if tp.shape != tI.shape:
        raise InputError(f"t_p_s has {tp.size} values, t_I_s {tI.size}: give one pair per record")
    ok = np.isfinite(tp) & np.isfinite(tI)
    if ok.sum() < 3:
        raise InputError(f"{int(ok.sum())} records with both t_p and t_I: a regression needs 3 or more")
    res = linregress(tp[ok], tI[ok])
    return TItpRegression(
        float(res.slope), float(res.intercept), float(res.rvalue), float(res.pvalue), float(res.stderr), int(ok.sum())
    )
