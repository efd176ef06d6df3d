"""Restitution laws for rocking impacts: a registry, one function per law.

A restitution coefficient here is the ratio of angular velocities
``eta = omega_after / omega_before`` at an impact (Čeh Eq. 12–13), not an
energy ratio; the kinetic energy drops by the factor ``eta**2`` (thesis Eq. 2).

Every law is a function ``law(block, **params) -> Restitution`` registered in
:data:`RESTITUTION_LAWS` (like ``scipy.integrate``'s ``METHODS``). A
:class:`Restitution` is a small frozen table the numba kernels read:

- ``mode = 0``: constant ``eta``;
- ``mode = 1``: ``eta_y[i]`` at the i-th impact (0-based; the last value repeats);
- ``mode = 2``: ``eta`` interpolated in ``eta_y`` at ``|omega_before|`` on the grid
  ``eta_x`` (rad/s; clamped at the ends).

Geometry conventions (all SI): the contact axes ``x1`` (before impact) and ``x2``
(after) are measured in metres from the middle of the base, positive towards the
new corner; a uniform prism has ``x1 = -b/2, x2 = +b/2``. The centre of mass is
at height ``R cos(alpha)`` and the central inertia is ``(alpha_I - 1) m R^2``, so
every law holds for a general body (:meth:`rocklab.Block.general`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..._errors import InputError

__all__ = [
    "Restitution",
    "RESTITUTION_LAWS",
    "make_restitution",
    "eta_housner",
    "eta_modified",
    "eta_axes",
    "eta_bumps",
]


@dataclass(frozen=True)
class Restitution:
    """A restitution law evaluated for one block.

    Attributes
    ----------
    name : str
        Registry key of the law (``"housner"``, ``"modified"``, ...).
    eta : float
        Velocity ratio omega_after/omega_before for ``mode == 0`` (and the first
        impact's value otherwise). Negative: the block bounces back onto the same
        corner; 0: it stays still.
    mode : int
        0 constant, 1 per impact number, 2 function of ``|omega_before|`` (see module doc).
    eta_x, eta_y : ndarray, shape (k,)
        Tables for modes 1 and 2 (``eta_x`` unused in mode 1).
    params : dict
        The parameters the law was built from (for reports).
    """

    name: str
    eta: float
    mode: int = 0
    eta_x: np.ndarray = field(default_factory=lambda: np.zeros(1))
    eta_y: np.ndarray = field(default_factory=lambda: np.zeros(1))
    params: dict = field(default_factory=dict, compare=False)

    def __post_init__(self):
        x = np.ascontiguousarray(self.eta_x, dtype=float).ravel()
        y = np.ascontiguousarray(self.eta_y, dtype=float).ravel()
        if self.mode == 0:
            x = np.zeros(1)
            y = np.array([float(self.eta)])
        if not (np.all(np.isfinite(y)) and math.isfinite(self.eta)):
            raise InputError(f"restitution {self.name!r}: eta must be finite; got {self.eta!r} / table")
        if np.any(np.abs(y) > 1.0) or abs(self.eta) > 1.0:
            raise InputError(
                f"restitution {self.name!r}: |eta| must be <= 1 (an impact cannot add energy); fix the value(s)"
            )
        if self.mode == 2 and (x.size != y.size or x.size < 1 or np.any(np.diff(x) <= 0)):
            raise InputError(
                f"restitution {self.name!r}: omega table must be strictly increasing and as long as the eta table"
            )
        x.setflags(write=False)
        y.setflags(write=False)
        object.__setattr__(self, "eta_x", x)
        object.__setattr__(self, "eta_y", y)
        object.__setattr__(self, "eta", float(self.eta))

    def __call__(self, omega_before_rad_s: float, impact_index: int = 0) -> float:
        """Eta for an impact (pure Python; the kernels use the same rule)."""
        if self.mode == 1:
            return float(self.eta_y[min(int(impact_index), self.eta_y.size - 1)])
        if self.mode == 2:
            return float(np.interp(abs(omega_before_rad_s), self.eta_x, self.eta_y))
        return self.eta

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        d = {"law": self.name, "eta": self.eta, "mode": self.mode}
        d.update({k: v for k, v in self.params.items() if not callable(v)})
        return d


# -- closed forms ----------------------------------------------------------------


def _geom(block):
    """K = I_C/m + (CoM height)^2 (m^2) and half-width (m) of ``block``."""
    R, a, aI = block.R_m, block.alpha_rad, block.alpha_I
    K = (aI - 1.0) * R * R + (R * math.cos(a)) ** 2
    return K, R * math.sin(a)


def _out(x):
    """A 0-d result as a Python float, arrays unchanged."""
    return float(x) if np.ndim(x) == 0 else x


def eta_housner(alpha_rad, alpha_I: float = 4.0 / 3.0):
    """Housner's eta = 1 - 2 sin^2(alpha)/alpha_I (Čeh Eq. 13 for alpha_I = 4/3; thesis Eq. 1).

    Vectorised: ``alpha_rad`` (rad) may be a float or an array of any shape.
    """
    return _out(1.0 - 2.0 * np.sin(np.asarray(alpha_rad, float)) ** 2 / alpha_I)


def eta_modified(alpha_rad, k, alpha_I: float = 4.0 / 3.0):
    """Modified eta_M(k) (Čeh Eq. 14): impulse resultant at ``k`` half-widths from the middle.

    For alpha_I = 4/3 this is ``(4 - 3 s^2 (1 + k^2)) / (4 - 3 s^2 (1 - k^2))``,
    s = sin(alpha); it equals thesis Eq. A3 with axes at ``-k b/2`` and ``+k b/2``.
    ``k = 1`` is Housner, ``k = 0`` no loss. Vectorised over ``alpha_rad`` (rad) and ``k``;
    k > 1 (impulse outside the base) is returned as computed but is unphysical.
    """
    s2 = np.sin(np.asarray(alpha_rad, float)) ** 2
    k2 = np.asarray(k, float) ** 2
    return _out((alpha_I - s2 - k2 * s2) / (alpha_I - s2 + k2 * s2))


def eta_axes(block, x1_m: float, x2_m: float) -> float:
    """Impact when the rotation axis jumps from ``x1_m`` to ``x2_m`` (thesis Eq. A3).

    Angular momentum about the new axis is conserved:
    ``eta = (K + x1 x2) / (K + x2^2)``, K = I_C/m + (CoM height)^2.
    """
    K, _ = _geom(block)
    return (K + x1_m * x2_m) / (K + x2_m * x2_m)


def eta_bumps(block, n: int, b2_m: float | None = None) -> float:
    """n bumps evenly spaced between the contact corners: n + 1 consecutive impacts.

    Eq. A7 (n = 1) generalised: the axis steps through ``x_j = -b2 + 2 b2 j/(n+1)``,
    j = 0..n+1, and the eta of each step (Eq. A3) multiply. ``n = 0`` is the
    cut-corner Housner value (Eq. A4); ``n -> inf`` tends to 1 (no loss).
    ``b2_m`` is the half-distance between the outer contact lines (default b/2).
    """
    K, half = _geom(block)
    b2 = half if b2_m is None else float(b2_m)
    x = -b2 + 2.0 * b2 * np.arange(n + 2) / (n + 1)
    return float(np.prod((K + x[:-1] * x[1:]) / (K + x[1:] ** 2)))


# -- the registry ----------------------------------------------------------------


def _num(name, v, lo=-math.inf, hi=math.inf):
    try:
        f = float(v)
    except (TypeError, ValueError):
        raise InputError(f"{name}={v!r}: must be a number") from None
    if not (math.isfinite(f) and lo <= f <= hi):
        raise InputError(f"{name}={v!r}: must be a finite number in [{lo}, {hi}]")
    return f


def _law_housner(block, **_):
    return Restitution("housner", eta_housner(block.alpha_rad, block.alpha_I))


def _law_modified(block, k=1.0, **_):
    k = _num("k (impulse position / half-width)", k, 0.0, 1.0)
    return Restitution("modified", eta_modified(block.alpha_rad, k, block.alpha_I), params={"k": k})


def _law_constant(block, eta=None, **_):
    if eta is None:
        raise InputError("restitution 'constant' needs eta=<value in [-1, 1]>, e.g. --eta 0.95")
    eta = _num("eta", eta, -1.0, 1.0)
    return Restitution("constant", eta, params={"eta": eta})


def _law_axes(block, x1_m=None, x2_m=None, **_):
    half = block.R_m * math.sin(block.alpha_rad)
    x1 = -half if x1_m is None else _num("x1_m", x1_m)
    x2 = half if x2_m is None else _num("x2_m", x2_m)
    if x2 == 0.0 and x1 == 0.0:
        raise InputError("restitution 'axes': x1_m and x2_m cannot both be 0")
    return Restitution("axes", eta_axes(block, x1, x2), params={"x1_m": x1, "x2_m": x2})


def _law_cut_corner(block, b2_m=None, **_):
    half = block.R_m * math.sin(block.alpha_rad)
    b2 = half if b2_m is None else _num("b2_m (half-distance of the contact lines)", b2_m, 0.0, half)
    return Restitution("cut_corner", eta_axes(block, -b2, b2), params={"b2_m": b2})


def _law_bumps(block, n=1, b2_m=None, **_):
    try:
        n_i = int(n)
    except (TypeError, ValueError):
        raise InputError(f"bumps n={n!r}: must be a non-negative integer") from None
    if n_i != n or n_i < 0:
        raise InputError(f"bumps n={n!r}: must be a non-negative integer number of bumps")
    half = block.R_m * math.sin(block.alpha_rad)
    b2 = half if b2_m is None else _num("b2_m", b2_m, 0.0, half)
    return Restitution("bumps", eta_bumps(block, n_i, b2), params={"n": n_i, "b2_m": b2})


def _law_per_impact(block, eta=None, omega_rad_s=None, func=None, by="number", n_table=4096, omega_max_rad_s=None, **_):
    """eta per impact: a sequence by impact number, a table over |omega_before|, or a callable.

    ``func`` is tabulated for the kernels: ``by="number"`` -> ``func(i)`` for
    i = 0..n_table-1; ``by="omega"`` -> ``func(w)`` on ``n_table`` points of
    [0, omega_max_rad_s] (default: 2 sqrt(2 (1 - cos alpha)) p, above any
    free-rocking velocity from rest below alpha).
    """
    if func is not None:
        if by == "number":
            y = np.array([func(i) for i in range(int(n_table))], float)
            return Restitution("per_impact", y[0], 1, np.zeros(1), y, {"by": "number"})
        if by == "omega":
            wmax = omega_max_rad_s or 2.0 * block.p_rad_s * math.sqrt(2 * (1 - math.cos(block.alpha_rad)))
            x = np.linspace(0.0, float(wmax), int(n_table))
            y = np.array([func(w) for w in x], float)
            return Restitution("per_impact", y[0], 2, x, y, {"by": "omega"})
        raise InputError(f"per_impact by={by!r}: use 'number' or 'omega'")
    if eta is None:
        raise InputError(
            "restitution 'per_impact' needs eta=[...] (per impact number), "
            "eta=[...] with omega_rad_s=[...], or func=callable"
        )
    y = np.atleast_1d(np.asarray(eta, float))
    if omega_rad_s is None:
        return Restitution("per_impact", y[0], 1, np.zeros(1), y, {"by": "number"})
    x = np.atleast_1d(np.asarray(omega_rad_s, float))
    return Restitution("per_impact", y[0], 2, x, y, {"by": "omega"})


#: Registry: law name -> function(block, **params) -> Restitution.
RESTITUTION_LAWS = {
    "housner": _law_housner,
    "modified": _law_modified,
    "constant": _law_constant,
    "axes": _law_axes,
    "cut_corner": _law_cut_corner,
    "bumps": _law_bumps,
    "per_impact": _law_per_impact,
}


def make_restitution(law, block, **params) -> Restitution:
    """Build a :class:`Restitution` for ``block`` from a registry name (or pass one through).

    Parameters
    ----------
    law : str or Restitution or float
        A key of :data:`RESTITUTION_LAWS`, a ready :class:`Restitution`, or a
        number (a constant eta).
    block : rocklab.Block
    **params
        The law's parameters: ``k`` (modified), ``eta`` (constant, per_impact),
        ``x1_m, x2_m`` (axes), ``b2_m`` (cut_corner, bumps), ``n`` (bumps),
        ``omega_rad_s, func, by`` (per_impact). Unknown names are ignored by laws
        that do not use them.
    """
    if isinstance(law, Restitution):
        return law
    if isinstance(law, (int, float)) and not isinstance(law, bool):
        return _law_constant(block, eta=law)
    key = str(law).strip().lower()
    if key not in RESTITUTION_LAWS:
        raise InputError(f"restitution={law!r}: unknown law; use one of {', '.join(RESTITUTION_LAWS)}")
    return RESTITUTION_LAWS[key](block, **params)
