"""Model-free analysis of a measured free-rocking record θ(t).

Zero crossings (impacts) after the release (found by :mod:`._release`), arch peaks,
per-impact restitution from local fits on each side of each crossing, and the energy loss
per rocking from successive amplitude peaks (Ther thesis Eq. 12). Times in s, angles in
rad; arrays have shape (n,).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.optimize import minimize_scalar

from .._errors import InputError
from .._diagnostics import warn
from ._release import ReleaseInfo, detect_release, settle_release

__all__ = [
    "ReleaseInfo",
    "detect_release",
    "find_crossings",
    "arch_peaks",
    "per_impact_eta",
    "EnergyLoss",
    "energy_loss_from_peaks",
    "check_record",
]


def check_record(t_s, theta_rad, nan: str = "raise", name: str = "theta_rad"):
    """Validate a record: equal lengths, increasing time, NaN rows raised or skipped.

    Returns
    -------
    t, theta : float ndarrays, n_skipped : int
    """
    t = np.asarray(t_s, dtype=float).ravel()
    y = np.asarray(theta_rad, dtype=float).ravel()
    if t.shape != y.shape:
        raise InputError(f"t_s ({t.size}) and {name} ({y.size}): must have the same length")
    bad = ~(np.isfinite(t) & np.isfinite(y))
    n_skip = int(bad.sum())
    if n_skip:
        if nan == "raise":
            i = int(np.flatnonzero(bad)[0])
            raise InputError(f"sample {i}: t_s or {name} is NaN ({n_skip} such rows); drop them or use nan='skip'")
        t, y = t[~bad], y[~bad]
    if t.size < 10:
        raise InputError(f"record has {t.size} usable samples: too short, need at least 10 (a few rocking cycles)")
    if np.any(np.diff(t) <= 0):
        i = int(np.flatnonzero(np.diff(t) <= 0)[0])
        raise InputError(f"t_s at sample {i + 1}: times must increase strictly; sort or de-duplicate the record")
    return t, y, n_skip


def find_crossings(t_s, theta_rad, start: int = 0, threshold: float = 0.0) -> np.ndarray:
    """Indices i with θ changing sign between samples i and i+1 (with hysteresis).

    A crossing counts only after θ has gone beyond ``threshold`` on the new side, so
    noise near rest does not add impacts. Returns an int array of the last sample
    before each crossing.
    """
    y = np.asarray(theta_rad, float)
    out = []
    i = start
    n = y.size
    if i >= n:
        return np.zeros(0, int)
    side = np.sign(y[i]) or 1.0
    while i < n - 1:
        # next sample on the other side
        rel = np.flatnonzero(side * y[i + 1 :] < 0)
        if rel.size == 0:
            break
        j = i + 1 + rel[0]
        # confirm: after j, |θ| exceeds the threshold on the new side before returning
        k = j
        confirmed = False
        while k < n and -side * y[k] >= 0:
            if -side * y[k] > threshold:
                confirmed = True
                break
            k += 1
        if not confirmed:
            break
        out.append(j - 1)
        side = -side
        i = j
    return np.asarray(out, int)


def _local_crossing_time(t, y, i, m=4) -> float:
    """Crossing time between samples i and i+1 from quadratic fits of ``m`` samples on each side.

    Each side's fitted polynomial is solved for its root next to the crossing; the two
    roots are averaged (the motion is continuous through the impact, only the slope
    changes). Falls back to linear interpolation when a side is too short.
    """
    t0 = t[i]
    lin = t0 + (t[i + 1] - t0) * y[i] / (y[i] - y[i + 1])
    roots = []
    for sl in (slice(max(i - m + 1, 0), i + 1), slice(i + 1, min(i + 1 + m, y.size))):
        tx, yx = t[sl] - t0, y[sl]
        if tx.size < 3:
            continue
        c = np.polynomial.polynomial.polyfit(tx, yx, 2)
        r = np.polynomial.polynomial.polyroots(c)
        r = r[np.isreal(r)].real + t0
        if r.size:
            roots.append(r[np.argmin(np.abs(r - lin))])
    if not roots:
        return float(lin)
    ts = float(np.mean(roots))
    dt = t[i + 1] - t[i]
    return ts if t[i] - 0.5 * dt <= ts <= t[i + 1] + 0.5 * dt else float(lin)


def arch_peaks(t_s, theta_rad, t_cross, release: ReleaseInfo | None = None, sigma_rad: float | None = None):
    """Peak of each arch between successive crossings (and the release arch).

    The peak is the extremum of a quartic fitted to the samples within the upper 60 %
    of the arch, which averages out noise and the sampling grid; its standard error
    follows from the fit covariance. The release arch (block let go from rest) peaks at
    the plateau angle θ0.

    Returns
    -------
    DataFrame ``t_s, theta_rad, se_theta_rad, n_samples``: one row per arch ending at a
    crossing (row 0 is the release arch when ``release`` is given and found).
    """
    t = np.asarray(t_s, float)
    y = np.asarray(theta_rad, float)
    tc = np.asarray(t_cross, float)
    rows = []
    if release is not None and release.found:
        rows.append(
            (release.t_s, release.theta0_rad, release.sigma_rad / np.sqrt(max(release.n_plateau, 1)), release.n_plateau)
        )
    for a, b in zip(tc[:-1], tc[1:]):
        m = (t > a) & (t < b)
        if m.sum() < 3:
            rows.append((np.nan, np.nan, np.nan, int(m.sum())))
            continue
        ta, ya = t[m], y[m]
        s = np.sign(np.median(ya)) or 1.0
        top = s * ya >= 0.4 * np.max(s * ya)
        tt, yy = ta[top], ya[top]
        deg = 4 if tt.size >= 7 else (2 if tt.size >= 4 else 0)
        if deg == 0:
            k = int(np.argmax(s * ya))
            rows.append((float(ta[k]), float(ya[k]), np.nan, int(m.sum())))
            continue
        t0 = tt.mean()
        sc = max(float(np.ptp(tt)), 1e-9)
        x = (tt - t0) / sc
        V = np.vander(x, deg + 1, increasing=True)
        c, *_ = np.linalg.lstsq(V, yy, rcond=None)
        dc = np.polynomial.polynomial.polyder(c)
        r = np.roots(dc[::-1])
        r = r[np.isreal(r)].real
        r = r[(r >= x.min()) & (r <= x.max())]
        if r.size:
            vals = np.polynomial.polynomial.polyval(r, c)
            k = int(np.argmax(s * vals))
            x0, v0 = float(r[k]), float(vals[k])
        else:
            k = int(np.argmax(s * yy))
            x0, v0 = float(x[k]), float(yy[k])
        res = yy - V @ c
        sig = sigma_rad if sigma_rad is not None else (float(np.sqrt(res @ res / max(tt.size - deg - 1, 1))))
        v = np.vander(np.array([x0]), deg + 1, increasing=True)[0]
        se = float(sig * np.sqrt(v @ np.linalg.pinv(V.T @ V) @ v))
        rows.append((float(t0 + sc * x0), v0, se, int(m.sum())))
    return pd.DataFrame(rows, columns=["t_s", "theta_rad", "se_theta_rad", "n_samples"])


def _arch_end_slopes(t, y, ta, tb, powers=(0, 2)):
    """Slopes at both ends of the arch between crossings ta < tb.

    Fits θ = (t − ta)(tb − t)·Σ c_j u^j, u = 2(t − ta)/(tb − ta) − 1 ∈ [−1, 1], over the
    powers j given (both ends pinned at the crossing times) and differentiates at the
    ends. The default (0, 2) is even in u: between impacts the motion is conservative
    and time-reversible, so an arch is symmetric about its peak.
    Returns (slope at ta, slope at tb, n samples).
    """
    m = (t > ta) & (t < tb)
    x, yy = t[m], y[m]
    pw = list(powers)[: max(x.size - 2, 1)]
    if x.size < 3:
        return np.nan, np.nan, int(x.size)
    L = tb - ta
    u = 2.0 * (x - ta) / L - 1.0
    base = (x - ta) * (tb - x)
    X = np.column_stack([base * u**j for j in pw])
    c, *_ = np.linalg.lstsq(X, yy, rcond=None)
    qa = float(sum(ci * (-1.0) ** j for ci, j in zip(c, pw)))
    qb = float(np.sum(c))
    return L * qa, -L * qb, int(x.size)


def _release_arch_slope(t, y, rel: ReleaseInfo, tc0, powers=(0, 2)):
    """Slope at the first crossing of the release arch (block let go from rest at θ0).

    The release quarter-cycle is half of a symmetric arch whose peak is the release
    instant; the peak time is found by minimising the misfit of the pinned symmetric
    arch over the samples that have moved.
    """
    m = (t >= t[max(rel.index - 1, 0)]) & (t < tc0)
    if m.sum() < 3:
        return np.nan, int(m.sum())
    x, yy = t[m], y[m]

    def fit(tm):
        ta = 2 * tm - tc0
        L = tc0 - ta
        u = 2.0 * (x - ta) / L - 1.0
        X = np.column_stack([(x - ta) * (tc0 - x) * u**j for j in powers])
        c, *_ = np.linalg.lstsq(X, yy, rcond=None)
        r = yy - X @ c
        return float(r @ r), c, L

    dt = float(np.median(np.diff(t)))
    lo, hi = rel.t_s - 4 * dt, min(rel.t_s + 3 * dt, x[0] + 0.5 * dt)
    res = minimize_scalar(lambda tm: fit(tm)[0], bounds=(lo, hi), method="bounded", options=dict(xatol=1e-6 * dt))
    _, c, L = fit(res.x)
    return -L * float(np.sum(c)), int(m.sum())


def _u_rise(theta_abs, alpha):
    """Rise of the centre of mass over R, cos(α − |θ|) − cos α (exact for a rectangle)."""
    return np.cos(alpha - theta_abs) - np.cos(alpha)


def _rel_se_u(theta, se, alpha):
    """Relative standard error of u from that of a peak angle."""
    th = np.abs(theta)
    if alpha is None:
        return se / th
    return np.sin(alpha - th) / _u_rise(th, alpha) * se


def _release_for(t, y, block):
    """The release; placed by the block's release quarter-cycle when the block is known."""
    if block is None:
        return detect_release(t, y)
    rel, undecided = settle_release(t, y, block, min(2e-4, 2e-3 / block.p_rad_s))
    if undecided is not None:
        warn("W-FIT-RELEASE", undecided)
    return rel


