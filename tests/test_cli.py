import pytest


def test_unknown_option_exit_2(run_cli):
    with pytest.raises(SystemExit) as e:
        run_cli("simulate", "--no-such-flag")
    assert e.value.code == 2


def test_no_command_prints_help_and_exit_2(run_cli):
    rc, out, _ = run_cli()
    assert rc == 2 and "demo" in out and "campaign" in out


def test_demo_sessions_carry_the_stated_truth(tmp_path):
    """The demo's synthetic runs: edge-contact truth is η_M(k = 1 − 2 l_c/b)·η_mat (Čeh Eq. 14, 16),
    full-contact truth is Čeh Table 3, and the configs name the run and contact."""
    import json

    from rocklab.fitting import catalogue_block, edge_contact_k, eta_modified
    from rocklab.pipelines import load_experiment
    from rocklab.pipelines import make_demo_campaign
    from rocklab.pipelines.campaign._demo import ETA_MAT_TRUE, L_C_M

    runs = (("B3M_edge", "B3M", "edge", "none"), ("B5M_full", "B5M", "full", "none"))
    # the configs and the truths are the subject, not the films: small frames, one process
    cfgs = make_demo_campaign(tmp_path, size=(160, 90), progress=False, runs=runs, workers=1)
    edge, full = (load_experiment(c) for c in cfgs)
    assert edge.name == "B3M_edge" and edge.contact == "edge" and edge.l_c_m == L_C_M
    assert edge.block_id == "B3M" and edge.video_decimation == 5
    b3 = catalogue_block("B3M")
    eta_edge = json.loads((cfgs[0].parent / "session.json").read_text())["blocks"][0]["eta_true"]
    # k = 1 - 2*1.5/45 = 0.9333 (Čeh Table 4, medium scale) -> η_M(α = 0.4182) = 0.7897
    assert edge_contact_k(b3.b_m, L_C_M) == pytest.approx(0.93333, abs=1e-5)
    assert eta_edge == pytest.approx(float(eta_modified(b3.alpha_rad, 0.933333)) * ETA_MAT_TRUE, abs=1e-5)
    eta_full = json.loads((cfgs[1].parent / "session.json").read_text())["blocks"][0]["eta_true"]
    assert full.contact == "full" and eta_full == pytest.approx(0.914)  # Čeh Table 3, B5M
    # the runs read the camcorder-like H.264 film, as a lab's footage is; --lossless the FFV1 one
    assert edge.video.path.name == "video.mp4" and edge.video.path.is_file()
    (lossless,) = make_demo_campaign(
        tmp_path / "lossless", size=(160, 90), progress=False, runs=runs[:1], camcorder=False
    )
    assert load_experiment(lossless).video.path.name == "video.mkv"


def test_demo_column_is_driven_by_its_table_imu(tmp_path):
    """The demo's column reads its table from the table IMU (fused with the film's table: 5.0 % ->
    1.3 % RMS error on the demo), not from a block's IMU, and that log runs until the column is at
    rest (plus 1 s) so that the IMU's drift is anchored."""
    import json

    from rocklab.pipelines import load_experiment, make_demo_campaign
    from rocklab.tracking import read_imu

    (cfg_path,) = make_demo_campaign(
        tmp_path, size=(320, 180), progress=False, runs=(("col", "column", "full", "sine"),)
    )
    cfg = load_experiment(cfg_path)
    assert cfg.columns == ("block_1", "block_2", "block_3") and cfg.imu is None
    assert cfg.table.source == "imu" and cfg.table.imu == (cfg_path.parent / "imu" / "table").resolve()
    meta = json.loads((cfg_path.parent / "session.json").read_text())
    col = meta["blocks"][0]
    assert col["sim_status"] == "rest" and col["column_status_t_s"] > meta["duration_s"]  # rests at 10.8 s, film 4 s
    log = read_imu(cfg.table.imu)
    t_end = meta["imu"]["table"]["t0_video_s"] + log.t_s[-1]
    assert abs(t_end - (col["column_status_t_s"] + 1.0)) < 1.0 / log.rate_hz + 1e-6
