"""Speed of one Overturning Acceleration Spectrum (80 x 120 + refinement, 30 s record, H/B = 12;
issue 27: <= 0.2 s on 2 cores).

Baselines: the same OAS by Newmark runs at p h <= 0.001 (the default before session 13), on the
dense grid (every point simulated), and solve_ivp DOP853 with events.

Prints, in one process:

1. wall time of the default OAS (adaptive grid, Taylor runs; all numba threads: issue 27's
   figure is on 2 cores) of FEMA far-field FF-1 (Northridge, Beverly Hills MUL009, 30 s at dt = 0.01 s) after a warm-up call that loads/compiles the
   kernels, the Newmark path's time on the same grid, alternated with it (the ratio is the
   figure that survives a loaded machine), then the dense grid's time and how many of its
   verdicts the adaptive grid shares; then the default and the Newmark path on one numba thread in
   process CPU time (min of 3, alternated: what a loaded machine does not distort);
2. the baseline, on the same work and the same number of threads: a random sample of the
   grid's runs (levels > 1.5) by ``simulate(method="event")`` (scipy ``solve_ivp`` DOP853,
   events for impact and overturning; one thread) and the same sampled runs by the OAS's own
   batch path on one numba thread; the per-run times, their ratio (per core), and how many
   sampled verdicts agree (the rest sit on the chaotic boundary).

Falls back to the bundled El Centro record if ../shared is absent.
Run: ``.venv/bin/python benchmarks/bench_oas.py`` (part of ``make bench``).
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from rocklab import Block, G
from rocklab.models import bundled_record, load_base_motion, overturning_spectrum, simulate

FF1 = Path(__file__).resolve().parents[2] / "shared/data/records/fema-p695-far-field/SortedEQFile_120111.txt"


def ivp_run(block, base, eta):
    """The package's event-driven reference (scipy solve_ivp DOP853 with impact events)."""
    r = simulate(
        block,
        base=base,
        duration_s=float(base.t_s[-1]),
        method="event",
        restitution=eta,
        fall_rad=block.alpha_rad,
        rtol=1e-9,
    )
    return bool(r.overturned)


def main() -> int:
    rec = load_base_motion(FF1, units="g") if FF1.is_file() else bundled_record("elcentro")
    print(f"record {rec.name}: {rec.duration_s:.1f} s at dt = {rec.dt_s:g} s")
    t0 = time.perf_counter()
    overturning_spectrum(rec, 12, levels=2, sizes=2, refine=1)
    overturning_spectrum(rec, 12, levels=2, sizes=2, refine=1, method="newmark")
    print(f"first call (cache load or compilation): {time.perf_counter() - t0:.2f} s")

    times, t_nm = [], []
    for _ in range(3):
        t0 = time.perf_counter()
        o = overturning_spectrum(rec, 12)
        times.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        nm = overturning_spectrum(rec, 12, method="newmark")
        t_nm.append(time.perf_counter() - t0)
    t_oas = float(np.median(times))
    t_newmark = float(np.median(t_nm))
    n_bis = bisection_runs(rec)
    n_runs = o.overturned.size + n_bis  # the dense grid's work: the baseline below is priced on it
    t0 = time.perf_counter()
    d = overturning_spectrum(rec, 12, grid="dense")
    t_dense = time.perf_counter() - t0
    same = float(np.mean(o.overturned == d.overturned))
    print(
        f"OAS 80 x 120 + bisection, H/B = 12, adaptive grid, Taylor runs (the default): {t_oas:.3f} s "
        f"(median of 3; {min(times):.3f}-{max(times):.3f}) "
        f"({o.n_runs + n_bis} runs); t_I = {o.t_I_s:.4f} s; target <= 0.2 s: {'OK' if t_oas <= 0.2 else 'MISSED'}"
    )
    print(
        f"  Newmark runs at p h <= 0.001 (the default before session 13), same process: {t_newmark:.3f} s "
        f"({nm.n_runs + n_bis} runs), t_I = {nm.t_I_s:.4f} s; the default is {t_newmark / t_oas:.2f}x faster"
    )
    print(
        f"  dense grid, same process: {t_dense:.3f} s ({d.n_runs + n_bis} runs), t_I = {d.t_I_s:.4f} s; "
        f"{100 * same:.2f} % of the verdicts identical; adaptive {t_dense / t_oas:.2f}x faster"
    )

    # per core: process CPU time of one OAS on one numba thread (the figure that survives a loaded machine)
    import numba

    nt = numba.get_num_threads()
    numba.set_num_threads(1)
    c_ty, c_nm = [], []
    for _ in range(3):
        c0 = time.process_time()
        overturning_spectrum(rec, 12)
        c_ty.append(time.process_time() - c0)
        c0 = time.process_time()
        overturning_spectrum(rec, 12, method="newmark")
        c_nm.append(time.process_time() - c0)
    numba.set_num_threads(nt)
    print(
        f"  1 numba thread, process CPU (min of 3, alternated): default {min(c_ty):.3f} CPU-s per OAS, Newmark "
        f"path {min(c_nm):.3f} CPU-s ({min(c_nm) / min(c_ty):.2f}x); wall figures above use {nt} threads"
    )

    # baseline in the same process: solve_ivp on a sample of grid runs that uplift
    alpha = o.alpha_rad
    rng = np.random.default_rng(1)
    rows = np.flatnonzero(o.levels > 1.5)
    sample = [(int(rng.choice(rows)), int(rng.integers(o.p_rad_s.size))) for _ in range(12)]
    t0 = time.perf_counter()
    agree = 0
    for i, j in sample:
        block = Block.general(G / (o.alpha_I * o.p_rad_s[j] ** 2), alpha, o.alpha_I)
        base = rec.scaled(o.levels[i] * math.tan(alpha) * G / rec.pga_m_s2)
        agree += ivp_run(block, base, o.eta) == bool(o.overturned[i, j])
    t_ivp = (time.perf_counter() - t0) / len(sample)
    # the same sampled runs through the OAS's batch path, one numba thread (per core)
    from rocklab.models.spectra._oas import CRIT, OAS_DEFAULTS, TAYLOR_P_H, batch_runs

    nt = numba.get_num_threads()
    numba.set_num_threads(1)
    sc = np.array([o.levels[i] * math.tan(alpha) * G / rec.pga_m_s2 for i, _ in sample])
    pp = np.array([o.p_rad_s[j] for _, j in sample])
    args = (alpha, o.eta, CRIT["angle"], 1, 0.0, TAYLOR_P_H, OAS_DEFAULTS["method"])
    batch_runs(rec, sc, pp, args)
    t0 = time.perf_counter()
    for _ in range(5):
        batch_runs(rec, sc, pp, args)
    t_b1 = (time.perf_counter() - t0) / 5 / len(sample)
    numba.set_num_threads(nt)
    print(
        "baseline: solve_ivp DOP853 with events (1 thread) on the same sampled runs; ratio per core "
        "against the batch path on 1 numba thread"
    )
    print(
        f"  solve_ivp: {1e3 * t_ivp:.1f} ms/run on {len(sample)} sampled grid runs (levels > 1.5); batch, "
        f"1 thread: {1e3 * t_b1:.3f} ms/run -> {t_ivp / t_b1:.4g}x per core; verdicts agree on "
        f"{agree}/{len(sample)}; the full OAS by solve_ivp would take ~{t_ivp * n_runs / 60:.0f} CPU-min"
    )
    where_the_time_goes(rec)
    return 0


