"""Speed of the multi-block column simulator (issue: a 3-block column through a 20 s record in <= 2 s).

Prints, in one process:

1. wall time of 3-block columns through the first 20 s of the bundled El Centro
   record (dt = 1e-4 s, compiled loop, after a warm-up call that loads/compiles it);
2. the same runs storing every 10th step (``output_dt_s=1e-3``) and no history
   (``output_dt_s=inf``): time, stored bytes, and a check that the events and
   peaks are those of the full run;
3. the thesis Fig. 40 overturning maps (3 columns x 10 x 10 pulses, as
   ``rocklab column --maps-png``), which store no history, against the same maps
   storing every step;
4. the ratio against the baseline: the SAME stepper run as plain Python (the
   kernels are ``register_jitable`` functions, ``jit=False`` calls them
   uncompiled) on an identical short workload, and a check that both give the
   same response.

Run: ``.venv/bin/python benchmarks/bench_column.py`` (part of ``make bench``).
"""

from __future__ import annotations

import math
import time

import numpy as np

from rocklab.blocks import Block
from rocklab.series import BaseMotion
from rocklab.models import Column, bundled_record, column_overturning_maps, simulate_column


def _timed(fn, repeat=1):
    best = np.inf
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _stored_mb(r):
    return (
        sum(getattr(r, a).nbytes for a in ("t_s", "phi_rad", "omega_rad_s", "theta_rad", "energy_J", "kinetic_J")) / 1e6
    )


def main() -> int:
    rec = bundled_record("elcentro")
    keep = rec.t_s <= 20.0
    el20 = BaseMotion(rec.t_s[keep], rec.acc_m_s2[keep], name="elcentro_20s")
    thesis = Column((Block(0.1, 0.2, density_kg_m3=2700.0),) * 3, cut_m=0.002)  # thesis §4.3 set-up
    large = Column((Block(0.3, 0.9, density_kg_m3=2700.0),) * 3, cut_m=0.002)

    # warm-up: load the cached machine code (or compile it on a fresh checkout)
    t_compile, _ = _timed(lambda: simulate_column(thesis, theta0_rad=[0, 0, 0.05], duration_s=0.01, dt_s=1e-4))
    print(f"first call (cache load or compilation): {t_compile:.2f} s")

    ok = True
    for name, col, pga in (
        ("3 x 0.1x0.2 m granite, 2 mm cuts", thesis, 0.172),
        ("3 x 0.3x0.9 m granite, 2 mm cuts", large, 0.20),
    ):
        base = el20.scaled_to_pga(pga, "g")
        t, r = _timed(lambda: simulate_column(col, base, duration_s=20.0, dt_s=1e-4, stop_at_rest=False), 3)
        steps = len(r.t_s) - 1
        print(
            f"{name}, El Centro 20 s at {pga:g} g: {t:.3f} s for {steps} steps "
            f"({1e6 * t / steps:.2f} us/step), {len(r.impacts)} impacts, "
            f"{len(r.configurations)} configuration changes, status {r.status}; "
            f"target <= 2 s: {'OK' if t <= 2.0 else 'MISSED'}"
        )
        ok &= t <= 2.0
        for odt in (1e-3, math.inf):
            t_d, r_d = _timed(
                lambda: simulate_column(col, base, duration_s=20.0, dt_s=1e-4, stop_at_rest=False, output_dt_s=odt), 3
            )
            same = (
                r_d.configurations.equals(r.configurations)
                and r_d.impacts.equals(r.impacts)
                and np.array_equal(r_d.max_abs_theta_rad, r.max_abs_theta_rad)
            )
            print(
                f"  output_dt_s={odt:g}: {t_d:.3f} s ({t / t_d:.2f}x), {len(r_d.t_s)} rows, "
                f"{_stored_mb(r_d):.2f} MB stored vs {_stored_mb(r):.2f} MB; same events and peaks: {same}"
            )
            ok &= same

    k = 10
    grid = dict(ap_m_s2=np.linspace(1.0, 12.0, k), tp_s=np.linspace(0.3, 2.4, k))
    t_lean, m_lean = _timed(lambda: column_overturning_maps(**grid))
    t_full, m_full = _timed(lambda: column_overturning_maps(**grid, output_dt_s=None))
    same = np.array_equal(m_lean.max_theta_over_alpha, m_full.max_theta_over_alpha)
    print(
        f"overturning maps 3 x {k} x {k}: {t_lean:.2f} s without history vs {t_full:.2f} s storing every "
        f"step ({t_full / t_lean:.2f}x); identical maps: {same}"
    )
    ok &= same

    # same stepper, plain Python vs compiled, identical workload (free rocking, many events)
    kw = dict(theta0_rad=[0.0, 0.0, 0.08], duration_s=0.3, dt_s=1e-4)
    t_py, r_py = _timed(lambda: simulate_column(thesis, jit=False, **kw))
    t_nb, r_nb = _timed(lambda: simulate_column(thesis, jit=True, **kw), 5)
    same = np.allclose(r_py.theta_rad, r_nb.theta_rad, atol=1e-12) and len(r_py.impacts) == len(r_nb.impacts)
    print(
        f"baseline (same stepper, plain Python) {t_py:.2f} s vs numba {t_nb * 1e3:.2f} ms for "
        f"{len(r_nb.t_s) - 1} steps with {len(r_nb.impacts)} impacts: ratio {t_py / t_nb:.0f}x; "
        f"identical response: {same}"
    )
    return 0 if (same and ok) else 1


if __name__ == "__main__":
    raise SystemExit(main())
