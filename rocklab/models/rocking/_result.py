"""Result containers of the single-block simulator."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import NamedTuple

import numpy as np

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ...blocks import Block
    from ._restitution import Restitution

__all__ = ["RockingResult", "BatchResult", "KernelResult", "block_energy"]


def block_energy(block, theta_rad, omega_rad_s, linearized: bool = False) -> np.ndarray:
    """Mechanical energy of a rocking block above its rest state, J.

    ``E = I_O omega^2 / 2 + m g R [cos(alpha - |theta|) - cos(alpha)]``, i.e. Čeh
    Eq. 15 with the rest energy ``m g h/2`` subtracted. Čeh Eq. 15 as printed has
    ``I_C theta'^2`` where the kinetic energy needs ``I_C theta'^2 / 2``; the
    conserved form is used here. ``linearized=True`` gives the invariant of the
    linearised equation, ``I_O [omega^2/2 + p^2 (alpha |theta| - theta^2/2)]``.
    """
    th = np.abs(np.asarray(theta_rad, float))
    w = np.asarray(omega_rad_s, float)
    a, I_O = block.alpha_rad, block.I_O_kg_m2
    if linearized:
        return I_O * (0.5 * w * w + block.p_rad_s**2 * (a * th - 0.5 * th * th))
    from ...blocks import G

    return 0.5 * I_O * w * w + block.mass_kg * G * block.R_m * (np.cos(a - th) - math.cos(a))


class KernelResult(NamedTuple):
    """What every integrator returns.

    ``t_s, theta_rad, omega_rad_s, energy_J`` (n,): the output grid, rotation (rad),
    angular velocity (rad/s) and energy above rest (J); ``impacts`` (4, k) C-contiguous rows
    t_s, omega_before, omega_after, eta of the first ``max_impacts`` impacts; ``n_impacts``
    (all of them); ``status`` (``rocking``, ``rest``, ``overturned``, ``no_uplift``);
    ``overturn_t_s``, ``fall_t_s`` (s, NaN if not reached); ``max_abs_theta_rad``.
    """

    t_s: np.ndarray
    theta_rad: np.ndarray
    omega_rad_s: np.ndarray
    energy_J: np.ndarray
    impacts: np.ndarray
    n_impacts: int
    status: str
    overturn_t_s: float
    fall_t_s: float
    max_abs_theta_rad: float


@dataclass(frozen=True)
class RockingResult:
    """Time history of one rocking block.

    Attributes
    ----------
    t_s, theta_rad, omega_rad_s, energy_J : ndarray, shape (n,)
        Output times (s), rotation (rad, > 0 about corner A, Čeh Fig. 1), angular
        velocity (rad/s), and energy above rest (J, see :func:`block_energy`).
    impacts : pandas.DataFrame
        One row per impact: ``t_s, omega_before_rad_s, omega_after_rad_s, eta``
        (built on first access from ``impacts_array``).
    impacts_array : ndarray, shape (4, n_impacts)
        The same table as rows t_s, omega_before_rad_s, omega_after_rad_s, eta.
    status : str
        ``"rest"`` (came to rest: amplitude below ``rest_tol * alpha`` with the base
        below uplift), ``"rocking"`` (still moving at the end), ``"overturned"``
        (fell: |theta| reached pi/2, the side hits the ground) or ``"no_uplift"``
        (started at rest and the base never exceeded g tan(alpha)).
    overturned : bool
        True when the block fell (status ``"overturned"``).
    overturn_t_s : float
        First time |theta| >= alpha with outward velocity (the block passed its
        unstable equilibrium); NaN if never. Under base motion it may still come
        back, so this can be finite while ``overturned`` is False.
    fall_t_s : float
        Time |theta| reached pi/2; NaN if it did not fall.
    max_abs_theta_rad : float
        Largest |theta| over every integration step, rad.
    block : rocklab.Block
    restitution : Restitution
        The law applied (``eta`` per impact is in ``impacts``).
    method : str
        ``"newmark"`` or ``"event"``.
    dt_s : float
        Integration step (newmark) or output step (event), s.
    n_impacts : int
        Number of impacts (the table may hold fewer if ``max_impacts`` was reached).
    """

    t_s: np.ndarray
    theta_rad: np.ndarray
    omega_rad_s: np.ndarray
    energy_J: np.ndarray
    impacts_array: np.ndarray
    status: str
    overturned: bool
    overturn_t_s: float
    fall_t_s: float
    max_abs_theta_rad: float
    block: "Block"
    restitution: "Restitution"
    method: str
    dt_s: float
    n_impacts: int
    linearized: bool = False
    base_name: str = ""
    meta: dict = field(default_factory=dict, compare=False)

    @cached_property
    def impacts(self):
        """DataFrame ``t_s, omega_before_rad_s, omega_after_rad_s, eta``, one row per impact."""
        import pandas as pd

        a = self.impacts_array
        return pd.DataFrame({"t_s": a[0], "omega_before_rad_s": a[1], "omega_after_rad_s": a[2], "eta": a[3]})

    @property
    def max_abs_theta_over_alpha(self) -> float:
        """max |theta| / alpha (dimensionless)."""
        return self.max_abs_theta_rad / self.block.alpha_rad

    def at(self, t_s):
        """Rotation and angular velocity at arbitrary times, impact-aware cubic Hermite.

        Between stored samples theta is the cubic Hermite of (theta, omega); the
        impacts are extra knots (theta = 0, omega- on the left, omega+ on the
        right), so the velocity jump is kept. Exact to the integrator's accuracy
        plus O(dt^4) when samples are stored every step (the default).

        Parameters
        ----------
        t_s : array_like, shape (n,)
            Times, s; NaN outside ``[t_s[0], t_s[-1]]``.

        Returns
        -------
        theta_rad, omega_rad_s : ndarray, shape (n,)
        """
        t = np.asarray(t_s, float)
        imp = self.impacts_array
        kt = np.concatenate([self.t_s, imp[0]])
        kx = np.concatenate([self.theta_rad, np.zeros(imp.shape[1])])
        kl = np.concatenate([self.omega_rad_s, imp[1]])  # velocity arriving at the knot
        kr = np.concatenate([self.omega_rad_s, imp[2]])  # velocity leaving the knot
        # impacts sort after a sample at the same time (stable sort on the concatenation)
        o = np.argsort(kt, kind="stable")
        kt, kx, kl, kr = kt[o], kx[o], kl[o], kr[o]
        k = np.clip(np.searchsorted(kt, t, side="right") - 1, 0, len(kt) - 2)
        h = kt[k + 1] - kt[k]
        hs = np.where(h > 0, h, 1.0)
        u = np.where(h > 0, (t - kt[k]) / hs, 0.0)
        x0, x1, v0, v1 = kx[k], kx[k + 1], kr[k], kl[k + 1]
        u2, u3 = u * u, u * u * u
        th = (2 * u3 - 3 * u2 + 1) * x0 + (u3 - 2 * u2 + u) * h * v0 + (3 * u2 - 2 * u3) * x1 + (u3 - u2) * h * v1
        w = ((6 * u2 - 6 * u) * x0 + (6 * u - 6 * u2) * x1) / hs + (3 * u2 - 4 * u + 1) * v0 + (3 * u2 - 2 * u) * v1
        out = (t < self.t_s[0]) | (t > self.t_s[-1]) | ~np.isfinite(t)
        th[out] = np.nan
        w[out] = np.nan
        return th, w

    def to_frame(self):
        """DataFrame ``t_s, theta_rad, omega_rad_s, energy_J`` (one row per output sample)."""
        import pandas as pd

        return pd.DataFrame(
            {"t_s": self.t_s, "theta_rad": self.theta_rad, "omega_rad_s": self.omega_rad_s, "energy_J": self.energy_J}
        )

    def to_dict(self, impacts: bool = True) -> dict:
        """JSON-ready summary: block, law, status, overturning and (optionally) the impacts."""
        b = self.block
        d = {
            "block": b.to_dict(),
            "alpha_rad": b.alpha_rad,
            "p_rad_s": b.p_rad_s,
            "eta_H": b.eta_H,
            "restitution": self.restitution.to_dict(),
            "method": self.method,
            "dt_s": self.dt_s,
            "linearized": self.linearized,
            "base_motion": self.base_name or None,
            "status": self.status,
            "overturned": bool(self.overturned),
            "overturn_t_s": _f(self.overturn_t_s),
            "fall_t_s": _f(self.fall_t_s),
            "max_abs_theta_rad": _f(self.max_abs_theta_rad),
            "max_abs_theta_over_alpha": _f(self.max_abs_theta_over_alpha),
            "n_impacts": int(self.n_impacts),
            "t_end_s": _f(self.t_s[-1]) if len(self.t_s) else 0.0,
        }
        if impacts:
            d["impacts"] = [{k: _f(v) for k, v in row.items()} for row in self.impacts.to_dict(orient="records")]
        return d


def _f(x):
    x = float(x)
    return x if math.isfinite(x) else None


@dataclass(frozen=True)
class BatchResult:
    """Summary of many independent rocking runs (one entry per block/amplitude).

    Attributes
    ----------
    overturned : ndarray of bool, shape (m,)
        The block fell (|theta| reached ``fall_rad``, default pi/2).
    overturn_t_s : ndarray, shape (m,)
        First time |theta| >= alpha with outward velocity, s (NaN if never).
    max_abs_theta_over_alpha : ndarray, shape (m,)
        max |theta| / alpha over the run.
    n_impacts : ndarray of int, shape (m,)
    status : ndarray of int8, shape (m,)
        0 rocking at the end, 1 rest, 2 overturned, 3 no uplift, 4 stopped safe (``stop_when_safe``).
    p_rad_s, alpha_rad, scale, eta : ndarray, shape (m,)
        The broadcast inputs.
    dt_s : ndarray, shape (m,)
        Integration step actually used (after sub-stepping), s.
    n_steps : int
        Total block-steps integrated (for throughput figures).
    theta_end_rad, omega_end_rad_s : ndarray, shape (m,)
        State where each run ended (rad, rad/s; the sign of theta names the
        pivot; 0, 0 at rest). Feed to :func:`free_rocking_overturns` for the
        fate of blocks still rocking at the end.
    t_end_s : ndarray, shape (m,)
        Time each run ended (early at rest or overturning), s.
    """

    overturned: np.ndarray
    overturn_t_s: np.ndarray
    max_abs_theta_over_alpha: np.ndarray
    n_impacts: np.ndarray
    status: np.ndarray
    p_rad_s: np.ndarray
    alpha_rad: np.ndarray
    scale: np.ndarray
    eta: np.ndarray
    dt_s: np.ndarray
    n_steps: int
    theta_end_rad: np.ndarray
    omega_end_rad_s: np.ndarray
    t_end_s: np.ndarray

    def to_frame(self):
        """DataFrame, one row per run."""
        import pandas as pd

        return pd.DataFrame(
            {
                "p_rad_s": self.p_rad_s,
                "alpha_rad": self.alpha_rad,
                "scale": self.scale,
                "eta": self.eta,
                "dt_s": self.dt_s,
                "overturned": self.overturned,
                "overturn_t_s": self.overturn_t_s,
                "max_abs_theta_over_alpha": self.max_abs_theta_over_alpha,
                "n_impacts": self.n_impacts,
                "status": self.status,
                "theta_end_rad": self.theta_end_rad,
                "omega_end_rad_s": self.omega_end_rad_s,
                "t_end_s": self.t_end_s,
            }
        )
