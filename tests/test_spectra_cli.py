"""CLI of the spectra commands: pulse, oas, design, equivalent (--json keys of issue 8)."""

import json

import pytest

FF = "records/fema-p695-far-field/SortedEQFile_{}.txt"


def test_pulse_json(run_cli, shared_data):
    rc, out, _ = run_cli("pulse", shared_data / FF.format("120112"), "--units", "g", "--json")
    d = json.loads(out)
    assert rc == 0 and d["t_p_s"] == pytest.approx(0.367, rel=0.01)  # Table 4, FF-2
    assert {"a_max_m_s2", "I_max_m_s", "t_p_s"} <= d.keys()


def test_design_json(run_cli):
    rc, out, _ = run_cli("design", "--height", 12, "--ag", 0.14, "--tI", 0.7, "--g", 9.81, "--json")
    assert rc == 0 and json.loads(out)["width_m"] == pytest.approx(1.2966, abs=2e-4)
    rc, out, _ = run_cli("design", "--height", 12, "--ag", 0.14, "--tI", 0.7, "--g", 9.81, "--mass-at-top", "--json")
    d = json.loads(out)
    assert d["width_m"] == pytest.approx(2.1204, abs=2e-4) and d["width_eq31_m"] == pytest.approx(2.122, abs=1e-3)


def test_equivalent_json(run_cli):
    rc, out, _ = run_cli("equivalent", "wall", "--R", 1.0, "--alpha", 0.1, "--json")
    d = json.loads(out)
    assert rc == 0 and {"p_rad_s", "theta_cr_rad", "lambda", "eta", "kappa1", "kappa2"} <= d.keys()
    assert d["theta_cr_rad"] == pytest.approx(0.2) and d["kappa1"] == 0.5 and d["eta"] is None
    rc, out, _ = run_cli("equivalent", "asym-frame", "--b", 0.3, "--H", 2, "--H1", 2.4, "--L", 3, "--h", 0.2, "--json")
    d = json.loads(out)
    assert rc == 0 and d["lambda"] < d["negative"]["lambda"]
    rc, _, err = run_cli("equivalent", "frame", "--R", 1.0)
    assert rc == 2 and "--alpha" in err and err.count("\n") == 1


def test_oas_json_csv_plot_and_many(run_cli, shared_data, tmp_path):
    rec = shared_data / FF.format("120112")
    rc, out, _ = run_cli(
        "oas",
        rec,
        "--units",
        "g",
        "--levels",
        12,
        "--sizes",
        30,
        "--json",
        "-o",
        tmp_path / "oas.csv",
        "--plot",
        tmp_path / "oas.png",
    )
    d = json.loads(out)
    assert rc == 0 and {"t_I_s", "t_I_prime_s", "beta", "f_min"} <= d.keys()
    assert d["t_I_s"] == pytest.approx(d["i_cr"] / d["f_min"])
    assert (tmp_path / "oas.png").stat().st_size > 10_000
    assert (tmp_path / "oas.csv").read_text().startswith("level,p_min_rad_s,R_unsafe_max_m,f_rad_s")
    # several records: summary table; same t_I as the single run
    rc, out, _ = run_cli(
        "oas",
        rec,
        shared_data / FF.format("120111"),
        "--units",
        "g",
        "--levels",
        12,
        "--sizes",
        30,
        "--workers",
        1,
        "--no-progress",
        "--json",
        "-o",
        tmp_path / "t.csv",
    )
    rows = json.loads(out)["records"]
    assert rc == 0 and rows[0]["t_I_s"] == pytest.approx(d["t_I_s"]) and rows[0]["error"] == ""
    assert (
        (tmp_path / "t.csv")
        .read_text()
        .startswith("record,t_p_s,t_I_s,t_I_prime_s,beta,f_min,f_min_level,f_min_R_m,error")
    )


def test_oas_bad_input(run_cli, shared_data, tmp_path):
    rc, _, err = run_cli("oas", shared_data / FF.format("120112"), "--units", "g", "--slenderness", 0)
    assert rc == 2 and "slenderness" in err and err.count("\n") == 1
    gap = tmp_path / "gap.txt"
    gap.write_text("0 0\n0.01 0.1\n0.02 -0.1\n0.05 0.2\n")
    rc, _, err = run_cli("oas", gap, "--units", "g")
    assert rc == 2 and "non-uniform" in err and err.count("\n") == 1
    empty = tmp_path / "empty.txt"
    empty.write_text("")
    rc, _, err = run_cli("pulse", empty, "--units", "g")
    assert rc == 2 and "empty" in err


def test_oas_many_on_a_dask_cluster(shared_data):
    distributed = pytest.importorskip("distributed")
    from rocklab.pipelines import oas_many

    recs = [shared_data / FF.format(r) for r in ("120111", "120112")]
    kw = dict(levels=8, sizes=20, refine=3)
    local = oas_many(recs, units="g", oas_kwargs=kw, workers=1, progress=False)
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0"
    ) as cluster:  # any free port: 8787 may be taken
        remote = oas_many(recs, units="g", oas_kwargs=kw, scheduler=cluster.scheduler_address, progress=False)
    assert list(remote["record"]) == [str(r) for r in recs]
    assert remote["t_I_s"].tolist() == pytest.approx(local["t_I_s"].tolist())
