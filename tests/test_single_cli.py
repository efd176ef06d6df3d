"""``rocklab simulate`` command line."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from rocklab import Block


def test_json_keys_and_values(run_cli):
    rc, out, err = run_cli(
        "simulate", "--width", 0.045, "--height", 0.2025, "--theta0", 0.15, "--duration", 3, "--json"
    )
    assert rc == 0, err
    d = json.loads(out)
    b = Block(0.045, 0.2025)
    assert d["alpha_rad"] == pytest.approx(b.alpha_rad) and d["p_rad_s"] == pytest.approx(b.p_rad_s)
    assert d["eta_H"] == pytest.approx(0.9294, abs=5e-5)
    assert d["status"] in ("rest", "rocking")
    assert d["max_abs_theta_over_alpha"] == pytest.approx(0.15 / b.alpha_rad)
    imp = d["impacts"]
    assert len(imp) > 5 and {"t_s", "omega_before_rad_s", "omega_after_rad_s"} <= set(imp[0])
    assert imp[0]["omega_after_rad_s"] / imp[0]["omega_before_rad_s"] == pytest.approx(b.eta_H)


def test_constant_law_and_csv_output(run_cli, tmp_path):
    out_csv = tmp_path / "h.csv"
    rc, out, err = run_cli(
        "simulate",
        "--width",
        0.045,
        "--height",
        0.2025,
        "--theta0",
        0.1,
        "--duration",
        1,
        "--restitution",
        "constant",
        "--eta",
        0.95,
        "-o",
        out_csv,
        "--json",
    )
    assert rc == 0, err
    d = json.loads(out)
    f = pd.read_csv(out_csv)
    assert list(f.columns) == ["t_s", "theta_rad", "omega_rad_s", "energy_J"]
    assert f.theta_rad.iloc[0] == 0.1 and np.allclose(np.diff(f.t_s), 1e-4)
    r = [i["omega_after_rad_s"] / i["omega_before_rad_s"] for i in d["impacts"]]
    assert np.allclose(r, 0.95)


def test_base_motion_scaled(run_cli, tmp_path):
    rec = tmp_path / "rec.csv"
    t = np.arange(0, 2, 0.01)
    pd.DataFrame({"t_s": t, "acc_m_s2": np.sin(2 * np.pi * t)}).to_csv(rec, index=False)
    rc, out, err = run_cli(
        "simulate",
        "--width",
        0.2,
        "--height",
        1.0,
        "--duration",
        2,
        "--dt",
        1e-3,
        "--base-motion",
        rec,
        "--scale-pga",
        0.1,
        "--json",
    )
    assert rc == 0, err
    assert json.loads(out)["status"] == "no_uplift"  # 0.1 g < tan(alpha) = 0.2
    rc, out, err = run_cli(
        "simulate",
        "--width",
        0.2,
        "--height",
        1.0,
        "--duration",
        2,
        "--dt",
        1e-3,
        "--base-motion",
        rec,
        "--units",
        "m/s2",
        "--scale-pga",
        3.0,
        "--json",
    )
    assert rc == 0 and json.loads(out)["max_abs_theta_over_alpha"] > 0


@pytest.mark.parametrize(
    "argv",
    [
        ("--width", 0.045, "--height", 0.2025, "--theta0", 0.3),
        ("--width", -1, "--height", 0.2),
        ("--width", 0.045, "--height", 0.2025, "--restitution", "constant"),
        ("--width", 0.045, "--height", 0.2025, "--base-motion", "/nonexistent/rec.AT2"),
        ("--width", 0.045, "--height", 0.2025, "--scale-pga", 0.3),
    ],
)
def test_bad_input_exit_2_one_line(run_cli, argv):
    rc, out, err = run_cli("simulate", *argv)
    assert rc == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("rocklab simulate: error:")


@pytest.mark.parametrize(
    "argv,expect",
    [
        (("--restitution", "modified", "--k", 1.0), lambda b: b.eta_H),
        (
            ("--restitution", "bumps", "--bumps", 1),
            lambda b: (2 * (b.h_m / 2) ** 2 + 0.5 * (b.b_m / 2) ** 2) / (2 * (b.h_m / 2) ** 2 + 2 * (b.b_m / 2) ** 2),
        ),
    ],
)
def test_laws_from_cli(run_cli, argv, expect):
    rc, out, err = run_cli(
        "simulate", "--width", 0.045, "--height", 0.2025, "--theta0", 0.1, "--duration", 1, "--json", *argv
    )
    assert rc == 0, err
    imp = json.loads(out)["impacts"][0]
    assert imp["omega_after_rad_s"] / imp["omega_before_rad_s"] == pytest.approx(expect(Block(0.045, 0.2025)))


def test_every_registered_integrator_is_reachable_from_the_command_line(run_cli):
    # the CLI takes its methods from the registry: taylor was unreachable behind a hard-coded list
    from rocklab.models.rocking import METHODS

    first = {}
    for m in METHODS:
        rc, out, err = run_cli(
            "simulate", "--width", 0.1, "--height", 0.3, "--theta0", 0.1, "--duration", 2, "--method", m, "--json"
        )
        assert rc == 0, err
        first[m] = json.loads(out)["impacts"][0]["t_s"]
    # the same first impact (to 1e-3 s) whichever method integrates it
    assert max(first.values()) - min(first.values()) < 1e-3
    rc, _, err = run_cli("simulate", "--width", 0.1, "--height", 0.3, "--theta0", 0.1, "--method", "rk4")
    assert rc == 2 and "newmark" in err and "taylor" in err and "event" in err
