"""Converged OAS verdicts: the reference a grid's verdicts are measured against, and its chaotic cells.

A verdict (overturned or not) of one OAS cell depends on the integrator only through the
trajectory's error; near the boundary a long rocking response amplifies that error, so a
grid of fixed-step runs is not converged there (on FEMA FF-9 the Newmark grid at
p h = 0.001 keeps 96 % of the verdicts of p h = 0.00025). :func:`oas_reference` computes
every cell of the grid (``grid="dense"``) with the Taylor-series integrator
(``method="taylor"``: one step per record interval, order from p h, truncation below
rounding, impacts and overturning as roots of the series), twice:

- at the reference tolerance and at a finer one (half the step, truncation 1e-20): cells
  whose verdict differs are *unresolved* (the verdict has not stopped changing);
- at the amplitude times ``1 - chaos_rel`` and ``1 + chaos_rel`` (1e-3): cells whose verdict
  flips are *chaotic*: no integrator can be expected to agree there, because a record
  known to three digits does not decide them.

Agreement of another OAS with the reference (:meth:`OASReference.agreement`) counts only
the cells that are neither.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..._errors import InputError
from ...blocks import G
from ...series import BaseMotion
from ._oas import CRIT, TAYLOR_P_H, OASResult, batch_runs, free_after_code, overturning_spectrum

__all__ = ["OASReference", "oas_reference", "CHAOS_REL", "CHECK_TOL"]

#: Relative change of the amplitude under which a flipping verdict counts as chaotic.
CHAOS_REL = 1e-3
#: Truncation bound of the finer check run (the reference runs at 1e-16).
CHECK_TOL = 1e-20


@dataclass(frozen=True)
class OASReference:
    """Converged verdicts of an OAS grid.

    Attributes
    ----------
    oas : OASResult
        The reference OAS: every cell simulated by ``method="taylor"`` (dense grid), its
        boundary bisected as in :func:`overturning_spectrum`; ``oas.t_I_s`` is the reference t_I, s.
    chaotic : ndarray of bool, shape (n_l, n_s)
        The verdict at amplitude times ``1 - chaos_rel`` or ``1 + chaos_rel`` differs from the
        verdict at the amplitude.
    unresolved : ndarray of bool, shape (n_l, n_s)
        The verdict differs between the reference tolerance and the finer check.
    chaos_rel : float
        The relative amplitude change used.
    """

    oas: OASResult
    chaotic: np.ndarray
    unresolved: np.ndarray
    chaos_rel: float = CHAOS_REL

    @property
    def overturned(self) -> np.ndarray:
        """Reference verdicts, shape (n_l, n_s)."""
        return self.oas.overturned

    @property
    def decided(self) -> np.ndarray:
        """Cells neither chaotic nor unresolved, shape (n_l, n_s): where agreement is measured."""
        return ~(self.chaotic | self.unresolved)

    @property
    def chaotic_fraction(self) -> float:
        """Fraction of the grid's cells that are chaotic."""
        return float(np.mean(self.chaotic))

    def agreement(self, other: OASResult) -> float:
        """Fraction of the decided cells where ``other``'s verdict equals the reference's.

        ``other`` must be an OAS of the same record on the same grid (levels and sizes).
        """
        if other.overturned.shape != self.overturned.shape or not (
            np.allclose(other.levels, self.oas.levels) and np.allclose(other.R_m, self.oas.R_m)
        ):
            raise InputError("agreement: the OAS is on another grid than the reference; use the same levels and sizes")
        d = self.decided
        return float(np.mean(other.overturned[d] == self.overturned[d])) if d.any() else float("nan")


def oas_reference(
    base: BaseMotion, slenderness: float = 12.0, *, chaos_rel: float = CHAOS_REL, **options
) -> OASReference:
    """Converged verdicts and chaotic cells of an OAS grid (the reference for other grids' verdicts).

    Parameters
    ----------
    base : BaseMotion
        The record (SI; m/s^2).
    slenderness : float
        h/b of the block.
    chaos_rel : float
        Relative amplitude change (dimensionless, in (0, 0.1]) under which a verdict that flips
        marks its cell chaotic; 1e-3 by default.
    **options
        Grid and definition options of :func:`overturning_spectrum` (``levels``, ``level_max``,
        ``sizes``, ``R_max_m``, ``R_min_m``, ``refine``, ``criterion``, ``free``, ``search``,
        ``alpha_I``, ``eta``, ``level_offset``, ``size_offset``); ``grid``, ``method`` and
        ``max_p_dt`` are set here.

    Returns
    -------
    OASReference
        Reference verdicts (``.oas``, t_I included), ``.chaotic`` and ``.unresolved`` masks.

    Notes
    -----
    Cost: four dense grids of Taylor runs (the verdicts, the check and the two amplitudes);
    about 1 ms per run of a 30 s record at dt = 0.01 s on one core.

    Examples
    --------
    A one-cycle sine pulse (peak 0.5 m/s², period 2 s) on a coarse 10 × 12 grid, H/B = 5: one cell
    of the 120 flips under a 0.1 % change of amplitude, none between the two tolerances.

    >>> from rocklab.models import oas_reference, pulse_motion
    >>> ref = oas_reference(pulse_motion("sine", 0.5, 2.0), 5.0, levels=10, sizes=12)
    >>> int(ref.chaotic.sum()), int(ref.unresolved.sum()), round(ref.oas.t_I_s, 3)
    (1, 0, 0.356)
    """
    for k in ("grid", "method", "max_p_dt", "verdicts", "guide"):
        if k in options:
            raise InputError(f"oas_reference: {k}= is set by the reference itself; leave it out")
    if not (math.isfinite(chaos_rel) and 0 < chaos_rel <= 0.1):
        raise InputError(f"chaos_rel={chaos_rel!r}: relative amplitude change must be in (0, 0.1]")
    o = overturning_spectrum(base, slenderness, grid="dense", method="taylor", **options)
    free_code, free_s = free_after_code(o.options["free"])
    crit = CRIT[o.options["criterion"]]
    lv, p = o.levels, o.p_rad_s
    i = np.repeat(np.arange(lv.size), p.size)
    j = np.tile(np.arange(p.size), lv.size)
    scales = lv[i] * math.tan(o.alpha_rad) * G / base.pga_m_s2

    def verdicts(factor, p_h, tol):
        args = (o.alpha_rad, o.eta, crit, free_code, free_s, p_h, "taylor", tol)
        return batch_runs(base, scales * factor, p[j], args).reshape(o.overturned.shape)

    check = verdicts(1.0, 0.5 * TAYLOR_P_H, CHECK_TOL)
    chaotic = (verdicts(1.0 - chaos_rel, TAYLOR_P_H, 1e-16) != o.overturned) | (
        verdicts(1.0 + chaos_rel, TAYLOR_P_H, 1e-16) != o.overturned
    )
    return OASReference(oas=o, chaotic=chaotic, unresolved=check != o.overturned, chaos_rel=float(chaos_rel))
