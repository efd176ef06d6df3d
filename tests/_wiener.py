"""What any linear smoother can reach on a table's acceleration from a noisy IMU and a noisy film.

An independent reference for ``rocklab.tracking.fuse_table_motion``, computed from the TRUE
acceleration ``a`` (known on synthetic tables) and the two sensors' stated noise, in the frequency
domain (two-sided densities):

- the IMU: white noise ``sigma_a`` per sample at ``rate_a`` over the interval mean of ``a`` (the
  synthetic IMU's): ``N_a(f) = sigma_a^2 / rate_a / sinc^2(f / rate_a)`` below ``rate_a / 2``,
  nothing above (aliased);
- the film: white noise ``sigma_x`` per frame at ``rate_x`` on the displacement ``x = -a / w^2``
  (``w = 2 pi f``): ``N_x(f) = w^4 sigma_x^2 / rate_x`` on ``a``, below ``rate_x / 2`` only (the
  displacement above is ``a / w^2``, negligible, so aliasing brings nothing);
- both at once: ``1/N = 1/N_a + 1/N_x`` (independent noises on one quantity).

A linear time-invariant smoother ``H(f)`` applied to ``a + n`` has the expected squared error
``|1 - H|^2 |A|^2 + |H|^2 M fs N`` per frequency bin; its minimum, ``H = |A|^2 / (|A|^2 + M fs N)``
(the Wiener filter knowing the signal's own periodogram, an oracle), is the least error of any
LTI smoother. A table is not stationary (at rest, then shaking), so a smoother may adapt; the
same oracle per cell of a short-time Fourier transform (windows of ``window_s``) bounds the
smoothers whose signal model is a spectrum that changes over the run. Neither can be reached
(both know the truth's spectrum), so a real smoother's error lies above both.
"""

from __future__ import annotations

import numpy as np


def noise_density(f, sigma_a, rate_a, sigma_x, rate_x):
    """Two-sided density of the combined measurement noise on the acceleration, (m/s²)²/Hz (inf
    where neither sensor sees ``f``)."""
    f = np.abs(np.asarray(f, float))
    inv = np.where(f < rate_a / 2, np.sinc(f / rate_a) ** 2 * rate_a / sigma_a**2, 0.0)
    w4 = (2 * np.pi * np.maximum(f, 1e-12)) ** 4
    inv = inv + np.where(f < rate_x / 2, rate_x / (w4 * sigma_x**2), 0.0)
    with np.errstate(divide="ignore"):
        return 1.0 / inv


def linear_smoother_bounds(a, fs, mask, sigma_a, rate_a, sigma_x, rate_x, windows_s=(0.25, 0.5), draws=4, seed=0):
    """Relative RMS error (over ``mask``, relative to RMS of ``a[mask]``) of the oracle Wiener
    smoothers: ``{"lti": expected, "lti_drawn": mean over draws, window_s: mean over draws}``.

    ``a`` : the true acceleration on a regular grid of ``fs`` Hz with rest on both sides (m/s²);
    ``mask`` : the samples the error is measured on.
    """
    from scipy.signal import istft, stft

    a = np.asarray(a, float)
    M = a.size
    f = np.fft.rfftfreq(M, 1.0 / fs)
    A = np.fft.rfft(a)
    N = noise_density(f, sigma_a, rate_a, sigma_x, rate_x)
    seen = np.isfinite(N)
    P = np.abs(A) ** 2
    NW = np.where(seen, M * fs * np.where(seen, N, 0.0), np.inf)  # E|W_k|^2
    H = np.where(seen, P / (P + np.where(seen, NW, 1.0)), 0.0)
    E = np.where(seen, P * np.where(seen, NW, 0.0) / (P + np.where(seen, NW, 1.0)), P)
    wts = np.full(f.size, 2.0)
    wts[0] = 1.0
    if M % 2 == 0:
        wts[-1] = 1.0
    ms = float(np.mean(a[mask] ** 2))
    # the LTI error is stationary: its mean square over the mask is its mean over the grid
    out: dict = {"lti": float(np.sqrt(np.sum(wts * E) / M**2 / ms))}
    rng = np.random.default_rng(seed)
    lti, loc = [], {w: [] for w in windows_s}
    for _ in range(draws):
        W = np.fft.rfft(rng.standard_normal(M)) * np.sqrt(np.where(seen, fs * np.where(seen, N, 0.0), 0.0))
        Y = np.where(seen, A + W, 0.0)
        lti.append(np.fft.irfft(H * Y, M))
        y = np.fft.irfft(Y, M)
        for w in windows_s:
            n = int(round(w * fs))
            kw = dict(fs=fs, nperseg=n, noverlap=3 * n // 4)
            ff, _, Sa = stft(a, **kw)
            Sy = stft(y, **kw)[2]
            win = np.hanning(n + 1)[:-1]  # scipy's default window, its scaling
            Nc = np.interp(ff, f, np.where(seen, N, 1e30)) * fs * np.sum(win**2) / np.sum(win) ** 2
            Pa = np.abs(Sa) ** 2
            loc[w].append(istft(Pa / (Pa + Nc[:, None]) * Sy, **kw)[1][:M])

    def rel(est):
        return float(np.mean([np.sqrt(np.mean((e[mask] - a[mask]) ** 2) / ms) for e in est]))

    out["lti_drawn"] = rel(lti)
    for w in windows_s:
        out[w] = rel(loc[w])
    return out
