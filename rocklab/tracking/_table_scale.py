"""The table acceleration's scale uncertainty, measured from the table IMU's agreement with the film.

A shake-table run's response near overturning moves by several per cent for 1 % of table
acceleration, so the scale error the validation ensembles sample matters. With one source
(an IMU, or the film) nothing measures it and a prior is assumed (1 %, a calibrated MEMS
accelerometer's sensitivity). With both, the film's metric displacement and the IMU's
acceleration carry independent scale errors ``e_f`` and ``e_i``, and their ratio is measured:

- the IMU's acceleration is splined on its own samples and integrated twice exactly (the
  spline's antiderivative), evaluated at the film's frames;
- it is regressed on the film's displacement, with nuisance terms that take the integration's
  unknown start position and velocity, the IMU's offset and everything below
  :data:`LOW_CUT_HZ` (cosines up to that frequency: a drifting offset, the twice-integrated
  noise's random walk); the slope is ``1 / (1 + d)``, ``d = e_f - e_i`` (the IMU's side is the
  dependent one: its twice-integrated noise would bias a slope on it towards zero);
- its standard error is the larger of two: the one the sources' noises imply (the IMU's white
  noise integrated twice is a correlated random walk at the frames, ``q [s² t / 2 - s³ / 6]``
  for ``s <= t`` with ``q = σ_a² Δt``, plus the film's white noise), and the residuals' own
  (Newey-West, Bartlett weights over :data:`HAC_LAG_S`: what the noise model misses, a drifting
  offset). A plain least-squares error would be several times too small: the twice-integrated
  noise is red.

The fused table takes the film's scale where the film is the less noisy source (below a few
hertz) and the IMU's above: its scale error is ``e = w e_f + (1 - w) e_i``, ``w`` the film's
share of the acceleration's power (per frequency ``S_a / (S_a + S_x (2πf)⁴)`` from the two
white noises, weighted by the motion's power spectrum above the IMU's noise). With independent
Gaussian priors of standard deviations :data:`FILM_SCALE_SD` (σ_f) and :data:`IMU_SCALE_SD`
(σ_i) and the measured ``d`` (standard error ``se``), ``e`` has the posterior mean
``c d / v`` and variance ``w² σ_f² + (1 - w)² σ_i² - c² / v``, with ``c = w σ_f² - (1 - w) σ_i²``
and ``v = σ_f² + σ_i² + se²``. The ensembles are centred on the fused table, so the scale
standard deviation they sample is the root mean square of ``e``: ``sqrt(mean² + variance)``.
Two sources that agree leave about ``(1/σ_f² + 1/σ_i²)^-1/2`` (0.29 %: an error they share);
a ``d`` beyond :data:`PRIOR_REJECT` prior standard deviations contradicts the priors, and the
disagreement is then sampled in full (``sqrt(d² + se² + floor²)``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "TableScale",
    "table_scale_agreement",
    "FILM_SCALE_SD",
    "IMU_SCALE_SD",
    "LOW_CUT_HZ",
    "HAC_LAG_S",
    "PRIOR_REJECT",
]

#: Relative standard deviation of the film's metric scale (a printed marker's size at the table's
#: depth: 0.1 mm of print on 100 mm, a few millimetres of depth at 1-2 m from the camera), -.
FILM_SCALE_SD = 0.003
#: Relative standard deviation of a calibrated MEMS accelerometer's sensitivity, -.
IMU_SCALE_SD = 0.01
#: Below this frequency the regression leaves the motion to nuisance terms (drift, the twice
#: integrated noise's random walk), Hz.
LOW_CUT_HZ = 0.5
#: Residual autocorrelation is counted up to this lag in the slope's standard error, s.
HAC_LAG_S = 2.0
#: A disagreement beyond this many of its prior standard deviations contradicts the priors.
PRIOR_REJECT = 3.0


@dataclass(frozen=True)
class TableScale:
    """The film's scale relative to the table IMU's, and the scale uncertainty it implies.

    Attributes
    ----------
    ratio_minus_one : float
        The film's scale over the IMU's, minus 1 (the film's scale error less the IMU's; the
        inverse slope of the IMU's twice-integrated acceleration on the film's displacement), -.
    se : float
        Its standard error, -.
    floor : float
        The standard deviation of an error both sources share (see the module doc), -.
    film_weight : float
        The film's share ``w`` of the fused acceleration's scale, -.
    offset : float
        The posterior mean of the fused table's scale error, -.
    sd : float
        The fused acceleration's scale standard deviation to sample (root mean square of its
        posterior error), -.
    n_frames : int
        Film frames in the regression.
    status : str
        ``"ok"``, or ``"failed"`` (too little overlap or shaking: ``sd`` is NaN).
    message : str
    """

    ratio_minus_one: float
    se: float
    floor: float
    film_weight: float
    offset: float
    sd: float
    n_frames: int
    status: str = "ok"
    message: str = ""

    def to_dict(self) -> dict:
        """``report.json``'s ``table.fusion.scale``."""
        return {
            "method": "the IMU's twice-integrated acceleration regressed on the film's displacement above "
            f"{LOW_CUT_HZ:g} Hz (Newey-West standard error over {HAC_LAG_S:g} s)",
            "film_over_imu_minus_one": _f(self.ratio_minus_one),
            "se": _f(self.se),
            "shared_floor": _f(self.floor),
            "film_weight": _f(self.film_weight),
            "fused_scale_offset": _f(self.offset),
            "film_scale_prior_sd": FILM_SCALE_SD,
            "imu_scale_prior_sd": IMU_SCALE_SD,
            "acc_scale_sd": _f(self.sd),
            "n_frames": int(self.n_frames),
            "status": self.status,
            "message": self.message,
        }


