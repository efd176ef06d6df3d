"""``rocklab run`` end to end on a synthetic track CSV with known truth."""

import json

import numpy as np
import pandas as pd
import pytest

from rocklab import Block
from rocklab.models import simulate
from rocklab.pipelines import read_rrd_scalars, read_rrd_summary

ETA_TRUE = 0.93
FPS = 150.0


def _session(tmp_path, seed=0, eta=ETA_TRUE, contact="full"):
    blk = Block(0.045, 0.2025)
    theta0 = 0.8 * blk.alpha_rad
    sim = simulate(blk, theta0_rad=theta0, duration_s=8.0, restitution="constant", eta=eta)
    t_rel = 0.5
    t = np.arange(0, 8.0, 1 / FPS)
    th = np.where(t < t_rel, theta0, np.interp(t - t_rel, sim.t_s, sim.theta_rad))
    rng = np.random.default_rng(seed)
    th_meas = th + rng.normal(0, np.radians(0.02), t.size)
    d = tmp_path / "exp"
    d.mkdir()
    pd.DataFrame({"t_s": t, "object": "block_1", "theta_rad": th_meas}).to_csv(d / "tracks.csv", index=False)
    pd.DataFrame({"frame": np.arange(t.size), "t_s": t, "object": "block_1", "theta_rad": th}).to_csv(
        d / "truth.csv", index=False
    )
    (d / "session.json").write_text(json.dumps({"eta": eta}))
    extra = '[contact]\ntype = "edge"\nl_c_m = 0.0015\n' if contact == "edge" else ""
    (d / "experiment.toml").write_text(
        f'name = "b6m_{contact}"\ntruth = "truth.csv"\n[block]\nid = "B6M"\n{extra}'
        '[sources.track]\npath = "tracks.csv"\nobject = "block_1"\n[output]\nrrd = true\n'
    )
    return d / "experiment.toml"


def _series_styles(rrd):
    """Entity → (RGBA, width, name) of every static SeriesLines style in a recording."""
    import rerun.chunk as rc

    out = {}
    for ch in rc.RrdReader(str(rrd)).stream().collect().stream():
        if not ch.is_static:
            continue
        rb = ch.to_record_batch()
        cols = {
            n.split(":")[-1]: rb.column(i).to_pylist()[0]
            for i, n in enumerate(rb.schema.names)
            if n.startswith("SeriesLines:")
        }
        if "colors" in cols:
            c = int(cols["colors"][0])
            out[str(ch.entity_path)] = (
                [(c >> 24) & 255, (c >> 16) & 255, (c >> 8) & 255, c & 255],
                float((cols.get("widths") or [0.0])[0]),
                (cols.get("names") or [""])[0],
            )
    return out


