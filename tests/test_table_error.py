"""The fused table's own error drawn by the validation ensembles (``rocklab.fitting.fused_error_draw``):
its band variances are the measured ones, it follows the smoother's σ, it leaves every other draw
as it was, it covers the error of a fused synthetic table (an independent check: a film of white
noise, not the rendered development sessions the spectrum was measured on), and a column model
whose band misses the measurement is not called consistent."""

import numpy as np
import pytest
from scipy.signal import butter, sosfiltfilt

from rocklab.fitting import FUSED_ERROR_BANDS_HZ, FUSED_ERROR_Z_VAR, InputUncertainty, fused_error_draw

FS = 256.0


def _band_var(x, keep):
    """Variance of ``x`` at ``keep`` in each band of FUSED_ERROR_BANDS_HZ (4th-order zero-phase filters)."""
    out = []
    for lo, hi in FUSED_ERROR_BANDS_HZ:
        if lo <= 0:
            sos = butter(4, hi, "lowpass", fs=FS, output="sos")
        elif hi >= FS / 2:
            sos = butter(4, lo, "highpass", fs=FS, output="sos")
        else:
            sos = butter(4, [lo, hi], "bandpass", fs=FS, output="sos")
        out.append(float(np.mean(sosfiltfilt(sos, x)[keep] ** 2)))
    return np.array(out)


def test_draw_has_the_measured_band_variances_and_follows_sigma():
    """Unit σ: the draws' variance in every band from 2 Hz up is the table's within 25 % (the
    filters' overlap); the total is their sum within 5 %. σ stepping from 1 to 3 triples the RMS."""
    rng = np.random.default_rng(0)
    t = np.arange(0, 8, 1 / FS)
    mid = (t > 1) & (t < 7)
    v = np.mean([_band_var(fused_error_draw(t, np.ones(t.size), rng), mid) for _ in range(40)], axis=0)
    ratio = v / np.array(FUSED_ERROR_Z_VAR)
    lows = np.array([lo for lo, _ in FUSED_ERROR_BANDS_HZ])
    assert np.all(np.abs(ratio[lows >= 2] - 1) < 0.25), ratio
    x = np.concatenate([fused_error_draw(t, np.ones(t.size), rng) for _ in range(20)])
    assert np.var(x) == pytest.approx(sum(FUSED_ERROR_Z_VAR), rel=0.05)
    sig = np.where(t < 4, 1.0, 3.0)
    d = np.array([fused_error_draw(t, sig, rng) for _ in range(20)])
    r = np.sqrt(np.mean(d[:, (t > 4.5) & (t < 7.5)] ** 2) / np.mean(d[:, (t > 0.5) & (t < 3.5)] ** 2))
    assert r == pytest.approx(3.0, rel=0.07)
    assert np.all(fused_error_draw(t, np.ones(t.size), rng, gain=0.0) == 0.0)


def test_other_draws_unchanged_and_the_error_added_only_for_a_fused_table():
    """Without σ, or with acc_fused 0, a table draw is bitwise the draw without the fused error (the
    IMU-only ensembles keep their members); with both, it differs by the fused error alone, whose
    RMS is σ times the square root of the table's total."""
    from rocklab.fitting._ensemble import table_draw

    t = np.arange(0, 6, 1 / FS)
    a = np.sin(2 * np.pi * t)
    unc = InputUncertainty(0.05, 0.01, 1e-4, 0.0, 0.0, 0.0, 0.003, acc_fused=1.0)
    off = InputUncertainty(0.05, 0.01, 1e-4, 0.0, 0.0, 0.0, 0.003, acc_fused=0.0)
    sig = np.full(t.size, 0.02)
    none = table_draw(t, a, unc, np.random.default_rng(5), 0.0).acc_m_s2
    zero = table_draw(t, a, off, np.random.default_rng(5), 0.0, sigma_m_s2=sig).acc_m_s2
    fused = table_draw(t, a, unc, np.random.default_rng(5), 0.0, sigma_m_s2=sig).acc_m_s2
    assert np.array_equal(none, zero)
    d = (fused - none)[500:-500]
    assert np.sqrt(np.mean(d**2)) == pytest.approx(0.02 * np.sqrt(sum(FUSED_ERROR_Z_VAR)), rel=0.15)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_drawn_error_covers_a_fused_synthetic_pulse(seed):
    """A 45 mm / 0.6 s sine pulse filmed at 50 fps (0.02 mm white noise) and logged by a 256 Hz, 5 mg
    IMU, fused: its true error over σ while the table moves has at most the drawn variance in all
    (measured 0.68-1.08 against 1.43) and below 5 Hz, the band a rocking block feels (0.018-0.087
    against 0.120)."""
    from test_table_scale import _sources

    from rocklab.synth._scripted_motion import sine_pulse_table
    from rocklab.tracking import fuse_table_motion

    table = sine_pulse_table(1.0, 0.6, 0.045)
    m = fuse_table_motion(*_sources(seed, 0.0, 0.0)).motion
    at = table.a(m.t_s)
    v = _band_var((m.ax_m_s2 - at) / m.sigma_ax_m_s2, np.abs(at) > 0)
    env = np.array(FUSED_ERROR_Z_VAR)
    below5 = np.array([hi <= 5 for _, hi in FUSED_ERROR_BANDS_HZ])
    assert 0.5 < v.sum() < env.sum()
    assert v[below5].sum() < env[below5].sum()


def _column_case(cover_fraction):
    """A one-level column that opens cw at 0.3 s, closes at 0.6 s and opens ccw; every member has
    exactly the measured motion, and the band holds ``cover_fraction`` of the measured samples."""
    from rocklab.fitting import ColumnEnsemble
    from rocklab.models import joint_sequence

    t = np.arange(0, 1.0, 0.02)
    y = np.where(t < 0.3, 0.0, np.where(t < 0.6, 0.02, -0.02))[:, None]
    n = 20
    th = np.repeat(y[None], n, axis=0)
    band = np.stack([y - 1e-3, y + 1e-3])
    k = int(round((1 - cover_fraction) * t.size))
    band[:, t.size - k :] += 0.01  # the band misses the last k samples
    seqs = [joint_sequence(t, th[i], 0.005) for i in range(n)]
    return t, y, ColumnEnsemble(t, th, seqs, np.zeros(n, bool), band)


@pytest.mark.parametrize("cover, verdict", [(1.0, "consistent"), (0.92, "consistent"), (0.88, "undecided")])
def test_column_consistent_needs_the_band_to_hold_the_measurement(cover, verdict):
    """Every event matched by every member, the count's p-value 1: consistent only with 90 % of the
    samples inside the band (0.92 consistent, 0.88 undecided)."""
    from rocklab.fitting import judge_column

    t, y, ens = _column_case(cover)
    v = judge_column(t, y, ens, [0.46], tol_s=0.02, t_start_s=0.0)
    assert v.all_matched_inside and v.n_events_inside >= 2
    assert v.band_coverage == pytest.approx(cover, abs=0.011)
    assert v.verdict == verdict
