"""``rocklab column``: output, JSON, bad input, maps PNG."""

from __future__ import annotations

import json

import numpy as np


def test_column_cli_text_and_json(run_cli, tmp_path):
    rc, out, err = run_cli(
        "column",
        "--blocks",
        "0.1x0.2,0.1x0.2,0.1x0.2",
        "--cut",
        "0.002",
        "--theta0",
        "0,0,0.05",
        "--duration",
        "0.5",
        "--dt",
        "2e-4",
    )
    assert rc == 0, err
    assert "status rocking" in out and "peak |theta| per block" in out and "configuration changes" in out
    csv = tmp_path / "col.csv"
    rc, out, err = run_cli(
        "column",
        "--blocks",
        "0.1x0.2,0.1x0.2,0.1x0.2",
        "--cut",
        "0.002",
        "--theta0",
        "0,0,0.05",
        "--duration",
        "0.5",
        "--dt",
        "2e-4",
        "--json",
        "-o",
        csv,
    )
    assert rc == 0, err
    d = json.loads(out)
    assert d["n_blocks"] == 3 and d["status"] == "rocking" and d["t_status_s"] is None
    assert d["max_abs_theta_rad"][2] == 0.05  # released from rest: the initial tilt is the peak
    assert d["configurations"][0] == {"t_s": 0.0, "joint": 2, "state": "cw", "event": "start"}
    import pandas as pd

    f = pd.read_csv(csv)
    assert {"t_s", "theta_2_rad", "phi_0_rad", "omega_1_rad_s", "energy_J"} <= set(f.columns)
    assert np.isclose(f.theta_2_rad.abs().max(), 0.05)


def test_column_cli_base_motion(run_cli, tmp_path):
    rec = tmp_path / "pulse.csv"
    t = np.arange(0, 1.0, 0.005)
    a = np.where(t < 0.6, -0.3 * np.sin(2 * np.pi * t / 0.6), 0.0)
    rec.write_text("t_s,acc_g\n" + "\n".join(f"{x:.3f},{y:.6f}" for x, y in zip(t, a)) + "\n")
    before = rec.read_bytes()
    rc, out, err = run_cli(
        "column", "--blocks", "0.1x0.2,0.1x0.2", "--base-motion", rec, "--scale-pga", "0.35", "--json", "--dt", "2e-4"
    )
    assert rc == 0, err
    d = json.loads(out)
    ev = d["configurations"]
    # 0.35 g exceeds the base joint's uplift level g a / z = 0.25 g: the base joint opens first, clockwise
    assert ev[0]["event"] == "opening" and ev[0]["joint"] == 0 and ev[0]["state"] == "cw"
    assert rec.read_bytes() == before


def test_column_cli_bad_input(run_cli):
    rc, out, err = run_cli("column", "--blocks", "0.1by0.2")
    assert rc == 2 and "--blocks" in err and len(err.strip().splitlines()) == 1
    rc, out, err = run_cli("column", "--blocks", "0.1x0.2")
    assert rc == 2 and "nothing moves" in err
    rc, out, err = run_cli("column", "--blocks", "0.1x0.2,0.1x0.2", "--cut", "0.001,0.002,0.003", "--theta0", "0.01")
    assert rc == 2 and "--cut" in err
    rc, out, err = run_cli("column")
    assert rc == 2 and "--blocks" in err


def test_column_cli_maps_png(run_cli, tmp_path):
    png = tmp_path / "maps.png"
    rc, out, err = run_cli("column", "--maps-png", png, "--maps-grid", "2", "--json")
    assert rc == 0, err
    d = json.loads(out)["maps"]
    assert np.array(d["overturned"]).shape == (3, 2, 2)
    # the strongest, longest pulse (12 m/s2, 2.4 s) topples every column; the weakest shortest one none
    assert all(np.array(d["overturned"])[:, 1, 1]) and not any(np.array(d["overturned"])[:, 0, 0])
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plot_column_response_png(tmp_path):
    from rocklab.blocks import Block
    from rocklab.models import Column, simulate_column
    from rocklab.pipelines.experiment._plots_column import plot_column_response

    r = simulate_column(Column((Block(0.1, 0.2),) * 2), theta0_rad=[0.0, 0.04], duration_s=0.3, dt_s=1e-3)
    png = tmp_path / "resp.png"
    fig = plot_column_response(r, png)
    assert png.read_bytes()[:4] == b"\x89PNG" and len(fig.axes) == 2
    assert len(fig.axes[0].lines) == 2  # one angle curve per block