def test_run_writes_report_figures_and_rrd(tmp_path, run_cli):
    cfg = _session(tmp_path)
    out = tmp_path / "out"
    rc, stdout, err = run_cli("run", cfg, "--out", out, "--json")
    assert rc == 0, err
    js = json.loads(stdout)
    assert js["ran"] is True
    rep = json.loads((out / "report.json").read_text())
    # the catalogue id resolved to Čeh Table 2's B6M
    assert rep["block"]["b_m"] == pytest.approx(0.045) and rep["block"]["mass_kg"] == pytest.approx(1.0896)
    assert rep["fit"]["eta_e"] == pytest.approx(ETA_TRUE, abs=0.002)
    lo, hi = rep["fit"]["ci95_eta_e"]
    assert lo < rep["fit"]["eta_e"] < hi
    # the eta_e simulation reproduces the measured response much better than Housner's
    sims = rep["simulations"]
    assert sims["eta_e"]["rms_vs_measured_rad"] < 0.2 * sims["housner"]["rms_vs_measured_rad"]
    assert sims["housner"]["eta"] == pytest.approx(Block(0.045, 0.2025).eta_H)
    assert rep["truth"]["theta_rms_error_rad"] == pytest.approx(np.radians(0.02), rel=0.2)
    assert rep["versions"]["rocklab"] and rep["units"]["theta"] == "rad"
    for f in (
        "summary.md",
        "report.html",
        "series.csv",
        "figures/theta.png",
        "figures/per_impact_eta.png",
        "session.rrd",
    ):
        assert (out / f).is_file(), f
    md, html = (out / "summary.md").read_text(encoding="utf-8"), (out / "report.html").read_text(encoding="utf-8")
    assert f"η_e = {rep['fit']['eta_e']:.4g}" in md and f"η_e = {rep['fit']['eta_e']:.4g}" in html
    assert html.count("data:image/png;base64,") == len(rep["outputs"]["figures"]) >= 2
    ser = pd.read_csv(out / "series.csv")
    assert {"t_s", "theta_track_rad", "theta_sim_eta_e_rad", "theta_truth_rad"} <= set(ser.columns)

    rows = read_rrd_summary(out / "session.rrd")
    n_ok = int(np.isfinite(ser["theta_track_rad"]).sum())
    assert rows["/experiment/block_1/theta/measured_track"] == n_ok + 1  # + static series style
    assert "/experiment/block_1/theta/sim_eta_e" in rows and "/experiment/block_1/impacts" in rows
    tt, vv = read_rrd_scalars(out / "session.rrd", "experiment/block_1/theta/measured_track")
    assert np.allclose(vv, ser["theta_track_rad"].to_numpy()[np.isfinite(ser["theta_track_rad"])])
    td, vd = read_rrd_scalars(out / "session.rrd", "experiment/block_1/theta_deg/measured_track")
    assert np.allclose(td, tt) and np.allclose(vd, np.degrees(vv), rtol=1e-12)  # θ also in degrees
    # measured bold and dark, each simulation its own colour and named with its η
    styles = _series_styles(out / "session.rrd")
    colour, width, _ = styles["/experiment/block_1/theta/measured_track"]
    assert max(colour[:3]) <= 60 and width >= 2.5
    sims = {k: v for k, v in styles.items() if "/theta/sim_" in k}
    assert len(sims) >= 3 and len({tuple(c[:3]) for c, _, _ in sims.values()}) == len(sims)
    assert all(w < width for _, w, _ in sims.values())
    eta_e = rep["simulations"]["eta_e"]["eta"]
    assert styles["/experiment/block_1/theta/sim_eta_e"][2] == f"sim eta_e (η = {eta_e:.4g})"

    # unchanged inputs: a no-op; --force re-runs
    mtime = (out / "report.json").stat().st_mtime_ns
    rc, stdout, _ = run_cli("run", cfg, "--out", out)
    assert rc == 0 and "nothing to do" in stdout and (out / "report.json").stat().st_mtime_ns == mtime
    rc, _, _ = run_cli("run", cfg, "--out", out, "--force")
    assert rc == 0 and (out / "report.json").stat().st_mtime_ns != mtime


def test_run_bad_config_leaves_nothing(tmp_path, run_cli):
    cfg = _session(tmp_path)
    cfg.write_text(cfg.read_text().replace('id = "B6M"', 'id = "B66X"'))
    out = tmp_path / "out"
    rc, _, err = run_cli("run", cfg, "--out", out)
    assert rc == 2 and "line 4" in err and "B66X" in err and len(err.strip().splitlines()) == 1
    assert not out.exists() and not [p for p in tmp_path.iterdir() if p.name.startswith(".out")]


def test_failing_stage_leaves_previous_output_intact(tmp_path, run_cli, monkeypatch):
    cfg = _session(tmp_path)
    out = tmp_path / "out"
    assert run_cli("run", cfg, "--out", out)[0] == 0
    before = (out / "report.json").read_text()
    import rocklab.pipelines.experiment._experiment as E
    import rocklab.pipelines.experiment._report as R

    def boom(*a, **k):
        raise RuntimeError("figure backend exploded")

    monkeypatch.setattr(R, "series_frame", boom)
    with pytest.raises(RuntimeError):
        E.run_experiment(cfg, out, force=True)
    assert (out / "report.json").read_text() == before
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out")]


def test_summary_numbers_for_people(tmp_path, run_cli):
    """summary.md shows 4 significant digits (it printed '95 % CI 0.9139585433325578 – ...')."""
    import re

    cfg = _session(tmp_path)
    out = tmp_path / "o"
    assert run_cli("run", cfg, "--out", out)[0] == 0
    text = (out / "summary.md").read_text()
    assert "95 % CI" in text

    def significant(num):
        return len(num.replace(".", "").lstrip("0"))

    long_numbers = [x for x in re.findall(r"\d+\.\d+", text) if significant(x) > 4]
    assert long_numbers == [], long_numbers


@pytest.mark.parametrize("status, code", [("ok", 0), ("suspect", 0), ("partial", 1), ("failed", 1)])
def test_run_exit_status_follows_the_report(monkeypatch, tmp_path, run_cli, status, code):
    """A run whose restitution fit failed reports "partial": exit 1, as the README documents
    (it exited 0)."""
    import rocklab.pipelines.experiment as exp

    cfg = tmp_path / "experiment.toml"
    cfg.write_text("")
    report = {"name": "t", "status": status, "fit": {"eta_e": None}}
    monkeypatch.setattr(exp, "run_experiment", lambda *a, **k: (report, True))
    rc, out, _ = run_cli("run", cfg, "--out", tmp_path / "out")
    assert rc == code and f"t: {status}" in out


