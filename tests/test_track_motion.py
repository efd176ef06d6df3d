"""Table motion: Savitzky-Golay derivatives with the window chosen from the noise."""

from __future__ import annotations

import numpy as np
import pytest

from rocklab import InputError
from rocklab.tracking import estimate_noise, table_motion

FPS = 50.0
A_M, T_S = 0.045, 0.6  # thesis Fig. 31: 45 mm, 0.6 s sine pulse


def _pulse(t):
    """45 mm, 0.6 s sine with a raised-cosine envelope (smooth start/stop), and its exact
    second derivative."""
    w = 2 * np.pi / T_S
    t0, t1, r = 0.3, 2.7, 0.3
    u = np.clip(np.minimum(t - t0, t1 - t) / r, 0, 1)
    e = 0.5 - 0.5 * np.cos(np.pi * u)
    du = np.where((u > 0) & (u < 1), np.where(t - t0 < t1 - t, 1.0, -1.0) / r, 0.0)
    e1 = 0.5 * np.pi * np.sin(np.pi * u) * du
    e2 = 0.5 * np.pi**2 * np.cos(np.pi * u) * du**2
    s, c = np.sin(w * t), np.cos(w * t)
    x = A_M * s * e
    a = A_M * (-(w**2) * s * e + 2 * w * c * e1 + s * e2)
    return x, a


@pytest.mark.parametrize("noise_m", [2e-5, 5e-5])
def test_sine_pulse_acceleration_within_5_percent(noise_m):
    """Video-like displacement noise (0.02-0.05 mm at 1.8 px/mm) -> acceleration RMS error <= 5 %."""
    t = np.arange(0, 3.0, 1 / FPS)
    x, a = _pulse(t)
    rng = np.random.default_rng(1)
    tm = table_motion(t, x + rng.normal(0, noise_m, t.size))
    m = (t > 0.2) & (t < 2.8)
    rel = np.sqrt(np.mean((tm.ax_m_s2[m] - a[m]) ** 2)) / np.sqrt(np.mean(a[m] ** 2))
    assert rel <= 0.05
    assert tm.noise_m == pytest.approx(noise_m, rel=0.35)
    # velocity too, against the exact derivative
    v_exact = np.gradient(x, t)  # only for a loose check; central differences are O(dt^2)
    assert np.sqrt(np.mean((tm.vx_m_s[m] - v_exact[m]) ** 2)) < 0.02 * np.max(np.abs(v_exact))


def test_window_grows_with_noise():
    t = np.arange(0, 3.0, 1 / FPS)
    x, _ = _pulse(t)
    rng = np.random.default_rng(2)
    windows = [table_motion(t, x + rng.normal(0, s, t.size)).window_s for s in (1e-5, 1e-4, 1e-3)]
    assert windows[0] < windows[1] < windows[2]


def test_noise_estimate_on_white_noise():
    rng = np.random.default_rng(3)
    for s in (1e-5, 1e-3):
        assert estimate_noise(rng.normal(0, s, 600)) == pytest.approx(s, rel=0.15)


def test_gaps_stay_nan_and_segments_are_differentiated_separately():
    t = np.arange(0, 4.0, 1 / FPS)
    x = 0.5 * 2.0 * t**2  # constant 2 m/s² acceleration
    x[80:130] = np.nan
    tm = table_motion(t, x, window_s=0.2, polyorder=2)
    assert np.all(np.isnan(tm.ax_m_s2[80:130]))
    ok = np.isfinite(tm.ax_m_s2)
    np.testing.assert_allclose(tm.ax_m_s2[ok], 2.0, rtol=1e-6)
    # displacement is relative to the first valid sample
    assert tm.x_m[0] == 0.0
    bm = tm.to_base_motion()
    assert bm.pga_m_s2 == pytest.approx(2.0, rel=1e-6)


def test_too_short_record_is_an_input_error():
    with pytest.raises(InputError, match="consecutive samples"):
        table_motion(np.arange(10) / FPS, np.r_[np.zeros(5), np.nan, np.zeros(4)])
