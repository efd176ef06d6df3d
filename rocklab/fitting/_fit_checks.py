"""What makes a restitution fit suspect: a gap that can hide an impact, a misfit far above the noise,
runs of one-signed residuals, impacts that disagree, a rest that is not at zero.

Used by :func:`rocklab.fitting.fit_restitution`; each finding becomes a named warning or a flag.
"""

from __future__ import annotations

import math

import numpy as np

from .._diagnostics import warn

__all__ = ["RESIDUAL_FACTOR", "RESIDUAL_FLOOR_RAD"]


#: A fit whose residual RMS exceeds this multiple of the measurement noise is flagged
#: W-FIT-RESIDUAL: the model (or the block's dimensions) does not describe the test.
RESIDUAL_FACTOR = 20.0
#: Smallest noise the residual is compared with, rad (0.057 deg): the rest plateau's noise
#: understates what a tracker does in motion (blur at impacts: the demo's slender blocks fit
#: to 3.6e-3 and 8.7e-3 rad RMS with the true eta and 2e-5 rad of plateau noise).
RESIDUAL_FLOOR_RAD = 1e-3


def cut_at_gap(t, y, t_release_s, sigma_rad):
    """Keep the record up to the first gap after the release that could hide an impact.

    Impacts inside a gap cannot be seen, so counting half-cycles across it makes every
    later impact one off (a 0.4 s occlusion turned eta_e 0.75 into 0.53). A gap is
    dangerous when it lasts more than half of the shortest half-cycle seen before it (or
    the first one after it, where fewer than two impacts precede it: half-cycles only
    shorten as the rocking decays); the fit then uses the data before the gap and says so
    (``W-FIT-GAP``). Half-cycles are those resolved by the sampling (over two steps), and a
    gap of one missing sample is no gap: two impacts hidden in it would be as unresolved
    without it (a dropped video frame, a variable frame rate).
    """
    d = np.diff(t)
    med = float(np.median(d))
    cand = np.flatnonzero((d > 2.5 * med) & (t[:-1] >= t_release_s))
    if not cand.size:
        return t, y, None
    # sign changes of theta away from the noise band: the impacts seen so far
    big = np.abs(y) > 5.0 * max(sigma_rad, 1e-9)
    idx = np.flatnonzero(big & (t >= t_release_s))
    sgn = np.sign(y[idx])
    t_cross = t[idx[1:][sgn[1:] != sgn[:-1]]]
    halves = np.diff(t_cross)
    resolved = halves > 2.0 * med
    for i in cand:
        before = resolved & (t_cross[1:] <= t[i])
        after = np.flatnonzero(resolved & (t_cross[:-1] >= t[i + 1]))
        if np.count_nonzero(before):
            half = float(np.min(halves[before]))
        elif after.size:  # half-cycles shorten as the rocking decays: the next one bounds those in the gap
            half = float(halves[after[0]])
        else:  # fewer than two impacts in the whole record: the fit fails on its own
            continue
        if d[i] > 0.5 * half:
            n_lost = int(round(d[i] / med)) - 1
            diag = warn(
                "W-FIT-GAP",
                f"theta(t) has a {d[i]:.4g} s gap ({n_lost} samples) at t = {t[i]:.4g} s, "
                f"longer than half the {'shortest half-cycle before it' if np.count_nonzero(before) else 'half-cycle after it'} "
                f"({half:.4g} s); the fit uses the {i + 1} samples before the gap",
            )
            return t[: i + 1], y[: i + 1], diag
    return t, y, None


def suspicion(t, y, res, rms, sigma, pie, tc, alpha):
    """Symptoms of slip or jumping: structured residuals, asymmetric decay, offset rest, jumps."""
    flags = []
    if res.size >= 20 and rms > 3.0 * sigma:
        s = np.sign(res)
        s = s[s != 0]
        runs = 1 + int(np.sum(s[1:] != s[:-1]))
        n1, n2 = int(np.sum(s > 0)), int(np.sum(s < 0))
        n = n1 + n2
        if n1 and n2:
            mu = 2.0 * n1 * n2 / n + 1
            var = (mu - 1) * (mu - 2) / (n - 1)
            z = (runs - mu) / math.sqrt(max(var, 1e-12))
            if z < -4:
                flags.append(
                    f"structured residuals: RMS {rms / sigma:.1f}x the noise and a runs test z = {z:.1f} "
                    "(misfit: slip, jump or a restitution that changes during rocking)"
                )
        big = np.abs(res) > 8.0 * max(rms, sigma)
        if big.any():
            flags.append(f"{int(big.sum())} residual(s) above 8x RMS: isolated jump or tracking glitch")
    ok = pie[pie["ok"]] if len(pie) else pie
    if len(ok) >= 4:
        # alternation between the two corners: median of (−1)^k (η_k − η_{k+1}) / 2 over consecutive
        # impacts; a steady trend or a single odd impact drops out, unequal corners do not
        e = ok["eta_peaks"].to_numpy()
        k = ok["impact"].to_numpy()
        se = ok["eta_peaks_se"].to_numpy()
        pair = np.flatnonzero(np.diff(k) == 1)
        if pair.size >= 3:
            a = ((-1.0) ** k[pair]) * (e[pair] - e[pair + 1]) / 2
            sd = float(np.sqrt(np.mean(se[pair] ** 2 + se[pair + 1] ** 2) / 4 / pair.size) + 1e-12)
            d = float(np.median(a))
            if abs(d) > max(4 * sd, 0.005):
                flags.append(
                    f"asymmetric amplitudes: per-impact eta alternates by {2 * d:+.3f} between the two "
                    "corners (tilted base, slip or unequal corners)"
                )
    after = t > tc[-1] + 2 * (tc[-1] - tc[-2]) if tc.size >= 2 else np.zeros_like(t, bool)
    if after.sum() >= 10:
        rest = float(np.median(y[after]))
        if abs(rest) > max(10 * sigma / math.sqrt(after.sum()) + 3 * sigma, 0.01 * alpha):
            flags.append(
                f"block came to rest at {rest:+.4f} rad, not 0: it slipped or jumped (or the level "
                "reference is off: try fit_offset=True)"
            )
    return flags