def test_free_rocking_report_gives_the_energy_loss_of_eq12(tmp_path, run_cli):
    """Ther's Eq. 12 in report.json and summary.md: with a constant η every rocking loses 1 − η²
    of its energy (kinetic energy scales by η² at an impact, the peaks' rise carries it)."""
    from rocklab.fitting import catalogue_block
    from rocklab.models import simulate

    eta = 0.9
    blk = catalogue_block("B5M")
    theta0 = 0.8 * blk.alpha_rad
    sim = simulate(blk, theta0_rad=theta0, duration_s=4.0, restitution="constant", eta=eta)
    t = np.arange(0, 4.0, 1 / 200)
    th = np.where(t < 0.3, theta0, np.interp(t - 0.3, sim.t_s, sim.theta_rad))
    pd.DataFrame({"t_s": t, "theta_rad": th}).to_csv(tmp_path / "tracks.csv", index=False)
    (tmp_path / "experiment.toml").write_text(
        'name = "eq12"\n[block]\nid = "B5M"\n[sources.track]\npath = "tracks.csv"\n[output]\nrrd = false\nfigures = false\n'
    )
    rc, _, err = run_cli("run", tmp_path / "experiment.toml", "--out", tmp_path / "out")
    assert rc == 0, err
    e = json.loads((tmp_path / "out" / "report.json").read_text())["energy_loss"]
    assert e["exact_rise"] and len(e["loss_per_rocking"]) >= 4
    assert np.allclose(e["loss_per_rocking"][:4], 1 - eta**2, atol=0.01)
    assert e["eta_equivalent"] == pytest.approx(eta, abs=0.005)
    assert "Eq. 12" in (tmp_path / "out" / "summary.md").read_text()


def test_the_thesis_contact_laws_are_simulated_from_experiment_toml(tmp_path, run_cli):
    """[simulate] laws takes the thesis's App. A laws with their geometry (Eq. A3-A7)."""
    from rocklab.fitting import catalogue_block
    from rocklab.models import eta_axes, eta_bumps

    blk = catalogue_block("B5M")
    theta0 = 0.8 * blk.alpha_rad
    sim = simulate(blk, theta0_rad=theta0, duration_s=3.0, restitution="constant", eta=0.9)
    t = np.arange(0, 3.0, 1 / 200)
    th = np.where(t < 0.3, theta0, np.interp(t - 0.3, sim.t_s, sim.theta_rad))
    pd.DataFrame({"t_s": t, "theta_rad": th}).to_csv(tmp_path / "tracks.csv", index=False)
    b2 = 0.4 * blk.b_m
    text = (
        'name = "appA"\n[block]\nid = "B5M"\n[sources.track]\npath = "tracks.csv"\n'
        f'[simulate]\nlaws = ["housner", "cut_corner", "bumps", "axes"]\nbumps = 2\nb2_m = {b2}\n'
        f"x1_m = {-0.5 * blk.b_m}\nx2_m = {0.25 * blk.b_m}\n[output]\nrrd = false\nfigures = false\n"
    )
    (tmp_path / "experiment.toml").write_text(text)
    rc, _, err = run_cli("run", tmp_path / "experiment.toml", "--out", tmp_path / "out")
    assert rc == 0, err
    sims = json.loads((tmp_path / "out" / "report.json").read_text())["simulations"]
    assert sims["cut_corner"]["eta"] == pytest.approx(eta_axes(blk, -b2, b2), rel=1e-12)
    assert sims["bumps"]["eta"] == pytest.approx(eta_bumps(blk, 2, b2), rel=1e-12)
    assert sims["axes"]["eta"] == pytest.approx(eta_axes(blk, -0.5 * blk.b_m, 0.25 * blk.b_m), rel=1e-12)
    # more contact lines lose less (thesis Fig. 12): the bumps' η lies above the cut corner's
    assert sims["housner"]["eta"] < sims["cut_corner"]["eta"] < sims["bumps"]["eta"] < 1
    (tmp_path / "experiment.toml").write_text(text.replace("bumps = 2", "bumps = -1"))
    rc, _, err = run_cli("run", tmp_path / "experiment.toml", "--out", tmp_path / "out2")
    assert rc == 2 and "simulate.bumps" in err and "line 8" in err
