"""The best table motion: the table IMU's acceleration fused with the video's displacement.

A camera samples the table's displacement well (0.02 mm at 960×540) but too slowly for its
acceleration (50 fps: a record's content above 25 Hz is lost; twice differentiated, the
displacement's noise grows as f²); an accelerometer samples the acceleration fast but noisily
(5 mg per sample) and with an offset (gravity leaking through a tilt, a calibration). The two
are complementary: a Kalman filter and Rauch–Tung–Striebel smoother on one clock takes the
low frequencies from the video and the high ones from the IMU, weighting each by its noise.

Model (continuous time, state ``s = [x, v, a, j, (snap,) b]``): table displacement (m), its
derivatives up to the jerk (m/s³) or the snap, the last driven by white noise of spectral density
``q``, and the IMU's offset ``b`` (m/s²), a random walk of density ``q_b``. Measurements: the
video's ``x_k = x + e`` (σ_x, its white-noise floor) at the frame times and the IMU's
``a_i = a + b + e`` (σ_a, its white-noise floor) at the IMU's times, both on the video's clock.
``q`` maximises the likelihood of the innovations (a bounded search over ``log q``); a shaking
table is not stationary (at rest, then shaking, a sine pulse's jerk stepping at its start and
end), so the density is made local (``q · scale(t)``): a smoothing's increments of the last
derivative (the driving noise's integral), squared per second and averaged over
:data:`ADAPT_WINDOW_S`, set ``scale``, ``q`` is searched again, and this :data:`ADAPT_PASSES`
times. A moving table blurs on the film: where the film's normalised innovations run above 1
(averaged over :data:`FILM_WINDOW_S`), its frames' variance is raised by as much (at most
:data:`FILM_MAX_INFLATE`), and one more pass finds ``q`` and ``scale``. All from the data: the two noise
floors, the film's local variance, ``q`` and ``scale``. This for each model order of
:data:`ORDERS`; the likelier order is kept. ``q_b`` lets the offset move by
:data:`BIAS_WALK_M_S2` in a second (a slow tilt: gravity's leak through it is taken out with the
offset, the film pinning the low frequencies).

What any linear smoother can reach. With white noises of density ``N_a = σ_a²/f_a`` on the
acceleration (the IMU, ``f_a`` Hz) and ``N_x = σ_x²/f_v`` on the displacement (the film, ``f_v``
frames/s), the film's noise on the acceleration is ``(2πf)⁴ N_x`` below ``f_v/2``, and the two
together ``N(f) = 1/(1/N_a + 1/((2πf)⁴ N_x))``: the film rules below
``f_c = (N_a/N_x)^(1/4) / 2π`` (5 Hz for 5 mg at 256 Hz and 0.02 mm at 50 fps), the IMU above. A
smoother ``H(f)`` leaves ``|1-H|² S + |H|² N`` per frequency, least at ``H = S/(S+N)`` (Wiener):
``∫ S N/(S+N) df``. With ``S`` the run's own spectrum (an oracle) this bounds every linear
time-invariant smoother; with the spectrum over each 0.25-0.5 s (short-time Fourier cells) it
bounds the adaptive ones (``tests/_wiener.py``). The demo's El Centro table (high-passed at 2 Hz
to fit a 10 mm stroke, its energy at 2-15 Hz) against the IMU's 5 mg: 1.9 % of the RMS
(stationary) / 1.6 % (local), most of it at 5-25 Hz; read at the frames as ``rocklab run``
reports it, 2.3 % / 1.9 % (the frames fall on the record's 0.01 s knots, where the true
acceleration has corners no sensor here resolves: a noiseless cut at 25 Hz alone leaves 1.2 %
there). So 1 % is out of reach for that record on these sensors (the x-IMU3's datasheet 160
µg/√Hz against the synthetic 440 µg/√Hz would make it 0.9 % / 0.8 %). A sine pulse's energy sits
where the film is exact: 0.4-0.5 % (local), reached within 1.1-1.2x; El Centro within 1.3-1.4x.
(The synthetic table does not tilt; a tilt's gravity leak, taken out by the gyro and the offset
state, would only add to these.)

The smoother's covariance gives each sample's σ of the acceleration. The video's filter
innovations, normalised by their predicted variance, should have unit mean square when the two
sources agree; a mean square above :data:`DISAGREE_NIS` (an IMU scale error, a mis-synced clock,
a wrong metric scale of the film) or an IMU offset above :data:`BIAS_MAX_M_S2` (a tilted or
badly calibrated table sensor) is flagged ``W-TABLE-FUSION``.

The smoother is written here (numpy, and numba for the filter) rather than taken from ``pykalman`` or
``filterpy``: the measurements alternate between two kinds on an irregular merged clock, which
needs a time-varying process noise and scalar updates; ``pykalman`` drops an observation whose
vector is partly missing and adds ``scikit-base``, ``filterpy`` pulls in matplotlib.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from .._diagnostics import warn
from .._errors import InputError
from ..series import TableMotion
from ._table_scale import TableScale, table_scale_agreement

__all__ = ["TableFusion", "fuse_table_motion", "BIAS_WALK_M_S2", "BIAS_MAX_M_S2", "DISAGREE_NIS", "ORDERS", "MARGIN_S"]

#: How far the IMU's offset may wander in one second (random walk), m/s²: slow tilts of the table.
BIAS_WALK_M_S2 = 0.01
#: An IMU offset larger than this (about 0.3° of tilt) means the two sources disagree, m/s².
BIAS_MAX_M_S2 = 0.05
#: Mean square of the video's normalised innovations above which the two sources disagree.
DISAGREE_NIS = 3.0
#: Integrators of the signal models tried (the likelier one is kept): displacement, velocity,
#: acceleration and jerk (driven by white snap), or with snap too. With a constant density, fused
#: RMS error with four / five on synthetic tables: El Centro 2.5 / 2.1 %, a 0.6 s sine pulse
#: 0.84 / 0.91 %; with the local density the likelihood prefers four (2.0-2.1 %, 0.49-0.51 %).
ORDERS = (4, 5)
#: The fused table covers the film's span and this much either side where the IMU logged, s.
MARGIN_S = 2.0
#: Window over which the driving noise's local power is averaged, s.
ADAPT_WINDOW_S = 0.05
#: Passes of smoothing and re-estimating the local density.
ADAPT_PASSES = 3
#: Window over which the film's normalised innovations set its local variance, s.
FILM_WINDOW_S = 0.3
#: The most a frame's variance is raised by its innovations.
FILM_MAX_INFLATE = 10.0
#: Smallest local density, relative to its mean (a table at rest still moves a little).
ADAPT_FLOOR = 0.01
#: Bounds of the search for ``log10 q``.
Q_BOUNDS = (-2.0, 12.0)


@dataclass(frozen=True)
class TableFusion:
    """The fused table motion and what the smoother says about its two sources.

    Attributes
    ----------
    motion : rocklab.series.TableMotion
        ``source="fused"``: displacement, velocity and acceleration at the IMU's sample times on
        the video clock (dropped samples filled) over the film's span and :data:`MARGIN_S` either
        side, with ``sigma_ax_m_s2``.
    imu_bias_m_s2 : ndarray, shape (n,)
        The IMU's offset the smoother found, at ``motion.t_s``, m/s² (taken out of the motion).
    q : float
        Spectral density of the white noise driving the model's last derivative, SI (the
        likelihood's maximum).
    order : int
        Integrators of the model kept (:data:`ORDERS`).
    sigma_x_m, sigma_a_m_s2 : float
        Measurement noise of the video's displacement (m) and of the IMU's acceleration (m/s²).
    video_nis : float
        Mean square of the video's normalised innovations (1 when the sources agree).
    status : str
        ``"ok"``, or ``"suspect"`` when the sources disagree (``message`` says how).
    message : str
    scale : rocklab.tracking.TableScale or None
        The film's scale against the IMU's and the fused acceleration's scale uncertainty
        (:func:`rocklab.tracking.table_scale_agreement`).
    """

    motion: TableMotion
    imu_bias_m_s2: np.ndarray
    q: float
    order: int
    sigma_x_m: float
    sigma_a_m_s2: float
    video_nis: float
    status: str = "ok"
    message: str = ""
    scale: TableScale | None = None

    def to_dict(self) -> dict:
        """``report.json``'s ``table.fusion``: the noises, q_j, the offset and the agreement."""
        b = self.imu_bias_m_s2
        s = self.motion.sigma_ax_m_s2
        return {
            "method": "Kalman filter + RTS smoother: film displacement and IMU acceleration (with its offset)",
            "order": int(self.order),
            "q_si": float(self.q),
            "sigma_x_m": float(self.sigma_x_m),
            "sigma_imu_m_s2": float(self.sigma_a_m_s2),
            "imu_bias_mean_m_s2": float(np.mean(b)),
            "imu_bias_max_abs_m_s2": float(np.max(np.abs(b))),
            "video_nis": float(self.video_nis),
            "sigma_acc_median_m_s2": float(np.nanmedian(s)) if s is not None else None,
            "status": self.status,
            "message": self.message,
            "scale": self.scale.to_dict() if self.scale is not None else None,
        }


