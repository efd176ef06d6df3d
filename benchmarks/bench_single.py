"""Single-block simulator speed against the plain solve_ivp code a user would write.

Two rocklab methods: the Newmark kernel (dt 1e-4 s) and the Taylor-series method
(``method="taylor"``, free rocking), each against the plain code at its own accuracy.

Baseline (same process, same work): scipy ``solve_ivp`` DOP853, rtol 1e-10, atol 1e-13,
one terminal event (theta = 0) per half-cycle, restarted after each impact with
omega+ = eta omega-, output on the same 1e-4 s grid, stopped at the same impact count as
the Newmark run (the block at rest). Accuracy: impact times of both against the same loop
at rtol 1e-13. Times are process CPU time, best of repeats, numba compilation excluded;
the simulated time quoted is the motion (release to rest), not the requested duration.

Under a base record (El Centro x 1.5, a 0.5 m x 3 m block rocking for 20 s) the run is
timed with the kernel's lean loops (default) and with its general loop only
(``lean=False``), against free rocking of the same block (eta = 1, 20 s) and solve_ivp.
"""

from __future__ import annotations

import math
import time

import numba
import numpy as np
from scipy.integrate import solve_ivp

from rocklab import Block
from rocklab.models import bundled_record, simulate, simulate_batch
from rocklab.models.rocking import Newmark, free_rocking_impact_times


def plain_dop853(blk, theta0, eta, t_grid, n_impacts, rtol=1e-10):
    """What a competent user writes: DOP853 with one terminal event per half-cycle."""
    p2, a = blk.p_rad_s**2, blk.alpha_rad

    def rhs(t, y, s):
        return (y[1], -p2 * math.sin(a * s - y[0]))

    def hit(t, y, s):
        return y[0]

    hit.terminal = True
    t, y, s = 0.0, [theta0, 0.0], 1.0 if theta0 > 0 else -1.0
    theta = np.zeros_like(t_grid)
    impacts = []
    while len(impacts) < n_impacts:
        hit.direction = -s  # towards theta = 0 from the side the block leans on (not the restart point)
        idx = np.flatnonzero(t_grid >= t)
        sol = solve_ivp(
            rhs, (t, t_grid[-1]), y, method="DOP853", rtol=rtol, atol=1e-13, events=hit, args=(s,), t_eval=t_grid[idx]
        )
        k = np.shape(sol.y)[-1] if np.size(sol.y) else 0
        theta[idx[:k]] = np.asarray(sol.y)[0][:k] if k else theta[idx[:k]]
        if sol.status != 1:
            break
        t = float(sol.t_events[0][0])
        impacts.append(t)
        y, s = [0.0, eta * float(sol.y_events[0][0][1])], -s
    return np.array(impacts), theta


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
    n_imp, t_motion = nm.n_impacts, float(nm.t_s[-1])
    grid = np.arange(int(round(t_motion / 1e-4)) + 1) * 1e-4
    t_pl, (imp_pl, _) = best(lambda: plain_dop853(blk, th0, blk.eta_H, grid, n_imp), 5)
    imp_ref, _ = plain_dop853(blk, th0, blk.eta_H, grid, n_imp, rtol=1e-13)
    eq_rtol = 1e-10
    n = min(n_imp, imp_pl.size, imp_ref.size)
    err_nm = np.abs(nm.impacts.t_s.to_numpy()[:n] - imp_ref[:n])
    err_pl = np.abs(imp_pl[:n] - imp_ref[:n])
    print(
        "baseline: plain solve_ivp DOP853 (rtol 1e-10, one terminal event per half-cycle, same 1e-4 s "
        "output grid, same impact count), same process, 1 thread"
    )
    print(
        f"B6M free rocking from 0.8 alpha: {t_motion:.4g} s of motion to rest, {n_imp} impacts "
        f"(Housner eta = {blk.eta_H:.4f})"
    )
    print(
        f"  rocklab simulate() newmark dt 1e-4: {t_nm * 1e3:8.3f} ms   impact times within "
        f"{err_nm.max():.2e} s of DOP853 at rtol 1e-13 (first 20: {err_nm[:20].max():.2e} s)"
    )
    print(f"  plain DOP853 rtol 1e-10:             {t_pl * 1e3:8.3f} ms   impact times within {err_pl.max():.2e} s")
    print(f"  ratio plain / rocklab: {t_pl / t_nm:.4g}x per {t_motion:.4g} s of motion")
    # equal accuracy: the loosest rtol at which the plain code's impact times are as good as rocklab's
    for rtol in (1e-9, 1e-8, 1e-7, 1e-6, 1e-5):
        imp_r, _ = plain_dop853(blk, th0, blk.eta_H, grid, n_imp, rtol=rtol)
        m = min(n, imp_r.size)
        if imp_r.size < n or np.abs(imp_r[:m] - imp_ref[:m]).max() > err_nm.max():
            break
        eq_rtol = rtol
    t_eq, (imp_eq, _) = best(lambda: plain_dop853(blk, th0, blk.eta_H, grid, n_imp, rtol=eq_rtol), 5)
    err_eq = np.abs(imp_eq[:n] - imp_ref[:n]).max()
    print(
        f"  plain DOP853 at equal accuracy (rtol {eq_rtol:g}): {t_eq * 1e3:8.3f} ms   impact times within "
        f"{err_eq:.2e} s -> ratio {t_eq / t_nm:.4g}x"
    )
    # the Taylor-series method: same output grid, far more accurate impact times; its baseline is the
    # plain code at rtol 1e-10 (the tightest above, and still less accurate than it)
    simulate(blk, th0, method="taylor", **kw)
    t_ty, ty = best(lambda: simulate(blk, th0, method="taylor", **kw), 20)
    err_ty = np.abs(ty.impacts.t_s.to_numpy()[:n] - imp_ref[:n]).max()
    # equal accuracy: the loosest rtol at which the plain code's impact times are as good as these
    ty_rtol, t_ty_pl, err_ty_pl = 1e-10, t_pl, err_pl.max()
    for rtol in (1e-11, 1e-12):
        if err_ty_pl <= err_ty:
            break
        t_r, (imp_r, _) = best(lambda: plain_dop853(blk, th0, blk.eta_H, grid, n_imp, rtol=rtol), 3)
        ty_rtol, t_ty_pl, err_ty_pl = rtol, t_r, np.abs(imp_r[:n] - imp_ref[:n]).max()
    print(
        f"  rocklab simulate(method='taylor'):  {t_ty * 1e3:8.3f} ms   impact times within {err_ty:.2e} s; "
        f"plain DOP853 at rtol {ty_rtol:g}: {t_ty_pl * 1e3:.3f} ms, within {err_ty_pl:.2e} s -> ratio "
        f"{t_ty_pl / t_ty:.4g}x"
    )
    # the rtol 1e-13 loop is itself a few 1e-11 s off: against impact times without time steps
    # (the energy integral by quadrature) the Taylor method is closer than any rtol of the loop
    t_q = free_rocking_impact_times(blk, th0, blk.eta_H, n)
    print(
        f"  impact times against the energy-integral quadrature ({n} impacts): taylor "
        f"{np.abs(ty.impacts.t_s.to_numpy()[:n] - t_q).max():.2e} s, newmark {np.abs(nm.impacts.t_s.to_numpy()[:n] - t_q).max():.2e} s, "
        f"plain DOP853 rtol 1e-10 {np.abs(imp_pl[:n] - t_q).max():.2e} s, rtol 1e-13 {np.abs(imp_ref[:n] - t_q).max():.2e} s"
    )
    t_ev, ev = best(lambda: simulate(blk, th0, method="event", rtol=1e-10, **kw), 2)
    print(
        f"  (rocklab's own event reference, method='event' with three events and dense output: "
        f"{t_ev * 1e3:.2f} ms, {t_ev / t_nm:.4g}x)"
    )

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
        print(
            f"  El Centro grid {P.size} runs (20 sizes x 25 scales, dt 1e-3, {bat.overturned.sum()} fall): "
            f"{bat.n_steps / t_b:.3g} block-steps/s/core"
        )
        print(
            f"  free rocking eta = 1 (always moving), {fr.p_rad_s.size} runs x 10 s: "
            f"{fr.n_steps / t_f:.3g} block-steps/s/core   (target >= 1e7)"
        )
    numba.set_num_threads(nthreads)