def bisection_runs(rec) -> int:
    """Runs of the default OAS's bisection, counted (``refine_where="curve"``: 10 steps on the levels behind t_I,
    t'_I and beta, fewer elsewhere)."""
    from rocklab.models.spectra import _oas

    real, n = _oas.batch_runs, [0]

    def counted(base, scale, p, args):
        n[0] += np.size(scale)
        return real(base, scale, p, args)

    _oas.batch_runs = counted
    try:
        o = overturning_spectrum(rec, 12)
    finally:
        _oas.batch_runs = real
    return n[0] - o.n_runs


def where_the_time_goes(rec) -> None:
    """One default OAS on one numba thread, CPU time of the calling thread (where a 1-thread parallel call
    runs; process CPU would add the idle OpenMP worker's spinning): the batch kernel's share, the Python around it
    (grid logic, bisection, order selection), and how evenly each parallel call's runs divide over 2 threads
    (each run timed alone, best of 2; dealt in chunks of ``RUNS_PER_CHUNK`` in the batch's interleaved order as the
    threads free up, as numba's dynamic schedule does)."""
    import numba

    import rocklab.models.rocking._batch as batch_mod
    from rocklab.models.spectra import _oas

    kernel = batch_mod.run_taylor_record
    calls, k_cpu = [], [0.0]

    def timed(*a):
        c0 = time.thread_time()
        out = kernel(*a)
        k_cpu[0] += time.thread_time() - c0
        calls.append(a)
        return out

    nt = numba.get_num_threads()
    numba.set_num_threads(1)
    totals, kernels = [], []
    batch_mod.run_taylor_record = timed
    try:
        for _ in range(3):
            calls.clear()
            k_cpu[0] = 0.0
            c0 = time.thread_time()
            _oas.overturning_spectrum(rec, 12)
            totals.append(time.thread_time() - c0)
            kernels.append(k_cpu[0])
    finally:
        batch_mod.run_taylor_record = kernel
    work = spans = 0.0
    for a in calls:  # each run of each parallel call alone, in the call's order
        cost = np.empty(a[0].size)
        for i in range(cost.size):
            one = tuple(x[i : i + 1] if isinstance(x, np.ndarray) and x.shape == a[0].shape else x for x in a)
            best = np.inf
            for _ in range(2):
                c0 = time.thread_time()
                kernel(*one)
                best = min(best, time.thread_time() - c0)
            cost[i] = best
        work += cost.sum()
        spans += _makespan(cost, batch_mod.RUNS_PER_CHUNK)
    numba.set_num_threads(nt)
    k = int(np.argmin(totals))
    print(
        f"where the time goes (one default OAS, 1 numba thread, thread CPU, best of 3): {totals[k]:.3f} CPU-s, "
        f"of which the batch kernel {kernels[k]:.3f} ({100 * kernels[k] / totals[k]:.1f} %; {len(calls)} parallel "
        f"calls), Python around it {totals[k] - kernels[k]:.3f}; each call's runs dealt to 2 threads in chunks of "
        f"{batch_mod.RUNS_PER_CHUNK} as they free up (its runs timed alone, best of 2): the busier thread holds "
        f"{100 * spans / work:.1f} % of the work (balance {work / 2 / spans:.3f}); estimate on 2 idle cores "
        f"{totals[k] - kernels[k] + kernels[k] * spans / work:.3f} s (the Python part serial)"
    )


def _makespan(cost, chunk: int, threads: int = 2) -> float:
    """Time of one parallel call whose runs (``cost``, s, in the call's order) go to ``threads`` threads in chunks
    of ``chunk``, each chunk to the thread that is free first (dynamic scheduling)."""
    busy = np.zeros(threads)
    for s in range(0, cost.size, chunk):
        busy[np.argmin(busy)] += cost[s : s + chunk].sum()
    return float(busy.max())


if __name__ == "__main__":
    raise SystemExit(main())
