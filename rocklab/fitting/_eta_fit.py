"""Constant-restitution calibration of a measured free-rocking record (Čeh §5.1).

``fit_restitution`` finds the η_e whose simulation (same block, θ0 from the data,
thread-burn release at a fitted time) best matches θ(t): by least squares on θ in a
window chosen by impact count (default: the middle 50 % of the response, as Čeh judged
amplitudes and periods), or by matching arch amplitudes and half-periods. η′_e is the
same θ fit on the first post-impact half-period only, with the release taken from the
plateau and release quarter-cycle.

Search: the θ objective over many cycles is multimodal in η (a wrong η slips whole
half-cycles), so η is first located with the amplitude/half-period objective around the
median per-impact η of the data, then refined on θ (coarse grid, bounded Brent).

Uncertainty: a profile-likelihood interval. For each η the release time and θ0 are
re-fitted (profiled out) and the 95 % interval is where SSE(η) − SSE_min ≤
χ²₁(0.95)·σ̂²·f, with σ̂² = SSE_min/(n − 4) and f = (1 + ρ₁)/(1 − ρ₁) ≥ 1 a correction
for lag-one autocorrelation ρ₁ of the window residuals (f = 1 for white measurement
noise; model misfit widens the interval instead of hiding in it). Checked: 48/50
synthetic B6M runs covered at 0.02° noise. For the "peaks" objective the same rule is
applied to the rad-scaled amplitude/time residuals, which makes it conservative.

Structure: :func:`fit_restitution` is a driver (check the arguments, :func:`_prepare` the
record, fit, interval, warnings, result); the search state lives in one problem object,
:class:`_EtaSearch` (record, release, impacts, windows, start values; lmfit's
``Minimizer`` is the model), whose :meth:`~_EtaSearch.fit` and :meth:`~_EtaSearch.fit_first`
give η_e and η′_e.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
import pandas as pd
from scipy.stats import chi2

from .._diagnostics import warn
from .._errors import InputError
from ..blocks import is_lab_size
from ..config import FIT_WINDOWS
from ._impacts import zero_crossings, arch_peaks, check_record, per_impact_eta
from ._release import settle_release
from ._fit_checks import RESIDUAL_FACTOR, RESIDUAL_FLOOR_RAD, cut_at_gap, suspicion
from ._simfit import ac_factor, grid_then_brent, Problem, profile_ci

__all__ = ["RestitutionFit", "fit_restitution", "WINDOWS", "OBJECTIVES"]

WINDOWS = FIT_WINDOWS
OBJECTIVES = ("theta", "peaks")


@dataclass(frozen=True)
class RestitutionFit:
    """Result of :func:`fit_restitution`.

    Attributes
    ----------
    eta_e : float
        Fitted constant restitution (ω⁺/ω⁻), NaN if the fit failed.
    eta_e_first : float
        η′_e fitted on the first post-impact half-period only (Čeh §5.1).
    ci95_eta_e : tuple (lo, hi)
        95 % profile-likelihood interval of η_e (see module doc).
    theta0_rad : float
        Initial angle, rad (sign as measured, relative to the fitted level when
        ``fit_offset``): profiled with the release time over the rest plateau and the
        fitted samples.
    release_t_s : float
        Fitted release time, s (record clock).
    rms_residual_rad : float
        RMS of θ_data − θ_sim over the fitted window (objective "theta") or of the
        amplitude/half-period residuals in rad (objective "peaks").
    sigma_theta_rad : float
        Measurement noise σ estimated on the rest plateau, rad.
    theta_offset_rad : float
        Fitted constant offset of the measured angle (0 unless ``fit_offset``), rad.
    per_impact_eta : tuple of float
        Per-impact restitution from the data alone (``eta_peaks``, see
        :func:`~rocklab.fitting.per_impact_eta`); the full table is ``per_impact``.
    n_impacts : int
        Impacts detected in the record.
    window : str, objective : str
    window_t_s : tuple (t0, t1)
        Fitted window on the record clock, s.
    n_points : int
        Residuals in the objective.
    eta_bounds : tuple
        Search bounds; ``at_bound`` lists parameters that ended on one.
    suspicious : bool
        True when slip/jump/misfit symptoms were found; ``flags`` says which.
    n_skipped : int
        NaN samples dropped (``nan="skip"``).
    n_evaluations : int
        Simulations run by the fit.
    per_impact : DataFrame
        Full :func:`~rocklab.fitting.per_impact_eta` table (not in ``to_dict``).
    status : "ok" | "suspect" | "failed";  message : reason when failed, notes otherwise
    warnings : tuple of str
        Codes of the plausibility warnings the fit raised (W-FIT-GAP, W-FIT-THETA0, W-FIT-BOUND).
    """

    eta_e: float
    eta_e_first: float
    ci95_eta_e: tuple
    theta0_rad: float
    release_t_s: float
    rms_residual_rad: float
    sigma_theta_rad: float
    per_impact_eta: tuple
    n_impacts: int
    window: str
    objective: str
    window_t_s: tuple
    n_points: int
    eta_bounds: tuple
    theta_offset_rad: float = 0.0
    block_name: str = ""
    suspicious: bool = False
    flags: tuple = ()
    at_bound: tuple = ()
    n_skipped: int = 0
    n_evaluations: int = 0
    status: str = "ok"
    message: str = ""
    per_impact: pd.DataFrame | None = field(default=None, repr=False)
    warnings: tuple = ()

    @property
    def ok(self) -> bool:
        """True when the fit produced a value (status ``"ok"``, or ``"suspect"`` with warnings)."""
        return self.status in ("ok", "suspect")

    def to_dict(self) -> dict:
        """Plain-JSON dict (NaN kept as float NaN; the CLI writes null)."""
        d = {
            k: getattr(self, k)
            for k in (
                "eta_e",
                "eta_e_first",
                "theta0_rad",
                "release_t_s",
                "rms_residual_rad",
                "sigma_theta_rad",
                "theta_offset_rad",
                "n_impacts",
                "window",
                "objective",
                "n_points",
                "block_name",
                "suspicious",
                "n_skipped",
                "n_evaluations",
                "status",
                "message",
            )
        }
        d["warnings"] = list(self.warnings)
        d["ci95_eta_e"] = [float(x) for x in self.ci95_eta_e]
        d["window_t_s"] = [float(x) for x in self.window_t_s]
        d["eta_bounds"] = [float(x) for x in self.eta_bounds]
        d["per_impact_eta"] = [float(x) for x in self.per_impact_eta]
        d["flags"] = list(self.flags)
        d["at_bound"] = list(self.at_bound)
        return d

    def report(self) -> str:
        """lmfit-style text report."""
        if not self.ok:
            return f"[[Restitution fit: FAILED]]\n    {self.message}"
        lo, hi = self.ci95_eta_e
        ab = set(self.at_bound)

        def b(name):
            return "  (at bound!)" if name in ab else ""

        lines = [
            "[[Fit Statistics]]",
            "    # fitting method   = peaks start, grid + bounded Brent on eta; release time and theta0 profiled",
            f"    # simulations      = {self.n_evaluations}",
            f"    # data points      = {self.n_points}",
            f"    # impacts (data)   = {self.n_impacts}",
            f"    window             = {self.window} ({self.window_t_s[0]:.3f}-{self.window_t_s[1]:.3f} s)",
            f"    objective          = {self.objective}",
            f"    residual RMS       = {self.rms_residual_rad:.3e} rad ({math.degrees(self.rms_residual_rad):.4f} deg)",
            f"    noise sigma        = {self.sigma_theta_rad:.3e} rad (rest plateau)",
            "[[Variables]]",
            f"    eta_e:        {self.eta_e:.5f}  95% CI [{lo:.5f}, {hi:.5f}] (profile likelihood){b('eta_e')}",
            f"    eta_e_first:  {self.eta_e_first:.5f}  (first post-impact half-period){b('eta_e_first')}",
            f"    release_t_s:  {self.release_t_s:.5f}{b('release_t_s')}",
            f"    theta0_rad:   {self.theta0_rad:.5f}  (profiled: rest plateau + motion)",
            f"    theta_offset: {self.theta_offset_rad:.2e} rad" + ("" if self.theta_offset_rad else " (not fitted)"),
            f"    search bounds eta in [{self.eta_bounds[0]:g}, {self.eta_bounds[1]:g}]",
        ]
        if len(self.per_impact_eta):
            pe = np.asarray(self.per_impact_eta, float)
            lines.append(f"[[Per-impact eta (peaks)]]  n = {pe.size}, first: " + ", ".join(f"{x:.4f}" for x in pe[:6]))
        if self.flags:
            lines.append("[[Warnings]]")
            lines += [f"    {f}" for f in self.flags]
        if self.message:
            lines.append(f"note: {self.message}")
        return "\n".join(lines)


def _failed(reason, window, objective, bounds, theta0=np.nan, sigma=np.nan, n_imp=0, n_skip=0, name=""):
    nan = float("nan")
    return RestitutionFit(
        eta_e=nan,
        eta_e_first=nan,
        ci95_eta_e=(nan, nan),
        theta0_rad=float(theta0),
        release_t_s=nan,
        rms_residual_rad=nan,
        sigma_theta_rad=float(sigma),
        per_impact_eta=(),
        n_impacts=int(n_imp),
        window=window,
        objective=objective,
        window_t_s=(nan, nan),
        n_points=0,
        eta_bounds=tuple(bounds),
        block_name=name,
        n_skipped=n_skip,
        status="failed",
        message=reason,
    )


class _MainFit(NamedTuple):
    """The main-window fit of :meth:`_EtaSearch.fit`."""

    eta: float
    sse: float
    objective: Callable[[float], float]
    release_t_s: float
    theta0_rad: float
    offset_rad: float
    residuals: np.ndarray
    window_residuals: np.ndarray


class _EtaSearch:
    """The η search on one measured record: data, release, impacts, windows and settings.

    The problem object of :func:`fit_restitution` (lmfit's ``Minimizer`` is the model: it
    holds what every objective needs, and :meth:`fit_window` is its ``minimize``). θ is
    sign-normalised (θ0 > 0); ``g`` is the start of the search, ``theta0`` the angle the
    simulations are linearised about (both re-centred by :meth:`recentre` when an offset
    is fitted). Simulation problems (:class:`~rocklab.fitting._simfit._Problem`) are built
    per window on first use and counted in :attr:`n_evaluations`.
    """

    def __init__(self, t, y, block, rel, tc, pie, theta0, dt_sim, sigma, bounds, eta_guess, fit_offset):
        self.t, self.y, self.block, self.rel, self.tc = t, y, block, rel, tc
        self.theta0, self.dt_sim, self.sigma = theta0, dt_sim, sigma
        self.lo_b, self.hi_b = bounds
        self.fit_offset = fit_offset
        dt_data = float(np.median(np.diff(t)))
        # plateau and release quarter-cycle: fix θ0 and the release time, independent of η
        self.rel_idx = np.flatnonzero(t < tc[0])
        self.tr_bounds = (rel.t_s - 4 * dt_data, rel.t_s + 3 * dt_data)
        ok_eta = pie.loc[pie["ok"], "eta_peaks"].to_numpy() if len(pie) else np.array([])
        g = float(np.median(ok_eta)) if ok_eta.size else float(block.eta_H)
        self.g = min(max(g if eta_guess is None else float(eta_guess), self.lo_b), self.hi_b)
        e0 = float(pie["eta_peaks"].iloc[0]) if len(pie) else float("nan")
        self.g_first = min(max(e0, self.lo_b), self.hi_b) if np.isfinite(e0) and eta_guess is None else self.g
        self._probs = {}

    @property
    def n_evaluations(self) -> int:
        """Simulations run so far."""
        return sum(q.n_sim for q in self._probs.values())

    def recentre(self, theta0, g):
        """Linearise about ``theta0`` and start from ``g`` (the simulation problems are rebuilt)."""
        self.theta0, self.g = theta0, g
        self._probs.clear()

    def window_span(self, kind):
        """(t0, t1) of window ``kind`` on the record clock, s."""
        tc, n_imp = self.tc, self.tc.size
        if kind == "all":
            return self.rel.t_s, tc[-1] + (tc[-1] - tc[-2])
        if kind == "first":
            return tc[0], tc[1]
        i0 = int(math.floor(0.25 * n_imp))
        i1 = int(math.ceil(0.75 * n_imp)) - 1
        i1 = min(max(i1, i0 + 2), n_imp - 1)
        return tc[i0], tc[i1]

    def problem(self, kind):
        """The simulation problem of window ``kind`` (built once per linearisation)."""
        if kind not in self._probs:
            b = self.window_span(kind)[1]
            self._probs[kind] = Problem(
                self.t,
                self.y,
                self.block,
                self.theta0,
                self.dt_sim,
                max(b, self.tc[1]) - self.rel.t_s + 0.2,
                offset=self.fit_offset,
            )
        return self._probs[kind]

    def peaks_objective(self, kind, prob):
        """SSE of arch amplitudes and half-periods in window ``kind`` as a function of η, and its data."""
        a, b = self.window_span(kind)
        tc = self.tc
        pk = arch_peaks(self.t, self.y, tc, release=None, sigma_rad=self.sigma)  # row k: arch after impact k
        ids = [
            k
            for k in range(len(pk))
            if a - 1e-9 <= tc[k] and tc[k + 1] <= b + 1e-9 and np.isfinite(pk.theta_rad.iloc[k])
        ]
        amp = np.abs(pk.theta_rad.to_numpy())[ids]
        half = np.diff(tc)[ids]

        def f(eta):
            r = prob.peaks_residual(eta, amp, half, ids)
            return float(r @ r)

        return f, (np.asarray(ids, int), amp, half)

    def search(self, f_grid, f, center, span, max_span=1.0):
        """Grid around ``center`` (widened while the best node is on its edge), then Brent; (η, f)."""
        lo_b, hi_b = self.lo_b, self.hi_b
        while True:
            lo, hi = max(lo_b, center - span), min(hi_b, center + span)
            x, fx, on_edge = grid_then_brent(f_grid, f, lo, hi)
            on_edge = on_edge and ((x - lo < 0.5 * span and lo > lo_b) or (hi - x < 0.5 * span and hi < hi_b))
            if not on_edge or span >= max_span:
                return x, fx
            span *= 3.0

    def fit_window(self, kind, obj, fixed=None):
        """Fit η on a window: ``(η, f(η), f, residual index, problem)``.

        ``fixed=(t_r, θ0, offset)`` holds the release fixed (the cheap η′_e fit).
        """
        t, tc = self.t, self.tc
        a, b = self.window_span(kind)
        prob = self.problem(kind)
        if obj == "peaks":
            f, idx = self.peaks_objective(kind, prob)
            x, fx = self.search(f, f, self.g, 0.025)
            return x, fx, f, idx, prob
        idx = np.union1d(self.rel_idx, np.flatnonzero((t >= a) & (t <= b)))
        tr_bounds = self.tr_bounds
        if fixed is not None:

            def f(eta):
                d = prob.residual(eta, idx, *fixed, sens=False)
                return float(d @ d)

            x, fx = self.search(f, f, self.g_first if kind == "first" else self.g, 0.025)
            return x, fx, f, idx, prob

        def f(eta):
            return prob.profile(eta, idx, tr_bounds)[0]

        def f_grid(eta):  # grid nodes only bracket the optimum: θ0 held, no sensitivity run
            return prob.profile(eta, idx, tr_bounds, sens=False)[0]

        # θ(t) over many cycles is multimodal in η (a wrong η slips whole half-cycles), so
        # start from the amplitude/half-period objective, which is not, and search narrowly
        n_win = int(np.sum((tc >= a) & (tc <= b)))
        if n_win >= 3:
            fp, _ = self.peaks_objective(kind, prob)
            center = self.search(fp, fp, self.g, 0.025)[0]
            x, fx = self.search(f_grid, f, center, 0.003, max_span=0.03)
        else:
            x, fx = self.search(f_grid, f, self.g, 0.025)
        return x, fx, f, idx, prob

    def fit(self, window, objective):
        """η on the main window: ``(η, f(η), f, release s, θ0 rad, offset rad, residuals, window residuals)``.

        With a fitted offset the θ0 linearisation is re-centred and the fit repeated (θ0
        enters linearly about the plateau level, and an offset moves it by far more than the
        noise: outer Gauss-Newton steps).
        """
        eta, f_eta, f, idx, prob = self.fit_window(window, objective)
        if objective != "theta":
            _, tr, theta0, offset = self.release_fit(eta)
            ids, amp, half = idx
            res = prob.peaks_residual(eta, amp, half, list(ids))
            return _MainFit(eta, f_eta, f, tr, theta0, offset, res, res)
        _, tr, theta0, offset = prob.profile(eta, idx, self.tr_bounds)
        for _ in range(4 if self.fit_offset else 0):
            if abs(theta0 - self.theta0) < 2e-6:
                break
            self.recentre(theta0, eta)
            eta, f_eta, f, idx, prob = self.fit_window(window, objective)
            _, tr, theta0, offset = prob.profile(eta, idx, self.tr_bounds)
        res = prob.residual(eta, idx, tr, theta0, offset)
        return _MainFit(eta, f_eta, f, tr, theta0, offset, res, res[self.t[idx] >= self.window_span(window)[0]])

    def fit_first(self, eta, offset):
        """η′_e: the θ fit of the first post-impact half-period with the release held.

        Release and θ0 come from the plateau and release quarter-cycle only (η-independent),
        so that a misfit of the main window (η changing during rocking) cannot leak into η′_e;
        with a fitted offset the plateau level θ0 + c is kept and the main fit's ``offset`` taken.
        """
        _, tr_1, th0_1, c_1 = self.release_fit(eta)
        fixed = (tr_1, th0_1 + c_1 - offset, offset) if self.fit_offset else (tr_1, th0_1, 0.0)
        return self.fit_window("first", "theta", fixed=fixed)[0]

    def at_bound(self, eta, eta_first, release_t_s):
        """Names of the fitted parameters that ended on a bound of their search."""
        lo_b, hi_b, tr_bounds = self.lo_b, self.hi_b, self.tr_bounds
        out = []
        if min(eta - lo_b, hi_b - eta) < 1e-4:
            out.append("eta_e")
        if min(eta_first - lo_b, hi_b - eta_first) < 1e-4:
            out.append("eta_e_first")
        if min(release_t_s - tr_bounds[0], tr_bounds[1] - release_t_s) < 1e-6:
            out.append("release_t_s")
        return out

    def suspicion(self, offset, residuals, rms, pie):
        """Slip/jump/misfit flags of the fit (:func:`~rocklab.fitting._fit_checks._suspicion`)."""
        return suspicion(self.t, self.y - offset, residuals, rms, self.sigma, pie, self.tc, self.block.alpha_rad)

    def release_fit(self, eta):
        """(SSE, release time s, θ0 rad, offset rad) from the plateau and release quarter-cycle only."""
        return self.problem("first").profile(eta, self.rel_idx, self.tr_bounds)


def _prepare(t_s, theta_rad, block, window, objective, bounds, dt_s, nan, eta_guess, theta0_rad, fit_offset):
    """Record checks, release, impacts and warnings: ``(search, diags, s0, n_skip)`` or a failed fit."""
    lo_b, hi_b = bounds
    t, y, n_skip = check_record(t_s, theta_rad, nan=nan)
    name = getattr(block, "name", "")
    p = block.p_rad_s
    dt_sim = float(dt_s) if dt_s is not None else min(2e-4, 2e-3 / p)
    rel, undecided = settle_release(t, y, block, dt_sim)
    fail = dict(window=window, objective=objective, bounds=(lo_b, hi_b), n_skip=n_skip, name=name)
    if not rel.found:
        return _failed(f"no release found: {rel.message}", theta0=rel.theta0_rad, sigma=rel.sigma_rad, **fail)
    diags = []
    if not is_lab_size(block.b_m, block.h_m):
        diags.append(
            warn(
                "W-FIT-UNITS",
                f"{name or 'block'}: b = {block.b_m:.4g} m, h = {block.h_m:.4g} m "
                f"(h/b = {block.h_m / block.b_m:.4g}) is not a rocking block in metres; "
                "check units and order",
            )
        )
    # from the last sample at rest: a gap that swallows the release (placed between samples) still counts
    t, y, gap_diag = cut_at_gap(t, y, min(rel.t_s, t[max(rel.n_plateau - 1, 0)]), rel.sigma_rad)
    if gap_diag is not None:
        diags.append(gap_diag)
    s0 = 1.0 if rel.theta0_rad > 0 else -1.0
    y = s0 * y  # symmetric block: fit with θ0 > 0
    theta0 = abs(rel.theta0_rad) if theta0_rad is None else abs(float(theta0_rad))
    alpha = block.alpha_rad
    if theta0 >= alpha:
        return _failed(
            f"theta0 = {theta0:.4g} rad >= alpha = {alpha:.4g} rad: the block would overturn, "
            "not rock (check b and h: swapped, or not in metres?)",
            theta0=rel.theta0_rad,
            sigma=rel.sigma_rad,
            **fail,
        )
    if theta0 > 0.9 * alpha:
        diags.append(
            warn(
                "W-FIT-THETA0",
                f"{name or 'block'}: measured theta0 = {theta0:.4g} rad is "
                f"{theta0 / alpha:.3f} alpha (alpha = {alpha:.4g} rad from b = "
                f"{block.b_m:.4g} m, h = {block.h_m:.4g} m); check b and h",
            )
        )
    if undecided is not None:
        diags.append(warn("W-FIT-RELEASE", f"{name or 'block'}: {undecided}"))
    tc = zero_crossings(t, y, rel)
    n_imp = int(tc.size)
    if n_imp < 3:
        return _failed(
            f"only {n_imp} impact(s) detected after release: need at least 3",
            theta0=rel.theta0_rad,
            sigma=rel.sigma_rad,
            n_imp=n_imp,
            **fail,
        )
    sigma = max(rel.sigma_rad, 1e-12)
    rel_info = rel.__class__(**{**rel.__dict__, "theta0_rad": theta0})
    pie = per_impact_eta(t, y, block, release=rel_info, crossings_t_s=tc)
    search = _EtaSearch(t, y, block, rel, tc, pie, theta0, dt_sim, sigma, (lo_b, hi_b), eta_guess, fit_offset)
    return search, diags, s0, n_skip, pie


def _residual_warning(name, block, rms, sigma_rad):
    """W-FIT-RESIDUAL when the fitted simulation misses the measurement by far more than the noise."""
    noise = max(sigma_rad, RESIDUAL_FLOOR_RAD)
    if not (np.isfinite(rms) and rms > RESIDUAL_FACTOR * noise):
        return []
    return [
        warn(
            "W-FIT-RESIDUAL",
            f"{name or 'block'}: the fitted simulation misses the measurement by "
            f"{rms:.4g} rad RMS, {rms / noise:.4g}x the noise "
            f"({noise:.4g} rad); check b = {block.b_m:.4g} m, h = "
            f"{block.h_m:.4g} m and the contact type",
        )
    ]


def _bound_warnings(name, at_bound, ci, lo_b, hi_b):
    """W-FIT-BOUND when η_e or η′_e, or the interval of η_e, reaches the search bounds."""
    eta_at_bound = [b for b in at_bound if b.startswith("eta")]  # the release time's bound is a sample
    if eta_at_bound:
        return [
            warn(
                "W-FIT-BOUND",
                f"{name or 'block'}: {', '.join(eta_at_bound)} at the bound of the search "
                f"(eta in [{lo_b:g}, {hi_b:g}])",
            )
        ]
    if np.isfinite(ci[0]) and min(ci[0] - lo_b, hi_b - ci[1]) < 1e-4:
        # a flat profile: the window's data do not pin eta_e down (seen on a 13 s film whose middle
        # half is millimetre rocking under tracking noise: [0.05, 0.968] reported as ok)
        return [
            warn(
                "W-FIT-BOUND",
                f"{name or 'block'}: the 95 % interval of eta_e, [{ci[0]:.4g}, {ci[1]:.4g}], "
                f"reaches the bound of the search (eta in [{lo_b:g}, {hi_b:g}]): the "
                'window\'s data do not constrain eta_e; fit window = "first" or a '
                "shorter record",
            )
        ]
    return []


def _check_options(window, objective, eta_bounds):
    """The fit's choices are known ones and its search interval lies in (0, 1); returns (lo, hi)."""
    if window not in WINDOWS:
        raise InputError(f"window={window!r}: use one of {WINDOWS}")
    if objective not in OBJECTIVES:
        raise InputError(f"objective={objective!r}: use one of {OBJECTIVES}")
    lo_b, hi_b = (float(x) for x in eta_bounds)
    if not (0 < lo_b < hi_b < 1):
        raise InputError(f"eta_bounds={eta_bounds}: need 0 < lo < hi < 1 (a restitution >= 1 gains energy)")
    return lo_b, hi_b


