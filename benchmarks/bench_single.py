"""Single-block simulator speed: Newmark kernel vs the solve_ivp reference, batch throughput.

Issue 2 §4 targets: free rocking of B6M (b = 0.045 m, h = 0.2025 m) from
theta0 = 0.8 alpha for 10 s at dt = 1e-4 s >= 200x faster than solve_ivp
(DOP853, rtol 1e-10) with impact times within 1e-6 s; batch >= 1e7
block-steps/s per core. Numba compilation is excluded (warm-up first); every
timing is the best of several repeats, both methods in this process, measured as
process CPU time (``time.process_time``, summed over threads) so that other
jobs on a shared machine do not count; per-core throughput = steps / CPU time.

Under a base record (El Centro x 1.5, a 0.5 m x 3 m block rocking for 20 s)
the run is timed with the kernel's lean loops (default) and with its general
loop only (``lean=False``: how every step under a record ran before the
lean loop), against free rocking of the same block (eta = 1, 20 s) and solve_ivp.
"""

from __future__ import annotations

import time

import numba
import numpy as np

import rocklab.models._single as single_mod
from rocklab import Block
from rocklab.models import bundled_record, simulate, simulate_batch
from rocklab.models._newmark import run_single


def best(f, n):
    """Best of n: process CPU time (s, all threads) -- robust on a machine shared with other jobs."""
    ts = []
    for _ in range(n):
        t = time.process_time()
        out = f()
        ts.append(time.process_time() - t)
    return min(ts), out


def main():
    blk = Block(0.045, 0.2025, name="B6M")
    th0 = 0.8 * blk.alpha_rad
    kw = dict(duration_s=10.0, dt_s=1e-4)
    simulate(blk, th0, **kw)  # warm-up (compile / load cache)
    t_nm, nm = best(lambda: simulate(blk, th0, **kw), 20)
    t_ev, ev = best(lambda: simulate(blk, th0, method="event", rtol=1e-10, **kw), 2)
    n = min(nm.n_impacts, ev.n_impacts)
    d = np.abs(nm.impacts.t_s.to_numpy()[:n] - ev.impacts.t_s.to_numpy()[:n])
    steps = len(nm.t_s) - 1
    print(f"B6M free rocking, theta0 = 0.8 alpha, 10 s, dt = 1e-4 s (Housner eta = {blk.eta_H:.4f})")
    print(f"  newmark simulate(): {t_nm * 1e3:8.2f} ms  ({steps} steps to rest at {nm.t_s[-1]:.3f} s, "
          f"{nm.n_impacts} impacts, {t_nm / steps * 1e9:.0f} ns/step incl. result building)")
    print(f"  event   simulate(): {t_ev * 1e3:8.2f} ms  (solve_ivp DOP853 rtol 1e-10, {ev.n_impacts} impacts)")
    print(f"  speed ratio event/newmark: {t_ev / t_nm:8.1f}x   (target >= 200x; DOP853 is scipy's "
          "fastest reference here)")
    t_ra, ra = best(lambda: simulate(blk, th0, method="event", rtol=1e-10, ode_method="Radau", **kw), 1)
    dr = np.abs(ra.impacts.t_s.to_numpy()[:20] - nm.impacts.t_s.to_numpy()[:20]).max()
    print(f"  event Radau  simulate(): {t_ra * 1e3:8.2f} ms -> ratio {t_ra / t_nm:8.1f}x "
          f"(first-20 impact times within {dr:.2e} s)")
    print(f"  max |impact time difference|: first 20 {d[:20].max():.2e} s, all {n} {d.max():.2e} s "
          "(target <= 1e-6 s)")

    rec = bundled_record("elcentro")
    under_record(rec)

    # batch throughput, one thread = per core; then all threads
    R = np.geomspace(0.1, 5.0, 20)
    p = np.sqrt(3 * 9.80665 / (4 * R))
    P, S = np.meshgrid(p, np.linspace(0.1, 1.5, 25))
    A = np.full_like(P, 0.2)
    free_eta1 = dict(eta=1.0, theta0_rad=0.5 * 0.2, duration_s=10.0, dt_s=1e-3)
    simulate_batch(p[:2], 0.2, base=rec, scale=0.5, duration_s=1.0)  # warm-up
    simulate_batch(p[:2], 0.2, eta=1.0, theta0_rad=0.1, duration_s=1.0)
    nthreads = numba.get_num_threads()
    for nt in sorted({1, nthreads}):
        numba.set_num_threads(nt)
        t_b, bat = best(lambda: simulate_batch(P.ravel(), A.ravel(), base=rec, scale=S.ravel()), 2)
        t_f, fr = best(lambda: simulate_batch(np.repeat(p, 25), 0.2, **free_eta1), 2)
        print(f"batch, {nt} thread(s):")
        print(f"  El Centro grid {P.size} runs (20 sizes x 25 scales, dt 1e-3, {bat.overturned.sum()} fall): "
              f"{bat.n_steps / t_b:.3g} block-steps/s/core")
        print(f"  free rocking eta = 1 (always moving), {fr.p_rad_s.size} runs x 10 s: "
              f"{fr.n_steps / t_f:.3g} block-steps/s/core   (target >= 1e7)")
    numba.set_num_threads(nthreads)


