"""Multi-block rocking columns: public API (Ther thesis §3.2–3.3, App. B–C).

A planar column of rigid blocks stacked on a rigid base; every joint is closed,
open clockwise or open counter-clockwise, and both directions are unknowns of
the formulation. Mass matrix and load vector follow the App. C reduction for
the current geometry (plus the velocity terms ``BᵀMḂφ̇`` the thesis drops,
switchable); openings and impacts by the enumeration models of §3.2.2–3.2.3.

Blocks of different sizes
-------------------------
Every level has its own width, height, mass and inertia: the App. C reduction (Eq. C1–C8: three
mass points per block, ``B`` from the current geometry, ``M̃ = BᵀMB``, ``p̃ = Bᵀp``) and the
opening and impact models (Eq. 4–9) are written per block and per joint and assume nothing of the
kind. The thesis's worked examples do use identical blocks (App. C's two 1 × 4 m blocks, Eq.
C9–C16; Psycharis's two-block impact, Eq. 10–11; §4.2 and §4.3), and it says nothing of a joint
between faces of different widths: here a joint pivots ``cut_m`` inside the NARROWER of its two
faces (:attr:`Column.half_width_m`), the corner of the narrower block on the wider one.

Sign convention (public)
------------------------
x to the right, base acceleration positive to the right. Block angles
``theta_rad`` and joint rotations ``phi_rad`` are positive CLOCKWISE, which is
the single-block convention of :func:`rocklab.models.simulate` (θ > 0 turns
about the right-hand corner): a one-block column's ``theta_rad[:, 0]`` is the
single-block ``theta_rad``. Joint states: ``"closed"``, ``"cw"`` (turning about
the right corner, phi >= 0) and ``"ccw"`` (left corner, phi <= 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ..._errors import InputError
from ...blocks import G as G_STD
from ...blocks import Block
from ...series import BaseMotion

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["Column", "ColumnResult", "simulate_column", "uplift_acc_m_s2", "STATE_NAMES"]

#: Public names of the internal joint states (-1 internal = clockwise).
STATE_NAMES = {0: "closed", -1: "cw", 1: "ccw"}
_STATUS = {0: "end", 1: "rest", 2: "overturned", 3: "tension", 4: "sliding", 5: "capacity", 6: "numerical"}
_KIND = {0: "start", 1: "opening", 2: "impact"}


@dataclass(frozen=True)
class Column:
    """A column of rigid blocks on a rigid base.

    Parameters
    ----------
    blocks : sequence of Block
        Bottom to top. Width ``b_m``, height ``h_m``, mass ``mass_kg`` and the
        corner-inertia coefficient ``alpha_I`` (centroidal inertia
        ``(alpha_I - 1) m R²``) are used.
    cut_m : float or sequence of float
        Cut (chamfered) edge size per joint, m; joint ``j`` is under block ``j``
        (joint 0 is the base joint). The pivot sits ``cut_m`` inside the
        narrower of the two faces.
    mu : float
        Friction coefficient of every joint; ``inf`` disables the sliding check.

    Attributes
    ----------
    n : int
        Number of blocks (= joints).
    half_width_m : ndarray (n,)
        Pivot offset from the joint centre, ``min(b_below, b_above)/2 - cut``, m.
    """

    blocks: tuple
    cut_m: tuple | float = 0.0
    mu: float = math.inf

    def __post_init__(self):
        blocks = tuple(self.blocks)
        if not blocks:
            raise InputError("blocks: a column needs at least one block; give e.g. --blocks 0.1x0.2")
        for i, b in enumerate(blocks):
            if not isinstance(b, Block):
                raise InputError(f"blocks[{i}]={b!r}: must be a rocklab.Block")
        object.__setattr__(self, "blocks", blocks)
        cut = (
            np.broadcast_to(np.asarray(self.cut_m, float), (len(blocks),)).copy()
            if np.ndim(self.cut_m) == 0
            else np.asarray(self.cut_m, float)
        )
        if cut.shape != (len(blocks),):
            raise InputError(f"cut_m has {cut.size} values for {len(blocks)} joints; give one per joint or one for all")
        for j, c in enumerate(cut):
            lim = min(blocks[j].b_m, blocks[j - 1].b_m if j else np.inf) / 2
            if not (np.isfinite(c) and 0 <= c < lim):
                raise InputError(f"cut_m[{j}]={c}: cut edge must be in [0, {lim:g}) m (half the joint width)")
        object.__setattr__(self, "cut_m", tuple(float(c) for c in cut))
        mu = float(self.mu)
        if not mu > 0:
            raise InputError(f"mu={self.mu!r}: friction coefficient must be positive (inf disables sliding)")
        object.__setattr__(self, "mu", mu)

    @classmethod
    def uniform(
        cls, b_m: float, H_m: float, n: int, mass_kg: float | None = None, cut_m: float = 0.0, mu: float = math.inf
    ) -> "Column":
        """``n`` equal blocks of width ``b_m`` and total height ``H_m`` (m); ``mass_kg`` per block."""
        if int(n) < 1:
            raise InputError(f"n={n}: number of blocks must be >= 1")
        return cls(tuple(Block(b_m, H_m / int(n), mass_kg=mass_kg) for _ in range(int(n))), cut_m, mu)

    @property
    def n(self) -> int:
        return len(self.blocks)

    @property
    def half_width_m(self) -> np.ndarray:
        b = np.array([blk.b_m for blk in self.blocks])
        lower = np.concatenate([[np.inf], b[:-1]])
        return np.minimum(b, lower) / 2 - np.asarray(self.cut_m)

    @property
    def height_m(self) -> float:
        return float(sum(b.h_m for b in self.blocks))

    def block_array(self) -> np.ndarray:
        """Packed parameters ``(n, 5)``: m kg, I_G kg m², h m, h/2 m, pivot half-width m."""
        out = np.empty((self.n, 5))
        for i, b in enumerate(self.blocks):
            out[i] = (b.mass_kg, (b.alpha_I - 1.0) * b.mass_kg * b.R_m**2, b.h_m, b.h_m / 2, 0.0)
        out[:, 4] = self.half_width_m
        return out

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        return {
            "blocks": [b.to_dict() for b in self.blocks],
            "cut_m": [float(x) for x in np.atleast_1d(self.cut_m)],
            "mu": self.mu,
        }


@dataclass(frozen=True)
class ColumnResult:
    """Response of a column.

    Attributes
    ----------
    column : Column
    t_s : ndarray (m,)
        Output times, s: ``k * output_dt_s`` (``output_dt_s = dt_s`` by
        default: every step) and, when the run ends off that grid, the last
        completed step ``k_end * dt_s``. Events fall between them.
    phi_rad, omega_rad_s : ndarray (m, n)
        Joint rotations (block j relative to block j-1, clockwise positive), rad,
        and their rates, rad/s.
    theta_rad : ndarray (m, n)
        Absolute block angles (cumulative sums of ``phi_rad``), rad.
    energy_J : ndarray (m,)
        Kinetic + potential energy relative to the base frame (zero at rest), J.
    kinetic_J : ndarray (m,)
    configurations : DataFrame
        ``t_s, joint, state, event``: every change of a joint's state
        (``closed | cw | ccw``) and why (``start | opening | impact``).
    impacts : DataFrame
        ``t_s, joint, omega_before_rad_s, ke_before_J, ke_after_J, state_after``.
    status : str
        As :func:`rocklab.models.simulate`: ``rest`` (all joints closed and the
        base no longer able to open one), ``rocking`` (still moving at the end),
        ``no_uplift`` (never opened), ``overturned`` (run stops: the centre of
        mass above an opening joint passed its pivot); and for columns
        ``tension`` / ``sliding`` (terminated: the column may disintegrate,
        thesis §3.3), ``capacity`` / ``numerical`` (failures).
    t_status_s : float
        Time of the terminating event (nan if the duration was reached), s.
    message : str
    params : dict
        Solver settings used.
    max_abs_theta_rad : ndarray (n,)
        Peak |θ| per block over EVERY completed integration step (not only the
        stored samples), rad.
    max_abs_phi_rad : ndarray (n,)
        Peak |φ| per joint over every completed step, rad.
    """

    column: Column
    t_s: np.ndarray
    phi_rad: np.ndarray
    omega_rad_s: np.ndarray
    theta_rad: np.ndarray
    energy_J: np.ndarray
    kinetic_J: np.ndarray
    configurations: pd.DataFrame
    impacts: pd.DataFrame
    status: str
    t_status_s: float
    message: str = ""
    params: dict = field(default_factory=dict)
    max_abs_theta_rad: np.ndarray | None = None
    max_abs_phi_rad: np.ndarray | None = None

    def __post_init__(self):
        # results built by hand (no kernel peaks): the peaks of the stored samples
        for name, x in (("max_abs_theta_rad", self.theta_rad), ("max_abs_phi_rad", self.phi_rad)):
            if getattr(self, name) is None:
                x = np.asarray(x)
                peak = np.max(np.abs(x), axis=0) if len(x) else np.full(x.shape[1:], np.nan)
                object.__setattr__(self, name, peak)

    @property
    def overturned(self) -> bool:
        return self.status == "overturned"

    @property
    def block_omega_rad_s(self) -> np.ndarray:
        """Absolute block angular velocities (clockwise positive), rad/s, shape (m, n)."""
        return np.cumsum(self.omega_rad_s, axis=1)

    def joint_sequence(self, threshold_rad: float = 0.005, min_duration_s: float = 0.0) -> list:
        """Opening/closing sequence read from the block angles, as for measured data.

        See :func:`rocklab.models.joint_sequence`; read from the stored samples
        (so at the ``output_dt_s`` resolution); the exact model events are in
        :attr:`configurations`.
        """
        from ._compare import joint_sequence

        return joint_sequence(self.t_s, self.theta_rad, threshold_rad, min_duration_s=min_duration_s)

    def to_frame(self):
        """Time history: ``t_s``, ``theta_<i>_rad``, ``phi_<j>_rad``, ``omega_<j>_rad_s``, ``energy_J``."""
        import pandas as pd

        d = {"t_s": self.t_s}
        for i in range(self.column.n):
            d[f"theta_{i}_rad"] = self.theta_rad[:, i]
        for j in range(self.column.n):
            d[f"phi_{j}_rad"] = self.phi_rad[:, j]
            d[f"omega_{j}_rad_s"] = self.omega_rad_s[:, j]
        d["energy_J"] = self.energy_J
        d["kinetic_J"] = self.kinetic_J
        return pd.DataFrame(d)

    def to_dict(self) -> dict:
        """Summary: status, peak rotations per block, configuration changes, impact count."""
        return {
            "status": self.status,
            "t_status_s": self.t_status_s,
            "message": self.message,
            "n_blocks": self.column.n,
            "max_abs_theta_rad": [
                float(x) for x in (self.max_abs_theta_rad if self.max_abs_theta_rad is not None else ())
            ],
            "n_impacts": int(len(self.impacts)),
            "configurations": [
                {"t_s": float(r.t_s), "joint": int(r.joint), "state": r.state, "event": r.event}
                for r in self.configurations.itertuples()
            ],
            "params": dict(self.params),
            "column": self.column.to_dict(),
        }


def _initial_state(column: Column, theta0, omega0):
    n = column.n
    th = np.zeros(n) if theta0 is None else np.broadcast_to(np.asarray(theta0, float), (n,)).copy()
    om = np.zeros(n) if omega0 is None else np.broadcast_to(np.asarray(omega0, float), (n,)).copy()
    if not (np.all(np.isfinite(th)) and np.all(np.isfinite(om))):
        raise InputError("theta0_rad/omega0_rad_s: initial block angles and rates must be finite")
    phi = np.diff(np.concatenate([[0.0], th]))
    v = np.diff(np.concatenate([[0.0], om]))
    # internal convention is counter-clockwise positive
    phi_i, v_i = -phi, -v
    s = np.sign(phi_i).astype(np.int64)
    for j in range(n):
        if s[j] == 0 and v_i[j] != 0.0:
            s[j] = int(np.sign(v_i[j]))
    return phi_i, v_i, s


def uplift_acc_m_s2(column: Column, g_m_s2: float = G_STD) -> float:
    """Smallest base acceleration (m/s²) that opens a joint of the column at rest.

    The rigid column moves with the base; joint j opens when the thrust of the
    part above it leaves the section: ``|a_g| > g a_j / z_j`` with ``z_j`` the
    height of that part's centre of mass above joint j.
    """
    blk = column.block_array()
    m, h = blk[:, 0], blk[:, 2]
    z_bottom = np.concatenate([[0.0], np.cumsum(h)[:-1]])
    out = math.inf
    for j in range(column.n):
        zc = np.sum(m[j:] * (z_bottom[j:] + h[j:] / 2)) / np.sum(m[j:]) - z_bottom[j]
        out = min(out, g_m_s2 * blk[j, 4] / zc)
    return out


def _quiet_time(column, base, g_m_s2):
    """Last time the base could open or slide the resting column (s); -inf without base."""
    if base is None:
        return -math.inf
    over = np.abs(base.acc_m_s2) > min(uplift_acc_m_s2(column, g_m_s2), column.mu * g_m_s2)
    return float(base.t_s[np.flatnonzero(over)[-1]]) if over.any() else -math.inf


def _stride(output_dt_s, dt_s, n_steps) -> int:
    """Steps per stored sample for ``output_dt_s`` (s); ``n_steps + 1`` stores none in between."""
    if output_dt_s is None:
        return 1
    odt = float(output_dt_s)
    if odt == math.inf:
        return n_steps + 1
    if not (math.isfinite(odt) and odt > 0):
        raise InputError(f"output_dt_s={output_dt_s!r}: must be positive (s), inf, or None for every step")
    k = int(round(odt / dt_s))
    if k < 1 or abs(k * dt_s - odt) > 1e-9 * odt:
        raise InputError(
            f"output_dt_s={odt:g}: must be a whole multiple of dt_s={dt_s:g} s "
            f"(e.g. {max(k, 1) * dt_s:g}), the events stay exact at any spacing"
        )
    return min(k, n_steps + 1)


#: Speed of the compiled column loop used for the time estimate, block-steps/s (measured: 3-block column, 1 core).
COLUMN_BLOCK_STEPS_PER_S = 3e6


def _check_cost(n, duration_s, dt_s, n_float, n_rows):
    """InputError before a column run that would not fit in memory or would take far too long."""
    from ..._errors import check_memory, check_time

    check_memory(
        8.0 * n_rows * (4 * n + 4),
        f"{duration_s:g} s of a {n}-block column at {dt_s:g} s ({n_rows} stored rows)",
        "shorten duration_s or give a coarser output_dt_s",
    )
    check_time(
        n_float * n / COLUMN_BLOCK_STEPS_PER_S,
        f"{duration_s:g} s of a {n}-block column at dt = {dt_s:g} s ({n_float:.3g} steps)",
        "give a coarser dt_s (e.g. 1e-4 s) or a shorter duration_s",
    )


def _event_tables(EVT, EVI, IMP):
    """The kernel's configuration changes and impacts (rows already cut to their counts) as tables."""
    import pandas as pd

    conf = pd.DataFrame(
        {
            "t_s": EVT,
            "joint": EVI[:, 0],
            "state": [STATE_NAMES[int(x)] for x in EVI[:, 1]],
            "event": [_KIND[int(x)] for x in EVI[:, 2]],
        }
    )
    imp = pd.DataFrame(
        {
            "t_s": IMP[:, 0],
            "joint": IMP[:, 1].astype(int),
            "omega_before_rad_s": -IMP[:, 2],
            "ke_before_J": IMP[:, 3],
            "ke_after_J": IMP[:, 4],
            "state_after": [STATE_NAMES[int(x)] for x in IMP[:, 5]],
        }
    )
    return conf, imp


