"""``rocklab fit ...`` commands: JSON keys, numbers, and one-line errors with exit status 2."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from rocklab.fitting import catalogue_block, ceh_full_contact, edge_contact_k, eta_modified
from rocklab.models import simulate

B6M = catalogue_block("B6M")


@pytest.fixture(scope="module")
def track_csv(tmp_path_factory):
    """tracks.csv-style file: a rocking block and the table, 150 fps, some frames lost."""
    rng = np.random.default_rng(3)
    fps, t_rel, th0 = 150.0, 0.4031, 0.08
    r = simulate(B6M, th0, 0.0, 5.0, 2e-5, restitution="constant", eta=0.93)
    t = np.arange(0, 5.0, 1 / fps)
    th = np.interp(t - t_rel, r.t_s, r.theta_rad, left=th0, right=0.0) + rng.normal(0, math.radians(0.02), t.size)
    status = np.array(["ok"] * t.size, dtype=object)
    lost = [150, 151, 300]
    status[lost] = "lost"
    th[lost] = np.nan
    n = t.size
    blk = pd.DataFrame(
        dict(
            frame=np.arange(n),
            t_s=t,
            object="block_1",
            x_m=0.0,
            y_m=0.0,
            theta_rad=th,
            sigma_theta_rad=math.radians(0.02),
            quality=1.0,
            status=status,
        )
    )
    tab = blk.assign(object="table", theta_rad=0.0, status="ok")
    path = tmp_path_factory.mktemp("fit") / "tracks.csv"
    pd.concat([blk, tab]).sort_values(["frame", "object"]).to_csv(path, index=False)
    return path


def test_fit_restitution_json(run_cli, track_csv):
    rc, out, err = run_cli("fit", "restitution", track_csv, "--width", 0.045, "--height", 0.2025, "--json")
    assert rc == 0, err
    d = json.loads(out)
    for k in (
        "eta_e",
        "eta_e_first",
        "ci95_eta_e",
        "theta0_rad",
        "release_t_s",
        "rms_residual_rad",
        "per_impact_eta",
        "status",
    ):
        assert k in d
    assert d["status"] == "ok" and abs(d["eta_e"] - 0.93) < 0.002
    assert d["ci95_eta_e"][0] < d["eta_e"] < d["ci95_eta_e"][1]
    assert abs(d["theta0_rad"] - 0.08) < 2e-4 and abs(d["release_t_s"] - 0.4031) < 3e-3
    assert d["n_skipped"] == 3 and "skipped 3" in err
    assert isinstance(d["per_impact_eta"], list) and abs(d["per_impact_eta"][0] - 0.93) < 0.01


def test_fit_restitution_nan_raise_and_bad_object(run_cli, track_csv):
    rc, out, err = run_cli("fit", "restitution", track_csv, "--width", 0.045, "--height", 0.2025, "--nan", "raise")
    assert rc == 2 and "line" in err and len(err.strip().splitlines()) == 1
    rc, out, err = run_cli("fit", "restitution", track_csv, "--width", 0.045, "--height", 0.2025, "--object", "nope")
    assert rc == 2 and "nope" in err
    rc, out, err = run_cli("fit", "restitution", track_csv, "--width", -0.045, "--height", 0.2025)
    assert rc == 2 and "b_m" in err


def test_fit_restitution_missing_columns_and_short(run_cli, tmp_path):
    p = tmp_path / "x.csv"
    p.write_text("t_s,angle\n0,0.1\n")
    rc, out, err = run_cli("fit", "restitution", p, "--width", 0.045, "--height", 0.2025)
    assert rc == 2 and "theta_rad" in err
    p.write_text("t_s,theta_rad\n" + "".join(f"{i / 150},0.05\n" for i in range(5)))
    rc, out, err = run_cli("fit", "restitution", p, "--width", 0.045, "--height", 0.2025)
    assert rc == 2 and "too short" in err and str(p) in err  # the file is named


def test_fit_restitution_failed_status(run_cli, tmp_path):
    # a block lying still at 0.05 rad: no release, a failed result (exit 1) with the reason
    p = tmp_path / "still.csv"
    t = np.arange(0, 2, 1 / 150)
    pd.DataFrame(dict(t_s=t, theta_rad=0.05 + 1e-4 * np.random.default_rng(0).normal(size=t.size))).to_csv(p)
    rc, out, err = run_cli("fit", "restitution", p, "--width", 0.045, "--height", 0.2025, "--json")
    d = json.loads(out)
    assert rc == 1 and d["status"] == "failed" and "release" in d["message"] and d["eta_e"] is None


def test_fit_eta_mat(run_cli, tmp_path):
    cat = ceh_full_contact()
    k = edge_contact_k(cat.b_m.to_numpy(), 0.0015)
    cat["eta_e"] = 0.985 * eta_modified(np.arctan2(cat.b_m, cat.h_m).to_numpy(), k)
    p = tmp_path / "edge.csv"
    cat.to_csv(p, index=False)
    rc, out, err = run_cli("fit", "eta-mat", p, "--lc-m", 0.0015, "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["eta_mat"] == pytest.approx(0.985, abs=1e-12) and len(d["per_block"]) == 27
    rc, out, err = run_cli("fit", "eta-mat", p, "--lc-m", 0.03)
    assert rc == 2 and "l_c" in err


def test_fit_k_table_and_predict(run_cli, tmp_path):
    p = tmp_path / "full.csv"
    ceh_full_contact().to_csv(p, index=False)
    rc, out, err = run_cli("fit", "k-table", p, "--eta-mat", 0.98895, "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert {k: round(v, 4) for k, v in d["coefficients"].items()} == {
        "hb2": 0.0047,
        "hb": -0.0258,
        "const": 1.0635,
        "b_cm": -0.0565,
    }
    assert 0 < d["r2"] < 1 and d["rmse"] > 0
    rows = {r["block"]: r for r in d["per_block"]}
    assert set(rows["B6M"]) == {"block", "k", "b_bar_m", "feasible"}
    assert not rows["B10S"]["feasible"] and rows["B6M"]["feasible"]
    coef = tmp_path / "coef.json"
    coef.write_text(out)
    c = d["coefficients"]
    k9 = c["hb2"] * 4.5**2 + c["hb"] * 4.5 + c["const"] + c["b_cm"] * 9
    # default coefficients: Eq. 19 as printed
    rc, out, err = run_cli("fit", "k-predict", "--hb", 4.5, "--b-cm", 6, "--json")
    d = json.loads(out)
    assert round(d["k"], 4) == 0.7036 and round(d["eta_M"], 4) == 0.9644 and not d["extrapolated"]
    assert d["b_bar_m"] == pytest.approx(0.03 * d["k"], rel=1e-12)
    rc, out, err = run_cli("fit", "k-predict", "--hb", 4.5, "--b-cm", 9, "--coefficients", coef, "--json")
    d = json.loads(out)
    assert rc == 0 and d["extrapolated"] and "outside" in d["message"]
    assert d["k"] == pytest.approx(k9, rel=1e-12)
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    rc, out, err = run_cli("fit", "k-predict", "--hb", 4.5, "--b-cm", 9, "--coefficients", bad)
    assert rc == 2 and "JSON" in err


def test_text_reports(run_cli, tmp_path):
    p = tmp_path / "full.csv"
    ceh_full_contact().to_csv(p, index=False)
    rc, out, err = run_cli("fit", "k-table", p, "--eta-mat", 0.989)
    assert rc == 0 and "B10S" in out and "infeasible" in out and "R-squared" in out
    rc, out, err = run_cli("fit", "eta-mat", p, "--lc-m", 0.0015, "--rule", "lsq")
    assert rc == 0 and "eta_mat =" in out and "lsq" in out
