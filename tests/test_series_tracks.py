"""``tracks.csv`` has one definition (rocklab.series): one reader, one writer, one status rule,
so ``rocklab fit restitution`` and ``rocklab run`` fit the same samples of the same file."""

import json

import numpy as np
import pandas as pd
import pytest

from rocklab import Block, InputError
from rocklab.models import simulate
from rocklab.series import TRACK3D_COLUMNS, TRACK_COLUMNS, USABLE_STATUSES, TableMotion, read_tracks, write_tracks

FPS = 100.0
ETA = 0.9


def _rows(n, obj="block_1", t0=0.0, extra3d=False, seed=0):
    rng = np.random.default_rng(seed)
    t = t0 + np.arange(n) / FPS
    cols = {
        "frame": np.arange(n),
        "t_s": t,
        "object": obj,
        "x_px": rng.normal(size=n),
        "y_px": rng.normal(size=n),
        "x_m": rng.normal(size=n),
        "y_m": rng.normal(size=n),
        "theta_rad": rng.normal(0, 0.05, n),
        "sigma_theta_rad": np.full(n, 1e-3),
        "quality": np.ones(n),
        "status": np.array(["ok"] * n, dtype=object),
    }
    if extra3d:
        for c in TRACK3D_COLUMNS[len(TRACK_COLUMNS) :]:
            cols[c] = rng.normal(size=n)
    return pd.DataFrame(cols)


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
@pytest.mark.parametrize("extra3d", [False, True])
def test_write_then_read_gives_the_same_rows(tmp_path, suffix, extra3d):
    # absolute times (epoch seconds) at 100 fps: 9 digits would merge every sample into a few times
    df = _rows(50, t0=1.7e9 + 0.123456, extra3d=extra3d)
    df.loc[[3, 7], "status"] = ["lost", "dropped"]
    df.loc[[3, 7], ["x_m", "y_m", "theta_rad"]] = np.nan
    p = write_tracks(tmp_path / f"tracks{suffix}", df)
    back = read_tracks(p)
    assert back.is_3d == extra3d
    assert np.array_equal(back.column("t_s"), df["t_s"].to_numpy(float))  # exact
    assert np.unique(back.column("t_s")).size == 50
    got, want = back.column("theta_rad"), df["theta_rad"].to_numpy(float)
    assert np.allclose(got, want, rtol=1e-8, atol=0, equal_nan=True)
    assert list(back.frame["status"]) == list(df["status"])
    assert back.column("line")[0] == 2  # line 1 is the header


def test_writer_refuses_rows_of_another_layout(tmp_path):
    df = _rows(5).drop(columns=["quality"])
    with pytest.raises(ValueError, match="TRACK_COLUMNS"):
        write_tracks(tmp_path / "tracks.csv", df)
    assert not (tmp_path / "tracks.csv").exists()


def test_usable_rows_follow_the_status_not_the_value(tmp_path):
    df = _rows(8)
    # every status but ok/corrected is unusable even where the row holds a number
    df["status"] = ["ok", "corrected", "interpolated", "low_quality", "outlier", " OK ", "lost", "ok"]
    df.loc[7, "theta_rad"] = np.nan  # ok but no value: unusable too
    p = write_tracks(tmp_path / "tracks.csv", df)
    rows = read_tracks(p).rows("block_1")
    assert rows.usable().tolist() == [True, True, False, False, False, True, False, False]
    t, th = rows.theta()
    assert t.size == 8 and np.isnan(th[[2, 3, 4, 6, 7]]).all()
    assert np.allclose(th[[0, 1, 5]], df["theta_rad"].to_numpy(float)[[0, 1, 5]], rtol=1e-8, atol=0)
    assert set(USABLE_STATUSES) == {"ok", "corrected"}


def test_the_block_is_picked_or_named(tmp_path):
    df = pd.concat([_rows(4, "table"), _rows(4, "block_1")], ignore_index=True)
    p = write_tracks(tmp_path / "tracks.csv", df)
    tr = read_tracks(p)
    assert tr.block_id() == "block_1"  # the only object that is not the table
    assert tr.rows().column("frame").tolist() == [0, 1, 2, 3]
    assert (tr.rows("table").frame["object"] == "table").all()
    with pytest.raises(InputError, match=r"object 'block_2' not in the file.*fix \[sources.track\] object"):
        tr.rows("block_2", fix="[sources.track] object")
    two = write_tracks(tmp_path / "two.csv", pd.concat([df, _rows(4, "block_2")], ignore_index=True))
    with pytest.raises(InputError, match="several objects"):
        read_tracks(two).rows()


