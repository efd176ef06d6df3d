"""Shared test fixtures. Tests (not the package) may read ../shared."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
SHARED_DATA = SHARED / "data"

#: the libraries' thread pools, sized from these variables when they load
THREAD_VARS = (
    "OPENCV_FOR_THREADS_NUM",
    "OPENBLAS_NUM_THREADS",
    "OMP_NUM_THREADS",
    "MKL_NUM_THREADS",
    "NUMBA_NUM_THREADS",
)


def _share_the_cores() -> None:
    """Under pytest-xdist, size each worker's thread pools to its share of the cores.

    Every library sizes its pool to the whole machine (OpenCV, three OpenBLAS copies, numba), so
    N workers run N pools on the cores. A pool's waits spin: OpenCV's calling thread yields in a
    loop until its helper, descheduled behind the other worker, finishes its stripe. In the suite
    on 2 cores that turned 18 CPU-s of chessboard search (the test alone) into 107-219. Set here,
    before any test imports them, and inherited by the CLI subprocesses the tests start; a
    variable already set is kept, and a single process (``TEST_WORKERS=0``) keeps the defaults.
    """
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "0") or 0)
    if workers < 2:
        return
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    threads = max(1, cores // workers)
    for var in THREAD_VARS:
        os.environ.setdefault(var, str(threads))


_share_the_cores()

#: Test files started first under pytest-xdist, heaviest first: CPU-s measured in a fresh clone on
#: 2 workers (session 20; test_kill.py first, its kills wait on the clock). xdist's own order
#: (files with the most tests first) had left few-test, heavy files (test_kill, test_synth_camcorder,
#: test_pipeline_forced) for the end, one worker running them while the other idled. A file not
#: listed keeps the collection order after these; a stale entry only changes the order.
HEAVY_FIRST = (
    "test_kill.py",
    "test_stereo.py",
    "test_track_appear_real.py",
    "test_mechanism_response.py",
    "test_track_propose.py",
    "test_synth_camcorder.py",
    "test_pipeline_forced.py",
    "test_track_verify.py",
    "test_calib.py",
    "test_track_markerless.py",
    "test_track_init.py",
    "test_track_latch_real.py",
    "test_papers_gallery.py",
    "test_track_level.py",
    "test_fuzz_corpus.py",
    "test_pipeline_column.py",
    "test_oas_reference.py",
    "test_release_noise.py",
    "test_track_reacquire_real.py",
    "test_track_init_level.py",
    "test_table_fusion.py",
    "test_track_background_angle.py",
    "test_track_point.py",
)


def pytest_collection_modifyitems(config, items):
    """Under pytest-xdist (``make test`` passes ``--no-loadscope-reorder``), the files of
    :data:`HEAVY_FIRST` first, so that the run does not end on one long file."""
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        return
    rank = {name: k for k, name in enumerate(HEAVY_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """Path to ../shared/data (real records and IMU logs); skips if absent."""
    if not SHARED_DATA.is_dir():
        pytest.skip("../shared/data not available")
    return SHARED_DATA


@pytest.fixture(scope="session")
def sine_session(tmp_path_factory) -> Path:
    """One rendered shake-table session shared by the tests that only read it: a block with ArUco
    markers on a sine-driven table (seed 3, 960x540 at 50 fps, 1.2 s, lossless film, no IMU).
    Tests must not write into it (copy what they change into their own ``tmp_path``)."""
    from rocklab.synth import synth_session

    out = tmp_path_factory.mktemp("sine_session") / "s"
    synth_session(out, seed=3, table="sine", size=(960, 540), duration_s=1.2, imu=False, mp4=False)
    return out


@pytest.fixture
def run_cli(capsys):
    """Run the rocklab CLI in-process; returns (exit_code, stdout, stderr)."""
    from rocklab.pipelines import main

    def _run(*argv):
        rc = main([str(a) for a in argv])
        out, err = capsys.readouterr()
        return rc, out, err

    return _run


@pytest.fixture
def simulate_loop():
    """``simulate`` with the kernel's lean loops on (``lean=True``) or off (every step in the
    general Newton loop, the reference for the lean loops): ``simulate_loop(lean, block, **kw)``."""
    from rocklab.models import simulate
    from rocklab.models.rocking import Newmark

    def run(lean, blk, *args, **kw):
        return simulate(blk, *args, method=Newmark(lean=lean), **kw)

    return run
