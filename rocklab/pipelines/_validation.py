"""Validation of base-excited runs: η_e from half cycles, an ensemble per law, a verdict per law.

What the run measured sets the ensemble's input uncertainty
(:class:`rocklab.fitting.InputUncertainty`):

- table acceleration noise: the robust standard deviation of the table acceleration in its
  rest before the shaking (the samples before it first leaves ±6 σ of its start level; a
  table fused from an IMU and the film: at least the IMU's white noise), sampled at
  :data:`INPUT_SAFETY` (2) times that;
  the bias the half-cycle fit of η_e finds is taken out, and a constant bias of its standard
  error and σ/√n (the rest gives gravity's level) sampled; a scale error of
  :data:`ACC_SCALE_SD` (1 %), or, for a table fused from its IMU and the film, the scale
  uncertainty their agreement measured (:func:`acc_scale_sd`); a fused table's own error is drawn
  too, from its smoother's σ per sample with the spectrum measured on synthetic sessions
  (:func:`rocklab.fitting.fused_error_draw`);
- clock offset: the table–video synchronisation residual, at least a quarter of the table's
  sample period (same clock, video table: 0); a record given as the table motion (the
  command, not a measurement): 2 % of its peak as noise, one record step as offset;
- block width and height: :data:`LENGTH_SD_M` (a caliper reading);
- measured θ: its rest level before the shaking is the measurement's zero (a camera or
  IMU offset, not a tilted block: the ensemble starts at rest, θ0 = 0 exactly) and the robust
  spread of its first differences there / √2 the measurement noise (at least
  :data:`MIN_NOISE_RAD`, and at least the RMS residual per degree of freedom of the half-cycle
  fit of η_e: a tracked θ is noisier in motion than at rest).

The band is the 5–95 % band of the predicted measurement with these errors sampled
conservatively (:data:`INPUT_SAFETY`, :data:`NOISE_SAFETY`, and scale and length errors a lab
cannot rule out): one run's errors are one draw for the whole record, so a nominal 90 % band
holds about 90 % of a run's samples only on average, and less than that half the time.

Each law's η is exact except η_e (its bootstrap standard error).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

__all__ = [
    "ACC_SCALE_SD",
    "acc_scale_sd",
    "fused_sigma",
    "INPUT_SAFETY",
    "NOISE_SAFETY",
    "Validation",
    "ForcedPrep",
    "prepare_forced",
    "validate_forced_run",
    "LENGTH_SD_M",
    "MIN_NOISE_RAD",
]

#: Standard deviation of a block's measured width and height, m.
LENGTH_SD_M = 2e-4
#: Smallest measurement noise assumed for θ, rad.
MIN_NOISE_RAD = 1e-4
#: The table acceleration's noise and bias are sampled at this many times their measured standard
#: deviation. One run's measured input carries one draw of its errors for the whole record, so its
#: response stays on one side of the ensemble for seconds: at 1x the band held 81–95 % of a run's
#: samples (6 synthetic runs of the benchmark), at 2x 93–96 %, the horizon 0–1 s earlier.
INPUT_SAFETY = 2.0
#: The measured θ's noise widens the band at this many times its estimate: a run that rests for half
#: its length would otherwise hold its nominal 90 % there, a coin toss around 0.9 (the test inside
#: the horizon uses the estimate itself).
NOISE_SAFETY = 1.5
#: Relative standard deviation of the table acceleration's scale (a calibrated MEMS accelerometer's
#: sensitivity, or the video's metric scale) when one source alone measured it, -.
ACC_SCALE_SD = 0.01


def acc_scale_sd(table) -> tuple[float, str]:
    """(relative scale sd, its source) of a measured table's acceleration: what its two sources'
    agreement measured (a fused table, :func:`rocklab.tracking.table_scale_agreement`), else the
    prior :data:`ACC_SCALE_SD` (one source: nothing to compare it with)."""
    sd = float(getattr(table, "acc_scale_sd", np.nan))
    if np.isfinite(sd) and sd > 0:
        return sd, "measured: table IMU vs film agreement"
    return ACC_SCALE_SD, "prior: one source"


@dataclass(frozen=True)
class Validation:
    """The validation of one base-excited run (``report.json["validation"]`` is :meth:`to_dict`).

    Attributes
    ----------
    horizon_s : float
        Predictability horizon of the reference law (``given``, else ``eta_e``, else the first), s.
    reference_law : str
    laws : dict
        Law → :class:`rocklab.fitting.LawVerdict`.
    bands : dict
        Law → (t_s (m,), p05_rad (m,), p95_rad (m,)) on the measured scale.
    eta_fit : dict or None
        :meth:`rocklab.fitting.ForcedRestitutionFit.to_dict`.
    uncertainty : dict
        The :class:`rocklab.fitting.InputUncertainty` used, SI.
    n_members : int
    rest_level_rad : float
    seconds : float
        Wall time of all ensembles, s.
    error_budget : dict or None
        :func:`rocklab.fitting.error_budget` of the reference law inside the horizon: each measured
        input's share of the model's spread (table noise, bias, scale, clock, sizes, θ0, η).
    acc_scale_source : str
        Where ``uncertainty["acc_scale"]`` comes from (:func:`acc_scale_sd`).
    """

    horizon_s: float
    reference_law: str
    laws: dict
    bands: dict = field(repr=False)
    eta_fit: dict | None
    uncertainty: dict
    n_members: int
    rest_level_rad: float
    seconds: float
    error_budget: dict | None = None
    acc_scale_source: str = ""

    def to_dict(self) -> dict:
        return {
            "horizon_s": float(self.horizon_s),
            "reference_law": self.reference_law,
            "horizon_fraction_of_alpha": _horizon_fraction(),
            "n_members": self.n_members,
            "laws": {k: v.to_dict() for k, v in self.laws.items()},
            "eta_e": self.eta_fit,
            "uncertainty": self.uncertainty,
            "acc_scale_source": self.acc_scale_source,
            "rest_level_rad": float(self.rest_level_rad),
            "ensemble_s": float(self.seconds),
            "error_budget": self.error_budget,
        }


def _horizon_fraction():
    from ..fitting import HORIZON_FRACTION

    return HORIZON_FRACTION


def _rest_window(x, k_sigma=6.0, n_min=10, sigma_floor=0.0):
    """Indices of the initial rest of ``x``: until it first stays outside ±k σ of its start level
    for three samples (one outlier, a differentiated track's first sample, does not end it).

    σ is the noise of the first samples' differences, at least ``sigma_floor`` (a smoothed series'
    differences understate how far its level wanders)."""
    x = np.asarray(x, float)
    head = x[: max(n_min, 20)]
    head = head[np.isfinite(head)]
    if head.size < n_min:
        return None
    lev = float(np.median(head))
    sig = 1.4826 * float(np.median(np.abs(np.diff(head)))) / np.sqrt(2.0)
    sig = max(sig, float(sigma_floor), 1e-12)
    away = ~(np.abs(x - lev) <= k_sigma * sig)
    run = away[:-2] & away[1:-1] & away[2:]
    out = np.flatnonzero(run)
    n = int(out[0]) if out.size else x.size
    return slice(0, n) if n >= n_min else None


def _robust_sd(x):
    d = np.diff(np.asarray(x, float))
    d = d[np.isfinite(d)]
    return 1.4826 * float(np.median(np.abs(d - np.median(d)))) / np.sqrt(2.0)


def _uncertainty(cfg, table, table_sync, y, msgs):
    """(InputUncertainty, rest level of θ in rad, whether θ starts at rest) from what the run measured."""
    from .._diagnostics import warn
    from ..fitting import InputUncertainty

    ta, aa = np.asarray(table.t_s, float), np.asarray(table.ax_m_s2, float)
    fin = np.isfinite(aa)
    peak = float(np.nanmax(np.abs(aa)))
    dt_tab = float(np.nanmedian(np.diff(ta)))
    if cfg.table.source == "record":
        warn(
            "W-VALID-ASSUMED", f"{cfg.path}: the table motion is a record (the command); noise 2 % of its peak assumed"
        )
        sa, sb, st = 0.02 * peak, 0.0, dt_tab
    else:
        # a fused table is smooth at rest: its level wanders by more than its first differences say
        # (±0.02 m/s² against 0.002 on the demo's El Centro run), within the IMU's white noise
        fused = table.source == "fused" and np.isfinite(table.acc_noise_m_s2)
        w = _rest_window(aa[fin], sigma_floor=float(table.acc_noise_m_s2) if fused else 0.0)
        if w is None:
            warn(
                "W-VALID-ASSUMED",
                f"{cfg.path}: the table acceleration has no rest before the shaking; noise 2 % of its peak assumed",
            )
            sa, sb = 0.02 * peak, 0.0
        else:
            rest = aa[fin][w]
            sa = _robust_sd(rest)
            sb = sa / np.sqrt(rest.size)
        if fused:
            # the fused table is smooth at rest; its error in the band that rocks a block is the
            # IMU's white noise there (the film takes over only below a few hertz)
            sa = max(sa, float(table.acc_noise_m_s2))
        if table_sync is not None:
            st = max(float(table_sync.residual_ms or 0.0) / 1000.0, 0.25 * dt_tab)
        else:
            st = 0.0
    wy = _rest_window(y)
    if wy is None:
        msgs.append(
            "validation: the measured θ does not start at rest; its noise is assumed 1 mrad and the run starts tilted"
        )
        level, sm = 0.0, 1e-3
    else:
        level = float(np.median(y[wy]))
        sm = max(_robust_sd(y[wy]), MIN_NOISE_RAD)
    unc = InputUncertainty(
        acc_noise_m_s2=INPUT_SAFETY * sa,
        acc_bias_m_s2=INPUT_SAFETY * sb,
        sync_s=st,
        length_m=LENGTH_SD_M,
        theta0_rad=0.0 if wy is not None else sm,  # a block at rest on the table is flat
        meas_noise_rad=sm,
        acc_scale=acc_scale_sd(table)[0],
        acc_fused=1.0 if fused_sigma(table) is not None else 0.0,
    )
    return unc, level, wy is not None


def fused_sigma(table):
    """A fused table's per-sample σ of its acceleration (m/s², ``TableMotion.sigma_ax_m_s2``), else None."""
    if table is None or getattr(table, "source", "") != "fused" or getattr(table, "sigma_ax_m_s2", None) is None:
        return None
    return np.asarray(table.sigma_ax_m_s2, float)