def _f(x) -> float | None:
    return float(x) if x is not None and np.isfinite(x) else None


def _nuisance(t, t0: float, span: float) -> np.ndarray:
    """Columns (m, k): 1, t, t² (start position, velocity, the IMU's offset) and cosines up to
    :data:`LOW_CUT_HZ` over ``span`` (a slowly drifting offset, the integrated noise's wander)."""
    u = (t - t0) / span
    cols = [np.ones_like(u), u, u * u]
    for j in range(1, int(math.ceil(2.0 * LOW_CUT_HZ * span)) + 1):
        cols.append(np.cos(math.pi * j * u))
    return np.stack(cols, 1)


def _hac_var(xr, u, lag: int) -> float:
    """Newey-West variance of the slope of ``u``'s regression on the partialled regressor ``xr``."""
    g = xr * u
    s = float(g @ g)
    for k in range(1, min(lag, len(g) - 1) + 1):
        s += 2.0 * (1.0 - k / (lag + 1.0)) * float(g[k:] @ g[:-k])
    return max(s, float(g @ g)) / float(xr @ xr) ** 2


def _model_var(fr, tv, sigma_a: float, dt_imu: float, sigma_x: float) -> float:
    """The slope's variance from the noise model: the IMU's white noise ``sigma_a`` (m/s², one per
    ``dt_imu`` s) integrated twice, and the film's white noise ``sigma_x`` (m), on regressor ``fr``
    (already orthogonal to the nuisance, which takes the integration's start)."""
    s = tv - tv[0]
    lo, hi = np.minimum.outer(s, s), np.maximum.outer(s, s)
    cov = sigma_a**2 * dt_imu * (lo**2 * hi / 2.0 - lo**3 / 6.0)
    return (float(fr @ cov @ fr) + sigma_x**2 * float(fr @ fr)) / float(fr @ fr) ** 2