def _transitions(dt, q: float, q_b: float, m: int):
    """F and Q of each step (``dt``, s, shape (n,)): ``m`` integrators driven by white noise of
    density ``q`` (the state's derivatives 0..m-1), then the offset, a random walk of density
    ``q_b``. Shapes (n, m + 1, m + 1)."""
    dt = np.asarray(dt, float)
    F = np.zeros((len(dt), m + 1, m + 1))
    Q = np.zeros_like(F)
    F[:, m, m] = 1.0
    Q[:, m, m] = q_b * dt
    for i in range(m):
        for j in range(i, m):
            F[:, i, j] = dt ** (j - i) / math.factorial(j - i)
        for j in range(m):
            p = 2 * m - 1 - i - j
            Q[:, i, j] = q * dt**p / (math.factorial(m - 1 - i) * math.factorial(m - 1 - j) * p)
    return F, Q


@njit(cache=True)
def _kalman(F, Q, z, kind, H, r, s0, P0, keep):  # pragma: no cover - compiled
    """Forward filter over the merged clock (step ``k`` goes from ``k - 1`` with ``F[k], Q[k]``).

    ``kind`` per step: 0 none, 1 video (row ``H[1]``), 2 IMU (``H[2]``); ``r`` each step's
    measurement variance.
    Returns the log-likelihood, each video innovation's square over its variance (NaN at other
    steps) and, with ``keep``, the predicted and filtered means and covariances. Plain loops over
    the state's 5-7 components: numba compiles them in seconds, matrix products in half a minute.
    """
    n, d = len(z), len(s0)
    s, P = s0.copy(), P0.copy()
    s2, FP, Ph = np.empty(d), np.empty((d, d)), np.empty(d)
    ll = 0.0
    nis = np.full(n, np.nan)
    nk = n if keep else 1
    sp, Pp = np.empty((nk, d)), np.empty((nk, d, d))
    sf, Pf = np.empty((nk, d)), np.empty((nk, d, d))
    for k in range(n):
        if k:
            Fk = F[k]
            for i in range(d):
                acc = 0.0
                for j in range(d):
                    acc += Fk[i, j] * s[j]
                s2[i] = acc
            s[:] = s2
            for i in range(d):
                for j in range(d):
                    acc = 0.0
                    for m in range(d):
                        acc += Fk[i, m] * P[m, j]
                    FP[i, j] = acc
            for i in range(d):
                for j in range(d):
                    acc = Q[k, i, j]
                    for m in range(d):
                        acc += FP[i, m] * Fk[j, m]
                    P[i, j] = acc
        if keep:
            sp[k], Pp[k] = s, P
        c = kind[k]
        if c:
            h = H[c]
            S = r[k]
            nu = z[k]
            for i in range(d):
                acc = 0.0
                for j in range(d):
                    acc += P[i, j] * h[j]
                Ph[i] = acc
                S += h[i] * acc
                nu -= h[i] * s[i]
            for i in range(d):
                s[i] += Ph[i] * nu / S
            for i in range(d):
                for j in range(d):
                    P[i, j] -= Ph[i] * Ph[j] / S
            for i in range(d):  # symmetric against rounding
                for j in range(i + 1, d):
                    P[i, j] = P[j, i] = 0.5 * (P[i, j] + P[j, i])
            ll -= 0.5 * (np.log(S) + nu * nu / S)
            if c == 1:
                nis[k] = nu * nu / S
        if keep:
            sf[k], Pf[k] = s, P
    return ll, nis, sp, Pp, sf, Pf


