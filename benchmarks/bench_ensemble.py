"""Shake-table validation: ensemble cost, and the verdicts and η_e intervals over many synthetic runs.

Run: ``python benchmarks/bench_ensemble.py [--seeds N] [--sweep-only | --speed-only]``; ``make bench``
runs the speed figure and 4 seeds, the figures in the lab guide are ``--seeds 24`` (about 8 min).

Speed: one law's ensemble (64 members) of an 8 s B5L run under a table-played El Centro,
against the baseline of the same 64 runs as a plain loop over ``simulate`` with the
unperturbed input.

Sweep: for every seed a block (B5L, B4L, B4M: Housner 4, 6 and 4 % below the truth) rocks under a table playing a record (the
bundled El Centro, the shared San Fernando / El Centro records when /work/shared/data is
there, a seeded band-limited random record, and a one-cycle sine pulse), exactly as ``rocklab synth`` makes the
table (``record_table``: cut, scaled to 1.6 × the uplift acceleration, high-passed to a
10 mm stroke; another scale when the block then rocks below 0.3 α or overturns, as a lab
picks the amplitude; also when it makes fewer than 6 half cycles above 0.08 α). What the run would measure is made from the truth with the demo session's
measured errors: θ at 50 Hz with a 0.45 mrad offset and 0.4 mrad noise, the table IMU at
256 Hz with 0.005 g noise, a 0.01 m/s² bias and a 0.2 ms clock error. Each run is judged
with the true η, η ± 5 % and Housner's η; η_e is fitted from its half cycles. Prints the counts.

``--fused``: the run also films the table (50 fps, 0.02 mm noise) and the table motion is the
IMU fused with the film, as ``rocklab run`` makes it; the IMU's scale is off by a draw of
``IMU_SCALE_SD`` (1 %) and the film's by one of ``FILM_SCALE_SD`` (0.3 %), and the ensembles
sample the scale uncertainty the two sources' agreement measured (``--scale-prior``: the 1 %
prior instead, as before it was measured) and the fused table's own error
(``rocklab.fitting.fused_error_draw``: its smoother's σ, with the spectrum measured on rendered
synthetic sessions).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from rocklab.series import TableMotion

SHARED = Path(__file__).resolve().parents[2] / "shared" / "data" / "records"


def _records():
    from rocklab.series import BaseMotion
    from rocklab.models import bundled_record, load_base_motion

    recs = [("elcentro", bundled_record("elcentro"))]
    for name in ("RSN68_SFERN_PEL090.AT2", "elCentro.AT2"):
        p = SHARED / name
        if p.is_file():
            recs.append((name, load_base_motion(p)))

    def random_record(seed):
        from scipy.signal import butter, sosfiltfilt

        rng = np.random.default_rng(1000 + seed)
        dt = 0.01
        t = np.arange(0, 12, dt)
        sos = butter(4, [0.8, 6.0], btype="bandpass", fs=1 / dt, output="sos")
        a = sosfiltfilt(sos, rng.standard_normal(t.size)) * (t / 2) ** 2 * np.exp(-t / 2)
        return BaseMotion(t, a, name=f"random{seed}")

    return recs, random_record


def make_run(seed: int, acc_noise=0.049, acc_bias=0.01, sync_sd=2e-4, fused=False, scale_prior=False):
    """(block, eta_true, prim, table, table_sync, truth) of one synthetic shake-table run."""
    from rocklab.fitting import catalogue_block, ceh_catalogue, half_cycle_segments
    from rocklab.models import simulate
    from rocklab.synth._scripted_motion import record_table, sine_pulse_table

    recs, random_record = _records()
    rng = np.random.default_rng(seed)
    bid = ("B5L", "B4L", "B4M")[seed % 3]
    block = catalogue_block(bid)
    eta = float(ceh_catalogue().set_index("block").loc[bid, "eta_e_full"])
    k = seed % (len(recs) + 2)
    name, rec = recs[k] if k < len(recs) else (f"random{seed}", random_record(seed))
    if k == len(recs) + 1:
        name = "sine pulse"
    # as a lab does: the table amplitude that makes the block rock (peak >= 0.3 α) and survive
    scales = (1.6, 1.3, 2.0, 1.1, 2.5, 3.0, 0.9) if name != "sine pulse" else np.arange(1.2, 6.0, 0.1)
    for f in scales:
        if name == "sine pulse":  # one 0.6 s cycle (thesis Fig. 31), peak acceleration f x uplift
            table = sine_pulse_table(1.0, 0.6, f * block.uplift_acc_m_s2 / 10.4 * 0.045)
        else:
            table = record_table(rec, 0.6, 6.9, 0.01, f * block.uplift_acc_m_s2, name=name)
        tb = table.base_motion(8.6)
        r = simulate(
            block, theta0_rad=0.0, duration_s=8.5, dt_s=1e-4, restitution="constant", eta=eta, base=tb, output_dt_s=1e-3
        )
        th = np.asarray(r.theta_rad)
        if r.status != "overturned" and np.max(np.abs(th)) >= 0.3 * block.alpha_rad:
            # and it keeps rocking: at least 6 half cycles above 0.08 alpha
            if len(half_cycle_segments(r.t_s, th, block.alpha_rad)) >= 6:
                break
    else:
        return None  # no amplitude rocks this block that way: the seed is skipped (and counted)
    t = np.arange(400) / 50.0
    truth = -np.interp(t, r.t_s, r.theta_rad, right=float(r.theta_rad[-1]))
    y = truth + 4.5e-4 + 4e-4 * rng.standard_normal(t.size)
    ti = np.arange(-0.7, 8.5, 1 / 256.0)
    sync_err = sync_sd * rng.standard_normal()
    acc = table.a(np.clip(ti + sync_err, 0, None)) + acc_noise * rng.standard_normal(ti.size) + acc_bias
    tab = TableMotion.from_acceleration(ti, acc, "imu")
    scale = None
    if fused:
        tab, scale = _fused_table(seed, table, ti, acc, scale_prior)
    return dict(
        block=block,
        eta=eta,
        prim=(t, y),
        table=tab,
        scale=scale,
        sync=SimpleNamespace(residual_ms=0.135),  # the table IMU's clock (a SyncResult's residual)
        truth=truth,
        record=name,
        block_id=bid,
        truth_impacts=len(r.impacts),
        overturned=r.status == "overturned",
    )


def _fused_table(seed, table, ti, acc, scale_prior):
    """The IMU (its scale off by a draw of 1 %) fused with a film of the table (its metric scale off
    by a draw of 0.3 %): (TableMotion, (imu error, film error, the fused table's error, TableScale))."""
    import dataclasses

    from rocklab._diagnostics import collecting
    from rocklab.tracking import FILM_SCALE_SD, IMU_SCALE_SD, fuse_table_motion, table_motion

    rng = np.random.default_rng(5000 + seed)  # apart from the run's own draws: the same run as without
    e_i, e_f = IMU_SCALE_SD * rng.standard_normal(), FILM_SCALE_SD * rng.standard_normal()
    tv = np.arange(int(8.5 * 50)) / 50.0
    video = table_motion(tv, (1 + e_f) * table.u(tv) + 2e-5 * rng.standard_normal(tv.size))
    with collecting():
        fusion = fuse_table_motion(video, ti, (1 + e_i) * acc)
    m = fusion.motion
    w = (m.t_s > 0) & (m.t_s < 8.4)
    ta = table.a(m.t_s[w])
    e_fused = float(m.ax_m_s2[w] @ ta / (ta @ ta)) - 1.0
    if scale_prior:
        m = dataclasses.replace(m, acc_scale_sd=float("nan"))
    return m, (e_i, e_f, e_fused, fusion.scale)


def judge_run(run, n=64):
    from rocklab.pipelines._validation import prepare_forced, validate_forced_run

    cfg = SimpleNamespace(table=SimpleNamespace(source="imu"), path=Path("synthetic"))
    msgs: list = []
    prep = prepare_forced(cfg, run["block"], run["prim"], run["table"], run["sync"], msgs)
    eta = run["eta"]
    laws = {"true": eta, "minus5": 0.95 * eta, "plus5": min(1.05 * eta, 1.0), "housner": run["block"].eta_H}
    v = validate_forced_run(prep, run["block"], laws, n=n)
    return prep.fit, v


def speed(n=64, repeats=3):
    from rocklab.fitting import InputUncertainty, simulate_ensemble
    from rocklab.series import BaseMotion
    from rocklab.models import simulate

    run = make_run(0)
    blk, (t, _), tab = run["block"], run["prim"], run["table"]
    unc = InputUncertainty(0.049, 0.003, 1e-3, 2e-4, 4e-4, 4e-4)
    simulate_ensemble(blk, tab.t_s, tab.ax_m_s2, t, eta=run["eta"], theta0_rad=0.0, t_start_s=0.0, unc=unc, n=2)
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        simulate_ensemble(blk, tab.t_s, tab.ax_m_s2, t, eta=run["eta"], theta0_rad=0.0, t_start_s=0.0, unc=unc, n=n)
        best = min(best, time.perf_counter() - t0)
    base = BaseMotion(tab.t_s - tab.t_s[0], -tab.ax_m_s2, name="table")
    t0 = time.perf_counter()
    for _ in range(n):
        simulate(
            blk,
            theta0_rad=0.0,
            duration_s=8.0,
            dt_s=1e-4,
            restitution="constant",
            eta=run["eta"],
            base=base,
            output_dt_s=1e-3,
        )
    loop = time.perf_counter() - t0
    print(
        f"ensemble of {n} (8 s {run['block_id']} run, perturbed inputs): {best:.2f} s "
        f"(target <= 5 s on 2 cores); baseline, the same {n} runs as a plain simulate loop "
        f"(unperturbed): {loop:.2f} s"
    )


def sweep(seeds, fused=False, scale_prior=False):
    rows = []
    skipped = []
    for s in seeds:
        run = make_run(s, fused=fused, scale_prior=scale_prior)
        if run is None:
            skipped.append(s)
            continue
        fit, v = judge_run(run)
        row = {
            "seed": s,
            "block": run["block_id"],
            "record": run["record"],
            "eta": run["eta"],
            "eta_e": fit.eta_e,
            "ci": fit.ci95,
            "horizon_s": v.horizon_s,
        }
        row.update(
            {
                law: (
                    lv.verdict,
                    lv.band_coverage,
                    lv.score,
                    min([p for k, p in lv.tests.items() if k != "eta_vs_half_cycles"] or [1.0]),
                    len(lv.tests),
                )
                for law, lv in v.laws.items()
            }
        )
        rows.append(row)
        cov = fit.ci95[0] <= run["eta"] <= fit.ci95[1]
        print(
            f"seed {s:3d} {run['block_id']} {run['record'][:14]:14s} truth {run['eta']:.4f} η_e {fit.eta_e:.4f} "
            f"[{fit.ci95[0]:.4f}, {fit.ci95[1]:.4f}] {'covers' if cov else 'MISSES'} | horizon {v.horizon_s:.2f} s | "
            + " ".join(f"{law}={lv.verdict[:5]}({lv.band_coverage:.2f},{lv.score:.3f})" for law, lv in v.laws.items()),
            flush=True,
        )
        if run["scale"] is not None:
            e_i, e_f, e_fu, sc = run["scale"]
            print(
                f"         scale: IMU {100 * e_i:+.3f} %, film {100 * e_f:+.3f} %, fused {100 * e_fu:+.3f} %; measured "
                f"film/IMU-1 {100 * sc.ratio_minus_one:+.3f} ± {100 * sc.se:.3f} %, sd sampled "
                f"{100 * v.uncertainty['acc_scale']:.3f} %",
                flush=True,
            )
    n = len(rows)
    if skipped:
        print(
            f"skipped (no table amplitude makes the block rock >= 0.3 α, 6 half cycles, and survive): seeds {skipped}"
        )
    ok_true = sum(r["true"][0] == "consistent" and r["true"][1] >= 0.9 for r in rows)
    bad = {law: sum(r[law][0] == "inconsistent" for r in rows) for law in ("minus5", "plus5", "housner")}
    cover = sum(r["ci"][0] <= r["eta"] <= r["ci"][1] for r in rows)
    hw = np.array([(r["ci"][1] - r["ci"][0]) / 2 for r in rows])
    print(
        f"true η consistent with coverage >= 0.9: {ok_true}/{n}; inconsistent: η-5% {bad['minus5']}/{n}, "
        f"η+5% {bad['plus5']}/{n}, Housner {bad['housner']}/{n}"
    )
    print(f"η_e 95 % interval covers the truth: {cover}/{n}; half-width median {np.median(hw):.4f}, max {hw.max():.4f}")
    # which test decided each inconsistent verdict: the ensemble alone, or the half cycles
    alone = {law: sum(r[law][3] < 0.01 / r[law][4] for r in rows) for law in ("minus5", "plus5", "housner")}
    print(
        f"...of which the ensemble's own tests (without the half-cycle η test) reject: η-5% {alone['minus5']}/{n}, "
        f"η+5% {alone['plus5']}/{n}, Housner {alone['housner']}/{n}"
    )
    return rows


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--sweep-only", action="store_true")
    ap.add_argument("--speed-only", action="store_true")
    ap.add_argument("--fused", action="store_true", help="the table IMU fused with a film of the table")
    ap.add_argument("--scale-prior", action="store_true", help="with --fused: sample the 1 %% prior scale sd")
    a = ap.parse_args()
    if not a.sweep_only:
        speed()
    if not a.speed_only:
        sweep(range(a.seeds), fused=a.fused, scale_prior=a.scale_prior)