def zero_crossings(t, y, rel):
    sig = max(rel.sigma_rad, 1e-9)
    ic = find_crossings(t, y, start=rel.index if rel.found else 0, threshold=max(4.0 * sig, 1e-6))
    return np.array([_local_crossing_time(t, y, i) for i in ic])


def per_impact_eta(
    t_s,
    theta_rad,
    block=None,
    release: ReleaseInfo | None = None,
    powers=(0, 2),
    max_se: float = 0.0025,
    crossings_t_s=None,
) -> pd.DataFrame:
    """Restitution of each impact from the data alone.

    Two estimates per impact:

    - ``eta_velocity`` = ω⁺/ω⁻ with ω⁻, ω⁺ the slopes at the crossing of local fits of the
      arches on each side (θ = (t − t_a)(t_b − t)·q(u), q even in u by default; crossing
      times from shared-root quadratic fits of the samples next to the crossing). No
      model and no finite differences, but the end slope of a noisy arch is poorly
      determined: at 150 fps and 0.02° noise its spread is ~0.02 for a 0.2 m block.
    - ``eta_peaks`` = sqrt(u_{i+1}/u_i), u = cos(α − |θ_peak|) − cos α the rise of the
      centre of mass at the arch peaks on each side. Energy between impacts is conserved,
      so u_{i+1}/u_i = (ω⁺/ω⁻)² exactly for a rigid rectangle; this uses the whole arch
      (amplitude) and is ~10× more precise. Needs only α from ``block``; without a block
      u ≈ |θ_peak| (small-angle rise, thesis Eq. 12 approximation), biased by O(|θ|/α).

    Parameters
    ----------
    t_s, theta_rad : array (n,)
    block : Block, optional
    release : ReleaseInfo, optional
        Computed when None: by :func:`~rocklab.fitting._release.settle_release` when ``block``
        is given, else by :func:`detect_release`.
    powers : tuple of int
        Powers of u in the arch polynomial q.
    max_se : float
        Impacts whose ``eta_peaks_se`` exceeds this are flagged ``ok=False``.
    crossings_t_s : array, optional
        Impact (zero-crossing) times if already known, s.

    Returns
    -------
    DataFrame, one row per impact: ``impact, t_s, omega_before_rad_s, omega_after_rad_s,
    eta_velocity, theta_peak_before_rad, theta_peak_after_rad, eta_peaks, eta_peaks_se,
    n_before, n_after, ok``.
    """
    t, y, _ = check_record(t_s, theta_rad)
    rel = release if release is not None else _release_for(t, y, block)
    cols = [
        "impact",
        "t_s",
        "omega_before_rad_s",
        "omega_after_rad_s",
        "eta_velocity",
        "theta_peak_before_rad",
        "theta_peak_after_rad",
        "eta_peaks",
        "eta_peaks_se",
        "n_before",
        "n_after",
        "ok",
    ]
    tc = zero_crossings(t, y, rel) if crossings_t_s is None else np.asarray(crossings_t_s, float)
    if tc.size == 0:
        return pd.DataFrame(columns=cols)
    peaks = arch_peaks(t, y, tc, release=rel, sigma_rad=rel.sigma_rad if rel.sigma_rad > 0 else None)
    if not rel.found:  # no release arch: the first crossing has no measured arch before it
        peaks = pd.concat([pd.DataFrame([[np.nan] * 3 + [0]], columns=peaks.columns), peaks], ignore_index=True)
    alpha = block.alpha_rad if block is not None else None
    rows = []
    for k in range(tc.size):
        if k == 0:
            wb, nb = _release_arch_slope(t, y, rel, tc[0], powers) if rel.found else (np.nan, 0)
        else:
            _, wb, nb = _arch_end_slopes(t, y, tc[k - 1], tc[k], powers)
        if k + 1 < tc.size:
            wa, _, na = _arch_end_slopes(t, y, tc[k], tc[k + 1], powers)
        else:
            wa, na = np.nan, 0
        pb, sb = peaks.theta_rad.iloc[k], peaks.se_theta_rad.iloc[k]
        pa, sa = (
            (peaks.theta_rad.iloc[k + 1], peaks.se_theta_rad.iloc[k + 1]) if k + 1 < len(peaks) else (np.nan, np.nan)
        )
        with np.errstate(invalid="ignore", divide="ignore"):
            if alpha is not None:
                ub, ua = _u_rise(abs(pb), alpha), _u_rise(abs(pa), alpha)
            else:
                ub, ua = abs(pb), abs(pa)
            ep = float(np.sqrt(ua / ub))
            se = float(0.5 * ep * np.hypot(_rel_se_u(pb, sb, alpha), _rel_se_u(pa, sa, alpha)))
            ev = float(wa / wb) if np.isfinite(wb) and wb != 0 else np.nan
        ok = bool(np.isfinite(ep) and np.isfinite(se) and se <= max_se)
        rows.append((k, tc[k], wb, wa, ev, pb, pa, ep, se, nb, na, ok))
    return pd.DataFrame(rows, columns=cols)


