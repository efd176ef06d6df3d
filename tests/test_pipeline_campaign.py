"""``rocklab campaign``: parallel experiments, a failing one reported, campaign fits with known truth."""

import json
from pathlib import Path
import re

import numpy as np
import pandas as pd
import pytest

from rocklab.fitting import catalogue_block, edge_contact_k, eta_modified
from rocklab.models import simulate
from rocklab.pipelines import read_rrd_summary

ETA_MAT = 0.985
L_C = 0.0015


def _exp(root, name, bid, contact, eta, seed, extra=""):
    blk = catalogue_block(bid)
    theta0 = 0.8 * blk.alpha_rad
    sim = simulate(blk, theta0_rad=theta0, duration_s=6.0, restitution="constant", eta=eta)
    t = np.arange(0, 6.0, 1 / 150)
    th = np.where(t < 0.4, theta0, np.interp(t - 0.4, sim.t_s, sim.theta_rad))
    th = th + np.random.default_rng(seed).normal(0, np.radians(0.02), t.size)
    d = root / name
    d.mkdir(parents=True)
    pd.DataFrame({"t_s": t, "theta_rad": th}).to_csv(d / "tracks.csv", index=False)
    contact_toml = f'[contact]\ntype = "edge"\nl_c_m = {L_C}\n' if contact == "edge" else ""
    (d / "experiment.toml").write_text(
        f'name = "{name}"\n{extra}[block]\nid = "{bid}"\n{contact_toml}[sources.track]\npath = "tracks.csv"\n'
        "[output]\nrrd = false\nfigures = false\n"
    )


def test_campaign_recovers_eta_mat_and_reports_failure(tmp_path, run_cli):
    root = tmp_path / "campaign"
    truth = {}
    for i, bid in enumerate(("B3M", "B6M")):
        b = catalogue_block(bid)
        eta = float(eta_modified(b.alpha_rad, edge_contact_k(b.b_m, L_C))) * ETA_MAT
        _exp(root, f"{bid}_edge", bid, "edge", eta, i)
        truth[f"{bid}_edge"] = eta
    _exp(root, "B4M_full", "B4M", "full", 0.882, 7)  # Čeh Table 3
    bad = root / "broken"
    bad.mkdir()
    (bad / "experiment.toml").write_text('[block]\nb_m = 0.045\nh_m = 0.2\n[sources.track]\npath = "missing.csv"\n')

    out = tmp_path / "out"
    rc, stdout, err = run_cli("campaign", root, "--out", out, "--workers", "2", "--no-progress", "--json")
    assert rc == 1, err  # one experiment failed: the campaign finishes the rest but says so
    assert "1 of 4 experiments FAILED" not in err  # the summary goes to stdout, not stderr

    def strict(c):  # NaN/Infinity are not JSON; the CLI must write null
        raise ValueError(f"non-JSON constant {c} in the --json output")

    res = json.loads(stdout, parse_constant=strict)
    assert res["n_experiments"] == 4 and res["n_ok"] == 3
    assert len(res["failures"]) == 1 and "missing.csv" in res["failures"][0]["error"]
    assert not (out / "experiments" / "broken").exists()  # a failed run leaves no partial output
    # η_mat = η_e / η_M from the two edge-contact runs (Čeh Eq. 16) recovers the truth
    assert res["eta_mat"]["eta_mat"] == pytest.approx(ETA_MAT, abs=0.002)
    # k from the full-contact run by Eq. 17-18 with the fitted η_mat: Table 5 gives 0.8397 for B4M
    # at η_mat = 0.989; here η_mat differs, so compare with the closed form instead
    from rocklab.fitting import k_from_eta

    k_expect = float(k_from_eta(catalogue_block("B4M").alpha_rad, 0.882 / res["eta_mat"]["eta_mat"]))
    (row,) = [r for r in res["k_table"]["per_block"] if r["block"] == "B4M"]
    assert row["k"] == pytest.approx(k_expect, abs=0.01)
    tab = pd.read_csv(out / "campaign.csv")
    (failed,) = tab[tab["status"] == "failed"].itertuples()  # the failure is listed, with its error
    assert failed.experiment == "broken" and "missing.csv" in failed.error
    assert res["status"] == "partial" and res["n_failed"] == 1
    for _, r in tab.iterrows():
        if r["experiment"] in truth:
            assert r["eta_e"] == pytest.approx(truth[r["experiment"]], abs=0.002)
    rows = read_rrd_summary(out / "campaign.rrd")
    assert rows["/campaign/experiments"] == 3
    # one clickable point per fitted experiment, carrying its name and where its report is
    assert {k for k in rows if k.startswith("/campaign/eta_vs_hb/")} == {
        "/campaign/eta_vs_hb/edge/B3M_edge",
        "/campaign/eta_vs_hb/edge/B6M_edge",
        "/campaign/eta_vs_hb/full/B4M_full",
    }
    assert (out / "figures" / "eta_vs_hb.png").is_file()
    # the people's report: the same numbers in Markdown and in one offline HTML file
    md = (out / "summary.md").read_text(encoding="utf-8")
    html = (out / "report.html").read_text(encoding="utf-8")
    eta_mat = res["eta_mat"]["eta_mat"]
    assert f"{eta_mat:.4g}" in md and f"{eta_mat:.4g}" in html
    assert "broken" in md and "FAILED" in html
    assert "[B4M_full](experiments/B4M_full/report.html)" in md and 'href="experiments/B4M_full/report.html"' in html
    assert html.count("data:image/png;base64,") == md.count("![") >= 1 and 'src="figures/' not in html
    assert (out / "experiments" / "B4M_full" / "report.html").is_file()