@dataclass(frozen=True)
class ForcedPrep:
    """What a base-excited run's validation starts from (:func:`prepare_forced`)."""

    t_s: np.ndarray
    theta_rad: np.ndarray  # measured θ minus its rest level
    level_rad: float
    theta0_rad: float
    unc: object  # rocklab.fitting.InputUncertainty
    fit: object  # rocklab.fitting.ForcedRestitutionFit
    table: object  # rocklab.series.TableMotion, the fitted bias taken out


def prepare_forced(cfg, block, prim, table, table_sync, msgs: list):
    """The input uncertainty, the measurement's zero and η_e from half cycles of a base-excited run.

    Parameters
    ----------
    cfg : ExperimentConfig
    block : rocklab.Block
    prim : (t_s, theta_rad)
        The primary measurement, on the table's clock.
    table : rocklab.series.TableMotion
        The table's motion (the video's sense of x).
    table_sync : rocklab.tracking.SyncResult or None
        The table IMU's synchronisation (``residual_ms``), when it was synchronised.
    msgs : list
        Notes are appended.

    Returns
    -------
    ForcedPrep or None
        None when the run cannot be validated (a note says why).
    """
    from ..fitting import fit_forced_restitution
    from .experiment import base_from_table

    t, y = (np.asarray(v, float) for v in prim)
    ok = np.isfinite(y)
    if ok.sum() < 20 or not np.isfinite(np.asarray(table.ax_m_s2, float)).any():
        msgs.append("validation skipped: fewer than 20 valid θ samples or no table acceleration")
        return None
    t, y = t[ok], y[ok]
    unc, level, at_rest = _uncertainty(cfg, table, table_sync, y, msgs)
    yl = y - level
    # t = 0 of the base is the measurement's t = 0 (the segments start anywhere on that clock)
    base = base_from_table(table, 0.0, str(cfg.path), sign=-1.0)
    fit = fit_forced_restitution(t, yl, block, base)
    if fit.status != "ok":
        msgs.append(f"η_e from half cycles ({fit.status}): {fit.message}")
    if fit.status != "failed":
        # a tracked θ is noisier while the block moves than at rest: the half cycles' residual says
        # how much (per degree of freedom: two start values per segment, η and the bias)
        dof = max(fit.n_samples - 2 * fit.n_segments - 2, 1)
        sm = float(fit.rms_residual_rad * np.sqrt(fit.n_samples / dof))
        # the table's bias the fit found (a tilted table, the gravity removal) is taken out of the
        # ensemble's input: the base was the mirrored acceleration, so the table's offset is -bias
        table = dataclasses.replace(table, ax_m_s2=np.asarray(table.ax_m_s2, float) + fit.base_bias_m_s2)
        sb = float(np.hypot(unc.acc_bias_m_s2, fit.base_bias_se_m_s2))
        unc = dataclasses.replace(unc, meas_noise_rad=max(sm, unc.meas_noise_rad), acc_bias_m_s2=sb)
    return ForcedPrep(t, yl, level, 0.0 if at_rest else float(yl[0]), unc, fit, table)


