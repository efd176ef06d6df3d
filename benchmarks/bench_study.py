"""The record study on Dask: throughput per worker and scaling from 1 to 2 workers (issue 27, item 3).

Baseline: the same study on a Dask ``LocalCluster`` of 1 worker process (1 thread, numba on 1
thread), in the same process, then on 2 such workers; efficiency = T(1) / (2 T(2)).

The study is every record of a folder x h/b 3, 5, 8, 12 (the thesis's far-field study is the 44
FEMA P695 records: pass their folder, e.g. the ``SortedEQFile_1xxxxx.txt`` files of
github.com/Hadi-Azarnasab/scale_fema_p695, not shipped; default: the 5 records in ../shared),
default OAS options, ``--band`` optional (8 OAS per run). Prints per cluster size: wall time,
runs/s and runs/s per worker; then the efficiency and the whole study's wall time on 2 workers.
Both clusters run the same tasks; their t_I are checked equal (a distributed run must not change
a result).

Run: ``.venv/bin/python benchmarks/bench_study.py [FOLDER] [--records N] [--band]`` (part of
``make bench`` with the default records).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "data" / "records"


def study_records(folder: Path | None, n: int | None) -> list:
    from rocklab.pipelines.spectra import expand_records

    if folder is None:
        items = expand_records([SHARED], recursive=True) if SHARED.is_dir() else []
    else:
        items = expand_records([folder])
    paths = [p for _, p, err in items if not err]
    return paths[:n] if n else paths


def run_on(n_workers: int, paths: list, band: bool):
    from dask.distributed import LocalCluster

    from rocklab.pipelines.spectra import oas_many

    with LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster:
        # warm-up: every worker loads the compiled kernels once (not part of the study's time)
        oas_many(
            paths[:1] * n_workers,
            units="g",
            slenderness=[12.0],
            oas_kwargs=dict(levels=2, sizes=2, refine=1),
            scheduler=cluster.scheduler_address,
            progress=False,
        )
        t0 = time.perf_counter()
        tab = oas_many(
            paths,
            units="g",
            slenderness=[3.0, 5.0, 8.0, 12.0],
            band=band,
            scheduler=cluster.scheduler_address,
            progress=False,
        )
        return time.perf_counter() - t0, tab


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", nargs="?", type=Path, default=None, help="folder of records (default ../shared's)")
    ap.add_argument("--records", type=int, default=None, help="only the first N records")
    ap.add_argument("--band", action="store_true", help="t_I bands (8 OAS per run)")
    a = ap.parse_args()
    # one numba thread per worker process: the workers are the parallelism
    os.environ["NUMBA_NUM_THREADS"] = "1"
    os.environ["PYTHONPATH"] = os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])
    paths = study_records(a.folder, a.records)
    if not paths:
        print("no records: give a folder of records (../shared is absent)")
        return 0
    n_runs = 4 * len(paths)
    print(
        f"study: {len(paths)} records x h/b 3, 5, 8, 12 = {n_runs} runs{' with bands' if a.band else ''}; "
        f"{os.cpu_count()} CPUs"
    )
    t = {}
    tabs = {}
    for n in (1, 2):
        t[n], tabs[n] = run_on(n, paths, a.band)
        print(
            f"{n} worker(s): {t[n]:.2f} s, {n_runs / t[n]:.3f} runs/s, {n_runs / t[n] / n:.3f} runs/s per worker"
            + (" (baseline)" if n == 1 else "")
        )
    errors = {n: int((tab["error"] != "").sum()) for n, tab in tabs.items()}
    if any(errors.values()):  # a run that failed takes no time: its figures would mean nothing
        first = next(e for tab in tabs.values() for e in tab["error"] if e)
        print(f"FAILED runs {errors}: {first}")
        return 1
    same = (tabs[1]["t_I_s"].fillna(-1).to_numpy() == tabs[2]["t_I_s"].fillna(-1).to_numpy()).all()
    eff = t[1] / (2 * t[2])
    print(f"parallel efficiency 1 -> 2 workers: {eff:.1%} (target >= 80 %); t_I identical on both: {same}")
    print(f"whole study on 2 workers: {t[2]:.1f} s wall")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