def test_campaign_on_a_dask_cluster_matches_local(tmp_path):
    """``--scheduler ADDR`` runs the same tasks on a Dask distributed cluster, same answers."""
    distributed = pytest.importorskip("distributed")
    from rocklab.pipelines.campaign import _campaign as C

    root = tmp_path / "c"
    _exp(root, "B4M_full", "B4M", "full", 0.882, 3)
    _exp(root, "B6M_full", "B6M", "full", 0.941, 4)
    local = C.run_campaign(root, tmp_path / "local", workers=1, progress=False)
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0"
    ) as cluster:  # any free port: 8787 may be taken
        remote = C.run_campaign(root, tmp_path / "remote", scheduler=cluster.scheduler_address, progress=False)
    assert remote.n_ok == local.n_ok == 2
    assert remote.table["eta_e"].tolist() == pytest.approx(local.table["eta_e"].tolist(), abs=1e-12)
    assert remote.table["eta_e"].tolist() == pytest.approx([0.882, 0.941], abs=0.002)


def _track_experiment(folder, name, eta, b_m=0.045, h_m=0.2025):
    """A track-only experiment (free rocking with noise) under ``folder``, named ``name``."""
    import pandas as pd

    from rocklab import Block
    from rocklab.models import simulate

    blk = Block(b_m, h_m)
    sim = simulate(blk, theta0_rad=0.8 * blk.alpha_rad, duration_s=3.0, restitution="constant", eta=eta)
    t = np.arange(0, 3.0, 1 / 100)
    th = np.where(t < 0.3, sim.theta_rad[0], np.interp(t - 0.3, sim.t_s, sim.theta_rad))
    th = th + np.random.default_rng(0).normal(0, 3e-4, t.size)
    folder.mkdir(parents=True)
    pd.DataFrame({"t_s": t, "theta_rad": th}).to_csv(folder / "tracks.csv", index=False)
    (folder / "experiment.toml").write_text(
        f'name = "{name}"\n[block]\nb_m = {b_m}\nh_m = {h_m}\n[sources.track]\npath = "tracks.csv"\n'
        "[output]\nrrd = false\nfigures = false\n"
    )


