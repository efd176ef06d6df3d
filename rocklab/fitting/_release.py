"""Where a thread-burn release happens in a measured θ(t): the block at rest at θ0, then let go.

:func:`detect_release` judges the release on the record's own noise, model-free.
:func:`settle_release` (used by :func:`~rocklab.fitting.fit_restitution`, which knows the
block) then places it where the physics of the release quarter-cycle fits the record best:
a slow start (θ0 near α creeps away for many samples) and a compressed film's stepping
plateau each fool a detector that only compares samples with a noise level. Times in s,
angles in rad; arrays have shape (n,).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.stats import chi2

from ._simfit import ac_factor, Problem

__all__ = ["ReleaseInfo", "detect_release", "settle_release"]


@dataclass(frozen=True)
class ReleaseInfo:
    """Where a thread-burn release happens in a record.

    Attributes
    ----------
    found : bool
    t_s : float
        Estimated release time (last sample at rest), s.
    index : int
        Index of the first sample that has moved.
    theta0_rad : float
        Median angle of the initial plateau, rad.
    sigma_rad : float
        Scatter of θ on the plateau (see :func:`_held_scale`), rad.
    n_plateau : int
        Number of plateau samples.
    message : str
    """

    found: bool
    t_s: float
    index: int
    theta0_rad: float
    sigma_rad: float
    n_plateau: int
    message: str = ""


def _held_scale(dev) -> float:
    """Scatter of a held block's angle about its level, rad: the 90th percentile of |dev| / 1.645.

    For white noise this is σ. Compressed video repeats a still block's angle for many frames
    and then steps (a median absolute deviation or a difference-based σ would be ~0 there);
    the percentile keeps those steps, and a few isolated glitches do not inflate it.
    """
    dev = np.abs(np.asarray(dev, float))
    return float(np.percentile(dev, 90) / 1.6449) if dev.size else 0.0


#: Why a record has no release: the block was not held still before it moved.
STARTS_IN_MOTION = (
    "record starts in motion: no rest plateau before release; keep ~0.1 s of the block at rest before the thread burns"
)
#: Why a record has no release: nothing departs from the first level.
NEVER_MOVES = "block never moves: no release in the record"


def _no_release(message, index, theta0_rad, sigma_rad, n_plateau) -> ReleaseInfo:
    """A record without a release (``found=False``, ``t_s`` NaN) and why."""
    return ReleaseInfo(False, float("nan"), int(index), float(theta0_rad), float(sigma_rad), int(n_plateau), message)


def _at_zero(theta0_rad) -> str:
    """Why a record has no release: its plateau is within noise of upright."""
    return f"initial angle {theta0_rad:.3g} rad is within noise of 0: no tilted start (thread-burn release) found"


def detect_release(t_s, theta_rad, min_plateau: int = 3) -> ReleaseInfo:
    """Find the initial rest plateau at θ0 and the moment the block starts to move.

    Every threshold comes from the record itself, so compressed or interlaced video and
    flicker, which make a held block's angle step, drift or alternate, are judged on their
    own scatter. The block is under way once it has come half-way down to upright for three
    consecutive samples; the departure is followed back while it keeps shrinking (a released
    block accelerates away monotonically), and the samples before are the plateau. Its
    scatter σ (90th percentile of the deviations, see :func:`_held_scale`) fixes where the
    motion is clearly under way (6 σ from the plateau's last level); from there the release
    is placed where the departure came within 1.5× the RMS scatter of the samples before,
    measured from their last level (the level of a compressed film can step while the block
    is held). θ0 is the median of the plateau.

    A record has no release (``found=False`` with the reason) when the plateau is shorter
    than half of ``max(min(20, n // 3), min_plateau)`` samples or not still compared with
    the release (its fitted acceleration above 5 % of the release's: the record starts in
    motion), when the block never comes half-way down, or when θ0 is within 10 σ of 0 — unless
    a noise level from the first samples finds one (:func:`_threshold_release`): a slow start
    (θ0 near α) creeps away under the noise, so the departure followed back leaves part of the
    motion in the plateau and its scatter hides θ0. When that finds the block moving earlier,
    θ0 and σ come from the samples before its release (the release time stays).
    """
    rel = _noise_release(t_s, theta_rad, min_plateau)
    alt = _threshold_release(t_s, theta_rad, min_plateau)
    if not rel.found:
        return alt if alt.found else rel
    if alt.found and alt.n_plateau < rel.n_plateau - 3:
        # the first samples' noise saw the block move earlier: a slow start's creep (or a compressed
        # film's step) follows, so θ0 and the scatter come from the samples before it
        pl = np.asarray(theta_rad, float)[: max(alt.n_plateau, 3)]
        med = float(np.median(pl))
        return ReleaseInfo(True, rel.t_s, rel.index, med, _held_scale(pl - med), rel.n_plateau)
    return rel


def _noise_release(t_s, theta_rad, min_plateau: int = 3) -> ReleaseInfo:
    """:func:`detect_release` without the fallback to the first samples' noise."""
    t = np.asarray(t_s, float)
    y = np.asarray(theta_rad, float)
    n = y.size
    m0 = max(min(20, n // 3), min_plateau)
    lvl = float(np.median(y[:m0]))
    s = 1.0 if lvl >= 0 else -1.0
    far = s * (lvl - y) > 0.5 * abs(lvl)
    run3 = far[:-2] & far[1:-1] & far[2:]
    if not run3.any():
        sig = _held_scale(y - float(np.median(y)))
        if abs(lvl) < 10 * max(sig, 1e-9):
            return _no_release(_at_zero(lvl), n, lvl, sig, n)
        return _no_release(NEVER_MOVES, n, lvl, sig, n)
    g = int(np.argmax(run3))
    i = g
    while i > 0 and y[i - 1] * s > y[i] * s:
        i -= 1
    pl = y[: max(i - 1, 0)]
    if pl.size >= m0 // 2:
        # under way: beyond 6 σ of the plateau's last level; then back to where the departure was
        # within the scatter of the samples before
        sig = _held_scale(pl - np.median(pl))
        last = float(np.median(pl[-m0:]))
        i = g
        while i > 0 and s * (last - y[i - 1]) > 6.0 * max(sig, 1e-12):
            i -= 1
        pl = y[: max(i - 1, 1)]
        med = float(np.median(pl))
        tol = 1.5 * max(float(np.sqrt(np.mean((pl - med) ** 2))), 1e-12)
        # within the scatter of the plateau's level, or of its last level: a compressed film's level
        # can step while the block is held, and a slow start drags the last samples towards upright
        last = float(np.median(pl[-max(3, m0 // 4) :]))
        while i > 0 and s * (med - y[i - 1]) > tol and s * (last - y[i - 1]) > tol:
            i -= 1
    n_pl = max(i - 1, 2)
    med = float(np.median(y[:n_pl]))  # plateau only: early-motion samples would bias θ0 towards 0
    sig = _held_scale(y[:n_pl] - med)
    # a held block does not accelerate: compare the plateau's fitted acceleration with the release's
    a_pl = 2.0 * abs(np.polynomial.polynomial.polyfit(t[:n_pl] - t[0], y[:n_pl], 2)[2]) if n_pl >= 3 else np.inf
    a_rel = 2.0 * abs(y[g] - med) / max(t[g] - t[n_pl], 1e-12) ** 2
    if n_pl < m0 // 2 or a_pl > 0.05 * a_rel:
        return _no_release(STARTS_IN_MOTION, 0, med, sig, 0)
    if abs(med) < 10 * max(sig, 1e-9):
        return _no_release(_at_zero(med), i, med, sig, n_pl)
    moved = np.flatnonzero(s * (med - y[i : g + 1]) > 6.0 * sig)  # first sample clearly under way
    return ReleaseInfo(True, float(t[max(i - 1, 0)]), i + int(moved[0]) if moved.size else g, med, sig, n_pl)


def _threshold_release(t_s, theta_rad, min_plateau: int = 3) -> ReleaseInfo:
    """Release against a noise level from the first samples (the start for :func:`settle_release`).

    The first samples must be flat (a quadratic fitted to them varies by less than 4 σ).
    The block is at rest until three consecutive samples lie beyond ``max(6 σ, 1e-3 |θ0|)``
    on the same side of the running plateau median (σ: standard deviation on the plateau); the release is placed where the departure was ~1 σ and θ0 is the median of
    the samples before it. A record that starts in motion, never moves, or whose plateau
    is at θ ≈ 0 has no release (``found=False`` with the reason).
    """
    t = np.asarray(t_s, float)
    y = np.asarray(theta_rad, float)
    n = y.size
    m0 = max(min(20, n // 3), min_plateau)
    # start: quadratic fit to the first samples; at rest the fitted curve stays within noise
    x = (t[:m0] - t[0]) / max(t[m0 - 1] - t[0], 1e-12)
    c = np.polynomial.polynomial.polyfit(x, y[:m0], 2)
    fit0 = np.polynomial.polynomial.polyval(x, c)
    sig = float(np.std(y[:m0] - fit0, ddof=3)) if m0 > 3 else 0.0
    med = float(np.median(y[:m0]))
    floor = max(1e-3 * abs(med), 1e-7)
    if np.ptp(fit0) > max(4.0 * sig, floor) or np.any(np.abs(y[:m0] - med) > max(8.0 * sig, floor)):
        return _no_release(STARTS_IN_MOTION, 0, med, sig, 0)
    # grow the plateau until the departure: 3 consecutive samples beyond tolerance on the same
    # side (a released block accelerates away; an isolated noise spike does not persist)
    i = m0
    tol = max(6.0 * sig, floor)
    while i < n:
        d = y[i : i + 3] - med
        if d.size == 3 and np.all(np.abs(d) > tol) and abs(np.sum(np.sign(d))) == 3:
            break
        if d.size < 3:
            i = n
            break
        i += 1
        if i % 16 == 0:
            med = float(np.median(y[:i]))
            sig = float(np.std(y[:i], ddof=1))
            tol = max(6.0 * sig, floor)
    if i >= n:
        return _no_release(NEVER_MOVES, n, med, sig, n)
    # the departure is quadratic in time: step back to where |θ − θ0| was ~1 σ
    sig = float(np.std(y[:i], ddof=1))
    j = i
    while j > 0 and abs(y[j - 1] - med) > 1.0 * sig:
        j -= 1
    n_pl = max(j - 1, 2)
    med = float(np.median(y[:n_pl]))  # plateau only: early-motion samples would bias θ0 towards 0
    sig = float(np.std(y[:n_pl], ddof=1))
    if abs(med) < 10 * max(sig, 1e-6):
        return _no_release(_at_zero(med), i, med, sig, n_pl)
    return ReleaseInfo(True, float(t[max(j - 1, 0)]), i, med, sig, n_pl)


def _release_at(t, y, t_r, s):
    """ReleaseInfo for a release at ``t_r`` (s): plateau, its median and scatter, first moved sample."""
    n_pl = max(int(np.searchsorted(t, t_r, side="right")), 2)
    theta0 = float(np.median(y[:n_pl]))
    sig = _held_scale(y[:n_pl] - theta0)
    moved = np.flatnonzero((t > t_r) & (s * (theta0 - y) > 6.0 * sig))
    first = int(moved[0]) if moved.size else min(n_pl, y.size - 1)
    return ReleaseInfo(True, float(t_r), first, float(theta0), sig, n_pl)


def settle_release(t, y, block, dt_s: float, max_nodes: int = 400, p_ambiguous: float = 0.999):
    """Release time where the release quarter-cycle of ``block`` fits the record best.

    The start comes from :func:`detect_release`. Every sample before the first pass through
    upright is then compared with the block released from rest at each candidate time (every
    sample up to two after the first one the detector saw clearly moved, at most ``max_nodes``
    of them; θ0 profiled by least squares); the best is refined by Brent's method between its
    neighbours. Before the first impact the motion does not depend on η,
    so one simulation serves every candidate. A second, separate minimum (more than 3 samples
    away) whose misfit is within the ``p_ambiguous`` χ²₁ quantile of the noise (scaled by the
    residuals' lag-one autocorrelation), or a best candidate at the edge of the record, leaves
    the release undecided (the caller warns ``W-FIT-RELEASE``).

    Parameters
    ----------
    t, y : array (n,)
        Checked record: times (s), angles (rad).
    block : rocklab.Block
    dt_s : float
        Simulation step, s.

    Returns
    -------
    (ReleaseInfo, str or None)
        The release, and why it is not decided (None when it is). The detector's answer is
        returned unchanged when it finds no release, the record never passes upright after it
        or θ0 is not below α (the fit fails on those itself), and when the block's release
        would come after the data show it moving (the block's dimensions do not describe the
        record: the fit's residual says so).
    """
    rel = detect_release(t, y)
    if not rel.found:
        return rel, None
    s = 1.0 if rel.theta0_rad > 0 else -1.0
    ys = s * y
    past = np.flatnonzero(ys[rel.index :] <= 0)
    th0 = abs(rel.theta0_rad)
    if past.size == 0 or th0 >= block.alpha_rad:
        return rel, None
    k1 = rel.index + int(past[0])  # first sample past upright: before it, the motion is η-free
    idx = np.arange(k1)
    # the block cannot have been at rest after the detector saw it clearly under way (give or take
    # the frame a compressed film can show it stirring early)
    k_max = min(rel.index + 2, k1 - 1)
    stride = max(1, (k_max - 1) // max_nodes)
    nodes = np.arange(1, k_max, stride)
    if nodes.size < 3:
        return rel, None
    for _ in range(2):  # θ0 enters linearly about th0; re-centre once on the profiled level
        prob = Problem(t, ys, block, th0, dt_s, t[k1] - t[0] + 0.1)
        sse = np.array([prob.at_release(0.5, idx, t[i])[0] for i in nodes])
        b = int(np.argmin(sse))
        lo, hi = t[nodes[max(b - 1, 0)]], t[nodes[min(b + 1, nodes.size - 1)]]
        res = minimize_scalar(
            lambda tr: prob.at_release(0.5, idx, tr)[0],
            bounds=(lo, hi),
            method="bounded",
            options=dict(xatol=1e-6 * (t[1] - t[0])),
        )
        f_hat, th_hat, _ = prob.at_release(0.5, idx, float(res.x))
        if abs(th_hat - th0) < 1e-3 * (block.alpha_rad - th0) or th_hat >= block.alpha_rad:
            break
        th0 = th_hat
    t_r = float(res.x)
    m0, S = prob.model(0.5, t[idx], t_r)
    resid = ys[idx] - m0 - (th_hat - prob.theta0) * S
    thresh = float(chi2.ppf(p_ambiguous, 1)) * f_hat / max(k1 - 2, 1) * ac_factor(resid)
    rivals = np.flatnonzero((np.abs(nodes - nodes[b]) > 3) & (sse - f_hat < thresh))
    if b == nodes.size - 1:  # the physics wants a later release than the data allow: not the block's motion
        return rel, None
    out = _release_at(t, y, t_r, s)
    note = None
    if rivals.size or b == 0:
        span = t[nodes[rivals]]
        other = (
            f"releases from {min(span.min(), t_r):.4g} to {max(span.max(), t_r):.4g} s fit as well"
            if rivals.size
            else "at the edge of the record"
        )
        note = (
            f"release at {t_r:.4g} s is not decided: {other} (the detector said {rel.t_s:.4g} s); "
            "eta from this record depends on which is right"
        )
    return out, note
