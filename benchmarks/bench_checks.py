"""Cost of the plausibility checks inside one ``rocklab run`` (issue target: < 2 % of the run).

Baseline in the same process: the same ``run_experiment`` call's total time. The work is a
rendered synthetic session (960x540, 50 fps, ArUco, an x-IMU log: video tracking, IMU,
sync, fit, simulations, report and Rerun recording). The checks are timed by cProfile as
the cumulative time of every function that only checks (output folder, config keys,
record/IMU/fit/video plausibility); their share is reported against the profiled total.
"""

from __future__ import annotations

import cProfile
import pstats
import tempfile
import time
from pathlib import Path

CHECKS = (
    "check_output_dir",
    "reject_unknown",
    "check_plausible",
    "check_imu_log",
    "_check_gyro_vs_tilt",
    "_check_still_tilt",
    "cut_at_gap",
    "check_frames",
    "check_step",
    "check_memory",
    "_check_block_rows",
    "_complete_rows",
    "_check_last_token",
    "at2_units",
    "clean_stale",
)


def main() -> None:
    from rocklab.pipelines.experiment._experiment import run_experiment
    from rocklab.synth import synth_session

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        synth_session(tmp / "s", seed=4, size=(960, 540), duration_s=4.0, mp4=False)
        run_experiment(tmp / "s" / "experiment.toml", tmp / "warm", force=True)  # numba compile, caches
        t0 = time.perf_counter()
        run_experiment(tmp / "s" / "experiment.toml", tmp / "plain", force=True)
        plain_s = time.perf_counter() - t0
        prof = cProfile.Profile()
        prof.enable()
        run_experiment(tmp / "s" / "experiment.toml", tmp / "prof", force=True)
        prof.disable()
    st = pstats.Stats(prof)
    total = max(v[3] for v in st.stats.values())  # the outermost call's cumulative time
    checks = sum(v[3] for (f, ln, name), v in st.stats.items() if name in CHECKS)
    print(f"baseline: the same run_experiment call, total {plain_s:.4g} s unprofiled, {total:.4g} s profiled")
    print(f"plausibility checks: {checks * 1e3:.4g} ms = {100 * checks / total:.3g} % of the run (target < 2 %)")


if __name__ == "__main__":
    main()