def test_campaign_refuses_two_experiments_of_one_name(tmp_path, run_cli):
    # two blocks of different size under one name would be one "block" in the k fit and one
    # entity in campaign.rrd: refused before any work, naming both configs
    root = tmp_path / "lab"
    _track_experiment(root / "mon", "take", 0.9)
    _track_experiment(root / "tue", "take", 0.8, b_m=0.06, h_m=0.3)
    out = tmp_path / "out"
    rc, _, err = run_cli("campaign", root, "--out", out, "--workers", "1", "--no-progress")
    assert rc == 2 and len(err.strip().splitlines()) == 1
    assert "'take'" in err and "mon/experiment.toml" in err and "tue/experiment.toml" in err
    assert not out.exists()


def test_campaign_links_follow_the_output_folder_not_the_name(tmp_path, run_cli):
    root = tmp_path / "lab"
    _track_experiment(root / "mon", "granite_a", 0.9)
    _track_experiment(root / "tue", "granite_b", 0.85)
    out = tmp_path / "out"
    rc, _, err = run_cli("campaign", root, "--out", out, "--workers", "1", "--no-progress")
    assert rc == 0, err
    md = (out / "summary.md").read_text()
    links = re.findall(r"\]\((experiments/[^)]+/report\.html)\)", md)
    assert len(links) == 2 and all((out / link).is_file() for link in links)
    # each link leads to its own experiment's report (its η_e, not the other's)
    for link, name in zip(sorted(links), ("granite_a", "granite_b")):
        rep = json.loads((out / link).parent.joinpath("report.json").read_text())
        assert rep["name"] == name


def _report(name, bid, contact, *, fit=None, half_cycles=None):
    blk = catalogue_block(bid)
    rep = {
        "name": name,
        "status": "ok",
        "block": {"name": bid, "b_m": blk.b_m, "h_m": blk.h_m, "eta_H": blk.eta_H},
        "contact": {"type": contact, "l_c_m": L_C if contact == "edge" else 0.0},
        "fit": fit,
    }
    if half_cycles is not None:
        rep["validation"] = {"eta_e": half_cycles}
    return {"config": f"{name}/experiment.toml", "out": f"out/{name}", "ok": True, "report": rep}


def test_a_base_excited_runs_half_cycle_eta_is_shown_but_not_pooled():
    # Čeh's η_mat (Eq. 16) and k (Eq. 18) are free-rocking quantities: a shake-table run's half-cycle
    # η_e is reported in its row, and the campaign fits come from the free runs alone
    from rocklab.pipelines import CampaignResult
    from rocklab.pipelines.campaign._campaign import _campaign_fits, _row

    truth = {
        b: eta_modified(catalogue_block(b).alpha_rad, edge_contact_k(catalogue_block(b).b_m, L_C)) * ETA_MAT
        for b in ("B3M", "B5M")
    }
    runs = [
        _report("B3M_edge", "B3M", "edge", fit={"eta_e": truth["B3M"], "ci95_eta_e": [truth["B3M"]] * 2}),
        _report("B5M_edge", "B5M", "edge", fit={"eta_e": truth["B5M"], "ci95_eta_e": [truth["B5M"]] * 2}),
        # a forced run whose half-cycle η is far off: pooling it would move η_mat by ~10 %
        _report("B5M_table", "B5M", "edge", half_cycles={"eta_e": 0.6, "ci95_eta_e": [0.59, 0.61], "status": "ok"}),
    ]
    table = pd.DataFrame([_row(r) for r in runs])
    assert list(table["eta_e_source"]) == ["free", "free", "half_cycles"]
    assert table["eta_e"].iloc[2] == pytest.approx(0.6) and table["ci_hi"].iloc[2] == pytest.approx(0.61)
    eta_mat, _ = _campaign_fits(table, [])
    assert eta_mat["eta_mat"] == pytest.approx(ETA_MAT, abs=1e-9)
    text = CampaignResult(out_dir=Path("out"), runs=runs, table=table).summary_text()
    assert "0.600" in text and "hc" in text.split("B5M_table")[1].splitlines()[0]


