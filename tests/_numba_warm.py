"""Fill numba's on-disk cache before the test workers start (``make test`` runs this first).

A fresh clone has no cached machine code: every pytest-xdist worker, and every CLI subprocess a
test starts, compiled the kernels it met first (~30 CPU-s for the Newmark loops alone), often the
same kernels at the same time, and a subprocess killed on purpose (tests/test_kill.py) compiled
them again each time. Here each group of kernels is compiled once, the groups in parallel, one
process per core, through the public calls the tests make (the same argument types, so the
same cached signatures). On a warm cache this takes the imports and a cache load (~2 CPU-s per
group). A failure here is printed and ignored: the tests themselves then compile, and judge.

Run: ``python tests/_numba_warm.py`` (all groups, in parallel) or ``... GROUP`` (one, in this process).
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


#: groups, heaviest first; a process compiles one group at a time
GROUPS = {"newmark": newmark, "batch": batch, "taylor": taylor, "column": column, "tracking": tracking}


def _one(name: str) -> None:
    import tempfile

    from rocklab._diagnostics import collecting

    with tempfile.TemporaryDirectory() as tmp, collecting():
        fn = GROUPS[name]
        fn(Path(tmp)) if name == "tracking" else fn()


def main(argv: list[str]) -> int:
    if argv:
        for name in argv:
            _one(name)
        return 0
    workers = max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1))
    env = dict(os.environ, NUMBA_NUM_THREADS="1", OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    root = Path(__file__).resolve().parents[1]
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(root), env.get("PYTHONPATH", "")]))
    todo, running, t0 = list(GROUPS), {}, time.perf_counter()
    while todo or running:
        while todo and len(running) < workers:
            name = todo.pop(0)
            running[name] = subprocess.Popen([sys.executable, __file__, name], env=env)
        for name, proc in list(running.items()):
            if proc.poll() is not None:
                del running[name]
                if proc.returncode:
                    print(f"numba warm-up: group {name!r} failed (exit {proc.returncode}); the tests compile it")
        time.sleep(0.05)
    print(f"numba warm-up: {len(GROUPS)} groups in {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