def _final_status(code, t_st, phi, om, never_moved):
    """(status, its time s or NaN, message) from the kernel's status code and the last state."""
    status = _STATUS[code]
    msg = ""
    if status == "end":
        moving = bool(np.any(om[-1] != 0.0)) or bool(np.any(phi[-1] != 0.0))
        status = "rocking" if moving else ("no_uplift" if never_moved else "rest")
        t_st = math.nan
    elif status == "rest" and never_moved:
        status = "no_uplift"
    elif status in ("tension", "sliding"):
        msg = f"terminated at t={t_st:.6g} s: {status} at a joint (the column may disintegrate)"
    elif status in ("capacity", "numerical"):
        msg = f"integration failed at t={t_st:.6g} s ({status}); reduce dt_s or check the input"
    return status, t_st, msg


def simulate_column(
    column: Column,
    base: BaseMotion | None = None,
    *,
    theta0_rad=None,
    omega0_rad_s=None,
    duration_s: float | None = None,
    dt_s: float = 1e-4,
    n_impacts: int = 1,
    velocity_terms: bool = True,
    max_enum_closed: int = 9,
    stop_at_rest: bool = True,
    overturn_angle_rad: float | None = None,
    rest_omega_rad_s: float = 1e-6,
    g_m_s2: float = G_STD,
    output_dt_s: float | None = None,
    jit: bool = True,
) -> ColumnResult:
    """Simulate a multi-block column under gravity and a horizontal base acceleration.

    Parameters
    ----------
    column : Column
    base : BaseMotion, optional
        Horizontal base acceleration (m/s², positive to the right); zero after
        its last sample. None: free rocking from ``theta0_rad``.
    theta0_rad, omega0_rad_s : float or array (n,), optional
        Initial absolute block angles (rad, clockwise positive) and rates (rad/s).
    duration_s : float, optional
        End time, s; default: the record's end + 5 s (or 10 s without a record).
    dt_s : float
        Time step, s (Newmark trapezoidal, events located inside the step).
    n_impacts : int
        Consecutive impacts per closing (1 = Housner; 2 = one mid-joint bump, the
        thesis's recommendation; k: k-1 evenly spaced bumps).
    velocity_terms : bool
        Include the centripetal terms of the App. C reduction (exact rigid-body
        dynamics). False reproduces the thesis's ``M̃(φ) φ̈ = p̃(φ)``.
    max_enum_closed : int
        Largest number of closed joints for which all configurations are
        enumerated at an opening or impact (thesis: 9); beyond it the most
        loaded joint opens alone (opening) or only the closing joint's options
        are tried (impact).
    stop_at_rest : bool
        Stop when every joint is closed after the record has ended.
    overturn_angle_rad : float, optional
        If given, overturning = any |block angle| beyond it; default: the centre
        of mass above an open joint passes its pivot while the joint opens.
    rest_omega_rad_s : float
        Post-impact joint rates below this close the joint (ends the accumulation
        of ever smaller impacts), rad/s.
    output_dt_s : float, optional
        Spacing of the stored time history, s: a whole multiple of ``dt_s``
        keeps every k-th step (plus the last completed step when the run ends
        between two samples). Default None: every step, as ``dt_s`` (20 s at
        1e-4 s = 200 001 rows). ``math.inf``: only the initial and the final
        state. The integration, the events (``configurations``, ``impacts``),
        ``status``, ``t_status_s`` and the peaks ``max_abs_theta_rad`` /
        ``max_abs_phi_rad`` do not depend on it (taken from every step); the
        stored samples equal the full history's at the shared times.
    jit : bool
        Use the compiled loop (False: pure Python, slow; the benchmark baseline).

    Returns
    -------
    ColumnResult
    """
    from ._core import run_core, run_core_jit

    duration_s, (phi0, v0, s0) = _checked_start(column, base, theta0_rad, omega0_rad_s, duration_s, dt_s, n_impacts)
    accb, t0b, dtb = _base_samples(base)
    n_float = duration_s / dt_s
    n_steps = int(math.ceil(n_float - 1e-9))
    stride = _stride(output_dt_s, dt_s, n_steps)
    n_rows = n_steps // stride + 2
    _check_cost(column.n, duration_s, dt_s, n_float, n_rows)
    par = np.array(
        [g_m_s2, column.mu, t0b, dtb, 1.0 if velocity_terms else 0.0, 1e-14, _quiet_time(column, base, g_m_s2), 0.0]
    )
    ovt = float(overturn_angle_rad) if overturn_angle_rad else -1.0
    head = (
        phi0,
        v0,
        s0,
        column.block_array(),
        par,
        accb,
        n_steps,
        float(dt_s),
        int(max_enum_closed),
        int(n_impacts),
        float(rest_omega_rad_s),
        bool(stop_at_rest),
        ovt,
        stride,
    )
    run = _run_kernel(run_core_jit if jit else run_core, head, n_rows, column.n, stride, dt_s)
    params = dict(
        dt_s=dt_s,
        output_dt_s=float(dt_s if output_dt_s is None else output_dt_s),
        duration_s=float(duration_s),
        n_impacts=int(n_impacts),
        velocity_terms=bool(velocity_terms),
        max_enum_closed=int(max_enum_closed),
        overturn_angle_rad=overturn_angle_rad,
        g_m_s2=g_m_s2,
        rest_omega_rad_s=rest_omega_rad_s,
        base=None if base is None else base.name,
    )
    return _column_result(column, run, params)


