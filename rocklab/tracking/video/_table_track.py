"""Table motion from a tracked displacement: Savitzky-Golay derivatives with the
window chosen from the measurement noise (the result: :class:`rocklab.series.TableMotion`)."""

from __future__ import annotations

import numpy as np

from ..._errors import InputError
from ...series import TableMotion

__all__ = ["table_motion", "estimate_noise", "choose_sg_window"]


def _segments(ok):
    """(start, stop) of runs where ``ok`` is True."""
    d = np.diff(np.r_[0, ok.astype(np.int8), 0])
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def _longest(x):
    segs = _segments(np.isfinite(x))
    if not segs:
        return np.array([])
    a, b = max(segs, key=lambda ab: ab[1] - ab[0])
    return x[a:b]


def _spectrum(x):
    """Hann-tapered periodogram of the detrended samples; E[P] = σ² for white noise."""
    n = len(x)
    k = np.arange(n)
    x = x - np.polyval(np.polyfit(k, x, 1), k)
    w = np.hanning(n)
    return np.abs(np.fft.rfft(x * w)) ** 2 / np.sum(w**2)


def estimate_noise(x) -> float:
    """White-noise σ of a displacement record from its high-frequency spectral floor.

    The median Hann periodogram above 0.6 × Nyquist over ``ln 2`` (periodogram
    values of white noise are exponential with mean σ²). Assumes the motion
    itself has little power there (sampling well above its bandwidth).
    """
    seg = _longest(np.asarray(x, float))
    if len(seg) < 16:
        return np.nan
    P = _spectrum(seg)
    hi = P[int(0.6 * (len(P) - 1)) :]
    return float(np.sqrt(np.median(hi) / np.log(2.0)))


def choose_sg_window(
    x, dt_s: float = 1.0, polyorder: int | None = None, noise=None, max_window: int = 61
) -> tuple[int, int]:
    """Savitzky-Golay window and order that minimise the predicted acceleration error.

    From the record's periodogram ``P`` and noise floor ``σ²`` the signal
    spectrum is ``S = P - σ²`` where the 5-bin smoothed ``P`` exceeds ``3σ²`` (else 0); for each candidate filter ``h`` (window
    ``N``, order ``p``) the predicted mean-square error of the second derivative is
    ``2 Σ_f |H(f) + (2πf)²|² S(f) / n + σ² Σ h²`` (bias from the filter's
    departure from an ideal differentiator, plus propagated noise). So the
    window grows with the noise and shrinks with fast motion.

    Returns
    -------
    window : int (odd, samples)
    polyorder : int
    """
    from scipy.signal import savgol_coeffs

    seg = _longest(np.asarray(x, float))
    orders = [polyorder] if polyorder is not None else [2, 3, 4, 5, 6]
    lo = min(orders) + 1 + (min(orders) % 2)
    if len(seg) < max(lo, 16):
        raise InputError(
            f"table displacement has at most {len(seg)} consecutive samples; need {max(lo, 16)} to differentiate it"
        )
    sigma = estimate_noise(seg) if noise is None else float(noise)
    P = _spectrum(seg)
    n = len(seg)
    # Signal power only where it stands clearly above the noise floor: a noise bin taken
    # for signal at high frequency would be weighted by (2πf)^4 and force tiny windows.
    Ps = np.convolve(P, np.ones(5) / 5, mode="same")
    S = np.where(Ps > 3.0 * sigma**2, np.maximum(P - sigma**2, 0.0), 0.0)
    f = np.fft.rfftfreq(n, dt_s)
    ideal = -((2 * np.pi * f) ** 2)
    best, best_err = (lo, orders[0]), np.inf
    for p in orders:
        for N in range(p + 1 + (p % 2), min(max_window, n - (1 - n % 2)) + 1, 2):
            h = savgol_coeffs(N, p, deriv=2, delta=dt_s, use="dot")
            k = np.arange(N) - N // 2
            H = np.exp(-2j * np.pi * np.outer(f, k) * dt_s) @ h
            # one-sided spectrum: factor 2 for the negative frequencies (Parseval)
            err = 2 * np.sum(np.abs(H - ideal) ** 2 * S) / n + sigma**2 * np.sum(h**2)
            if err < best_err:
                best, best_err = (N, p), err
    return best


def table_motion(
    t_s, x_m, window_s: float | None = None, polyorder: int | None = None, object: str = "table"
) -> TableMotion:
    """Velocity and acceleration of a displacement record by Savitzky-Golay differentiation.

    Parameters
    ----------
    t_s : array_like (n,)
        Uniform sample times, s.
    x_m : array_like (n,)
        Displacement, m; NaN gaps are respected (each run is differentiated
        separately; runs shorter than the window give NaN).
    window_s : float, optional
        Window length in seconds; default chosen from the noise (:func:`choose_sg_window`).
    polyorder : int, optional
        Polynomial order (>= 2); default chosen with the window.
    """
    from scipy.signal import savgol_filter

    t = np.asarray(t_s, float)
    x = np.asarray(x_m, float)
    if t.shape != x.shape or t.ndim != 1 or len(t) < 2:
        raise InputError("table_motion: t_s and x_m must be 1-D arrays of the same length >= 2")
    dt = float(np.median(np.diff(t)))
    if not dt > 0:
        raise InputError("table_motion: t_s must increase")
    noise = estimate_noise(x)
    if window_s is None:
        n, polyorder = choose_sg_window(x, dt, polyorder, noise)
    else:
        polyorder = 3 if polyorder is None else int(polyorder)
        n = int(round(window_s / dt)) | 1
        n = max(n, polyorder + 2 if (polyorder + 2) % 2 else polyorder + 3)
    ok = np.isfinite(x)
    first = np.flatnonzero(ok)
    x0 = x[first[0]] if len(first) else 0.0
    xs = x - x0
    v = np.full_like(x, np.nan)
    a = np.full_like(x, np.nan)
    for s0, s1 in _segments(ok):
        if s1 - s0 >= n:
            seg = xs[s0:s1]
            v[s0:s1] = savgol_filter(seg, n, polyorder, deriv=1, delta=dt, mode="interp")
            a[s0:s1] = savgol_filter(seg, n, polyorder, deriv=2, delta=dt, mode="interp")
    return TableMotion(t, xs, v, a, int(n), int(polyorder), float(noise), object)
