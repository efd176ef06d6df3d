"""Closed-form restitution relations used by the calibration (Čeh et al. 2018, Eq. 13–18).

All functions are vectorised over numpy arrays. Angles in rad, lengths in m.
"""

from __future__ import annotations

import numpy as np

from .._errors import InputError
from ..models import eta_housner, eta_modified  # noqa: F401  (re-exported: the calibration's laws)

__all__ = ["eta_housner", "eta_modified", "k_from_eta", "edge_contact_k", "alpha_from_hb"]


def alpha_from_hb(hb):
    """Slenderness angle α = atan(b/h) from the aspect ratio h/b, rad."""
    hb = np.asarray(hb, dtype=float)
    return np.arctan2(1.0, hb)


def k_from_eta(alpha_rad, eta_rb):
    """Invert Eq. 14 for k given a rigid-body restitution η_RB (Čeh Eq. 18).

    k = sqrt[(1 − η_RB)(4 − 3 sin²α) / ((1 + η_RB) 3 sin²α)]. Returns NaN where
    η_RB ≥ 1 or η_RB ≤ −1 (no real k). k > 1 (impulse outside the base) is
    returned as computed; callers flag it infeasible.
    """
    s2 = np.sin(np.asarray(alpha_rad, dtype=float)) ** 2
    e = np.asarray(eta_rb, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        arg = (1.0 - e) * (4.0 - 3.0 * s2) / ((1.0 + e) * 3.0 * s2)
        k = np.sqrt(np.where((e < 1.0) & (e > -1.0), arg, np.nan))
    return k if k.ndim else float(k)


def edge_contact_k(b_m, l_c_m, contact: str = "inner"):
    """k for edge-contact experiments from the base-strip width l_c (Čeh Table 4).

    The block stands on two strips of width ``l_c`` flush with its edges. With the
    impulse at the strip's inner edge, b̄ = b/2 − l_c and k = 2 b̄ / b = 1 − 2 l_c / b;
    ``contact="midway"`` puts it midway across the strip, k = 1 − l_c / b.

    Parameters
    ----------
    b_m : float or array
        Block width, m.
    l_c_m : float
        Strip width, m (Čeh: 1.5 mm).
    contact : {"inner", "midway"}
    """
    b = np.asarray(b_m, dtype=float)
    lc = float(l_c_m)
    if not np.isfinite(lc) or lc < 0:
        raise InputError(f"l_c_m={l_c_m!r}: contact strip width must be a finite value >= 0 m")
    if np.any(~np.isfinite(b)) or np.any(b <= 0):
        raise InputError("b_m: block widths must be finite and > 0 m")
    if np.any(2 * lc >= b):
        raise InputError(f"l_c_m={lc}: the strip must be narrower than half the block width b/2")
    if contact == "inner":
        k = 1.0 - 2.0 * lc / b
    elif contact == "midway":
        k = 1.0 - lc / b
    else:
        raise InputError(f"contact={contact!r}: must be 'inner' or 'midway'")
    return k if k.ndim else float(k)