def _checked_start(column, base, theta0_rad, omega0_rad_s, duration_s, dt_s, n_impacts):
    """(duration s, (joint angles, rates, signs)) of a run whose inputs are checked; InputError otherwise."""
    if not isinstance(column, Column):
        raise InputError("column: must be a rocklab.models.Column")
    if not (math.isfinite(dt_s) and dt_s > 0):
        raise InputError(f"dt_s={dt_s!r}: time step must be positive (s)")
    if int(n_impacts) < 1:
        raise InputError(f"n_impacts={n_impacts}: number of consecutive impacts must be >= 1")
    if base is not None and not isinstance(base, BaseMotion):
        raise InputError("base: must be a BaseMotion (see rocklab.models.load_base_motion)")
    if duration_s is None:
        duration_s = (float(base.t_s[-1]) + 5.0) if base is not None else 10.0
    if not (math.isfinite(duration_s) and duration_s > 0):
        raise InputError(f"duration_s={duration_s!r}: must be positive (s)")
    from ..rocking import check_step

    check_step(max(b.p_rad_s for b in column.blocks), dt_s, "dt_s")
    phi0, v0, s0 = _initial_state(column, theta0_rad, omega0_rad_s)
    for j, b in enumerate(column.blocks):  # each joint opens by less than its block's slenderness
        if abs(phi0[j]) >= b.alpha_rad:
            raise InputError(
                f"theta0_rad: block {j + 1} starts {abs(phi0[j]):.4g} rad open against the one "
                f"below, not < its alpha = {b.alpha_rad:.4g} rad (it would fall at release); "
                "give smaller initial angles"
            )
    return duration_s, (phi0, v0, s0)