@dataclass(frozen=True)
class EnergyLoss:
    """Relative energy loss per rocking from successive peaks (Ther thesis Eq. 12).

    ``loss_i = (E_i − E_{i+1})/E_i ≈ (u_i − u_{i+1})/u_i`` with ``u`` the rise of the centre
    of mass at the i-th amplitude peak (exact for a rectangular block; |θ| when no block
    is given — the thesis's small-angle approximation).

    Attributes
    ----------
    peaks : DataFrame ``t_s, theta_rad, se_theta_rad, n_samples, u`` (u in m with a block,
        rad without)
    loss : ndarray (n_peaks − 1,) relative energy loss between successive peaks
    mean4 : mean of four consecutive losses starting at ``start`` (the thesis's statistic)
    start : first loss index averaged
    eta_equivalent : sqrt(1 − mean4), the constant velocity restitution losing that energy
    exact : True when u is the exact rise (block given)
    """

    peaks: pd.DataFrame = field(repr=False)
    loss: np.ndarray = field(repr=False)
    mean4: float
    start: int
    eta_equivalent: float
    exact: bool

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        return dict(
            mean4=self.mean4,
            start=self.start,
            eta_equivalent=self.eta_equivalent,
            exact=self.exact,
            loss=[float(x) for x in self.loss],
            peaks=self.peaks.to_dict(orient="records"),
        )

    def report(self) -> str:
        kind = "exact rise of the centre of mass" if self.exact else "small-angle u ~ |theta|"
        n = min(4, self.loss.size - self.start)
        return "\n".join(
            [
                "[[Energy loss per rocking (thesis Eq. 12)]]",
                f"    mean of {n} consecutive losses from #{self.start}: {100 * self.mean4:.2f} %  ({kind})",
                f"    equivalent restitution sqrt(1 - loss) = {self.eta_equivalent:.4f}",
                "    losses: " + ", ".join(f"{100 * x:.1f}%" for x in self.loss[:8]),
            ]
        )


