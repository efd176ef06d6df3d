"""Columns through ``rocklab run`` measured by one IMU per level, no film (thesis §4.2).

Fig. 29's set-up: two granite blocks 100 x 300 mm (200 mm thick), edges cut to a 96 mm contact,
the upper block released from φ2 = 0.153 rad, both measured by x-IMUs at 256 Hz. The session is
synthetic (the true model is the column model with one impact per closing), its IMU logs start at
different times, and the run must put them on one clock, read each level's start angle, and
judge the 1- and 2-impact models by their ensembles' event sequences.
"""

import json

import pytest

from rocklab import Block

FIG29_EVENTS_S = (0.13, 0.187, 0.193)  # thesis §4.2: lower joint opens, upper impacts, lower impacts


def _run(tmp_path_factory, name, **synth):
    from rocklab.pipelines.experiment._experiment import run_experiment
    from rocklab.synth import synth_session

    d = tmp_path_factory.mktemp(name)
    synth_session(d / "s", table="none", video=False, **synth)
    with open(d / "s" / "experiment.toml", "a") as f:
        f.write("\n[output]\nrrd = false\n")
    rep, _ = run_experiment(d / "s" / "experiment.toml", d / "out")
    return rep, json.loads((d / "s" / "session.json").read_text()), d / "out"


@pytest.fixture(scope="module")
def fig29_run(tmp_path_factory):
    granite = [Block(0.1, 0.3, depth_m=0.2, density_kg_m3=2700.0, name=f"block_{i + 1}") for i in range(2)]
    return _run(
        tmp_path_factory, "fig29", seed=3, blocks=2, block=granite, theta0_rad=[0.0, -0.153], column_cut_m=0.002
    )


def test_fig29_three_events_through_run(fig29_run):
    rep, meta, _ = fig29_run
    col = rep["column"]
    assert col["source"] == "imu" and rep["status"] == "ok"
    # each level's start angle read from its IMU at rest (counter-clockwise), the lower one flat
    assert col["theta0_rad"][0] == 0.0 and abs(col["theta0_rad"][1] + 0.153) < 1e-3
    # the lower IMU put on the upper's clock by the impacts: its offset is the logs' start difference
    true = meta["imu"]["block_2"]["t0_video_s"] - meta["imu"]["block_1"]["t0_video_s"]
    assert abs(col["imu_clocks"][0]["offset_s"] - true) < 1e-3  # measured 0.0 ms
    ev = col["model_events"]
    opens = next(e for e in ev if e["joint"] == 0 and e["event"] == "opening")
    upper = next(e for e in ev if e["joint"] == 1 and e["event"] == "impact")
    lower = next(e for e in ev if e["joint"] == 0 and e["event"] == "impact")
    times = (opens["t_from_start_s"], upper["t_from_start_s"], lower["t_from_start_s"])
    # the lower block turns clockwise, the upper comes back counter-clockwise (thesis §4.2)
    assert opens["state"] == "cw" and upper["state"] == "ccw" and lower["state"] == "ccw"
    assert max(abs(a - b) for a, b in zip(times, FIG29_EVENTS_S)) < 0.01  # measured 0.0056, 0.0037, 0.0006
    # the release found in the upper IMU, against the truth's (on the upper log's clock)
    rel_true = meta["blocks"][1]["release_s"] - meta["imu"]["block_2"]["t0_video_s"]
    assert abs(col["start_t_s"] - rel_true) < 2e-3


def test_fig29_true_model_consistent_bump_model_not(fig29_run):
    rep, _, out = fig29_run
    val = rep["validation"]
    assert val["reference_law"] == "impacts_1" and set(val["laws"]) == {"impacts_1", "impacts_2"}
    true, bump = val["laws"]["impacts_1"], val["laws"]["impacts_2"]
    assert true["verdict"] == "consistent" and true["n_events_inside"] >= 4  # measured 6
    assert true["n_matched_inside"] == true["n_events_inside"]
    assert true["band_coverage"] > bump["band_coverage"] + 0.3  # measured 1.0 against 0.29
    # one mid-joint bump per closing loses less energy: its later openings come at other times
    assert bump["verdict"] == "inconsistent" and bump["n_matched_inside"] < bump["n_events_inside"]
    assert bump["score"] < true["score"]
    ser = __import__("pandas").read_csv(out / "series.csv")
    for o in ("block_1", "block_2"):
        assert f"theta_{o}_imu_rad" in ser and f"theta_{o}_sim_column_p05_rad" in ser
    assert "impacts_1" in (out / "summary.md").read_text()


