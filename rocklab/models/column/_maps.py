"""Overturning maps of columns under pulses (Ther thesis §5.2, Fig. 40–41).

A column of total height H and width B made of 1, 2, 3, ... equal blocks is
excited by a full-sine base-acceleration pulse ``a_p sin(2π t / t_p)``,
``0 <= t <= t_p``, and left to rock freely afterwards; each cell of the
``(a_p, t_p)`` grid records whether it overturned.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..._errors import InputError
from ._sim import Column, simulate_column
from ...series import BaseMotion

__all__ = ["sine_pulse", "ColumnMaps", "column_overturning_maps"]


def sine_pulse(ap_m_s2: float, tp_s: float, dt_s: float = 1e-3, sign: float = 1.0) -> BaseMotion:
    """Full-sine acceleration pulse ``sign * a_p sin(2π t/t_p)`` on ``[0, t_p]`` (m/s², s)."""
    if not (tp_s > 0 and math.isfinite(ap_m_s2)):
        raise InputError(f"sine pulse a_p={ap_m_s2!r}, t_p={tp_s!r}: t_p must be positive, a_p finite")
    n = max(int(round(tp_s / dt_s)), 2)
    t = np.linspace(0.0, tp_s, n + 1)
    return BaseMotion(t, sign * ap_m_s2 * np.sin(2 * np.pi * t / tp_s), name=f"sine a_p={ap_m_s2:g} t_p={tp_s:g}")


@dataclass(frozen=True)
class ColumnMaps:
    """Overturning maps.

    Attributes
    ----------
    n_blocks : ndarray (k,)
        Number of blocks of each column.
    ap_m_s2 : ndarray (na,)
        Pulse amplitudes, m/s².
    tp_s : ndarray (nt,)
        Pulse periods, s.
    overturned : ndarray (k, na, nt) bool
        Unsafe: overturned, or stopped (below).
    max_theta_over_alpha : ndarray (k, na, nt)
        Peak |block angle| over the column's slenderness angle atan(B/H).
    H_m, B_m : float
    params : dict
    stopped : ndarray (k, na, nt) bool
        Runs the model stopped because a joint went into tension or slid (the column comes
        apart; :func:`simulate_column` status ``tension``/``sliding``): counted unsafe, as the
        thesis's model stops there too, and reported by W-COLUMN-APART.
    """

    n_blocks: np.ndarray
    ap_m_s2: np.ndarray
    tp_s: np.ndarray
    overturned: np.ndarray
    max_theta_over_alpha: np.ndarray
    H_m: float
    B_m: float
    params: dict = field(default_factory=dict)
    stopped: np.ndarray | None = None

    @property
    def overturned_fraction(self) -> np.ndarray:
        """Share of grid cells that overturn, per column, shape (k,)."""
        return self.overturned.reshape(len(self.n_blocks), -1).mean(axis=1)

    def to_frame(self):
        """Long table ``n_blocks, ap_m_s2, tp_s, overturned, max_theta_over_alpha``."""
        import pandas as pd

        k, na, nt = self.overturned.shape
        nb, ap, tp = np.meshgrid(self.n_blocks, self.ap_m_s2, self.tp_s, indexing="ij")
        return pd.DataFrame(
            {
                "n_blocks": nb.ravel(),
                "ap_m_s2": ap.ravel(),
                "tp_s": tp.ravel(),
                "overturned": self.overturned.ravel(),
                "stopped": (np.zeros_like(self.overturned) if self.stopped is None else self.stopped).ravel(),
                "max_theta_over_alpha": self.max_theta_over_alpha.ravel(),
            }
        )

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        return {
            "H_m": self.H_m,
            "B_m": self.B_m,
            "n_blocks": self.n_blocks.tolist(),
            "ap_m_s2": self.ap_m_s2.tolist(),
            "tp_s": self.tp_s.tolist(),
            "overturned": self.overturned.tolist(),
            "overturned_fraction": self.overturned_fraction.tolist(),
            "stopped": None if self.stopped is None else self.stopped.tolist(),
            "params": dict(self.params),
        }


def column_overturning_maps(
    H_m: float = 12.0,
    B_m: float = 1.0,
    n_blocks=(1, 2, 3),
    ap_m_s2=None,
    tp_s=None,
    *,
    n_impacts: int = 1,
    dt_s: float = 2e-3,
    free_s: float = 10.0,
    progress=None,
    **sim_kwargs,
) -> ColumnMaps:
    """Overturning maps of 1-, 2-, 3-block columns under full-sine pulses (thesis Fig. 40).

    Parameters
    ----------
    H_m, B_m : float
        Total height and width, m (thesis: 12 m and 1 m).
    n_blocks : sequence of int
    ap_m_s2, tp_s : array, optional
        Grid of amplitudes (m/s²) and periods (s); default a coarse 8 × 8 grid
        over 1–10 m/s² and 0.5–4 s.
    n_impacts : int
        1 = Housner's impact (Fig. 40), 2 = one mid-joint bump.
    dt_s : float
        Time step, s (the columns' p ~ 0.8 rad/s allows a coarse step).
    free_s : float
        Free rocking after the pulse, s.
    progress : callable, optional
        Called with the number of finished runs (for a progress bar).
    **sim_kwargs
        Passed to :func:`simulate_column` (e.g. ``velocity_terms=False``). The
        runs store no time history (``output_dt_s=inf``): overturning and the
        peak angles come from every step all the same.
    """
    ap = np.asarray(ap_m_s2 if ap_m_s2 is not None else np.linspace(1.0, 10.0, 8), float)
    tp = np.asarray(tp_s if tp_s is not None else np.linspace(0.5, 4.0, 8), float)
    nb = np.asarray(n_blocks, int)
    if (nb < 1).any() or ap.ndim != 1 or tp.ndim != 1 or (tp <= 0).any():
        raise InputError("column_overturning_maps: n_blocks >= 1, 1-D grids and positive t_p required")
    over = np.zeros((nb.size, ap.size, tp.size), bool)
    stopped = np.zeros_like(over)
    peak = np.zeros_like(over, dtype=float)
    alpha = math.atan2(B_m, H_m)
    done = 0
    run_kwargs = {"output_dt_s": math.inf, **sim_kwargs}
    for k, n in enumerate(nb):
        col = Column.uniform(B_m, H_m, int(n), mass_kg=1.0)
        for i, a in enumerate(ap):
            for j, t in enumerate(tp):
                r = simulate_column(
                    col,
                    sine_pulse(a, t, dt_s=min(dt_s, t / 50)),
                    duration_s=t + free_s,
                    dt_s=dt_s,
                    n_impacts=n_impacts,
                    **run_kwargs,
                )
                stopped[k, i, j] = r.status in ("tension", "sliding")
                over[k, i, j] = r.overturned or stopped[k, i, j]
                peak[k, i, j] = float(np.max(np.asarray(r.max_abs_theta_rad))) / alpha
                done += 1
                if progress is not None:
                    progress(done)
    if stopped.any():
        from ..._diagnostics import warn

        warn(
            "W-COLUMN-APART",
            f"{int(stopped.sum())} of {stopped.size} column runs stopped with a joint in tension or sliding "
            "(the column comes apart): counted as unsafe; see ColumnMaps.stopped",
        )
    return ColumnMaps(
        nb,
        ap,
        tp,
        over,
        peak,
        float(H_m),
        float(B_m),
        dict(n_impacts=n_impacts, dt_s=dt_s, free_s=free_s, pulse="full sine", **sim_kwargs),
        stopped,
    )