def _smooth(F, sp, Pp, sf, Pf):
    """Rauch–Tung–Striebel pass: smoothed means (n, d) and covariances (n, d, d). Run once per
    fusion, so plain numpy (0.05 s for 2 500 steps)."""
    ss, Ps = sf.copy(), Pf.copy()
    for k in range(len(sf) - 2, -1, -1):
        C = np.linalg.solve(Pp[k + 1], F[k + 1] @ Pf[k]).T
        ss[k] = sf[k] + C @ (ss[k + 1] - sp[k + 1])
        Ps[k] = Pf[k] + C @ (Ps[k + 1] - Pp[k + 1]) @ C.T
    return ss, Ps


def _model(m: int, dt, z, kind, r, x0):
    """``run(q, keep, scale=None)`` of the model with ``m`` integrators on the merged clock:
    ``(F, filter output)``; ``scale`` (per step) multiplies the driving noise's density."""
    H = np.zeros((3, m + 1))
    H[1, 0] = 1.0  # the film sees the displacement
    H[2, 2] = H[2, m] = 1.0  # the IMU the acceleration and its offset
    s0 = np.zeros(m + 1)
    s0[0] = x0
    # broad prior: a table of 1 m stroke at 1 m/s, 10 m/s2, 1e3 m/s3 (and up); the offset of a 1 deg tilt
    P0 = np.diag(np.r_[[1.0, 1.0, 100.0], np.full(m - 3, 1e6), (0.017 * 9.81) ** 2])

    def run(q, keep, scale=None):
        F, Q = _transitions(dt, q, BIAS_WALK_M_S2**2, m)
        if scale is not None:
            Q[:, :m, :m] *= scale[:, None, None]
        return F, _kalman(F, Q, z, kind, H, r, s0, P0, keep)

    return run