def test_reader_names_the_missing_column(tmp_path):
    p = tmp_path / "t.csv"
    pd.DataFrame({"t_s": [0.0, 0.1], "angle": [0.0, 0.1]}).to_csv(p, index=False)
    with pytest.raises(InputError, match=r"t\.csv, line 1: missing column\(s\) \['theta_rad'\]"):
        read_tracks(p)


def test_table_motion_from_acceleration_has_no_displacement():
    t = np.arange(200) / 200.0
    a = np.sin(2 * np.pi * 3 * t)
    tm = TableMotion.from_acceleration(t + 5.0, a, source="imu")
    assert tm.x_m is None and list(tm.columns()) == ["acc_m_s2"]
    bm = tm.to_base_motion()
    assert bm.t_s[0] == 0.0 and bm.dt_s == pytest.approx(1 / 200.0)
    assert np.array_equal(bm.acc_m_s2, a)


def _session(tmp_path):
    """A free-rocking track of block_1 (and a still table) with frames lost, dropped, corrected,
    interpolated and of low quality; the not-usable rows hold wrong numbers, not NaN."""
    blk = Block(0.1, 0.2)
    theta0 = 0.7 * blk.alpha_rad
    sim = simulate(blk, theta0_rad=theta0, duration_s=5.0, restitution="constant", eta=ETA)
    t_rel = 0.4
    t = np.arange(0, 5.0, 1 / FPS)
    th = np.where(t < t_rel, theta0, np.interp(t - t_rel, sim.t_s, sim.theta_rad))
    th = th + np.random.default_rng(3).normal(0, np.radians(0.02), t.size)
    df = _rows(t.size)
    df["t_s"], df["theta_rad"] = t, th
    status = np.array(["ok"] * t.size, dtype=object)
    k = np.arange(t.size)
    for every, start, what in ((23, 61, "interpolated"), (29, 70, "low_quality"), (31, 90, "outlier")):
        sel = (k >= start) & (k < 300) & ((k - start) % every == 0)
        status[sel] = what
        df.loc[sel, "theta_rad"] = th[sel] + 0.03  # a number, but a wrong one
    status[150:153] = "lost"
    status[200:202] = "dropped"
    df.loc[np.isin(status, ("lost", "dropped")), "theta_rad"] = np.nan
    status[[120, 260]] = "corrected"  # vouched for by hand: kept
    df["status"] = status
    table = _rows(t.size, "table")
    table["t_s"], table["theta_rad"] = t, 0.0
    d = tmp_path / "exp"
    d.mkdir()
    write_tracks(d / "tracks.csv", pd.concat([table, df], ignore_index=True))
    (d / "experiment.toml").write_text(
        'name = "same-samples"\n[block]\nb_m = 0.1\nh_m = 0.2\n'
        '[sources.track]\npath = "tracks.csv"\nobject = "block_1"\n[output]\nrrd = false\n'
    )
    return d, int(np.sum(~np.isin(status, USABLE_STATUSES)))


def test_fit_and_run_fit_the_same_samples(tmp_path, run_cli):
    d, n_bad = _session(tmp_path)
    assert n_bad > 20
    rc, out, err = run_cli(
        "fit", "restitution", d / "tracks.csv", "--width", "0.1", "--height", "0.2", "--nan", "skip", "--json"
    )
    assert rc == 0, err
    fit = json.loads(out)
    assert fit["n_skipped"] == n_bad
    rc, out, err = run_cli("run", d / "experiment.toml", "--out", tmp_path / "out", "--json")
    rep = json.loads((tmp_path / "out" / "report.json").read_text())
    assert rep["fit"]["status"] == fit["status"] == "ok"
    assert f"{n_bad} samples of the track" in " ".join(rep["messages"])
    for key in ("eta_e", "theta0_rad", "release_t_s", "rms_residual_rad"):
        assert rep["fit"][key] == pytest.approx(fit[key], rel=1e-9, abs=1e-12), key
    per = [np.array(x["per_impact_eta"], dtype=float) for x in (rep["fit"], fit)]  # null: no eta there
    np.testing.assert_allclose(per[0], per[1], rtol=1e-9, equal_nan=True)
    assert abs(fit["eta_e"] - ETA) < 0.02  # and the samples they share are the right ones


def test_reader_refuses_a_damaged_table(tmp_path):
    p = tmp_path / "tracks.parquet"
    p.write_bytes(b"PAR1 not really parquet")
    with pytest.raises(InputError, match=r"tracks\.parquet: not a readable table"):
        read_tracks(p)


