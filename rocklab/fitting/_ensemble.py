"""Ensembles of base-excited simulations and the verdict of a law against a measurement.

One deterministic simulation of a shake-table run cannot validate a law: the response is
chaotic, so an error of a few per mil in the measured table motion moves it by a large
fraction of α within a few impacts. :func:`simulate_ensemble` runs ``n`` simulations
(default :data:`DEFAULT_ENSEMBLE_SIZE` = 64) that sample what the run does not know
exactly (:class:`InputUncertainty`): white noise on every table acceleration sample, a
constant bias and a scale error of the table acceleration, the clock offset between table and block, a
table fused from its IMU and the film's own error (its smoother's σ per sample, with the spectrum measured
on synthetic sessions: :func:`rocklab.fitting.fused_error_draw`), the block's width and
height, the start angle and the law's η. :func:`judge_law` compares the measured θ(t)
with it:

- the band: 5–95 % of the *predicted measurement* (each member plus one draw of the
  measurement noise) at every measured sample; ``band_coverage`` is the fraction of
  measured samples inside it;
- the predictability horizon: the first time the members' 5–95 % spread of θ exceeds
  :data:`HORIZON_FRACTION` α (0.1 α); before it the ensemble predicts θ(t) itself, after it
  only statistics of the response;
- the tests, each a two-sided p-value: inside the horizon, Σ z² of the measured samples
  (z = measured − ensemble median over the ensemble's and the measurement's spread; χ² with
  the residuals' autocorrelation counted); beyond it, the rank of the measured peak |θ|/α,
  number of half cycles, late amplitude (the energy left in the last quarter of the run) and
  time to rest among the members, and the probability of the measured overturning outcome;
  and, when a fit of η_e from half cycles is given (:mod:`._forced`), the law's η against it;
- ``score`` = the smallest p-value times the number of tests (Bonferroni, at most 1):
  ``inconsistent`` below 0.01, ``consistent`` from 0.05 with band coverage ≥ 0.9 when a
  test could tell the laws apart (η against the half cycles, or at least two half cycles
  inside the horizon), otherwise ``undecided`` (a block that hardly rocks decides nothing).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

__all__ = [
    "DEFAULT_ENSEMBLE_SIZE",
    "HORIZON_FRACTION",
    "InputUncertainty",
    "Ensemble",
    "LawVerdict",
    "simulate_ensemble",
    "judge_law",
    "response_statistics",
]

#: Members of an ensemble unless told otherwise (64 runs of an 8 s block: ~0.3 s).
DEFAULT_ENSEMBLE_SIZE = 64
#: The predictability horizon is where the ensemble's 5–95 % spread of θ passes this fraction of α.
HORIZON_FRACTION = 0.1
_P_INCONSISTENT, _P_CONSISTENT, _COVERAGE = 0.01, 0.05, 0.9


@dataclass(frozen=True)
class InputUncertainty:
    """One standard deviation of each input a base-excited run measures (SI units).

    Attributes
    ----------
    acc_noise_m_s2 : float
        White noise of every table-acceleration sample, m/s².
    acc_bias_m_s2 : float
        A constant offset of the table acceleration (gravity removal), m/s².
    sync_s : float
        Clock offset between the table acceleration and the measured θ, s.
    length_m : float
        Width and height of the block (independently), m.
    theta0_rad : float
        Start angle, rad.
    meas_noise_rad : float
        Noise of the measured θ, rad (widens the predicted-measurement band).
    acc_scale : float
        Relative error of the table acceleration's scale (an accelerometer's sensitivity), -.
    acc_fused : float
        Multiple of a fused table's own error drawn (:func:`rocklab.fitting.fused_error_draw`, from
        the per-sample σ given to the ensemble): 1 as measured, 0 none, -.
    """

    acc_noise_m_s2: float
    acc_bias_m_s2: float
    sync_s: float
    length_m: float
    theta0_rad: float
    meas_noise_rad: float
    acc_scale: float = 0.0
    acc_fused: float = 0.0

    def to_dict(self) -> dict:
        return {k: float(v) for k, v in self.__dict__.items()}


@dataclass(frozen=True)
class Ensemble:
    """Members of one law's ensemble on the measured time grid.

    Attributes
    ----------
    t_s : ndarray, (m,)
    theta_rad : ndarray, (n, m)
        Simulated θ of every member (after overturning or rest: held at its last value).
    eta : ndarray, (n,)
    overturned : ndarray of bool, (n,)
    band_rad : ndarray, (2, m)
        5 % and 95 % of the predicted measurement (member + measurement noise).
    seconds : float
        Wall time of the simulations, s.
    """

    t_s: np.ndarray
    theta_rad: np.ndarray = field(repr=False)
    eta: np.ndarray = field(repr=False)
    overturned: np.ndarray = field(repr=False)
    band_rad: np.ndarray = field(repr=False)
    seconds: float = 0.0


def table_draw(tt, aa, unc, rng, t_start_s: float, sign: float = 1.0, sigma_m_s2=None):
    """One draw of a measured table acceleration within its uncertainty, as the simulator's input.

    Parameters
    ----------
    tt, aa : ndarray (n,)
        The measured table's times (s) and acceleration (m/s²), finite.
    unc : InputUncertainty
        Scale, white noise, bias and sync errors drawn, in that order, from ``rng``; then, with
        ``sigma_m_s2`` and ``unc.acc_fused`` > 0, the fused table's own error.
    rng : numpy.random.Generator
    t_start_s : float
        The simulation's start on the measurement's clock, s.
    sign : float
        -1 mirrors the table (the measurement's θ counter-clockwise, the simulator's clockwise).
    sigma_m_s2 : ndarray (n,), optional
        A fused table's per-sample standard deviation (``TableMotion.sigma_ax_m_s2``), m/s².

    Returns
    -------
    rocklab.series.BaseMotion
        The draw splined onto 1 ms samples, its time from ``t_start_s``.
    """
    from scipy.interpolate import CubicSpline

    from ..series import BaseMotion
    from ._table_error import fused_error_draw

    a = aa * (1.0 + unc.acc_scale * rng.standard_normal())
    a += unc.acc_noise_m_s2 * rng.standard_normal(aa.size) + unc.acc_bias_m_s2 * rng.standard_normal()
    ts = tt + unc.sync_s * rng.standard_normal()
    if sigma_m_s2 is not None and unc.acc_fused > 0:
        a += fused_error_draw(tt, sigma_m_s2, rng, unc.acc_fused)
    tf = np.arange(ts[0], ts[-1], 1e-3)
    af = CubicSpline(ts, a)(tf)
    return BaseMotion.from_samples(sign * af, 1e-3, t0_s=float(tf[0]) - t_start_s, units="m/s2", name="table")


def finite_table(table_t_s, table_acc_m_s2, table_sigma_m_s2):
    """(t, a, σ or None) of a measured table at the samples where all given are finite."""
    tt = np.asarray(table_t_s, float)
    aa = np.asarray(table_acc_m_s2, float)
    fin = np.isfinite(tt) & np.isfinite(aa)
    if table_sigma_m_s2 is None:
        return tt[fin], aa[fin], None
    sg = np.asarray(table_sigma_m_s2, float)
    fin &= np.isfinite(sg)
    return tt[fin], aa[fin], sg[fin]


def simulate_ensemble(
    block,
    table_t_s,
    table_acc_m_s2,
    t_out_s,
    *,
    eta: float,
    theta0_rad: float,
    t_start_s: float,
    unc: InputUncertainty,
    eta_sd: float = 0.0,
    n: int = DEFAULT_ENSEMBLE_SIZE,
    sign: float = -1.0,
    dt_s: float = 1e-4,
    seed: int = 0,
    table_sigma_m_s2=None,
) -> Ensemble:
    """Simulate ``n`` members of a base-excited run, sampling :class:`InputUncertainty`.

    Parameters
    ----------
    block : rocklab.Block
    table_t_s, table_acc_m_s2 : array_like, (k,)
        Measured table acceleration (s, m/s²) on the measurement's clock.
    t_out_s : array_like, (m,)
        Times at which θ is wanted (the measured samples), s.
    eta, eta_sd : float
        The law's restitution and its standard deviation.
    theta0_rad, t_start_s : float
        Start angle (rad) and time (s); the block starts with ω = 0.
    unc : InputUncertainty
    n : int
        Members.
    sign : float
        -1 mirrors the table (the measurement's θ is counter-clockwise, the simulator's clockwise).
    dt_s : float
        Simulator step, s.
    seed : int
        Same seed, same members.
    table_sigma_m_s2 : array_like, (k,), optional
        A fused table's per-sample σ (m/s²): its own error is drawn at ``unc.acc_fused`` times it.

    Returns
    -------
    Ensemble
    """
    import time

    from ..blocks import Block
    from ..models import simulate

    rng = np.random.default_rng(seed)
    tt, aa, sg = finite_table(table_t_s, table_acc_m_s2, table_sigma_m_s2)
    t_out = np.asarray(t_out_s, float)
    out = np.empty((n, t_out.size))
    etas = np.clip(eta + eta_sd * rng.standard_normal(n), -1.0, 1.0)
    over = np.zeros(n, bool)
    t0 = time.perf_counter()
    span = float(t_out[-1] - t_start_s)
    for i in range(n):
        base = table_draw(tt, aa, unc, rng, t_start_s, sign, sg)
        b = block.b_m + unc.length_m * rng.standard_normal()
        h = block.h_m + unc.length_m * rng.standard_normal()
        blk = Block(b, h, depth_m=block.depth_m, mass_kg=block.mass_kg, alpha_I=block.alpha_I)
        th0 = float(
            np.clip(theta0_rad + unc.theta0_rad * rng.standard_normal(), -0.99 * blk.alpha_rad, 0.99 * blk.alpha_rad)
        )
        r = simulate(
            blk,
            theta0_rad=th0,
            duration_s=max(span, 1e-3),
            dt_s=dt_s,
            restitution="constant",
            eta=float(etas[i]),
            base=base,
            output_dt_s=1e-3,
        )
        th = np.asarray(r.theta_rad)
        out[i] = np.interp(t_out - t_start_s, r.t_s, th, left=th0, right=th[-1])
        over[i] = r.status == "overturned"
    secs = time.perf_counter() - t0
    noisy = out + unc.meas_noise_rad * rng.standard_normal(out.shape)
    band = np.percentile(noisy, [5.0, 95.0], axis=0)
    return Ensemble(t_out, out, etas, over, band, secs)


def _half_cycles(t, y, alpha, floor):
    """Extrema above ``floor`` (one per half cycle) and the zero crossings after them, s."""
    y = np.nan_to_num(np.asarray(y, float))
    sgn = np.sign(y)
    idx = np.flatnonzero((sgn[:-1] * sgn[1:] < 0))
    events = []
    last = 0
    for k in idx:
        if np.max(np.abs(y[last : k + 1])) > floor:
            f = y[k] / (y[k] - y[k + 1])
            events.append(float(t[k] + f * (t[k + 1] - t[k])))
        last = k + 1
    return np.asarray(events)


def response_statistics(t_s, theta_rad, alpha_rad: float, noise_rad: float = 0.0) -> dict:
    """Statistics of a rocking response that stay meaningful beyond the predictability horizon.

    Returns
    -------
    dict
        ``peak_over_alpha`` (max |θ|/α), ``n_half_cycles`` (zero crossings after an
        excursion above 0.05 α), ``late_amplitude_over_alpha`` (RMS of θ over the last
        quarter, /α: what the impacts left of the energy), ``time_to_rest_s`` (from
        which |θ| stays below max(3 noise, 0.01 α); inf when it never rests),
        ``overturned`` (|θ| reached α), ``event_t_s`` (the zero crossings).
    """
    t = np.asarray(t_s, float)
    y = np.asarray(theta_rad, float)
    a = abs(np.nan_to_num(y))
    ev = _half_cycles(t, y, alpha_rad, 0.05 * alpha_rad)
    q = t >= t[0] + 0.75 * (t[-1] - t[0])
    quiet = a < max(3.0 * noise_rad, 0.01 * alpha_rad)
    moved = np.flatnonzero(~quiet)
    if moved.size == 0:
        rest = float(t[0])
    elif moved[-1] < t.size - max(3, int(0.05 * t.size)):
        rest = float(t[moved[-1] + 1])
    else:
        rest = math.inf
    return {
        "peak_over_alpha": float(np.nanmax(a) / alpha_rad),
        "n_half_cycles": int(ev.size),
        "late_amplitude_over_alpha": float(np.sqrt(np.nanmean(np.square(y[q]))) / alpha_rad),
        "time_to_rest_s": rest,
        "overturned": bool(np.nanmax(a) >= alpha_rad),
        "event_t_s": ev,
    }


def _rank_p(x, sample):
    """Two-sided rank p-value of x among the sample (ties split; +1 smoothing)."""
    s = np.asarray(sample, float)
    below = np.sum(s < x) + 0.5 * np.sum(s == x)
    above = s.size - below
    return float(min(1.0, 2.0 * min(below + 1, above + 1) / (s.size + 1)))


@dataclass(frozen=True)
class LawVerdict:
    """A law judged against a measurement by its ensemble (see the module doc).

    Attributes
    ----------
    verdict : str
        "consistent", "inconsistent" or "undecided".
    score : float
        Bonferroni-corrected smallest p-value of the tests (0–1; small: the law disagrees).
    band_coverage : float
        Fraction of measured samples inside the 5–95 % band.
    horizon_s : float
        Predictability horizon, s (the end of the run when the spread never passes 0.1 α).
    tests : dict
        Test name → two-sided p-value.
    statistics : dict
        Statistic name → {measured, p05, p50, p95} over the members.
    overturning_probability : float
    events : list of dict
        Per half-cycle zero crossing k: {k, measured_t_s, p05_t_s, p95_t_s} (first 10).
    """

    verdict: str
    score: float
    band_coverage: float
    horizon_s: float
    tests: dict
    statistics: dict
    overturning_probability: float
    events: list = field(default_factory=list)

    def to_dict(self) -> dict:
        return {
            "verdict": self.verdict,
            "score": float(self.score),
            "band_coverage": float(self.band_coverage),
            "horizon_s": float(self.horizon_s),
            "tests": {k: float(v) for k, v in self.tests.items()},
            "statistics": self.statistics,
            "overturning_probability": float(self.overturning_probability),
            "events": self.events,
        }


def _finite_or_none(x):
    return float(x) if np.isfinite(x) else None


def judge_law(
    t_s, theta_rad, ens: Ensemble, alpha_rad: float, meas_noise_rad: float, *, eta_law=None, eta_fit=None
) -> LawVerdict:
    """Judge one law's ensemble against the measured θ(t) (see the module doc).

    Parameters
    ----------
    t_s, theta_rad : array_like, (m,)
        The measurement on the ensemble's grid (s, rad); NaN samples are left out.
    ens : Ensemble
    alpha_rad, meas_noise_rad : float
    eta_law : (float, float), optional
        The law's η and its standard deviation, for the test against ``eta_fit``.
    eta_fit : (float, float), optional
        η_e fitted from the run's half cycles and its standard error.
    """
    from scipy.stats import chi2

    from ._simfit import ac_factor

    t = np.asarray(t_s, float)
    y = np.asarray(theta_rad, float)
    ok = np.isfinite(y)
    lo, hi = ens.band_rad
    coverage = float(np.mean((y[ok] >= lo[ok]) & (y[ok] <= hi[ok])))
    p05, p50, p95 = np.percentile(ens.theta_rad, [5.0, 50.0, 95.0], axis=0)
    wide = np.flatnonzero(p95 - p05 > HORIZON_FRACTION * alpha_rad)
    horizon = float(t[wide[0]]) if wide.size else float(t[-1])
    tests = {}
    inside = ok & (t < horizon)
    if inside.sum() >= 8:
        sd = np.std(ens.theta_rad[:, inside], axis=0)
        z = (y[inside] - p50[inside]) / np.sqrt(sd**2 + meas_noise_rad**2)
        n_eff = max(1.0, z.size / ac_factor(z))
        tests["inside_horizon"] = float(chi2.sf(float(np.mean(z**2)) * n_eff, n_eff))
    meas = response_statistics(t[ok], y[ok], alpha_rad, meas_noise_rad)
    members = [response_statistics(t, th, alpha_rad, 0.0) for th in ens.theta_rad]
    stats = {}
    for key in ("peak_over_alpha", "n_half_cycles", "late_amplitude_over_alpha", "time_to_rest_s"):
        vals = np.array([m[key] for m in members], float)
        if not np.all(vals == vals[0]) or vals[0] != meas[key]:
            tests[key] = _rank_p(meas[key], vals)
        fin = vals[np.isfinite(vals)]
        qs = np.percentile(fin, [5, 50, 95]) if fin.size else [np.nan] * 3
        stats[key] = {
            "measured": _finite_or_none(meas[key]),
            "p05": _finite_or_none(qs[0]),
            "p50": _finite_or_none(qs[1]),
            "p95": _finite_or_none(qs[2]),
        }
    p_over = float(np.mean(ens.overturned | np.array([m["overturned"] for m in members])))
    n = len(members)
    same = p_over if meas["overturned"] else 1.0 - p_over
    tests["overturning"] = float(min(1.0, (same * n + 1) / (n + 1)))
    if eta_law is not None and eta_fit is not None and np.isfinite(eta_fit[0]) and np.isfinite(eta_fit[1]):
        s = math.hypot(eta_fit[1], eta_law[1])
        if s > 0:
            from scipy.stats import norm

            tests["eta_vs_half_cycles"] = float(2.0 * norm.sf(abs(eta_law[0] - eta_fit[0]) / s))
    score = float(min(1.0, min(tests.values()) * len(tests)))
    # a law is only called consistent by tests that could have told it apart: an η compared with
    # the half cycles, or two half cycles predicted inside the horizon
    informative = "eta_vs_half_cycles" in tests or int(np.sum(meas["event_t_s"] < horizon)) >= 2
    if score < _P_INCONSISTENT:
        verdict = "inconsistent"
    elif score >= _P_CONSISTENT and coverage >= _COVERAGE and informative:
        verdict = "consistent"
    else:
        verdict = "undecided"
    events = []
    for k, tm in enumerate(meas["event_t_s"][:10]):
        et = np.array([m["event_t_s"][k] for m in members if m["event_t_s"].size > k])
        q = np.percentile(et, [5, 95]) if et.size >= 0.5 * n else (np.nan, np.nan)
        events.append(
            {"k": k + 1, "measured_t_s": float(tm), "p05_t_s": _finite_or_none(q[0]), "p95_t_s": _finite_or_none(q[1])}
        )
    return LawVerdict(verdict, score, coverage, horizon, tests, stats, p_over, events)


#: The sources an error budget separates: a field of :class:`InputUncertainty`, or ``eta``.
BUDGET_SOURCES = (
    "acc_noise_m_s2", "acc_bias_m_s2", "acc_scale", "acc_fused", "sync_s", "length_m", "theta0_rad", "eta",
)  # fmt: skip


def error_budget(
    block,
    table_t_s,
    table_acc_m_s2,
    t_out_s,
    *,
    eta: float,
    eta_sd: float,
    theta0_rad: float,
    t_start_s: float,
    unc: InputUncertainty,
    t_end_s: float | None = None,
    n: int = 32,
    seed: int = 0,
    table_sigma_m_s2=None,
) -> dict:
    """How much of the model's spread each measured input causes (issue: the input error budget).

    One ensemble per source with only that source sampled (the others at their measured values);
    the spread is the RMS over ``t_out_s`` up to ``t_end_s`` (default the whole run) of the
    ensemble's standard deviation of θ. The shares are each source's variance over their sum (the
    sources interact, so the sum need not equal the all-sources variance, which is reported beside).
    ``table_sigma_m_s2`` is a fused table's per-sample σ (its own error, ``acc_fused``; without it
    that source is 0).

    Returns
    -------
    dict
        ``{"sources": {name: {"sd_rad": ..., "share": ...}}, "all_sd_rad": ..., "t_end_s": ..., "n": n}``,
        sources named as :data:`BUDGET_SOURCES`.
    """
    t = np.asarray(t_out_s, float)
    end = float(t[-1] if t_end_s is None else t_end_s)
    w = t <= end
    zero = InputUncertainty(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)

    def spread(u, sd):
        e = simulate_ensemble(
            block, table_t_s, table_acc_m_s2, t, eta=eta, eta_sd=sd, theta0_rad=theta0_rad,
            t_start_s=t_start_s, unc=u, n=n, seed=seed, table_sigma_m_s2=table_sigma_m_s2,
        )  # fmt: skip
        return float(np.sqrt(np.mean(np.std(e.theta_rad[:, w], axis=0) ** 2)))

    sd = {}
    for src in BUDGET_SOURCES:
        if src == "eta":
            sd[src] = spread(zero, eta_sd) if eta_sd > 0 else 0.0
        else:
            v = getattr(unc, src)
            off = src == "acc_fused" and table_sigma_m_s2 is None
            sd[src] = spread(replace(zero, **{src: v}), 0.0) if v > 0 and not off else 0.0
    total = sum(s * s for s in sd.values())
    return {
        "sources": {k: {"sd_rad": v, "share": (v * v / total) if total > 0 else 0.0} for k, v in sd.items()},
        "all_sd_rad": spread(replace(unc, meas_noise_rad=0.0), eta_sd),
        "t_end_s": end,
        "n": int(n),
    }