def _ml_q(run, scale):
    """(log-likelihood, q) at the likelihood's maximum over ``log10 q`` in :data:`Q_BOUNDS`."""
    from scipy.optimize import minimize_scalar

    res = minimize_scalar(
        lambda lq: -run(10.0**lq, False, scale)[1][0], bounds=Q_BOUNDS, method="bounded", options={"xatol": 0.05}
    )
    return -float(res.fun), 10.0 ** float(res.x)


def _adapted(run, m: int, q: float, dt, scale=None, passes: int = ADAPT_PASSES):
    """The driving noise's density made local, in ``passes`` passes from ``scale``: smooth, read the
    driving noise's local power from the smoothed increments of the model's last derivative
    (their squares per second, averaged over :data:`ADAPT_WINDOW_S`, relative to their mean, at
    least :data:`ADAPT_FLOOR`), find ``q`` by maximum likelihood again. Returns (log-likelihood,
    q, scale per step)."""
    ll = math.nan
    w = max(3, int(round(ADAPT_WINDOW_S / float(np.median(dt[dt > 0])))))
    for _ in range(passes):
        F, (_, _, sp, Pp, sf, Pf) = run(q, True, scale)
        ss, _ = _smooth(F, sp, Pp, sf, Pf)
        last = ss[:, m - 1]
        inc = np.diff(last, prepend=last[0]) ** 2
        rate = np.divide(inc, dt, out=np.zeros_like(inc), where=dt > 0)  # steps of dt 0 carry nothing
        power = np.convolve(rate, np.ones(w) / w, mode="same")
        scale = np.clip(power / max(float(np.mean(power)), 1e-300), ADAPT_FLOOR, None)
        ll, q = _ml_q(run, scale)
    return ll, q, scale


