"""Shared test fixtures. Tests (not the package) may read ../shared."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
SHARED_DATA = SHARED / "data"


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """Path to ../shared/data (real records and IMU logs); skips if absent."""
    if not SHARED_DATA.is_dir():
        pytest.skip("../shared/data not available")
    return SHARED_DATA


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