def _base_samples(base):
    """(acceleration m/s², first time s, step s) of the base record as the kernel reads them."""
    if base is None:
        return np.zeros(0), 0.0, 1.0
    # writable: numba types read-only arrays apart
    return np.array(base.acc_m_s2, dtype=float), float(base.t_s[0]), base.dt_s


@dataclass(frozen=True)
class _KernelRun:
    """What the column loop returned, cut to its counts, in the clockwise-positive convention."""

    t_s: np.ndarray  # (rows,) s
    phi: np.ndarray  # (rows, n) joint angles, rad
    om: np.ndarray  # (rows, n) joint rates, rad/s
    en: np.ndarray  # (rows, 2) kinetic and potential energy, J
    conf: object  # configuration changes (DataFrame)
    imp: object  # impacts (DataFrame)
    code: int
    t_status_s: float
    peak: np.ndarray  # (2, n) max |theta| and |phi|, rad


def _run_kernel(fn, head, n_rows, n, stride, dt_s):
    """Run the compiled loop ``fn(*head, ...)``, growing the event tables tenfold while they overflow."""
    ecap = 20000
    PHI = np.empty((n_rows, n))
    VEL = np.empty((n_rows, n))
    EN = np.empty((n_rows, 2))
    PEAK = np.full((2, n), np.nan)  # stays nan when the run fails before its first sample
    while True:
        EVT = np.empty(ecap)
        EVI = np.empty((ecap, 3), np.int64)
        IMP = np.empty((ecap, 6))
        nr, ne, ni, st, t_st, k_last = fn(*head, PHI, VEL, EN, EVT, EVI, IMP, PEAK)
        if st != 5 or ecap >= 5_000_000:
            break
        ecap *= 10
    conf, imp = _event_tables(EVT[:ne], EVI[:ne], IMP[:ni])
    t = (np.arange(nr) * stride) * dt_s  # the full history's k * dt_s, bit for bit
    t[nr - 1 :] = k_last * dt_s
    return _KernelRun(t, -PHI[:nr], -VEL[:nr], EN[:nr], conf, imp, int(st), t_st, PEAK)


def _column_result(column, run, params):
    """The ColumnResult of a kernel run: its history, events and final status (``params``: the run's options)."""
    status, t_st, msg = _final_status(run.code, run.t_status_s, run.phi, run.om, len(run.conf) == 0)
    return ColumnResult(
        column=column,
        t_s=run.t_s,
        phi_rad=run.phi,
        omega_rad_s=run.om,
        theta_rad=np.cumsum(run.phi, axis=1),
        energy_J=run.en.sum(axis=1),
        kinetic_J=run.en[:, 0].copy(),
        configurations=run.conf,
        impacts=run.imp,
        status=status,
        t_status_s=float(t_st),
        message=msg,
        params=params,
        max_abs_theta_rad=run.peak[0].copy(),
        max_abs_phi_rad=run.peak[1].copy(),
    )