def _film_variance(r, kind, nis, t):
    """Each frame's variance raised where the film's innovations are larger than it says (their
    normalised square averaged over :data:`FILM_WINDOW_S`, at least 1): a moving table blurs."""
    v = np.flatnonzero(kind == 1)
    tv = t[v]
    x = np.nan_to_num(nis[v], nan=1.0)
    c = np.concatenate([[0.0], np.cumsum(x)])
    lo = np.searchsorted(tv, tv - FILM_WINDOW_S / 2)
    hi = np.searchsorted(tv, tv + FILM_WINDOW_S / 2, side="right")
    local = (c[hi] - c[lo]) / np.maximum(hi - lo, 1)
    out = r.copy()
    out[v] *= np.clip(local, 1.0, FILM_MAX_INFLATE)
    return out


def _merged_clock(video: TableMotion, t_imu, a_imu, rate_hz):
    """One clock: the IMU's regular grid (its dropped samples included, as outputs) and the
    video's frames, each step with its measurement kind (0 none, 1 video, 2 IMU)."""
    n_out = int(math.floor((t_imu[-1] - t_imu[0]) * rate_hz + 0.5)) + 1
    t_out = t_imu[0] + np.arange(n_out) / rate_hz
    slot = np.clip(np.round((t_imu - t_imu[0]) * rate_hz).astype(np.int64), 0, n_out - 1)
    kind_out = np.zeros(n_out, np.int8)
    z_out = np.zeros(n_out)
    kind_out[slot], z_out[slot] = 2, a_imu
    tv, xv = np.asarray(video.t_s, float), np.asarray(video.x_m, float)
    ok = np.isfinite(xv)
    tv, xv = tv[ok], xv[ok]
    t = np.concatenate([t_out, tv])
    kind = np.concatenate([kind_out, np.ones(len(tv), np.int8)])
    z = np.concatenate([z_out, xv])
    order = np.argsort(t, kind="stable")
    is_out = np.zeros(len(t), bool)
    is_out[:n_out] = True
    return t[order], z[order], kind[order], is_out[order], t_out