def _interval(f_main, eta_hat, f_hat, dof, win_res, level, bounds):
    """Profile-likelihood confidence interval of eta at ``level``: the cost ``f_main(eta)`` rises by the
    chi-square quantile times the residual variance (``f_hat`` over ``dof`` degrees of freedom),
    inflated for the window residuals' autocorrelation."""
    s2 = f_hat / max(dof, 1)
    thresh = float(chi2.ppf(level, 1)) * s2 * ac_factor(win_res)
    return profile_ci(f_main, eta_hat, f_hat, thresh, *bounds)


def fit_restitution(
    t_s,
    theta_rad,
    block,
    window: str = "middle50",
    objective: str = "theta",
    *,
    eta_bounds=(0.05, 0.9995),
    dt_s: float | None = None,
    nan: str = "raise",
    level: float = 0.95,
    eta_guess: float | None = None,
    theta0_rad: float | None = None,
    fit_offset: bool = False,
) -> RestitutionFit:
    """Fit a constant restitution η_e to a measured free-rocking record.

    Parameters
    ----------
    t_s, theta_rad : array (n,)
        Record times (s, increasing) and rotation (rad), including a rest plateau before
        the thread-burn release (the plateau gives θ0 and the noise level).
    block : rocklab.Block
    window : {"middle50", "all", "first"}
        Samples compared: between the impacts at 25 % and 75 % of the detected impact
        count (Čeh's middle 50 %), the whole response, or the first post-impact
        half-period. The release quarter-cycle is always included (it fixes the release
        time and does not depend on η).
    objective : {"theta", "peaks"}
        Least squares on θ(t), or on arch amplitudes and half-periods (rad-scaled).
    eta_bounds : (lo, hi)
        Search interval for η (0 < lo < hi < 1).
    dt_s : float, optional
        Simulation step, s (default min(2e-4, 2e-3/p); the trapezoidal rule with exact
        contact detection then puts impact times within ~1e-6 s).
    nan : {"raise", "skip"}
        NaN samples: InputError naming the first, or dropped (counted in ``n_skipped``).
    level : float
        Confidence level of the interval (default 0.95).
    eta_guess : float, optional
        Start of the search (default: median per-impact η from the data).
    theta0_rad : float, optional
        Initial angle to linearise about, rad (default: the rest-plateau median). θ0 is
        refined jointly with the release time for every η in either case.
    fit_offset : bool
        Also fit a constant offset of the measured angle (camera level error, IMU bias
        integrated before release): the block then impacts at θ_measured = offset.
        θ objective only; costs 2–3 refits (the θ0 linearisation is re-centred).

    Returns
    -------
    RestitutionFit
        ``status="failed"`` with the reason when no release is found, fewer than 3
        impacts are detected, or θ0 is beyond the block's slenderness angle.

    Examples
    --------
    A record of the same block with η = 0.9, sampled at 200 Hz after 0.3 s of rest, gives η back:

    >>> import numpy as np
    >>> from rocklab import Block
    >>> from rocklab.fitting import fit_restitution
    >>> from rocklab.models import simulate
    >>> b = Block(0.045, 0.2025)
    >>> r = simulate(b, theta0_rad=0.15, restitution="constant", eta=0.9, duration_s=3.0)
    >>> t = np.arange(0, 3.0, 1 / 200)
    >>> theta = np.where(t < 0.3, 0.15, np.interp(t - 0.3, r.t_s, r.theta_rad))
    >>> fit = fit_restitution(t, theta, b)
    >>> fit.status, round(fit.eta_e, 4)
    ('ok', 0.9)
    """
    lo_b, hi_b = _check_options(window, objective, eta_bounds)
    prep = _prepare(
        t_s, theta_rad, block, window, objective, (lo_b, hi_b), dt_s, nan, eta_guess, theta0_rad, fit_offset
    )
    if isinstance(prep, RestitutionFit):
        return prep
    search, diags, s0, n_skip, pie = prep
    tc, name = search.tc, getattr(block, "name", "")
    w0, w1 = search.window_span(window)
    objective_used = "theta" if window == "first" else objective
    eta_hat, f_hat, f_main, tr_hat, theta0_hat, offset, res, win_res = search.fit(window, objective_used)
    eta_first = eta_hat if window == "first" else search.fit_first(eta_hat, offset)
    n_pts = int(res.size)
    rms = float(np.sqrt(np.mean(win_res**2))) if win_res.size else float("nan")
    n_par = (4 + int(fit_offset)) if objective_used == "theta" else 1
    ci = _interval(f_main, eta_hat, f_hat, n_pts - n_par, win_res, level, (lo_b, hi_b))
    at_bound = search.at_bound(eta_hat, eta_first, tr_hat)
    flags = search.suspicion(offset, win_res if objective_used == "theta" else np.array([]), rms, pie)
    diags += _residual_warning(name, block, rms, search.rel.sigma_rad)
    diags += _bound_warnings(name, at_bound, ci, lo_b, hi_b)
    # every warning the fit raised is in its message (the fit object travels without the stderr lines)
    msg = "; ".join(([f"{n_skip} NaN sample(s) skipped"] if n_skip else []) + [d.message for d in diags])
    return RestitutionFit(
        eta_e=float(eta_hat),
        eta_e_first=float(eta_first),
        ci95_eta_e=ci,
        theta0_rad=float(s0 * theta0_hat),
        release_t_s=float(tr_hat),
        rms_residual_rad=rms,
        sigma_theta_rad=float(search.rel.sigma_rad),
        per_impact_eta=tuple(float(x) for x in pie["eta_peaks"]),
        n_impacts=int(tc.size),
        window=window,
        objective=objective_used,
        window_t_s=(float(w0), float(w1)),
        n_points=n_pts,
        eta_bounds=(lo_b, hi_b),
        theta_offset_rad=float(s0 * offset),
        block_name=name,
        suspicious=bool(flags),
        flags=tuple(flags),
        at_bound=tuple(at_bound),
        n_skipped=n_skip,
        n_evaluations=search.n_evaluations,
        status="suspect" if any(d.severity == "suspect" for d in diags) else "ok",
        message=msg,
        per_impact=pie,
        warnings=tuple(d.code for d in diags),
    )