@pytest.fixture(scope="module")
def mixed_run(tmp_path_factory):
    # two different granite blocks, the narrower upper one held tilted: the true model is known exactly
    blocks = [
        Block(0.12, 0.30, depth_m=0.2, density_kg_m3=2700.0, name="block_1"),
        Block(0.08, 0.22, depth_m=0.2, density_kg_m3=2700.0, name="block_2"),
    ]
    return _run(tmp_path_factory, "mixed", seed=5, blocks=2, block=blocks, theta0_rad=[0.0, -0.12])


def test_different_blocks_true_model_consistent(mixed_run):
    rep, meta, _ = mixed_run
    col = rep["column"]
    assert [(b["b_m"], b["h_m"]) for b in col["blocks"]] == [(0.12, 0.30), (0.08, 0.22)]
    assert col["theta0_rad"][0] == 0.0 and abs(col["theta0_rad"][1] + 0.12) < 2e-3
    true_offset = meta["imu"]["block_2"]["t0_video_s"] - meta["imu"]["block_1"]["t0_video_s"]
    assert abs(col["imu_clocks"][0]["offset_s"] - true_offset) < 2e-3  # measured 0.7 ms
    laws = rep["validation"]["laws"]
    true, bump = laws["impacts_1"], laws["impacts_2"]
    assert true["verdict"] == "consistent" and true["n_events_inside"] >= 4  # measured 6 of 6
    assert true["n_matched_inside"] == true["n_events_inside"]
    assert bump["verdict"] == "inconsistent"  # measured 1 of 8 matched
    # the nominal model's events are the truth's (same model, the measured start angles)
    t_rel = meta["blocks"][0]["release_s"]
    truth = [(e["t_s"] - t_rel, e["joint"], e["event"]) for e in meta["blocks"][0]["column_events"]][:3]
    model = [(e["t_from_start_s"], e["joint"], e["event"]) for e in col["model_events"]][:3]
    assert [m[1:] for m in model] == [t[1:] for t in truth]
    assert max(abs(m[0] - t[0]) for m, t in zip(model, truth)) < 0.01


def test_column_keys_read_written_and_checked(tmp_path):
    from rocklab import InputError
    from rocklab.config import load_experiment_config

    for o in ("a", "b"):
        (tmp_path / "imu" / o).mkdir(parents=True)
    base = '[block]\nb_m = 0.1\nh_m = 0.3\n[sources.table]\nfrom = "none"\n[column]\nobjects = ["a", "b"]\n'
    good = base + 'imu = ["imu/a", "imu/b"]\nimu_axis = "-y"\nb_m = [0.12, 0.08]\ntheta0_rad = [0.0, -0.1]\n'
    p = tmp_path / "experiment.toml"
    p.write_text(good)
    cfg = load_experiment_config(p)
    assert [b.b_m for b in cfg.column_blocks()] == [0.12, 0.08] and [b.h_m for b in cfg.column_blocks()] == [0.3, 0.3]
    assert cfg.column_imus == (tmp_path / "imu" / "a", tmp_path / "imu" / "b") and cfg.primary == "imu"
    p.write_text(cfg.to_toml())  # written through the schema, read back the same
    assert load_experiment_config(p) == cfg
    bad = {
        'imu = ["imu/a", "imu/b"]\nimu_axis = "auto"\n': "'column.imu_axis'",
        'imu = ["imu/a"]\nimu_axis = "y"\n': "one per \\[column\\] object",
        'imu = ["imu/a", "imu/c"]\nimu_axis = "y"\n': "does not exist",
        'imu = ["imu/a", "imu/b"]\nimu_axis = "y"\nb_m = [0.1, 0.1, 0.1]\n': "3 values for 2",
        'imu = ["imu/a", "imu/b"]\nimu_axis = "y"\nb_m = [0.1, 0.004]\ncut_m = 0.002\n': "half the narrowest",
        "cut_m = 0.0\n": "needs at least one of",
    }
    for extra, msg in bad.items():
        p.write_text(base + extra)
        with pytest.raises(InputError, match=msg):
            load_experiment_config(p)