def table_scale_agreement(
    video,
    imu_t_s,
    imu_acc_m_s2,
    *,
    sigma_a_m_s2: float | None = None,
    sigma_x_m: float | None = None,
    film_scale_sd: float = FILM_SCALE_SD,
    imu_scale_sd: float = IMU_SCALE_SD,
) -> TableScale:
    """Measure the film's scale against the table IMU's and the scale uncertainty that leaves.

    Parameters
    ----------
    video : rocklab.series.TableMotion
        The film's table (``x_m`` at its frames, m).
    imu_t_s, imu_acc_m_s2 : array_like, shape (m,)
        The IMU's sample times on the film's clock (s, increasing) and its acceleration along the
        film's x (m/s²).
    sigma_a_m_s2, sigma_x_m : float, optional
        The IMU's white noise per sample (m/s²) and the film's (m); default: their high-frequency
        floors (:func:`rocklab.tracking.estimate_noise`).
    film_scale_sd, imu_scale_sd : float
        The two sources' calibration standard deviations (relative), which set the floor.

    Returns
    -------
    TableScale
    """
    from scipy.interpolate import CubicSpline

    from .video import estimate_noise

    floor = 1.0 / math.sqrt(1.0 / film_scale_sd**2 + 1.0 / imu_scale_sd**2)
    ti, ai = np.asarray(imu_t_s, float), np.asarray(imu_acc_m_s2, float)
    ok = np.isfinite(ti) & np.isfinite(ai)
    ti, ai = ti[ok], ai[ok]
    tv, xv = np.asarray(video.t_s, float), np.asarray(video.x_m, float)
    m = np.isfinite(xv) & (tv >= (ti[0] if ti.size else np.inf)) & (tv <= (ti[-1] if ti.size else -np.inf))
    if m.sum() < 50 or ti.size < 16:
        return TableScale(math.nan, math.nan, floor, *(3 * [math.nan]), int(m.sum()), "failed", "too little overlap")
    tv, xv = tv[m], xv[m]
    X = CubicSpline(ti, ai).antiderivative(2)(tv)
    span = float(tv[-1] - tv[0])
    N = _nuisance(tv, float(tv[0]), span)
    # Frisch-Waugh: the slope from both sides with the nuisance projected out. The IMU's side is
    # the dependent one: its twice-integrated noise (0.2 mm above 0.5 Hz for 5 mg at 256 Hz) in the
    # regressor would bias the slope towards zero by its variance over the motion's (0.6 % on a
    # synthetic El Centro table), the film's 0.02 mm by 1e-4
    fr = xv - N @ np.linalg.lstsq(N, xv, rcond=None)[0]
    ir = X - N @ np.linalg.lstsq(N, X, rcond=None)[0]
    den = float(fr @ fr)
    if not den > 0:
        return TableScale(math.nan, math.nan, floor, *(3 * [math.nan]), int(tv.size), "failed", "no shaking")
    b = float(fr @ ir) / den  # IMU over film
    u = ir - b * fr
    dt = float(np.median(np.diff(tv)))
    dof = max(tv.size - N.shape[1] - 1, 1)
    sa = float(sigma_a_m_s2) if sigma_a_m_s2 is not None else estimate_noise(ai)
    sx = float(sigma_x_m) if sigma_x_m is not None else estimate_noise(xv)
    var_model = _model_var(fr, tv, sa, float(np.median(np.diff(ti))), sx)
    se_b = math.sqrt(max(_hac_var(fr, u, int(round(HAC_LAG_S / dt))) * tv.size / dof, var_model))
    k, se = 1.0 / b, se_b / b**2
    # the shaking must stand above the two sources' difference for the slope to mean anything
    if not (np.sqrt(den / tv.size) > 10.0 * float(np.sqrt(np.mean(u * u)))):
        msg = "the table's motion above the low cut hardly exceeds the two sources' difference"
        return TableScale(k - 1.0, se, floor, *(3 * [math.nan]), int(tv.size), "failed", msg)
    w = _film_weight(ti, ai, sa, sx, dt)
    d, sf2, si2 = k - 1.0, film_scale_sd**2, imu_scale_sd**2
    c, v = w * sf2 - (1.0 - w) * si2, sf2 + si2 + se**2
    mean = c * d / v
    var = w * w * sf2 + (1.0 - w) ** 2 * si2 - c * c / v
    if abs(d) > PRIOR_REJECT * math.sqrt(v):  # the priors cannot explain it: either source may be wrong
        msg = f"the film and the IMU disagree by {100 * d:.2g} % (priors allow {100 * math.sqrt(v):.2g} %)"
        return TableScale(d, se, floor, w, mean, math.sqrt(d * d + se * se + floor * floor), int(tv.size), "ok", msg)
    return TableScale(d, se, floor, w, mean, math.sqrt(mean * mean + max(var, 0.0)), int(tv.size))


def _film_weight(ti, ai, sigma_a: float, sigma_x: float, dt_film: float) -> float:
    """The film's share of the fused acceleration: per frequency the smoother's weight on the film
    (its displacement noise as acceleration against the IMU's), averaged over the motion's power
    above the IMU's white noise and :data:`LOW_CUT_HZ`."""
    dt_i = float(np.median(np.diff(ti)))
    tg = np.arange(ti[0], ti[-1], dt_i)
    a = np.interp(tg, ti, ai)
    a = a - a.mean()
    p = np.abs(np.fft.rfft(a)) ** 2 - a.size * sigma_a**2
    f = np.fft.rfftfreq(a.size, dt_i)
    keep = (f >= LOW_CUT_HZ) & (p > 0)
    if not keep.any():
        return 1.0
    s_a, s_x = 2.0 * sigma_a**2 * dt_i, 2.0 * sigma_x**2 * dt_film
    wf = s_a / (s_a + s_x * (2.0 * np.pi * f[keep]) ** 4)
    return float(np.sum(wf * p[keep]) / np.sum(p[keep]))
