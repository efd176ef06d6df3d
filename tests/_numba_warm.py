"""Fill numba's on-disk cache before the test workers start (``make test`` runs this first).

A fresh clone has no cached machine code: every pytest-xdist worker, and every CLI subprocess a
test starts, compiled the kernels it met first (~30 CPU-s for the Newmark loops alone), often the
same kernels at the same time, and a subprocess killed on purpose (tests/test_kill.py) compiled
them again each time. Here the kernels are compiled once, in groups shared out over two
processes, through the public calls the tests make (the same argument types, so the same cached
signatures). On a warm cache this costs the imports and the cache loads: 6 CPU-s in all. A group
that fails is printed and skipped: the tests then compile it themselves, and judge.

Run: ``python tests/_numba_warm.py`` (all groups, in parallel) or ``... GROUP ...`` (in this process).
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np


def _pulse(duration_s: float = 2.0, dt_s: float = 0.01):
    from rocklab.series import BaseMotion

    t = np.arange(0.0, duration_s, dt_s)
    return BaseMotion(t, 3.0 * np.sin(2 * np.pi * t) * (t < 1.0))


def newmark() -> None:
    """Single block, Newmark: the lean loops (free, forced) and the general loop."""
    from rocklab import Block
    from rocklab.models import simulate
    from rocklab.models.rocking import Newmark

    blk = Block(0.045, 0.2025)
    for lean in (True, False):
        simulate(blk, theta0_rad=0.5 * blk.alpha_rad, duration_s=1.0, method=Newmark(lean=lean))
        simulate(blk, duration_s=1.5, base=_pulse(), method=Newmark(lean=lean))


def taylor() -> None:
    """Single block, Taylor series (free rocking only: a record needs Newmark)."""
    from rocklab import Block
    from rocklab.models import simulate

    blk = Block(0.045, 0.2025)
    simulate(blk, theta0_rad=0.5 * blk.alpha_rad, duration_s=1.0, method="taylor")


def batch() -> None:
    """Many blocks in parallel (``simulate_batch``): Newmark and the Taylor record kernel, free and
    forced, with and without the safe stop (the record's arrays are read-only, a free run's are not)."""
    from rocklab import Block
    from rocklab.models import simulate_batch

    blk = Block(0.045, 0.2025)
    sc = np.array([0.5, 1.0, 2.0])
    for method in ("newmark", "taylor"):
        simulate_batch(blk.p_rad_s, blk.alpha_rad, theta0_rad=0.1, duration_s=1.0, method=method)
        for safe in (False, True):
            simulate_batch(blk.p_rad_s, blk.alpha_rad, base=_pulse(), scale=sc, method=method, stop_when_safe=safe)


def column() -> None:
    """Multi-block columns (the compiled loop)."""
    from rocklab import Block
    from rocklab.models import Column, simulate_column

    col = Column((Block(0.1, 0.3, mass_kg=15.0),) * 2)
    simulate_column(col, _pulse(), duration_s=1.0)


def tracking(tmp: Path) -> None:
    """The IMU CSV reader and the table fusion's Kalman filter."""
    from rocklab.tracking import fuse_table_motion, table_motion
    from rocklab.tracking.imu._fastcsv import parse_numeric_csv

    csv = tmp / "warm.csv"
    csv.write_text("t_s,a\n" + "".join(f"{k * 0.01:.2f},{k % 7 * 0.5}\n" for k in range(50)))
    parse_numeric_csv(csv)
    tv = np.arange(100) / 50.0
    video = table_motion(tv, 1e-3 * np.sin(2 * np.pi * tv))
    ti = np.arange(-0.5, 2.5, 1 / 256.0)
    fuse_table_motion(video, ti, -((2 * np.pi) ** 2) * 1e-3 * np.sin(2 * np.pi * ti))


GROUPS = {"newmark": newmark, "batch": batch, "column": column, "taylor": taylor, "tracking": tracking}

#: The groups in two processes. A kernel's callees are compiled with it (or loaded, if cached),
#: so ``batch`` follows ``newmark`` in one process: run in parallel, both compiled the Newmark
#: step (run_block). Cold compile CPU-s measured one after another with one thread: newmark 47,
#: batch 28, column 35, taylor 14 (2 after batch), tracking 3.
CHAINS = (("newmark", "batch"), ("column", "taylor", "tracking"))


def _run_groups(names: list[str]) -> int:
    """Compile the named groups in this process; a group that fails is named and skipped."""
    import tempfile
    import traceback

    from rocklab._diagnostics import collecting

    failed = 0
    for name in names:
        fn = GROUPS[name]
        try:
            with tempfile.TemporaryDirectory() as tmp, collecting():
                fn(Path(tmp)) if name == "tracking" else fn()
        except Exception:
            failed += 1
            print(f"numba warm-up: group {name!r} failed, the tests compile it:\n{traceback.format_exc()}")
    return 1 if failed else 0


def main(argv: list[str]) -> int:
    if argv:
        return _run_groups(argv)
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    chains = CHAINS if cores >= len(CHAINS) else (tuple(n for c in CHAINS for n in c),)
    env = dict(os.environ, NUMBA_NUM_THREADS="1", OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    root = Path(__file__).resolve().parents[1]
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(root), env.get("PYTHONPATH", "")]))
    t0 = time.perf_counter()
    procs = [subprocess.Popen([sys.executable, __file__, *names], env=env) for names in chains]
    for p in procs:
        p.wait()
    print(f"numba warm-up: {len(GROUPS)} groups in {len(procs)} processes, {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