def validate_forced_run(prep: ForcedPrep, block, laws: dict, *, n=None, seed=0) -> Validation:
    """Judge every law by its ensemble (see the module doc).

    Parameters
    ----------
    prep : ForcedPrep
    block : rocklab.Block
    laws : dict
        Law → η (``eta_e`` is added when the half-cycle fit succeeded and it is not there).
    n : int, optional
        Members per law (default :data:`rocklab.fitting.DEFAULT_ENSEMBLE_SIZE`).
    seed : int
        The members' random seed (the same input draws for every law).
    """
    from ..fitting import DEFAULT_ENSEMBLE_SIZE, judge_law, simulate_ensemble

    n = n or DEFAULT_ENSEMBLE_SIZE
    fit, unc, t = prep.fit, prep.unc, prep.t_s
    good = fit.status != "failed"
    todo = dict(laws)
    if "eta_e" not in todo and good:
        todo["eta_e"] = fit.eta_e
    verdicts, bands, secs = {}, {}, 0.0
    band_unc = dataclasses.replace(unc, meas_noise_rad=NOISE_SAFETY * unc.meas_noise_rad)
    for law, eta in todo.items():
        sd = fit.se if law == "eta_e" and good else 0.0
        ens = simulate_ensemble(
            block,
            prep.table.t_s,
            prep.table.ax_m_s2,
            t,
            eta=float(eta),
            eta_sd=sd,
            theta0_rad=prep.theta0_rad,
            t_start_s=float(t[0]),
            unc=band_unc,
            n=n,
            seed=seed,
            table_sigma_m_s2=fused_sigma(prep.table),
        )
        secs += ens.seconds
        verdicts[law] = judge_law(
            t,
            prep.theta_rad,
            ens,
            block.alpha_rad,
            unc.meas_noise_rad,
            eta_law=(float(eta), sd),
            eta_fit=(fit.eta_e, fit.se) if good else None,
        )
        bands[law] = (t, ens.band_rad[0] + prep.level_rad, ens.band_rad[1] + prep.level_rad)
    ref = next((k for k in ("given", "eta_e") if k in verdicts), next(iter(verdicts)))
    from ..fitting import error_budget

    h = verdicts[ref].horizon_s
    budget = error_budget(
        block, prep.table.t_s, prep.table.ax_m_s2, t, eta=float(todo[ref]),
        eta_sd=fit.se if ref == "eta_e" and good else 0.0, theta0_rad=prep.theta0_rad, t_start_s=float(t[0]),
        unc=unc, t_end_s=float(h) if h is not None and np.isfinite(h) else None, n=max(8, n // 2), seed=seed,
        table_sigma_m_s2=fused_sigma(prep.table),
    )  # fmt: skip
    return Validation(
        horizon_s=verdicts[ref].horizon_s,
        reference_law=ref,
        laws=verdicts,
        bands=bands,
        eta_fit=fit.to_dict(),
        uncertainty=unc.to_dict(),
        n_members=n,
        rest_level_rad=prep.level_rad,
        seconds=secs,
        error_budget=budget,
        acc_scale_source=acc_scale_sd(prep.table)[1],
    )


def summary_lines(v: Validation, alpha_rad: float) -> list[str]:
    """The validation's part of ``summary.md`` (markdown lines)."""
    from .reports import sig as _g

    f = v.eta_fit or {}
    ci = f.get("ci95_eta_e") or [None, None]
    lines = [
        f"## Validation ({v.n_members} simulations per law, sampling the measured inputs' uncertainty)",
        "",
        f"Predictability horizon ({v.reference_law}): {_g(v.horizon_s)} s (the ensemble's 5–95 % spread of θ "
        f"passes {_g(_horizon_fraction())} α there; beyond it only the statistics are compared).",
        "",
        f"η_e from {f.get('n_segments', 0)} half cycles: {_g(f.get('eta_e'))} (95 % CI {_g(ci[0])} – {_g(ci[1])}, "
        f"status {f.get('status')})",
        "",
        "| law | verdict | score | band coverage | horizon (s) | P(overturn) | peak θ/α measured (5–95 %) | half cycles measured (5–95 %) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for law, lv in v.laws.items():
        pk, hc = lv.statistics["peak_over_alpha"], lv.statistics["n_half_cycles"]
        lines.append(
            f"| {law} | **{lv.verdict}** | {_g(lv.score)} | {_g(lv.band_coverage)} | {_g(lv.horizon_s)} | "
            f"{_g(lv.overturning_probability)} | {_g(pk['measured'])} ({_g(pk['p05'])} – {_g(pk['p95'])}) | "
            f"{_g(hc['measured'])} ({_g(hc['p05'])} – {_g(hc['p95'])}) |"
        )
    unc = v.uncertainty
    lines += [
        "",
        f"Inputs sampled (1 σ): table acceleration noise {_g(unc['acc_noise_m_s2'])} m/s², bias "
        f"{_g(unc['acc_bias_m_s2'])} m/s², scale {_g(100 * unc['acc_scale'])} % ({v.acc_scale_source}), clock "
        f"{_g(1000 * unc['sync_s'])} ms, width and height {_g(1000 * unc['length_m'])} mm, θ noise "
        f"{_g(unc['meas_noise_rad'])} rad"
        + (
            ", the fused table's own error (its smoother's σ, the spectrum measured on synthetic sessions)."
            if unc.get("acc_fused")
            else "."
        ),
        "",
    ]
    b = v.error_budget
    if b:
        names = {
            "acc_noise_m_s2": "table noise", "acc_bias_m_s2": "table bias", "acc_scale": "table scale",
            "sync_s": "clock offset", "length_m": "block size", "theta0_rad": "θ0", "eta": "η",
            "acc_fused": "fused table's own error",
        }  # fmt: skip
        parts = sorted(b["sources"].items(), key=lambda kv: -kv[1]["share"])
        lines += [
            f"Error budget up to {_g(b['t_end_s'])} s (share of the model's spread of θ; all inputs together: "
            f"{_g(b['all_sd_rad'])} rad RMS): "
            + ", ".join(f"{names.get(k, k)} {100 * d['share']:.3g} %" for k, d in parts if d["share"] > 0)
            + ".",
            "",
        ]
    return lines