def energy_loss_from_peaks(t_s, theta_rad, block=None, start: int = 0, n_avg: int = 4) -> EnergyLoss:
    """Thesis Eq. 12: energy loss between successive amplitude peaks, mean of ``n_avg``.

    Parameters
    ----------
    t_s, theta_rad : array (n,)
    block : Block, optional
        Gives the exact rise u = R[cos(α − |θ|) − cos α] (m), without it u = |θ|; and the
        release from the block's release quarter-cycle (see :func:`per_impact_eta`).
    start : int
        Index of the first loss averaged (0: the first rocking after release).
    n_avg : int
        Number of consecutive losses averaged (the thesis uses four).
    """
    t, y, _ = check_record(t_s, theta_rad)
    rel = _release_for(t, y, block)
    tc = zero_crossings(t, y, rel)
    if tc.size < 2:
        raise InputError(f"record has {tc.size} impact(s): need at least 2 for peak-to-peak energy loss")
    pk = arch_peaks(t, y, tc, release=rel).dropna(subset=["theta_rad"])
    if block is not None:
        u = block.R_m * _u_rise(np.abs(pk.theta_rad.to_numpy()), block.alpha_rad)
    else:
        u = np.abs(pk.theta_rad.to_numpy())
    pk = pk.assign(u=u)
    loss = (u[:-1] - u[1:]) / u[:-1]
    sel = loss[start : start + n_avg]
    if sel.size < n_avg:
        raise InputError(f"start={start}: only {loss.size} peak-to-peak losses in the record; need start + {n_avg}")
    m4 = float(np.mean(sel))
    eq = float(np.sqrt(1 - m4))
    return EnergyLoss(
        peaks=pk.reset_index(drop=True),
        loss=loss,
        mean4=m4,
        start=int(start),
        eta_equivalent=eq,
        exact=block is not None,
    )
