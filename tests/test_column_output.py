"""``simulate_column(output_dt_s=...)``: a decimated time history of the SAME run.

Invariants against the full history (every step): the stored samples are the
full history's rows at the shared times, the events, status and peaks do not
change, and the stored arrays shrink with the spacing.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from rocklab import InputError
from rocklab.blocks import Block
from rocklab.series import BaseMotion
from rocklab.models import Column, bundled_record, column_overturning_maps, sine_pulse, simulate_column


def _elcentro_3s():
    rec = bundled_record("elcentro")
    keep = rec.t_s <= 3.0
    return BaseMotion(rec.t_s[keep], rec.acc_m_s2[keep], name="elcentro_3s").scaled_to_pga(0.3, "g")


THESIS = Column((Block(0.1, 0.2, density_kg_m3=2700.0),) * 3, cut_m=0.002)

# name -> (column, base, kwargs): free rocking with many impacts, a record, a run ended by
# overturning and one ended inside a step by sliding (both off the decimated grid)
CASES = {
    "free": (THESIS, None, dict(theta0_rad=[0.0, 0.0, 0.08], duration_s=0.3, dt_s=1e-4)),
    "record": (THESIS, "elcentro", dict(duration_s=3.0, dt_s=1e-4, stop_at_rest=False)),
    "overturn": (Column.uniform(1.0, 12.0, 3, mass_kg=1.0), sine_pulse(8.0, 1.5), dict(duration_s=11.5, dt_s=2e-3)),
    "sliding": (
        Column((Block(0.3, 0.3, mass_kg=1.0),), mu=0.3),
        BaseMotion.from_arrays(
            np.arange(0.0, 1.0, 0.01), np.where(np.arange(0.0, 1.0, 0.01) > 0.2, 0.5 * 9.81, 0.0), "m/s2"
        ),
        dict(duration_s=1.0, dt_s=1e-3),
    ),
}


@pytest.fixture(scope="module")
def runs():
    out = {}
    for name, (col, base, kw) in CASES.items():
        base = _elcentro_3s() if base == "elcentro" else base
        out[name] = {
            odt: simulate_column(col, base, output_dt_s=odt, **kw)
            for odt in (None, 7 * kw["dt_s"], 10 * kw["dt_s"], math.inf)
        }
    return out


@pytest.mark.parametrize("name", list(CASES))
def test_decimated_history_is_the_full_one_at_shared_times(runs, name):
    full = runs[name][None]
    dt = CASES[name][2]["dt_s"]
    assert np.array_equal(full.t_s, np.arange(len(full.t_s)) * dt)
    for odt, r in runs[name].items():
        if odt is None:
            continue
        stride = len(full.t_s) if odt == math.inf else round(odt / dt)
        # rows 0, stride, 2 stride, ... and the last completed step
        rows = np.unique(np.r_[np.arange(0, len(full.t_s), stride), len(full.t_s) - 1])
        assert len(r.t_s) == len(rows) < len(full.t_s)
        np.testing.assert_allclose(r.t_s, full.t_s[rows], rtol=0, atol=1e-12)
        for attr in ("phi_rad", "omega_rad_s", "theta_rad", "energy_J", "kinetic_J"):
            np.testing.assert_allclose(
                getattr(r, attr), getattr(full, attr)[rows], rtol=0, atol=1e-12, err_msg=f"{name} {odt} {attr}"
            )


@pytest.mark.parametrize("name", list(CASES))
def test_events_status_and_peaks_do_not_depend_on_the_spacing(runs, name):
    full = runs[name][None]
    # the full history's own peaks: the kernel's running maxima over every step
    np.testing.assert_array_equal(full.max_abs_theta_rad, np.abs(full.theta_rad).max(axis=0))
    np.testing.assert_array_equal(full.max_abs_phi_rad, np.abs(full.phi_rad).max(axis=0))
    for odt, r in runs[name].items():
        pd.testing.assert_frame_equal(r.configurations, full.configurations)
        pd.testing.assert_frame_equal(r.impacts, full.impacts)
        assert (r.status, r.message) == (full.status, full.message)
        assert r.t_status_s == full.t_status_s or (math.isnan(r.t_status_s) and math.isnan(full.t_status_s))
        np.testing.assert_array_equal(r.max_abs_theta_rad, full.max_abs_theta_rad)
        np.testing.assert_array_equal(r.max_abs_phi_rad, full.max_abs_phi_rad)


def test_expected_endings(runs):
    # the cases really end as intended: off the decimated grid, at the thesis-style events
    assert runs["overturn"][None].status == "overturned"
    assert runs["sliding"][None].status == "sliding" and abs(runs["sliding"][None].t_status_s - 0.206) <= 1e-3
    assert len(runs["free"][None].impacts) > 50 and len(runs["record"][None].impacts) >= 3
    assert len(runs["overturn"][None].configurations) >= 1


def test_peaks_come_from_every_step_not_the_samples(runs):
    r = runs["record"][math.inf]
    assert len(r.t_s) == 2  # the initial and the final state only
    # the column rocked: its peak is far above anything the two stored (resting) samples show
    assert np.all(r.max_abs_theta_rad > 10 * np.abs(r.theta_rad).max(axis=0) + 1e-3)


def test_stored_arrays_shrink_with_the_spacing(runs):
    full = runs["record"][None]
    nb = lambda r: sum(
        getattr(r, a).nbytes for a in ("t_s", "phi_rad", "omega_rad_s", "theta_rad", "energy_J", "kinetic_J")
    )
    row = nb(full) / len(full.t_s)
    for k in (7, 10):
        r = runs["record"][k * 1e-4]
        assert nb(r) <= nb(full) / k + 2 * row
    assert nb(runs["record"][math.inf]) == 2 * row


def test_bad_output_spacing_is_one_line():
    col = Column((Block(0.1, 0.2),))
    with pytest.raises(InputError, match="whole multiple of dt_s") as e:
        simulate_column(col, theta0_rad=0.05, duration_s=0.1, dt_s=1e-3, output_dt_s=2.5e-3)
    assert "\n" not in str(e.value)
    with pytest.raises(InputError, match="output_dt_s"):
        simulate_column(col, theta0_rad=0.05, duration_s=0.1, dt_s=1e-3, output_dt_s=-1e-3)
    with pytest.raises(InputError, match="whole multiple"):
        simulate_column(col, theta0_rad=0.05, duration_s=0.1, dt_s=1e-3, output_dt_s=1e-4)


def test_maps_store_no_history_and_match_the_full_runs():
    col_kw = dict(ap_m_s2=[3.0, 9.0], tp_s=[0.6, 1.8], n_blocks=(1, 3), dt_s=2e-3, free_s=4.0)
    lean = column_overturning_maps(**col_kw)
    full = column_overturning_maps(**col_kw, output_dt_s=None)
    np.testing.assert_array_equal(lean.overturned, full.overturned)
    np.testing.assert_array_equal(lean.max_theta_over_alpha, full.max_theta_over_alpha)
    assert lean.overturned.any() and not lean.overturned.all()


def test_cli_output_dt(run_cli, tmp_path):
    args = (
        "column",
        "--blocks",
        "0.1x0.2,0.1x0.2,0.1x0.2",
        "--cut",
        "0.002",
        "--theta0",
        "0,0,0.05",
        "--duration",
        "0.25",
        "--dt",
        "2e-4",
        "--json",
    )
    rc, out_full, err = run_cli(*args, "-o", tmp_path / "full.csv")
    assert rc == 0, err
    rc, out_dec, err = run_cli(*args, "-o", tmp_path / "dec.csv", "--output-dt", "1e-3")
    assert rc == 0, err
    rc, out_none, err = run_cli(*args)  # no -o: no history kept, same summary
    assert rc == 0, err
    full = pd.read_csv(tmp_path / "full.csv")
    dec = pd.read_csv(tmp_path / "dec.csv")
    assert len(full) == 1251 and len(dec) == 251
    np.testing.assert_allclose(dec.to_numpy(), full.to_numpy()[::5], rtol=0, atol=1e-12)
    import json

    d_full, d_dec, d_none = (json.loads(o) for o in (out_full, out_dec, out_none))
    for d in (d_dec, d_none):
        for key in ("status", "max_abs_theta_rad", "n_impacts", "configurations"):
            assert d[key] == d_full[key]
    assert d_dec["params"]["output_dt_s"] == 1e-3 and d_full["params"]["output_dt_s"] == 2e-4
    rc, _, err = run_cli(*args, "-o", tmp_path / "bad.csv", "--output-dt", "3e-4")
    assert rc == 2 and "whole multiple" in err and len(err.strip().splitlines()) == 1
