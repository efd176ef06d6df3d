"""Overturning design check with the replacement impulse duration (Ther thesis Eq. 21–24, 31).

A symmetric body (pier, column, block) is safe against overturning under a site
described by its PGA a_p and replacement impulse duration t_I if (Eq. 21/31)

    a_p / a_p,min <= max( i_cr / (t_I p), 1 ),   a_p,min = g tan(alpha),
    p = sqrt(g / (alpha_I R)),                   i_cr = sqrt(2 / (1 + cos alpha)).

For a pier of height H and width B whose centre of mass is at height c H
(c = 1/2 solid, c = 1 mass at the top), tan(alpha) = B / (2 c H) and
R = sqrt((c H)^2 + (B/2)^2); the inertia coefficient alpha_I = I_O/(m R^2)
(Eq. 22) describes the mass distribution: 4/3 for a uniform rectangle, 1 for a
point mass (mass at the top of a weightless pier). Units SI (m, s, m/s^2).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from ..._errors import InputError
from ..._errors import positive as _pos
from ...blocks import G, Block, inertia_coefficient

__all__ = ["DesignCheck", "design_check", "required_width", "required_width_slender"]


@dataclass(frozen=True)
class DesignCheck:
    """Result of the Eq. 21/31 check for one block.

    Attributes
    ----------
    safe : bool
        a_p <= a_p,allow.
    a_p_m_s2, a_p_allow_m_s2 : float
        Demand and allowed PGA, m/s^2 (allowed = a_p,min max(i_cr/(t_I p), 1)).
    a_p_min_m_s2 : float
        Uplift acceleration g tan(alpha), m/s^2.
    p_rad_s, i_cr, t_I_s : float
        Frequency parameter, Eq. 18, duration used.
    utilisation : float
        a_p / a_p,allow (<= 1 safe).
    """

    safe: bool
    a_p_m_s2: float
    a_p_allow_m_s2: float
    a_p_min_m_s2: float
    p_rad_s: float
    i_cr: float
    t_I_s: float
    utilisation: float

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        return asdict(self)


def design_check(block: Block, a_p_m_s2: float, t_I_s: float, exact_icr: bool = True) -> DesignCheck:
    """Check a block against PGA ``a_p_m_s2`` (m/s^2) and ``t_I_s`` (s), thesis Eq. 21/31.

    ``exact_icr=False`` uses i_cr = 1 (the "≈" form of Eq. 21, i.e. Eq. 31).
    """
    a_p = _pos("a_p_m_s2", a_p_m_s2)
    t_I = _pos("t_I_s", t_I_s)
    alpha = block.alpha_rad
    icr = math.sqrt(2 / (1 + math.cos(alpha))) if exact_icr else 1.0
    a_min = G * math.tan(alpha)
    allow = a_min * max(icr / (t_I * block.p_rad_s), 1.0)
    return DesignCheck(
        safe=a_p <= allow,
        a_p_m_s2=a_p,
        a_p_allow_m_s2=allow,
        a_p_min_m_s2=a_min,
        p_rad_s=block.p_rad_s,
        i_cr=icr,
        t_I_s=t_I,
        utilisation=a_p / allow,
    )


def required_width(
    height_m: float,
    a_g_m_s2: float,
    t_I_s: float,
    *,
    cm_height_ratio: float = 0.5,
    alpha_I: float = 4.0 / 3.0,
    exact_icr: bool = True,
    g: float = G,
) -> float:
    """Smallest pier width B (m) that Eq. 21 declares safe (thesis Eq. 23, §5.3.4).

    Solves ``a_g / (g tan alpha) = i_cr sqrt(alpha_I R / g) / t_I`` for B, with
    tan(alpha) = B/(2cH), R = sqrt((cH)^2 + (B/2)^2). If the block does not even
    uplift at the width B0 = 2cH a_g/g (left side 1); narrower piers rock but
    stay safe down to the root of the equation, which is the answer (or B0 when
    i_cr/(t_I p) < 1 there).

    Parameters
    ----------
    height_m : float
        Pier height H, m.
    a_g_m_s2 : float
        Design PGA, m/s^2.
    t_I_s : float
        Design replacement impulse duration, s.
    cm_height_ratio : float
        Centre-of-mass height / H: 0.5 solid pier, 1.0 mass at the top.
    alpha_I : float
        I_O/(m R^2): 4/3 solid, 1 point mass at the top (Eq. 22).
    exact_icr : bool
        Use i_cr = sqrt(2/(1+cos alpha)) (exact Eq. 21) or i_cr = 1 (Eq. 31).
    g : float
        Gravity, m/s^2 (the thesis example is reproduced with 9.81).

    Returns
    -------
    float
        Width B, m.
    """
    from scipy.optimize import brentq

    H = _pos("height_m", height_m)
    ag = _pos("a_g_m_s2", a_g_m_s2)
    tI = _pos("t_I_s", t_I_s)
    c = _pos("cm_height_ratio", cm_height_ratio)
    g = _pos("g (gravity, m/s^2)", g)
    alpha_I = inertia_coefficient(alpha_I)
    if c > 1:
        raise InputError(f"cm_height_ratio={c}: the centre of mass is in the pier; give a height ratio in (0, 1]")
    b_uplift = 2 * c * H * ag / g  # width at which a_g = a_p,min

    def excess(B):
        ta = B / (2 * c * H)
        R = math.hypot(c * H, B / 2)
        a = math.atan(ta)
        icr = math.sqrt(2 / (1 + math.cos(a))) if exact_icr else 1.0
        return ag / (g * ta) - icr * math.sqrt(alpha_I * R / g) / tI

    if excess(b_uplift) >= 0:
        return b_uplift  # i_cr/(t_I p) <= 1 at B0: only "no uplift" is safe (Eq. 21's max with 1)
    try:
        return brentq(excess, 1e-9 * H, b_uplift, xtol=1e-12, rtol=1e-14)
    except (ValueError, RuntimeError, OverflowError):  # no sign change, or no convergence, in floats
        raise InputError(
            f"height {H:g} m, a_g {ag:g} m/s2, t_I {tI:g} s, g {g:g} m/s2: no pier width between 1e-9 H and "
            f"{b_uplift:g} m solves Eq. 21; check the values and their units (m, m/s2, s)"
        ) from None


def required_width_slender(
    height_m: float,
    a_g_m_s2: float,
    t_I_s: float,
    *,
    cm_height_ratio: float = 0.5,
    alpha_I: float = 4.0 / 3.0,
    g: float = G,
) -> float:
    """Slender approximation of :func:`required_width` (thesis Eq. 24 of §5.3.4).

    cos(alpha) ≈ 1, R ≈ cH, i_cr ≈ 1 give ``B = 2 c H a_g t_I / (g sqrt(alpha_I c H / g))``:
    the thesis's ``sqrt(H) t_I a_g / sqrt(g) * sqrt(3/2)`` (solid) and ``* 2`` (mass at top).
    """
    H = _pos("height_m", height_m)
    ag = _pos("a_g_m_s2", a_g_m_s2)
    tI = _pos("t_I_s", t_I_s)
    c = _pos("cm_height_ratio", cm_height_ratio)
    return 2 * c * H * ag * tI / (g * math.sqrt(alpha_I * c * H / g))