def under_record(rec):
    """One block rocking under a record: lean loops vs general loop vs free rocking vs solve_ivp."""
    big = Block(0.5, 3.0, name="0.5 x 3 m")
    T, dt = 20.0, 1e-4
    kw = dict(duration_s=T, dt_s=dt, stop_at_rest=False)
    base = rec.scaled(1.5)
    kwf = dict(kw, restitution="constant", eta=1.0)

    runs = {
        "lean": lambda: simulate(big, 0.0, base=base, **kw),
        "general": lambda: simulate(big, 0.0, base=base, method=Newmark(lean=False), **kw),
        "free": lambda: simulate(big, 0.5 * big.alpha_rad, **kwf),
    }
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
    print(
        f"{big.name} under El Centro x 1.5, {T:g} s, dt = {dt:g} s, every step stored "
        f"({ln.n_impacts} impacts, {100 * np.mean(ln.theta_rad == 0):.0f} % of steps at rest):"
    )
    print(f"  lean loops (default): {t_ln * 1e3:7.2f} ms  {n_ln / t_ln:.3g} block-steps/s/core")
    print(
        f"  general loop only:    {t_gn * 1e3:7.2f} ms  {n_ln / t_gn:.3g} block-steps/s/core "
        f"-> lean is {t_gn / t_ln:.2f}x faster (max |theta difference| {d:.1e} rad, "
        f"{gn.n_impacts} impacts)"
    )
    print(
        f"  free rocking, same block (eta = 1, {fr.n_impacts} impacts): {n_fr / t_fr:.3g} block-steps/s/core "
        f"-> under the record at {t_fr / n_fr / (t_ln / n_ln):.2f}x its rate"
    )
    print(
        f"  event (solve_ivp DOP853 rtol 1e-10, first 10 s): {t_ev * 1e3:.0f} ms  {n_ev / t_ev:.3g} "
        f"block-steps/s -> ratio {t_ev / n_ev / (t_ln / n_ln):.0f}x per simulated second"
    )


if __name__ == "__main__":
    main()
