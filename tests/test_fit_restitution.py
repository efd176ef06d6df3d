"""η_e calibration, per-impact η and thesis Eq. 12 on synthetic free rocking with known truth.

Truth comes from ``rocklab.models.simulate`` at dt = 2e-5 s (ten times finer than the fit's
own simulations), sampled at 150 fps after a thread-burn release at a random sub-frame time,
with white θ noise of 0.02° (Čeh's optical system).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from rocklab._diagnostics import RocklabWarning, collecting

from rocklab import InputError
from rocklab.fitting import (
    catalogue_block,
    energy_loss_from_peaks,
    fit_many,
    fit_restitution,
    per_impact_eta,
    summarize_repeats,
)
from rocklab.models import simulate

B6M = catalogue_block("B6M")
FPS = 150.0
NOISE = math.radians(0.02)


def synthetic(seed, eta=0.93, block=B6M, noise=NOISE, duration=6.0, sign=1.0, law=None):
    """(t_s, theta_rad, truth) of a thread-burn free-rocking record."""
    rng = np.random.default_rng(seed)
    t_rel = 0.4 + rng.uniform(0, 1 / FPS)
    th0 = sign * rng.uniform(0.05, 0.12)
    if law:
        r = simulate(block, th0, 0.0, duration, 2e-5, **law)
    else:
        r = simulate(block, th0, 0.0, duration, 2e-5, restitution="constant", eta=eta)
    t = np.arange(0, duration, 1 / FPS)
    th = np.interp(t - t_rel, r.t_s, r.theta_rad, left=th0, right=0.0)
    return t, th + rng.normal(0, noise, t.size), dict(t_rel=t_rel, theta0=th0, impacts=r.impacts)


def test_eta_e_accuracy_and_interval_coverage_50_runs():
    # Issue 5: |eta_e - 0.93| <= 0.002 and the 95 % interval covers the truth in >= 90 % of 50 runs.
    covered, errs = 0, []
    for seed in range(50):
        t, y, tr = synthetic(seed)
        f = fit_restitution(t, y, B6M)
        assert f.ok, f.message
        errs.append(f.eta_e - 0.93)
        lo, hi = f.ci95_eta_e
        covered += lo <= 0.93 <= hi
    assert np.max(np.abs(errs)) <= 0.002
    assert covered >= 45, covered
    # the interval is not vacuous: its width is far below the accuracy requirement
    assert hi - lo < 1e-3


def test_fit_recovers_release_theta0_and_reports():
    t, y, tr = synthetic(3)
    f = fit_restitution(t, y, B6M)
    assert abs(f.release_t_s - tr["t_rel"]) < 2e-3
    assert abs(f.theta0_rad - tr["theta0"]) < 1e-4
    assert f.rms_residual_rad == pytest.approx(NOISE, rel=0.15)  # residuals are the noise
    assert not f.suspicious and f.flags == () and f.at_bound == ()
    assert abs(f.eta_e_first - 0.93) < 0.003
    assert f.n_impacts >= 15
    d = f.to_dict()
    json.dumps(d)
    assert set(
        [
            "eta_e",
            "eta_e_first",
            "ci95_eta_e",
            "theta0_rad",
            "release_t_s",
            "rms_residual_rad",
            "per_impact_eta",
            "status",
        ]
    ) <= set(d)
    rep = f.report()
    assert "eta_e:" in rep and "profile likelihood" in rep and "at bound" not in rep


@pytest.mark.parametrize("window,objective", [("all", "theta"), ("middle50", "peaks"), ("first", "theta")])
def test_other_windows_and_objectives(window, objective):
    t, y, _ = synthetic(7)
    f = fit_restitution(t, y, B6M, window=window, objective=objective)
    assert abs(f.eta_e - 0.93) < 0.002
    lo, hi = f.ci95_eta_e
    # (coverage is tested for the default window above; here only a sane, narrow interval)
    assert lo < f.eta_e < hi and hi - lo < 0.004


def test_negative_start_and_other_block():
    t, y, tr = synthetic(11, sign=-1.0)
    f = fit_restitution(t, y, B6M)
    assert f.theta0_rad < 0 and abs(f.eta_e - 0.93) < 0.002
    b2l = catalogue_block("B2L")  # stocky: eta_H = 0.54, Table 3 eta_e,full = 0.708
    t, y, _ = synthetic(12, eta=0.708, block=b2l)
    f = fit_restitution(t, y, b2l)
    assert abs(f.eta_e - 0.708) < 0.002


def test_first_half_period_sees_the_first_impact_only():
    # eta changes during rocking: 0.95 at the first impact, then 0.90. eta'_e (first post-impact
    # half-period) must find 0.95. No constant eta matches the middle 50 % (amplitudes there need
    # 0.90 per impact after a 0.95 one): eta_e is a compromise close to 0.90, and the misfit shows.
    t, y, _ = synthetic(5, law=dict(restitution="per_impact", eta=[0.95] + [0.90] * 200))
    f = fit_restitution(t, y, B6M)  # 6.8e-3 rad RMS: flagged by the runs test, below W-FIT-RESIDUAL's 0.02
    assert abs(f.eta_e_first - 0.95) < 0.003
    assert 0.90 < f.eta_e < 0.92 and f.suspicious
    assert any("structured residuals" in s for s in f.flags)
    assert not any("asymmetric" in s for s in f.flags)


def test_per_impact_eta_within_001():
    n_ok = 0
    for seed in range(1, 6):
        t, y, tr = synthetic(seed)
        pie = per_impact_eta(t, y, B6M)
        ok = pie[pie.ok]
        n_ok += len(ok)
        assert np.all(np.abs(ok.eta_peaks - 0.93) <= 0.01), seed
    assert n_ok >= 20  # impacts with adjacent peaks well above the noise are flagged ok
    t, y, tr = synthetic(0)
    pie = per_impact_eta(t, y, B6M)
    ok = pie[pie.ok]
    assert np.all(np.abs(ok.eta_peaks - 0.93) <= 0.01)
    # impact times agree with the simulator's impacts
    true_t = tr["impacts"].t_s.to_numpy()[: len(ok)] + tr["t_rel"]
    assert np.all(np.abs(ok.t_s.to_numpy() - true_t) < 1.5e-3)
    # local-fit velocities (no model): unbiased but noisy at 0.02°/150 fps; documented spread
    first = pie.eta_velocity.to_numpy()[:6]
    assert np.all(np.abs(first - 0.93) < 0.08)
    # noise-free record: both estimators are exact to sampling/fit error
    t, y0, _ = synthetic(0, noise=0.0)
    clean = per_impact_eta(t, y0, B6M).head(8)
    assert np.all(np.abs(clean.eta_peaks - 0.93) < 5e-4)
    assert np.all(np.abs(clean.eta_velocity - 0.93) < 5e-3)


def test_per_impact_trend_is_visible():
    etas = np.linspace(0.96, 0.90, 12)
    t, y, _ = synthetic(2, law=dict(restitution="per_impact", eta=list(etas) + [0.90] * 100), noise=0.2 * NOISE)
    pie = per_impact_eta(t, y, B6M).head(8)
    assert np.all(np.abs(pie.eta_peaks.to_numpy() - etas[:8]) < 0.005)
    assert np.polyfit(np.arange(8), pie.eta_peaks, 1)[0] < 0


def test_thesis_eq12_energy_loss_from_peaks():
    # Energy is conserved between impacts, so the loss between successive peaks is 1 - eta^2.
    t, y, _ = synthetic(4)
    el = energy_loss_from_peaks(t, y, B6M)
    assert el.exact and el.start == 0
    assert el.mean4 == pytest.approx(1 - 0.93**2, abs=0.004)
    assert el.eta_equivalent == pytest.approx(0.93, abs=0.002)
    assert el.mean4 == pytest.approx(np.mean(el.loss[:4]), rel=1e-14)
    assert "Eq. 12" in el.report()
    json.dumps(el.to_dict())
    # thesis small-angle variant (u ~ |theta|, no block): first-order approximation, biased low
    approx = energy_loss_from_peaks(t, y)
    assert not approx.exact and 0.5 * el.mean4 < approx.mean4 < 1.5 * el.mean4
    with pytest.raises(InputError):
        energy_loss_from_peaks(t, y, B6M, start=400)


def test_failed_fits_have_reasons():
    t, y, tr = synthetic(1)
    # fewer than 3 impacts: cut the record after the second impact
    t2 = tr["impacts"].t_s.to_numpy()[1] + tr["t_rel"] + 0.05
    f = fit_restitution(t[t < t2], y[t < t2], B6M)
    assert f.status == "failed" and "impact" in f.message and math.isnan(f.eta_e)
    assert "FAILED" in f.report()
    # record starting in motion: no release
    m = t > tr["t_rel"] + 0.05
    f = fit_restitution(t[m], y[m], B6M)
    assert f.status == "failed" and "release" in f.message


def test_bad_input_errors():
    t, y, _ = synthetic(1)
    y2 = y.copy()
    y2[100] = np.nan
    with pytest.raises(InputError, match="sample 100"):
        fit_restitution(t, y2, B6M)
    f = fit_restitution(t, y2, B6M, nan="skip")
    assert f.ok and f.n_skipped == 1 and abs(f.eta_e - 0.93) < 0.002
    with pytest.raises(InputError, match="eta_bounds"):
        fit_restitution(t, y, B6M, eta_bounds=(0.5, 1.0))
    with pytest.raises(InputError, match="too short"):
        fit_restitution(t[:5], y[:5], B6M)
    with pytest.raises(InputError, match="same length"):
        fit_restitution(t, y[:-1], B6M)
    with pytest.raises(InputError, match="window"):
        fit_restitution(t, y, B6M, window="middle")


def test_parameter_at_bound_is_flagged():
    t, y, _ = synthetic(8)
    with pytest.warns(RocklabWarning, match="W-FIT-BOUND"):
        f = fit_restitution(t, y, B6M, eta_bounds=(0.5, 0.9295))
    assert "eta_e" in f.at_bound and f.eta_e == pytest.approx(0.9295, abs=1e-4)
    assert f.status == "suspect" and "W-FIT-BOUND" in f.warnings and f.ok
    assert "(at bound!)" in f.report()


def test_suspicious_runs_flagged():
    # a slip: the block's rest position jumps by 0.01 rad during rocking
    t, y, tr = synthetic(9)
    y_slip = y + np.where(t > 1.6, 0.01, 0.0)
    f = fit_restitution(t, y_slip, B6M)
    assert f.suspicious and any("rest" in s or "residual" in s for s in f.flags)
    # unequal corners: eta alternates 0.95 / 0.91
    t, y, _ = synthetic(10, law=dict(restitution="per_impact", eta=[0.95, 0.91] * 100))
    f = fit_restitution(t, y, B6M)
    assert f.suspicious and any("asymmetric" in s for s in f.flags)


def test_repeats_mean_std_and_outliers():
    vals = [0.930, 0.931, 0.929, 0.9305, 0.9295, 0.95, float("nan")]
    s = summarize_repeats(vals)
    assert s.outliers == (5,) and s.failed == (6,) and s.n_used == 5
    assert s.mean == pytest.approx(np.mean(vals[:5]), rel=1e-14)
    assert s.std == pytest.approx(np.std(vals[:5], ddof=1), rel=1e-12)
    assert "outliers" in s.report()


def test_slender_block_many_impacts_no_cycle_slip():
    # B9M (h/b = 8.25, Table 3 eta_e,full = 0.969): ~50 impacts in 10 s. θ(t) over the middle
    # window is multimodal in η; the fit must not lock onto a neighbouring half-cycle.
    b9m = catalogue_block("B9M")
    t, y, _ = synthetic(21, eta=0.969, block=b9m, duration=10.0)
    f = fit_restitution(t, y, b9m)
    assert f.n_impacts > 30 and abs(f.eta_e - 0.969) < 0.002 and not f.suspicious


def test_fit_many_and_summary_of_fits():
    t, y, tr = synthetic(13)
    m = t > tr["t_rel"] + 0.05  # second run starts in motion: a failed fit
    fits = fit_many([(t, y), (t[m], y[m])], block=B6M)
    s = summarize_repeats(fits)
    assert fits[0].ok and not fits[1].ok
    assert s.failed == (1,) and s.n_used == 1 and s.mean == fits[0].eta_e and math.isnan(s.std)


def test_level_offset_fitted():
    # a camera levelled 0.2° off: the block impacts at θ_measured = 0.0035 rad
    t, y, _ = synthetic(14)
    off = math.radians(0.2)
    f = fit_restitution(t, y + off, B6M, fit_offset=True)
    assert f.theta_offset_rad == pytest.approx(off, abs=2e-4)
    assert abs(f.eta_e - 0.93) < 0.002 and abs(f.eta_e_first - 0.93) < 0.003
    assert not any("rest" in s for s in f.flags)
    plain = fit_restitution(t, y + off, B6M)  # without the offset the rest level gives it away
    assert plain.suspicious and any("fit_offset" in s for s in plain.flags)


def test_campaign_table_groups_runs_and_feeds_k_table():
    import dataclasses

    from rocklab.fitting import campaign_table, k_table

    t, y, _ = synthetic(13)
    f = fit_restitution(t, y, B6M)
    b2m = catalogue_block("B2M")
    runs = [(B6M, dataclasses.replace(f, eta_e=v)) for v in (0.941, 0.942, 0.940, 0.99)]
    runs += [(b2m, dataclasses.replace(f, eta_e=v)) for v in (0.67, 0.672)]
    tab = campaign_table(runs).set_index("block")
    assert tab.loc["B6M", "n_outliers"] == 1 and tab.loc["B6M", "eta_e"] == pytest.approx(0.941, abs=1e-12)
    assert tab.loc["B2M", "eta_e"] == pytest.approx(0.671, abs=1e-12) and tab.loc["B2M", "n_used"] == 2
    kt = k_table(tab.reset_index(), eta_mat=0.989, form=None)
    assert set(kt.per_block.block) == {"B6M", "B2M"}


def test_interval_reaching_the_search_bound_is_suspect():
    # a profile flat out to the search range: the data do not constrain eta_e within it. It was
    # reported "ok" (a demo B9M film of 13 s gave [0.05, 0.968]); now W-FIT-BOUND, suspect.
    t, y, _ = synthetic(3, eta=0.93, noise=0.002)
    with collecting():
        f = fit_restitution(t, y, B6M, eta_bounds=(0.9297, 0.934))
    assert not f.at_bound  # both estimates are inside the range (0.92995, 0.93135) ...
    assert f.ci95_eta_e[0] == pytest.approx(0.9297)  # ... but the interval runs into its lower end
    assert f.status == "suspect" and "W-FIT-BOUND" in f.warnings and "95 % interval" in f.message
    with collecting():
        wide = fit_restitution(t, y, B6M)
    assert wide.status == "ok" and "W-FIT-BOUND" not in wide.warnings
