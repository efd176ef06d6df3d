"""Speed of the restitution fit (issue 5): one η_e fit and a 30-experiment campaign.

Targets: one fit of a 10 s record at 150 fps in <= 1 s; 30 experiments in <= 30 s.
Baseline in the same process: a naive grid search (η step 0.001 over [0.5, 0.999], release
time and θ0 fixed from the rest plateau, dt = 1e-4 s) — what one would write first.
Prints wall times, the speed ratio and the accuracy of both. Run: ``python benchmarks/bench_fit.py``.
"""

from __future__ import annotations

import math
import time

import numpy as np

from rocklab.fitting import catalogue_block, ceh_catalogue, detect_release, fit_many, fit_restitution
from rocklab.models import simulate

FPS = 150.0
NOISE = math.radians(0.02)


def record(block, eta, seed, duration=10.0):
    rng = np.random.default_rng(seed)
    t_rel = 0.4 + rng.uniform(0, 1 / FPS)
    th0 = rng.uniform(0.3, 0.6) * block.alpha_rad
    r = simulate(block, th0, 0.0, duration, 2e-5, restitution="constant", eta=eta)
    t = np.arange(0, duration, 1 / FPS)
    th = np.interp(t - t_rel, r.t_s, r.theta_rad, left=th0, right=0.0)
    return t, th + rng.normal(0, NOISE, t.size)


def naive_grid(t, y, block):
    """Baseline: SSE on the whole record for η on a 0.001 grid, release fixed from the data."""
    rel = detect_release(t, y)
    best = (np.inf, np.nan)
    for eta in np.arange(0.5, 0.9995, 0.001):
        r = simulate(block, rel.theta0_rad, 0.0, t[-1] - rel.t_s, 1e-4, restitution="constant", eta=eta)
        m = np.interp(t - rel.t_s, r.t_s, r.theta_rad, left=rel.theta0_rad, right=0.0)
        sse = float(np.sum((y - m) ** 2))
        best = min(best, (sse, eta))
    return best[1]


def main():
    b6m = catalogue_block("B6M")
    # warm up (numba compilation / cache load)
    t, y = record(b6m, 0.93, 0)
    fit_restitution(t, y, b6m)

    runs = [record(b6m, 0.93, s) for s in range(1, 11)]
    t0 = time.perf_counter()
    fits = [fit_restitution(t, y, b6m) for t, y in runs]
    t_fit = (time.perf_counter() - t0) / len(runs)
    err = max(abs(f.eta_e - 0.93) for f in fits)

    t0 = time.perf_counter()
    eta_naive = naive_grid(*runs[0], b6m)
    t_naive = time.perf_counter() - t0
    print(f"one eta_e fit (B6M, 10 s at 150 fps): {t_fit:.3f} s  (target <= 1 s), max |err| = {err:.2e}")
    print(f"naive grid search baseline:          {t_naive:.3f} s, |err| = {abs(eta_naive - 0.93):.2e}")
    print(f"speed ratio baseline / fit:          {t_naive / t_fit:.1f}x")

    # campaign: 30 experiments over the Čeh catalogue with Table 3 restitutions
    cat = ceh_catalogue().dropna(subset=["eta_e_full"])
    rng = np.random.default_rng(5)
    rows = cat.sample(30, replace=True, random_state=5).reset_index(drop=True)
    camp = []
    for i, r in rows.iterrows():
        blk = catalogue_block(r.block)
        camp.append((*record(blk, float(r.eta_e_full), int(rng.integers(1 << 30))), blk))
    t0 = time.perf_counter()
    cf = fit_many(camp)
    t_camp = time.perf_counter() - t0
    errs = np.array([f.eta_e - e for f, e in zip(cf, rows.eta_e_full)])
    n_ok = sum(f.ok for f in cf)
    print(
        f"30-experiment campaign:              {t_camp:.2f} s  (target <= 30 s), {n_ok}/30 ok, "
        f"max |err| = {np.nanmax(np.abs(errs)):.2e}"
    )
    if t_fit > 1.0 or t_camp > 30.0:
        print("WARNING: speed target missed on this machine")


if __name__ == "__main__":
    main()
