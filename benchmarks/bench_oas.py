"""Speed of one Overturning Acceleration Spectrum (issue 8: 80 x 120 + refinement, 30 s record,
H/B = 12, <= 10 s on 2 cores).

Prints, in one process:

1. wall time of the full default OAS of FEMA far-field FF-1 (Northridge, Beverly Hills MUL009,
   30 s at dt = 0.01 s) after a warm-up call that loads/compiles the kernel;
2. the ratio against a baseline run in the same process: the same OAS computed with the
   general batch simulator ``simulate_batch`` (``engine="batch"``), and the share of grid
   verdicts on which the two agree.

Falls back to the bundled El Centro record if ../shared is absent.
Run: ``.venv/bin/python benchmarks/bench_oas.py`` (part of ``make bench``).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from rocklab.models import bundled_record, load_base_motion, overturning_spectrum

FF1 = Path(__file__).resolve().parents[2] / "shared/data/records/fema-p695-far-field/SortedEQFile_120111.txt"


def main() -> int:
    rec = load_base_motion(FF1, units="g") if FF1.is_file() else bundled_record("elcentro")
    print(f"record {rec.name}: {rec.duration_s:.1f} s at dt = {rec.dt_s:g} s")
    t0 = time.perf_counter()
    overturning_spectrum(rec, 12, levels=2, sizes=2, refine=1)
    print(f"first call (cache load or compilation): {time.perf_counter() - t0:.2f} s")

    t0 = time.perf_counter()
    o = overturning_spectrum(rec, 12)
    t_oas = time.perf_counter() - t0
    n_runs = o.overturned.size
    print(f"OAS 80 x 120 + 10 bisections, H/B = 12: {t_oas:.2f} s ({n_runs} grid runs, "
          f"{1e3 * t_oas / n_runs:.3f} ms/run); t_I = {o.t_I_s:.4f} s; target <= 10 s: "
          f"{'OK' if t_oas <= 10 else 'MISSED'}")

    # baseline in the same process: the same OAS on the general simulate_batch (Newmark)
    overturning_spectrum(rec, 12, levels=2, sizes=2, refine=1, engine="batch")  # warm-up
    t0 = time.perf_counter()
    ob = overturning_spectrum(rec, 12, engine="batch")
    t_b = time.perf_counter() - t0
    agree = float(np.mean(ob.overturned == o.overturned))
    print(f"baseline: same OAS on simulate_batch (Newmark, p h <= 0.02, 10 s free rocking): {t_b:.2f} s, "
          f"t_I = {ob.t_I_s:.4f} s; ratio OAS kernel / baseline = {t_oas / t_b:.2f}; grid verdicts agree "
          f"on {100 * agree:.1f} % (the rest on the chaotic boundary)")
    return 0 if t_oas <= 10 else 1


if __name__ == "__main__":
    raise SystemExit(main())