def general_loop(*args):
    """run_single with the lean loops off (every step in the general Newton loop)."""
    return run_single(*args, False)


def under_record(rec):
    """One block rocking under a record: lean loops vs general loop vs free rocking vs solve_ivp."""
    big = Block(0.5, 3.0, name="0.5 x 3 m")
    T, dt = 20.0, 1e-4
    kw = dict(duration_s=T, dt_s=dt, stop_at_rest=False)
    base = rec.scaled(1.5)
    kwf = dict(kw, restitution="constant", eta=1.0)

    def general():
        single_mod.run_single = general_loop
        try:
            return simulate(big, 0.0, base=base, **kw)
        finally:
            single_mod.run_single = run_single

    runs = {"lean": lambda: simulate(big, 0.0, base=base, **kw), "general": general,
            "free": lambda: simulate(big, 0.5 * big.alpha_rad, **kwf)}
    for f in runs.values():
        f()  # warm-up
    # interleaved repeats: the three see the same machine state (turbo, neighbours' load)
    ts = {k: [] for k in runs}
    out = {}
    for _ in range(12):
        for k, f in runs.items():
            t, out[k] = best(f, 1)
            ts[k].append(t)
    (t_ln, t_gn, t_fr), (ln, gn, fr) = (min(ts[k]) for k in runs), (out[k] for k in runs)
    kwe = dict(kw, duration_s=10.0)
    t_ev, ev = best(lambda: simulate(big, 0.0, base=base, method="event", rtol=1e-10, **kwe), 1)
    n_ln, n_fr, n_ev = len(ln.t_s) - 1, len(fr.t_s) - 1, int(round(10.0 / dt))
    d = np.max(np.abs(ln.theta_rad - gn.theta_rad))
    print(f"{big.name} under El Centro x 1.5, {T:g} s, dt = {dt:g} s, every step stored "
          f"({ln.n_impacts} impacts, {100 * np.mean(ln.theta_rad == 0):.0f} % of steps at rest):")
    print(f"  lean loops (default): {t_ln * 1e3:7.2f} ms  {n_ln / t_ln:.3g} block-steps/s/core")
    print(f"  general loop only:    {t_gn * 1e3:7.2f} ms  {n_ln / t_gn:.3g} block-steps/s/core "
          f"-> lean is {t_gn / t_ln:.2f}x faster (max |theta difference| {d:.1e} rad, "
          f"{gn.n_impacts} impacts)")
    print(f"  free rocking, same block (eta = 1, {fr.n_impacts} impacts): {n_fr / t_fr:.3g} block-steps/s/core "
          f"-> under the record at {t_fr / n_fr / (t_ln / n_ln):.2f}x its rate")
    print(f"  event (solve_ivp DOP853 rtol 1e-10, first 10 s): {t_ev * 1e3:.0f} ms  {n_ev / t_ev:.3g} "
          f"block-steps/s -> ratio {t_ev / n_ev / (t_ln / n_ln):.0f}x per simulated second")


if __name__ == "__main__":
    main()
