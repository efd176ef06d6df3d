"""Clock synchronisation of two angular-rate signals (IMU vs video track, or two IMUs).

Convention: signal b at its time ``t_b`` corresponds to signal a at
``t_a = t_b + offset_s + drift * t_b`` (``SyncResult.to_a``).

Method (``sync_offset``)
------------------------
1. Coarse: both rates resampled on a common 1 kHz grid (a box-filtered to
   b's differentiation window), normalised cross-correlation, parabolic
   interpolation of the peak.
2. Fine: least squares.  With a differentiated track (``window_b_s > 0``) on
   the *integrated* rates (angles, which do not amplify the track's noise the
   way differences do): minimise over the offset the residual of
   ``B(t_b) - A_w(t_b + offset)`` after removing a constant and a linear trend
   (integration constant, gyro bias residual), with ``A_w`` the integral of
   a's rate smoothed by b's window.  Two gyros: on the rates themselves.
3. Windows: the fine fit in consecutive windows (101-point scan over +-max(50 ms,
   1000 ppm of the overlap) around the global offset, kept when the fit
   explains half of the window's variance); with drift (long logs) a straight
   line through the window offsets.  ``residual_ms`` is the RMS scatter of
   the window offsets about the clock model.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import cumulative_trapezoid

from .._errors import InputError

__all__ = ["SyncResult", "sync_offset", "sync_events", "track_rate", "sync_imu_to_track"]


@dataclass(frozen=True)
class SyncResult:
    """Clock model between two recordings: ``t_a = t_b + offset_s + drift * t_b``.

    Attributes
    ----------
    offset_s : float
        Offset at ``t_b = 0``, s.
    drift : float
        Clock-rate difference, s/s (0 when not fitted).
    residual_ms : float
        RMS scatter of the window offsets about the clock model, ms (NaN with
        fewer than 3 usable windows).
    correlation : float
        Peak normalised cross-correlation of the rates (0..1), normalised over
        the overlap of the two spans at that lag.
    n_windows : int
        Windows with enough motion used for the drift / residual.
    window_t_s, window_offset_s : ndarray
        Window times (b clock; slope-weighted centroids) and their offsets, s.
    sign : int
        +1, or -1 when b's rate is a's with the opposite sign convention
        (b was flipped before the fit).
    """

    offset_s: float
    drift: float
    residual_ms: float
    correlation: float
    n_windows: int = 0
    window_t_s: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)
    window_offset_s: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)
    sign: int = 1

    def to_a(self, t_b):
        """Map times on clock b to clock a, s."""
        t_b = np.asarray(t_b, float)
        return t_b + self.offset_s + self.drift * t_b

    def to_dict(self) -> dict:
        """``offset_s, offset_ms, drift, drift_ppm, residual_ms, correlation, n_windows``."""
        return {
            "offset_s": float(self.offset_s),
            "offset_ms": 1e3 * float(self.offset_s),
            "drift": float(self.drift),
            "drift_ppm": 1e6 * float(self.drift),
            "residual_ms": float(self.residual_ms),
            "correlation": float(self.correlation),
            "n_windows": int(self.n_windows),
            "sign": int(self.sign),
        }


def _clean(t, y, name):
    t = np.asarray(t, float).ravel()
    y = np.asarray(y, float).ravel()
    if t.shape != y.shape:
        raise InputError(
            f"sync: t_{name} and rate_{name} differ in length ({t.size} vs {y.size}); pass matching arrays"
        )
    ok = np.isfinite(t) & np.isfinite(y)
    t, y = t[ok], y[ok]
    if t.size < 8:
        raise InputError(f"sync: signal {name} has {t.size} finite samples; need at least 8")
    if np.any(np.diff(t) <= 0):
        raise InputError(f"sync: t_{name} must increase strictly; sort and de-duplicate the times")
    return t, y


def _box(t, y, w):
    """Rate box-filtered over width ``w`` (s), via the integral; returns a callable.

    Cubic interpolation: linear interpolation of a band-limited signal biases
    sub-sample offsets towards the sample grid (a ripple in the cost).
    """
    from scipy.interpolate import make_interp_spline

    if w <= 0:
        return make_interp_spline(t, y, k=3)
    Y = make_interp_spline(t, cumulative_trapezoid(y, t, initial=0.0), k=3)
    return lambda x: (Y(x + 0.5 * w) - Y(x - 0.5 * w)) / w


def _lowpass(t, y, fc):
    from scipy.signal import butter, sosfiltfilt

    fs = 1.0 / float(np.median(np.diff(t)))
    if fc >= 0.45 * fs or y.size < 30:
        return y
    return sosfiltfilt(butter(4, fc, fs=fs, output="sos"), y)


def _coarse(span_a, fa, tb, yb, fs, max_offset_s, center=0.0):
    from scipy.signal import correlate, correlation_lags

    ga = np.arange(span_a[0], span_a[1], 1.0 / fs)
    gb = np.arange(tb[0], tb[-1], 1.0 / fs)
    a = fa(ga)
    b = np.interp(gb, tb, yb)
    a = a - a.mean()
    b = b - b.mean()
    c = correlate(a, b, mode="full", method="fft")
    lags = correlation_lags(a.size, b.size, mode="full")
    off = ga[0] - gb[0] + lags / fs
    if max_offset_s is not None:
        c = np.where(np.abs(off - center) <= max_offset_s, c, np.nan)
    k = int(np.argmax(np.where(np.isfinite(c), np.abs(c), -np.inf)))
    # normalise over the overlap at this lag: signal outside the other's span (an IMU that
    # logs on after the camera stops) says nothing about how well the two agree
    lag = int(lags[k])
    n0, n1 = max(0, lag), min(a.size, b.size + lag)
    ao, bo = a[n0:n1], b[n0 - lag : n1 - lag]
    den = np.sqrt(np.sum(ao * ao) * np.sum(bo * bo)) or 1.0
    corr = float(c[k] / den)
    if corr < 0:
        c = -c
    frac = 0.0
    if 0 < k < c.size - 1 and np.isfinite(c[k - 1]) and np.isfinite(c[k + 1]):
        d = c[k - 1] - 2 * c[k] + c[k + 1]
        frac = 0.5 * (c[k - 1] - c[k + 1]) / d if d < 0 else 0.0
    return float(off[k] + frac / fs), corr


def _fine(ta, A, tb, B, guess, half, detrend=True, scan=None):
    """Offset minimising the residual ``B - A(t + offset)`` near ``guess`` (+- ``half``).

    The mean is always removed; ``detrend`` also removes a linear trend
    (integration constant and residual gyro bias of angles).  ``scan``: first
    evaluate the cost on these candidate offsets and start from the best.
    Returns ``(offset, explained, t_c)``: ``explained`` = 1 - cost / variance
    of B; ``t_c`` the time the offset refers to, the centroid of the samples
    weighted by the squared slope of the model (where the timing information
    is; with drift inside the window this, not the window middle, is the time
    the fitted offset belongs to).
    """
    from scipy.optimize import minimize_scalar

    x_all = tb - tb.mean()

    def resid0(y, x):
        y = y - y.mean()
        if detrend and x @ x > 0:
            y = y - x * (x @ y) / (x @ x)
        return y

    def cost(off):
        m = (tb + off > ta[0]) & (tb + off < ta[-1])
        if m.sum() < 8:
            return np.inf
        r = resid0(B[m] - A(tb[m] + off), x_all[m])
        return float(r @ r) / m.sum()

    if scan is not None and len(scan):
        c = np.array([cost(o) for o in scan])
        guess = float(scan[int(np.argmin(c))])
    res = minimize_scalar(cost, bounds=(guess - half, guess + half), method="bounded", options={"xatol": 1e-6})
    r0 = resid0(B, x_all)
    var = float(r0 @ r0) / max(1, B.size)
    off = float(res.x)
    m = (tb + off > ta[0]) & (tb + off < ta[-1])
    slope = A.derivative()(tb[m] + off) if hasattr(A, "derivative") else np.gradient(A(tb[m] + off), tb[m])
    wgt = slope**2
    t_c = float(wgt @ tb[m] / wgt.sum()) if wgt.sum() > 0 else float(tb[m].mean())
    return off, (1.0 - float(res.fun) / var) if var > 0 else 0.0, t_c


def sync_offset(
    t_a,
    rate_a,
    t_b,
    rate_b,
    *,
    max_offset_s: float | None = None,
    window_b_s: float = 0.0,
    drift: bool | str = "auto",
    window_s: float | None = None,
    grid_hz: float = 1000.0,
    theta_b=None,
) -> SyncResult:
    """Clock offset (and drift) between two angular-rate recordings.

    Parameters
    ----------
    t_a, rate_a : array_like (n,)
        Reference signal (e.g. the IMU rate about the rocking axis), s and rad/s.
    t_b, rate_b : array_like (m,)
        Signal to align (e.g. a video track's rate), s and rad/s; NaNs skipped.
    max_offset_s : float, optional
        Largest plausible |offset|, s (default: unrestricted).
    window_b_s : float
        Width of the differentiation window of b, s (``2 / fps`` for central
        differences of a track); a is smoothed the same way before comparing.
    drift : bool or "auto"
        Fit a linear clock drift (``"auto"``: when the overlap exceeds 120 s).
    window_s : float, optional
        Window length for drift / residual, s (default: overlap / 6, >= 1 s).
    grid_hz : float
        Grid rate of the coarse cross-correlation, Hz.
    theta_b : array_like (m,), optional
        b's angles (rad) when b is a track: the fine fit then compares them
        with a's integrated rate directly (no gap-bridging integration of b).

    Returns
    -------
    SyncResult
    """
    ta, ya = _clean(t_a, rate_a, "a")
    if theta_b is not None:
        th_all = np.asarray(theta_b, float).ravel()
        if th_all.shape != np.shape(np.ravel(t_b)):
            raise InputError("sync: theta_b and t_b differ in length; pass matching arrays")
    tb, yb = _clean(t_b, rate_b, "b")
    if window_b_s <= 0 and theta_b is None:
        # Two gyros: the same zero-phase low-pass on both (a quarter of the lower
        # rate).  Interpolating white noise lowers its variance between samples,
        # which would pull the offset towards half-sample shifts.
        fc = 0.25 / max(np.median(np.diff(ta)), np.median(np.diff(tb)))
        ya, yb = _lowpass(ta, ya, fc), _lowpass(tb, yb, fc)
    fa = _box(ta, ya, window_b_s)
    off0, corr = _coarse((ta[0], ta[-1]), fa, tb, yb, grid_hz, max_offset_s)
    sign = -1 if corr < 0 else 1
    yb = sign * yb
    use_angle = window_b_s > 0 or theta_b is not None
    if theta_b is not None:
        # Fine fit on b's own angles (finite samples) against a's integrated rate.
        tt = np.asarray(t_b, float).ravel()
        ok = np.isfinite(tt) & np.isfinite(th_all)
        tB, B = tt[ok], sign * th_all[ok]
        Aint = cumulative_trapezoid(ya, ta, initial=0.0)
    else:
        # Angles suit a noisy differentiated track (no noise amplification); two
        # gyros compare best on the rates themselves.
        tB, B = tb, cumulative_trapezoid(yb, tb, initial=0.0)
        Aint = cumulative_trapezoid(fa(ta), ta, initial=0.0)

    from scipy.interpolate import make_interp_spline

    A = make_interp_spline(ta, Aint, k=3)

    def fine(mask_t0, mask_t1, guess, half, scan=None):
        if use_angle:
            m = (tB >= mask_t0) & (tB < mask_t1)
            return _fine(ta, A, tB[m], B[m], guess, half, True, scan)
        m = (tb >= mask_t0) & (tb < mask_t1)
        return _fine(ta, fa, tb[m], yb[m], guess, half, False, scan)

    off = fine(-np.inf, np.inf, off0, 3.0 / grid_hz)[0]
    lo, hi = max(tb[0], ta[0] - off), min(tb[-1], ta[-1] - off)
    overlap = hi - lo
    fit_drift = (overlap > 120.0) if drift == "auto" else bool(drift)
    w = window_s or max(1.0, overlap / 6.0)
    edges = np.arange(lo, hi - 0.5 * w + 1e-9, w)
    wt, wo = [], []
    thr = 0.2 * np.std(yb[(tb >= lo) & (tb <= hi)]) if overlap > 0 else 0.0
    # Windows may drift from the global offset by up to 1000 ppm of the overlap.
    dev = max(0.05, 1e-3 * overlap)
    for e in edges:
        m = (tb >= e) & (tb < e + w)
        if m.sum() < 16 or np.std(yb[m]) < thr:
            continue
        # Scan +-dev on the grid step, then refine: robust against the other
        # peaks of a quasi-periodic (rocking) signal.
        scan = off + np.linspace(-dev, dev, 101)
        o, explained, t_c = fine(e, e + w, off, 1.5 * (scan[1] - scan[0]), scan)
        if explained < 0.5:  # too little common motion in this window to time it
            continue
        wt.append(t_c)
        wo.append(o)
    wt, wo = np.asarray(wt), np.asarray(wo)
    d = 0.0
    resid = np.nan
    if fit_drift and wt.size >= 2:
        d, c0 = np.polyfit(wt, wo, 1)
        off = float(c0)
        model = off + d * wt
    else:
        model = np.full(wt.shape, off)
    if wt.size >= 3:
        resid = 1e3 * float(np.sqrt(np.mean((wo - model) ** 2)))
    return SyncResult(float(off), float(d), resid, abs(corr), int(wt.size), wt, wo, sign)


def track_rate(t_s, theta_rad):
    """Angular rate of a video track by central differences, rad/s.

    Parameters
    ----------
    t_s, theta_rad : array_like (n,)
        Track times (s) and angles (rad); NaN where the tracker lost the object.

    Returns
    -------
    (ndarray, ndarray)
        Times and rates (n,); NaN where a neighbour is missing.
    """
    t = np.asarray(t_s, float)
    th = np.asarray(theta_rad, float)
    w = np.full(t.shape, np.nan)
    if t.size >= 3:
        w[1:-1] = (th[2:] - th[:-2]) / (t[2:] - t[:-2])
    return t, w


def sync_imu_to_track(rotation, t_s, theta_rad, **kwargs) -> SyncResult:
    """Offset of a video track's clock onto an IMU's clock from the rocking rates.

    ``rotation`` is an :class:`ImuRotation` (or any object with ``t_s`` and
    ``omega_rad_s``); the track gives ``t_s, theta_rad``.  Returns the clock
    model with a = IMU and b = video: ``t_imu = t_video + offset_s + drift * t_video``.
    """
    t, w = track_rate(t_s, theta_rad)
    dt = float(np.nanmedian(np.diff(t))) if len(t) > 1 else 0.0
    kwargs.setdefault("window_b_s", 2.0 * dt)
    return sync_offset(rotation.t_s, rotation.omega_rad_s, t, w, theta_b=theta_rad, **kwargs)


def sync_events(
    t_a, t_b, *, max_offset_s: float | None = None, tol_s: float = 0.02, drift: bool | str = "auto"
) -> SyncResult:
    """Clock model from matched event instants (e.g. impacts seen by two sensors).

    Parameters
    ----------
    t_a, t_b : array_like
        Event times on clocks a and b, s (e.g. ``ImuRotation.impact_t_s``).
    max_offset_s : float, optional
        Largest plausible |offset|, s.
    tol_s : float
        Events match when within ``tol_s`` after applying the offset, s.
    drift : bool or "auto"
        Fit a clock drift (``"auto"``: with >= 10 matches spanning > 120 s).

    Returns
    -------
    SyncResult
        ``correlation`` is the fraction of b's events matched; ``n_windows``
        the number of matches; ``window_t_s``/``window_offset_s`` the matched b
        events and their individual offsets; ``residual_ms`` their RMS scatter
        about the clock model.

    Notes
    -----
    The coarse offset is the pairwise difference ``t_a - t_b`` that matches
    the most events within ``tol_s``; the fine model is least squares on the
    matched pairs (two passes of matching).
    """
    a = np.sort(np.asarray(t_a, float)[np.isfinite(t_a)])
    b = np.sort(np.asarray(t_b, float)[np.isfinite(t_b)])
    if a.size < 2 or b.size < 2:
        raise InputError(f"sync_events: need >= 2 events on each clock (got {a.size}, {b.size})")
    cand = (a[:, None] - b[None, :]).ravel()
    if max_offset_s is not None:
        cand = cand[np.abs(cand) <= max_offset_s]
    if cand.size == 0:
        raise InputError("sync_events: no event pair within max_offset_s; raise max_offset_s")
    if cand.size > 20000:  # keep the vote cheap on long event lists
        cand = cand[np.random.default_rng(0).choice(cand.size, 20000, replace=False)]

    def matches(off, d=0.0):
        x = b + off + d * b
        k = np.clip(np.searchsorted(a, x), 1, a.size - 1)
        near = np.where(np.abs(a[k - 1] - x) < np.abs(a[k] - x), k - 1, k)
        ok = np.abs(a[near] - x) <= tol_s
        return ok, a[near] - b

    votes = np.array([np.count_nonzero(matches(c)[0]) for c in cand])
    off, d = float(cand[int(np.argmax(votes))]), 0.0
    ok = np.zeros(b.size, dtype=bool)
    for _ in range(2):
        ok, diff = matches(off, d)
        if ok.sum() == 0:
            break
        span = np.ptp(b[ok]) if ok.sum() > 1 else 0.0
        fit = (ok.sum() >= 10 and span > 120.0) if drift == "auto" else bool(drift)
        if fit and ok.sum() >= 3:
            d, off = np.polyfit(b[ok], diff[ok], 1)
        else:
            d, off = 0.0, float(np.mean(diff[ok]))
    model = off + d * b[ok]
    resid = 1e3 * float(np.sqrt(np.mean((diff[ok] - model) ** 2))) if ok.sum() >= 3 else np.nan
    return SyncResult(float(off), float(d), resid, float(ok.mean()), int(ok.sum()), b[ok], diff[ok])
