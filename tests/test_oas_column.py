"""The OAS of a multi-block column (thesis Fig. 43): one block is the single block's OAS."""

import json

import numpy as np
import pytest

from rocklab import InputError
from rocklab.models import column_overturning_spectrum, overturning_spectrum, pulse_motion

GRID = dict(levels=4, sizes=12, R_max_m=1000.0, R_min_m=0.3, refine=5)


@pytest.fixture(scope="module")
def sine():
    return pulse_motion("sine", 2.0, 1.0)  # one full sine, t_p = 2 s: a boundary free of chaos


def test_one_block_column_is_the_single_block(sine):
    # two integrators (the column's joint model, the batch block kernel) and two free-rocking
    # rules (10/p seconds, the energy verdict) reach the same boundary: every grid verdict and
    # every bisection step agree
    col = column_overturning_spectrum(sine, 6.0, 1, **GRID)
    blk = overturning_spectrum(sine, 6.0, **GRID)
    assert np.isfinite(col.p_min_rad_s).sum() >= 3
    np.testing.assert_allclose(col.p_min_rad_s, blk.p_min_rad_s, rtol=1e-12)  # NaN where both are NaN
    assert col.t_I_s == pytest.approx(blk.t_I_s, rel=1e-12)
    # and a two-block column's boundary is a different one (the comparison can fail)
    two = column_overturning_spectrum(sine, 6.0, 2, **GRID)
    assert np.nanmax(np.abs(two.p_min_rad_s / col.p_min_rad_s - 1)) > 0.01
    assert two.options["n_blocks"] == 2 and np.isnan(two.eta)


def test_top_down_grid_finds_the_dense_scan_boundary(sine):
    kw = dict(GRID, refine=0, sizes=10)
    top = column_overturning_spectrum(sine, 6.0, 2, n_impacts=2, **kw)
    dense = column_overturning_spectrum(sine, 6.0, 2, n_impacts=2, grid="dense", **kw)
    np.testing.assert_array_equal(top.p_min_rad_s, dense.p_min_rad_s)
    assert top.n_runs < dense.n_runs  # the small blocks below the boundary are not simulated


@pytest.mark.parametrize(
    "kw, word",
    [({"n_blocks": 0}, "n_blocks"), ({"n_impacts": 1.5}, "n_impacts"), ({"search": "contiguous"}, "top-down")],
)
def test_bad_options_are_one_line_errors(sine, kw, word):
    with pytest.raises(InputError, match=word):
        column_overturning_spectrum(sine, 6.0, **{"n_blocks": 2, **kw})


def test_cli_oas_column(run_cli, tmp_path):
    args = ("oas", "--pulse", "sine,1m/s2,2", "--slenderness", "6", "--levels", "4", "--sizes", "12")
    rc, out, err = run_cli(*args, "--column", "1", "--refine", "5", "--json", "-o", tmp_path / "c.csv")
    assert rc == 0, err
    d = json.loads(out)
    blk = overturning_spectrum(pulse_motion("sine", 2.0, 1.0), 6.0, levels=4, sizes=12, refine=5)
    assert d["options"]["n_blocks"] == 1 and d["t_I_s"] == pytest.approx(blk.t_I_s, rel=1e-6)
    assert (tmp_path / "c.csv").read_text().startswith("level,p_min_rad_s")
    rc, _, err = run_cli(*args, "--column", "2", "--eta", "0.9")
    assert rc == 2 and "--eta" in err and "Traceback" not in err


def test_a_column_coming_apart_counts_unsafe(sine):
    # stocky blocks (three of h/b = 2) under 4 a_p,min: a joint would take tension (thesis §3.3: the
    # calculation stops, the column may disintegrate); such runs are unsafe and counted
    from rocklab._diagnostics import collecting

    with collecting() as diags:
        o = column_overturning_spectrum(sine, 6.0, 3, levels=2, level_max=4.0, sizes=2, R_max_m=1000.0, R_min_m=100.0)
    assert o.options["n_terminated"] >= 1
    (d,) = [d for d in diags if d.code == "W-COLUMN-APART"]  # said, not only counted
    assert d.message.startswith(f"{o.options['n_terminated']} column runs")
    assert o.overturned[1, 0]  # R = 1000 m at a_p = 4 a_p,min: tension, not a safe block
    assert not o.overturned[0].any()  # at a_p,min nothing lifts far enough


def test_a_failed_step_is_taken_again_shorter():
    """Thesis Fig. 43's grid (El Centro, 3 blocks, 10 impacts per closing): the cell at R = 19.91 m,
    scale 1.823 failed 'numerical' at the grid's step 0.005/p with numba 0.68 and took the whole
    figure with it. The run is taken again with half and a quarter of the step: its verdict is a
    real one and equals the quarter step's."""
    import math

    from rocklab.models import bundled_record
    from rocklab.models.spectra._oas_column import _overturns

    args = (bundled_record("elcentro"), 1.8230518719308604, 19.905358527674867, math.atan(1 / 12), 3, 10)
    got = _overturns(*args, 0.005, 10.0, 1e-4, True)
    assert got not in ("capacity", "numerical")
    assert got == _overturns(*args, 0.00125, 10.0, 1e-4, True)