def fuse_table_motion(
    video: TableMotion,
    imu_t_s,
    imu_acc_m_s2,
    *,
    sigma_a_m_s2: float | None = None,
    sigma_x_m: float | None = None,
    q: float | None = None,
    order: int | None = None,
    label: str = "table",
) -> TableFusion:
    """Fuse a table IMU's acceleration with the video's displacement (see the module doc).

    Parameters
    ----------
    video : rocklab.series.TableMotion
        The video's table motion (``x_m`` required; its ``noise_m`` is σ_x by default).
    imu_t_s, imu_acc_m_s2 : array_like, shape (m,)
        The IMU's sample times on the video's clock (s) and its acceleration along the video's
        x (m/s², gravity removed); samples need not be regular (dropped packets).
    sigma_a_m_s2 : float, optional
        The IMU's white noise, m/s² (default: its high-frequency floor,
        :func:`rocklab.tracking.estimate_noise`).
    sigma_x_m : float, optional
        The video's white noise, m (default ``video.noise_m``).
    q : float, optional
        Spectral density of the white noise driving the model (see the module doc; default: the
        likelihood's maximum).
    order : int, optional
        Integrators in the signal model (default: whichever of :data:`ORDERS` the likelihood prefers).
    label : str
        Names the table in messages.

    Returns
    -------
    TableFusion

    Raises
    ------
    InputError
        No video displacement, fewer than 16 IMU samples or none inside the film.
    """
    from .video import estimate_noise

    if video.x_m is None or np.isfinite(np.asarray(video.x_m, float)).sum() < 4:
        raise InputError(f"{label}: fusing the table needs the video's displacement (x_m); it has none")
    ti, ai = np.asarray(imu_t_s, float), np.asarray(imu_acc_m_s2, float)
    tv = np.asarray(video.t_s, float)[np.isfinite(np.asarray(video.x_m, float))]
    # the film's span and MARGIN_S either side (an IMU's rest before the film): the smoother keeps
    # (order + 2)^2 numbers per sample, which an hour-long log would turn into gigabytes
    ok = np.isfinite(ti) & np.isfinite(ai) & (ti >= tv[0] - MARGIN_S) & (ti <= tv[-1] + MARGIN_S)
    ti, ai = ti[ok], ai[ok]
    if len(ti) < 16 or np.any(np.diff(ti) <= 0):
        raise InputError(
            f"{label}: the table IMU needs at least 16 samples at increasing times within {MARGIN_S:g} s of the "
            f"film ({tv[0]:.3f}-{tv[-1]:.3f} s on its clock) to be fused; check the sync"
        )
    rate = 1.0 / float(np.median(np.diff(ti)))
    sa = float(sigma_a_m_s2) if sigma_a_m_s2 is not None else estimate_noise(ai)
    sx = float(sigma_x_m) if sigma_x_m is not None else float(video.noise_m)
    if not (np.isfinite(sx) and sx > 0):
        sx = 1e-4  # no noise estimate: a tenth of a millimetre, a coarse film's
    sx = max(sx, 1e-6)
    sa = max(sa, 1e-4)
    t, z, kind, is_out, t_out = _merged_clock(video, ti, ai, rate)
    r = np.array([0.0, sx * sx, sa * sa])[kind]
    dt = np.diff(t, prepend=t[0])
    x0 = z[np.flatnonzero(kind == 1)[0]]
    fits = []
    adapt = q is None
    for m in ORDERS if order is None else (int(order),):
        run = _model(m, dt, z, kind, r, x0)
        if q is None:  # a shaking table is not stationary: the noise's density follows the motion
            fits.append((*_adapted(run, m, _ml_q(run, None)[1], dt), m, run))
        else:
            fits.append((run(q, False)[1][0], float(q), None, m, run))
    _, q, scale, m, run = max(fits, key=lambda f: f[0])  # the model the data find likelier
    F, (_, nis, sp, Pp, sf, Pf) = run(q, True, scale)
    if adapt:
        r2 = _film_variance(r, kind, nis, t)
        run = _model(m, dt, z, kind, r2, x0)
        _, q, scale = _adapted(run, m, q, dt, scale, passes=1)  # from the density found
        F, (_, _, sp, Pp, sf, Pf) = run(q, True, scale)
    ss, Ps = _smooth(F, sp, Pp, sf, Pf)
    ss, Ps = ss[is_out], Ps[is_out]
    sig = np.sqrt(np.maximum(Ps[:, 2, 2], 0.0))
    scale = table_scale_agreement(video, ti, ai, sigma_a_m_s2=sa, sigma_x_m=sx)
    motion = TableMotion(
        t_out,
        ss[:, 0],
        ss[:, 1],
        ss[:, 2],
        noise_m=sx,
        object=video.object,
        source="fused",
        sigma_ax_m_s2=sig,
        acc_noise_m_s2=sa,
        acc_scale_sd=scale.sd,
    )
    return _judge(motion, ss[:, m], float(q), m, sx, sa, nis[np.isfinite(nis)], label, scale)


def _judge(motion, bias, q, order, sx, sa, nis, label, scale=None) -> TableFusion:
    """The fusion with its status: the sources disagree when the video's innovations are too
    large for their variance or the IMU's offset is too large for a level table."""
    # the first innovations carry the broad prior, not a disagreement
    nis_ = float(np.mean(nis[min(10, len(nis) // 10) :])) if len(nis) else math.nan
    b_max = float(np.max(np.abs(bias)))
    why = []
    if nis_ > DISAGREE_NIS:
        why.append(
            f"the film's displacement departs from the IMU's twice-integrated acceleration by {math.sqrt(nis_):.3g} "
            f"times its expected scatter (bound {math.sqrt(DISAGREE_NIS):.3g})"
        )
    if b_max > BIAS_MAX_M_S2:
        why.append(
            f"the IMU reads an offset of up to {b_max:.3g} m/s2 against the film (bound {BIAS_MAX_M_S2:g} m/s2, "
            f"{math.degrees(math.asin(min(b_max / 9.81, 1.0))):.2g} deg of tilt)"
        )
    status, msg = "ok", ""
    if why:
        status = "suspect"
        msg = warn(
            "W-TABLE-FUSION",
            f"{label}: the table IMU and the film disagree: {'; '.join(why)}; the fused table follows the film at low "
            "frequencies. Check the table IMU's scale and mounting, the sync and the film's metric scale",
        ).message
    return TableFusion(motion, bias, q, order, sx, sa, nis_, status, msg, scale)
