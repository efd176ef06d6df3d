"""Overturning curves of simple pulses (thesis §4, Fig. 33-34): bays and islands resolved.

The same runs as the OAS (:func:`~rocklab.models.spectra._oas._runs`), in the
dimensionless plane (a_p/a_p,min, p t_p) of one pulse shape.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..._errors import InputError
from ...blocks import G
from ._oas import CRIT, OAS_DEFAULTS, check_opts, free_after_code, batch_runs, normalised_critical_impulse
from ...series import BaseMotion

__all__ = ["OverturningCurve", "overturning_curve"]


@dataclass(frozen=True)
class OverturningCurve:
    """Normalised overturning curve of a simple pulse (thesis Fig. 33a, 34).

    Attributes
    ----------
    kind : str
        Pulse kind (see :func:`rocklab.models.pulse_shape`), ``n`` lobes for n-half-sines.
    ptp : ndarray, shape (n_x,)
        p t_p values (t_p = one lobe's duration).
    levels : ndarray, shape (n_l,)
        a_p/a_p,min grid.
    overturned : ndarray of bool, shape (n_l, n_x)
        Grid verdicts; bays and islands of multi-lobe pulses show here.
    a_min_ratio : ndarray, shape (n_x,)
        Refined lowest a_p/a_p,min that overturns (NaN if none on the grid).
    impulse_ratio : ndarray, shape (n_x,)
        Overturning impulse curve p I / a_p,min = F a_min_ratio p t_p (Fig. 34b).
    i_cr : float
        Its short-pulse limit for a single lobe (Eq. 18).
    """

    kind: str
    n: int
    alpha_rad: float
    ptp: np.ndarray
    levels: np.ndarray
    overturned: np.ndarray
    a_min_ratio: np.ndarray
    impulse_ratio: np.ndarray
    i_cr: float

    def to_frame(self):
        """The result as a pandas DataFrame (SI units in the column names)."""
        import pandas as pd

        return pd.DataFrame({"ptp": self.ptp, "a_min_ratio": self.a_min_ratio, "impulse_ratio": self.impulse_ratio})


def overturning_curve(
    kind: str,
    slenderness: float,
    ptp,
    levels,
    *,
    n: int = 1,
    refine: int = 12,
    criterion: str = "angle",
    free="energy",
    alpha_I: float = 4.0 / 3.0,
    eta: float | None = None,
    samples_per_lobe: int = 200,
) -> OverturningCurve:
    """Overturning curve a_p/a_p,min vs p t_p of a simple pulse, bays and islands resolved.

    Every (level, p t_p) grid point is simulated (dimensionless: p = 1, t_p = p t_p);
    the lowest overturning level is then refined by bisection against the safe
    level below it. See :func:`overturning_spectrum` for ``criterion``, ``free``, ``eta``.
    """
    from ._pulses import pulse_duration, pulse_fullness, pulse_shape

    alpha = math.atan(1.0 / check_opts(slenderness, 2, 2, 2.0, 1.0, 2.0, alpha_I))
    eta_v = 1.0 - 2.0 * math.sin(alpha) ** 2 / alpha_I if eta is None else float(eta)
    if criterion not in CRIT:
        raise InputError(f"criterion={criterion!r}: use 'angle' or 'fall'")
    fc, fs = free_after_code(free)
    x = np.atleast_1d(np.asarray(ptp, float))
    lv = np.atleast_1d(np.asarray(levels, float))
    if (x <= 0).any() or (lv <= 0).any():
        raise InputError("ptp and levels must be positive")
    over = np.zeros((lv.size, x.size), bool)
    amin = np.full(x.size, np.nan)
    args = (alpha, eta_v, CRIT[criterion], fc, fs, OAS_DEFAULTS["max_p_dt"])
    for j, tp in enumerate(x):
        # dimensionless: p = 1 rad/s, the pulse in g (record in m/s^2 times level tan(alpha))
        dt = tp / samples_per_lobe
        t = np.arange(int(round(pulse_duration(kind, tp, n) / dt)) + 2) * dt
        base = BaseMotion.from_samples(G * pulse_shape(kind, t, tp, n), dt, name=kind)
        o = batch_runs(base, lv * math.tan(alpha), np.ones(lv.size), args)
        over[:, j] = o
        hit = np.flatnonzero(o)
        if hit.size == 0:
            continue
        k = hit[0]
        hi = lv[k]
        lo = lv[k - 1] if k > 0 else 1.0
        for _ in range(refine if lo < hi else 0):
            mid = 0.5 * (lo + hi)
            if batch_runs(base, np.array([mid * math.tan(alpha)]), np.ones(1), args)[0]:
                hi = mid
            else:
                lo = mid
        amin[j] = hi
    F = pulse_fullness(kind)
    return OverturningCurve(
        kind=kind,
        n=int(n),
        alpha_rad=alpha,
        ptp=x,
        levels=lv,
        overturned=over,
        a_min_ratio=amin,
        impulse_ratio=F * amin * x,
        i_cr=normalised_critical_impulse(alpha),
    )
