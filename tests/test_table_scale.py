"""The table acceleration's scale uncertainty measured from the table IMU's agreement with the film
(``rocklab.tracking.table_scale_agreement``), on synthetic tables with injected scale errors: the
film's displacement at 50 fps with the demo tracker's 0.02 mm noise, the IMU's acceleration at
256 Hz with 5 mg noise, an offset and dropped samples, both on one clock."""

import math

import numpy as np
import pytest

from rocklab.tracking import FILM_SCALE_SD, IMU_SCALE_SD, table_motion, table_scale_agreement


def _sources(seed, e_imu, e_film, *, period_s=0.6, T=3.0):
    """(video TableMotion, IMU t, IMU acceleration) of a one-cycle sine pulse (thesis Fig. 31), the
    IMU reading ``1 + e_imu`` times the truth, the film ``1 + e_film``."""
    from rocklab.synth._scripted_motion import sine_pulse_table

    table = sine_pulse_table(1.0, period_s, 0.045)
    rng = np.random.default_rng(seed)
    ti = np.arange(-rng.uniform(0.5, 1.5), T, 1 / 256.0)
    keep = np.ones(ti.size, bool)
    k = rng.integers(50, ti.size - 50)
    keep[k : k + 6] = False  # a burst of lost packets
    ti = ti[keep]
    a = (1 + e_imu) * table.a(ti) + 0.049 * rng.standard_normal(ti.size) + 0.01
    tv = np.arange(int(T * 50)) / 50.0
    video = table_motion(tv, (1 + e_film) * table.u(tv) + 2e-5 * rng.standard_normal(tv.size))
    return video, ti, a


@pytest.mark.parametrize("e_imu, e_film", [(0.008, 0.0), (-0.005, 0.002), (0.0, -0.004)])
def test_injected_scale_error_recovered_within_its_sd(e_imu, e_film):
    """The film's scale over the IMU's is the injected one within 2 standard errors, and the
    standard error is far below the 1 % prior (measured 0.19-0.33 %); a wrong answer (no error
    found, or the opposite sign) is outside."""
    for seed in range(3):
        video, ti, a = _sources(seed, e_imu, e_film)
        sc = table_scale_agreement(video, ti, a)
        d_true = (1 + e_film) / (1 + e_imu) - 1
        assert sc.status == "ok"
        assert abs(sc.ratio_minus_one - d_true) < 2 * sc.se
        assert sc.se < 0.004
        assert abs(sc.ratio_minus_one + d_true) > 2 * sc.se  # the sign is told
        # a sine pulse's acceleration is carried by the film below a few hertz
        assert sc.film_weight > 0.8  # measured 0.88


def test_standard_error_and_sd_are_calibrated():
    """Over 24 sessions with scale errors drawn from the priors (IMU 1 %, film 0.3 %): the measured
    disagreement's z = (d - d_true) / se has RMS near 1 (measured 0.85; 0.94 over 60) and |z| < 2 in
    at least 20 (measured 23); the fused table's scale error over the sd sampled has RMS near 1
    (measured 1.06; 1.14 over 60) and is within 2 sd in at least 20 (measured 22; 55 of 60)."""
    z, r = [], []
    for seed in range(24):
        rng = np.random.default_rng(100 + seed)
        e_i, e_f = IMU_SCALE_SD * rng.standard_normal(), FILM_SCALE_SD * rng.standard_normal()
        sc = table_scale_agreement(*_sources(seed, e_i, e_f))
        z.append((sc.ratio_minus_one - ((1 + e_f) / (1 + e_i) - 1)) / sc.se)
        r.append((sc.film_weight * e_f + (1 - sc.film_weight) * e_i) / sc.sd)
    z, r = np.array(z), np.array(r)
    assert 0.6 < np.sqrt(np.mean(z**2)) < 1.4
    assert np.sum(np.abs(z) < 2) >= 20
    assert 0.6 < np.sqrt(np.mean(r**2)) < 1.4
    assert np.sum(np.abs(r) < 2) >= 20


def test_agreeing_sources_leave_the_shared_floor_and_disagreeing_ones_their_difference():
    """Exact sources: the sd is about the floor, (1/0.3² + 1/1²)^-1/2 = 0.287 %, not the 1 % prior;
    an IMU 4 % off (beyond what the priors allow) is sampled in full."""
    floor = 1 / math.sqrt(1 / FILM_SCALE_SD**2 + 1 / IMU_SCALE_SD**2)
    sc = table_scale_agreement(*_sources(0, 0.0, 0.0))
    assert sc.floor == pytest.approx(floor) and floor == pytest.approx(0.00287, abs=1e-5)
    assert floor <= sc.sd < 0.0035
    bad = table_scale_agreement(*_sources(0, 0.04, 0.0))
    assert bad.sd >= abs(bad.ratio_minus_one) > 0.03 and "disagree" in bad.message


def test_validation_samples_the_measured_scale_and_keeps_the_prior_for_one_source():
    """The single-block and the column validations' input uncertainty take a fused table's measured
    scale sd and draw its own error (acc_fused 1, from its smoother's σ); an IMU table alone keeps
    ACC_SCALE_SD (1 %) and draws no fused error."""
    import dataclasses
    from types import SimpleNamespace

    from rocklab.pipelines._validation import ACC_SCALE_SD, _uncertainty, acc_scale_sd
    from rocklab.pipelines.experiment._column_run import _column_uncertainty
    from rocklab.series import TableMotion

    t = np.arange(0, 4, 1 / 256.0)
    a = np.where(t > 1.0, np.sin(2 * np.pi * (t - 1.0)), 0.0) + 0.01 * np.random.default_rng(0).standard_normal(t.size)
    imu = TableMotion.from_acceleration(t, a, "imu")
    fused = dataclasses.replace(
        imu, source="fused", acc_noise_m_s2=0.01, acc_scale_sd=0.0031, sigma_ax_m_s2=np.full(t.size, 0.02)
    )
    cfg = SimpleNamespace(table=SimpleNamespace(source="imu"), path="synthetic")
    y = np.r_[np.zeros(50), 0.01 * np.sin(np.arange(150) / 5.0)] + 1e-4 * np.random.default_rng(1).standard_normal(200)
    assert _uncertainty(cfg, imu, None, y, [])[0].acc_scale == ACC_SCALE_SD == 0.01
    assert _uncertainty(cfg, fused, None, y, [])[0].acc_scale == 0.0031
    assert acc_scale_sd(fused)[1].startswith("measured") and acc_scale_sd(imu)[1].startswith("prior")
    tv = np.arange(200) / 50.0
    th = y[:, None] * np.ones((1, 2))
    assert _uncertainty(cfg, fused, None, y, [])[0].acc_fused == 1.0
    assert _uncertainty(cfg, imu, None, y, [])[0].acc_fused == 0.0
    col_fused, col_imu = (_column_uncertainty(None, tv, th, 1.0, tab) for tab in (fused, imu))
    assert col_fused.acc_scale == 0.0031 and col_fused.acc_fused == 1.0
    assert col_imu.acc_scale == 0.01 and col_imu.acc_fused == 0.0