def test_campaign_groups_repeats_by_their_tags(tmp_path, run_cli):
    # Ther's repeat experiments (thesis Tables 2-3): configurations tagged in experiment.toml,
    # mean ± std per configuration. With a constant η the energy lost per rocking is exactly
    # 1 - η² (kinetic energy scales by η² at the impact, none is lost between impacts)
    from rocklab.pipelines.campaign import group_repeats
    from rocklab.pipelines.campaign._groups import campaign_tags, check_group_by

    root = tmp_path / "repeats"
    truth = {"a": 0.93, "b": 0.86}
    for i, (conf, tape) in enumerate((("a", "micropore"), ("a", "none"), ("b", "micropore"), ("b", "none"))):
        tags = f'[experiment]\ntags = {{ config = "{conf}", tape = "{tape}" }}\n'
        _exp(root, f"B6M_{conf}{i}", "B6M", "full", truth[conf], 20 + i, extra=tags)
    out = tmp_path / "out"
    # one process (the grouping is the subject; the pool is run by the test above)
    args = ("--group-by", "config", "--group-by", "config,tape", "--workers", "1", "--no-progress", "--json")
    rc, stdout, err = run_cli("campaign", root, "--out", out, *args)
    assert rc == 0, err
    groups = pd.read_csv(out / "groups.csv", keep_default_na=False, na_values=[""])
    assert list(dict.fromkeys(groups["group_by"])) == ["config", "config+tape"]
    by_conf = groups[groups["group_by"] == "config"].set_index("group")
    for conf, eta in truth.items():
        r = by_conf.loc[conf]
        assert r["n"] == 2 and r["eta_e_n"] == 2
        assert r["eta_e_mean"] == pytest.approx(eta, abs=0.003)
        assert 0 < r["eta_e_std"] < 0.003  # two noisy repeats: a spread, and a small one
        assert r["energy_loss_mean4_mean"] == pytest.approx(1 - eta**2, abs=0.01)
        assert r["eta_equivalent_mean"] == pytest.approx(eta, abs=0.005)
    combo = [g for g in json.loads(stdout)["groups"] if g["group_by"] == "config+tape"]
    assert sorted(g["group"] for g in combo) == ["a/micropore", "a/none", "b/micropore", "b/none"]
    assert all(g["n"] == 1 and g["eta_e_std"] is None for g in combo)  # one repeat: no spread, null in JSON
    md = (out / "summary.md").read_text(encoding="utf-8")
    assert "## Repeats by tag" in md and f"{by_conf.loc['a', 'eta_e_mean']:.4g}" in md
    tab = pd.read_csv(out / "campaign.csv")
    assert sorted(tab["tag_config"]) == ["a", "a", "b", "b"]
    rep = json.loads((out / "experiments" / "B6M_a0" / "report.json").read_text())
    assert rep["tags"] == {"config": "a", "tape": "micropore"}

    # without --group-by: one grouping per tag name; each tape holds one repeat of each
    # configuration, so its mean η_e lies halfway and its spread is the configurations' gap / √2
    groupings = check_group_by((), campaign_tags(sorted(root.rglob("experiment.toml"))), root)
    assert groupings == (("config",), ("tape",))
    by_tape = group_repeats(tab, groupings).query("group_by == 'tape'").set_index("group")
    assert by_tape.loc["micropore", "eta_e_mean"] == pytest.approx(np.mean(list(truth.values())), abs=0.003)
    assert by_tape.loc["none", "eta_e_std"] == pytest.approx(abs(truth["a"] - truth["b"]) / np.sqrt(2), abs=0.004)
    # a tag nobody carries: refused before any work, naming the tags there are
    rc, _, err = run_cli("campaign", root, "--out", tmp_path / "out3", "--group-by", "confg")
    assert rc == 2 and "'confg'" in err and "tags found: config, tape" in err and "Traceback" not in err
    assert not (tmp_path / "out3").exists()