def test_experiment_stages_are_objects_until_the_report(tmp_path):
    from rocklab.pipelines.experiment import analyse_experiment, load_experiment
    from rocklab.pipelines.experiment._stages import FitStage, LawSimulation

    d, n_bad = _session(tmp_path)
    res = analyse_experiment(load_experiment(d / "experiment.toml"))
    assert isinstance(res.fit, FitStage) and not res.fit.forced
    assert all(isinstance(s, LawSimulation) for s in res.simulations.values())
    th0, t_rel = res.fit.release()
    assert abs(t_rel - 0.4) < 0.02 and abs(res.fit.eta_e - ETA) < 0.02
    # the eta_e law simulates with the fitted value and starts at the fitted release
    sim = res.simulations["eta_e"]
    assert sim.eta == res.fit.eta_e and sim.t_s[0] == pytest.approx(t_rel, abs=1e-12)
    assert sim.theta_rad[0] == pytest.approx(th0, abs=1e-12)
    rep = res.to_dict()
    assert rep["fit"]["eta_e"] == res.fit.eta_e and rep["fit"]["excluded_impacts"] == []
    np.testing.assert_array_equal(rep["per_impact_eta"], res.fit.fit.per_impact_eta)  # NaN where none
    assert rep["simulations"]["eta_e"]["n_impacts"] == len(sim.impacts) > 10
    assert rep["table"] is None and rep["sync"] is None and rep["audit"]["verdict"] == res.audit.verdict


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    """A rendered free-rocking session (``rocklab synth``) whose target is hidden for two frames
    (filled by interpolation, asked for in track.toml), with a frame dropped and one corrected by
    hand, tracked to tracks.csv."""
    from rocklab.pipelines import main

    root = tmp_path_factory.mktemp("rendered")
    s = root / "s"
    argv = ["synth", "--out", s, "--seed", 5, "--size", "480x270", "--no-imu", "--occlusion", "0.82,0.86"]
    assert main([str(a) for a in argv]) == 0
    toml = s / "track.toml"
    text = toml.read_text()
    assert "interpolate_max_gap_frames = 0" in text
    toml.write_text(text.replace("interpolate_max_gap_frames = 0", "interpolate_max_gap_frames = 8"))
    (root / "fix.csv").write_text(
        "object,frame,to_frame,t_s,to_t_s,action,theta_rad\nblock_1,35,,,,drop,\nblock_1,60,,,,,0.05\n"
    )
    argv = ["track", s / "video.mkv", "--config", toml, "-o", root / "tracks.csv", "--corrections", root / "fix.csv"]
    assert main([str(a) for a in argv]) == 0
    for src in ("track", "video"):
        (s / f"exp_{src}.toml").write_text(
            f'name = "{src}"\n[block]\nb_m = 0.1\nh_m = 0.2\n[sources]\nprimary = "{src}"\n'
            '[sources.track]\npath = "../tracks.csv"\nobject = "block_1"\n'
            '[sources.video]\npath = "video.mkv"\ntrack_config = "track.toml"\nobject = "block_1"\n'
            'corrections = "../fix.csv"\n[output]\nrrd = false\nfigures = false\n'
        )
    return root


def test_fit_and_run_use_the_same_samples_of_a_rendered_session(rendered, run_cli):
    status = read_tracks(rendered / "tracks.csv").rows("block_1").frame["status"].value_counts().to_dict()
    assert status["interpolated"] >= 2 and status["dropped"] == 1 and status["corrected"] == 1
    n_bad = status["interpolated"] + status["dropped"]
    rc, out, err = run_cli(
        "fit", "restitution", rendered / "tracks.csv", "--width", 0.1, "--height", 0.2, "--nan", "skip", "--json"
    )
    fit = json.loads(out)
    assert rc == 0 and fit["status"] == "ok" and fit["n_skipped"] == n_bad, err
    assert abs(fit["eta_e"] - 0.75) < 0.02  # the session's true eta
    for src, rel in (("track", 1e-12), ("video", 1e-8)):  # tracks.csv holds 9 significant digits
        run_cli("run", rendered / "s" / f"exp_{src}.toml", "--out", rendered / f"out_{src}")
        rep = json.loads((rendered / f"out_{src}" / "report.json").read_text())["fit"]
        assert rep["n_skipped"] == n_bad, src  # the interpolated samples are not fitted by either
        for key in ("eta_e", "theta0_rad", "release_t_s"):
            assert rep[key] == pytest.approx(fit[key], rel=rel), (src, key)
