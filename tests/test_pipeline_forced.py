"""``rocklab run`` on a shake-table session: the simulation driven by the table motion tracked from
video reproduces the rendered truth, and the sign convention (camera θ counter-clockwise, simulator θ
clockwise) is the right one."""

import json

import numpy as np
import pandas as pd
import pytest


@pytest.fixture(scope="module")
def sine_session(tmp_path_factory):
    from rocklab.synth import synth_session

    d = tmp_path_factory.mktemp("forced") / "session"
    synth_session(d, seed=2, table="sine", size=(960, 540), duration_s=3.0, imu=False, mp4=False)
    with open(d / "experiment.toml", "a") as f:
        f.write(
            '\n[fit]\nrestitution = false\n[simulate]\nlaws = ["housner"]\neta = 0.75\n'
            "[output]\nvideo_decimation = 10\n"
        )
    return d


def test_table_driven_simulation_matches_truth(sine_session, tmp_path):
    from rocklab.pipelines import run_experiment

    meta = json.loads((sine_session / "session.json").read_text())
    assert meta["blocks"][0]["eta_true"] == 0.75
    alpha = meta["blocks"][0]["block"]["alpha_rad"]
    rep, ran = run_experiment(sine_session / "experiment.toml", tmp_path / "out")
    assert ran and rep["status"] == "ok" and rep["fit"] is None
    ser = pd.read_csv(tmp_path / "out" / "series.csv")
    th, sim = ser["theta_video_rad"].to_numpy(), ser["theta_sim_given_rad"].to_numpy()
    ok = np.isfinite(th) & np.isfinite(sim)
    peak = np.max(np.abs(th[ok]))
    assert peak > 0.5 * alpha  # the pulse really rocks the block
    rms = np.sqrt(np.mean((th[ok] - sim[ok]) ** 2))
    rms_mirrored = np.sqrt(np.mean((th[ok] + sim[ok]) ** 2))
    # the true η drives the measured table motion to the measured rotation (measured 0.009 rad at
    # 1280x720); the mirrored convention would be off by about the amplitude
    assert rms < 0.06 * peak
    assert rms_mirrored > 5 * rms
    # table acceleration from video vs the rendered truth
    tr = pd.read_csv(sine_session / "truth.csv")
    tb = tr[tr["object"] == "table"]
    a_true = np.interp(ser["t_s"], tb["t_s"], tb["ax_m_s2"])
    a = ser["table_acc_m_s2"].to_numpy()
    m = np.isfinite(a)
    assert np.sqrt(np.mean((a[m] - a_true[m]) ** 2)) < 0.05 * np.sqrt(np.mean(a_true[m] ** 2))


def test_table_from_imu_is_synced_to_the_video(tmp_path):
    """A record-driven run takes the table acceleration from the table IMU (the camera's 50 fps
    cannot sample it); the IMU clock is found from the table acceleration itself."""
    from rocklab.pipelines.campaign._demo import _render_one
    from rocklab.pipelines import run_experiment

    cfg = _render_one(tmp_path / "s", 5, "B5L_elcentro", "B5L", "full", "record", (640, 360), 50.0)
    assert 'from = "imu"' in cfg.read_text()
    rep, _ = run_experiment(cfg, tmp_path / "out")
    meta = json.loads((tmp_path / "s" / "session.json").read_text())
    sync = rep["sync"]["table_imu"]
    # IMU sample k sits at video time t0 + k / rate: t_imu = t_video - t0
    assert sync["offset_s"] == pytest.approx(-meta["imu"]["table"]["t0_video_s"], abs=1e-3)
    ser = pd.read_csv(tmp_path / "out" / "series.csv")
    tr = pd.read_csv(tmp_path / "s" / "truth.csv")
    tb = tr[tr["object"] == "table"]
    a_true = np.interp(ser["t_s"], tb["t_s"], tb["ax_m_s2"])
    a = ser["table_acc_m_s2"].to_numpy()
    m = np.isfinite(a)
    # same sense as the video's x; fused with the film's displacement: the IMU alone (5 mg noise) gave
    # 5.4 % RMS, the film alone 8.3 %; the report's figure (a cubic spline at the frames) is the same
    err = np.sqrt(np.mean((a[m] - a_true[m]) ** 2)) / np.sqrt(np.mean(a_true[m] ** 2))
    assert rep["table_source"] == "fused" and rep["table"]["fusion"]["status"] == "ok"
    assert rep["truth"]["table_acc_rms_error_rel"] < 0.035
    assert err < 0.04
    # each sample's sigma: the error's scale (not a constant, not zero)
    sig = ser["table_sigma_acc_m_s2"].to_numpy()[m]
    assert 0.005 < np.median(sig) < 0.05 and np.sqrt(np.mean((a[m] - a_true[m]) ** 2)) < 3 * np.median(sig)
    assert "Table motion: fused from the table IMU" in (tmp_path / "out" / "summary.md").read_text()


def test_streaming_without_rrd_file_still_logs_the_video(sine_session, tmp_path):
    """``rrd = false`` with --spawn/--connect: the frames are kept while tracking and logged."""
    from rocklab.pipelines import load_experiment
    from rocklab.pipelines import analyse_experiment
    from rocklab.pipelines.experiment._log_experiment import log_experiment
    from rocklab.pipelines import read_rrd_summary

    text = (sine_session / "experiment.toml").read_text()
    assert text.count("video_decimation = 10\n") == 1
    cfg_path = sine_session / "experiment_stream.toml"
    cfg_path.write_text(text.replace("video_decimation = 10\n", "video_decimation = 10\nrrd = false\n"))
    cfg = load_experiment(cfg_path)
    assert cfg.rrd is False
    n_frames = json.loads((sine_session / "session.json").read_text())["n_frames"]
    res = analyse_experiment(cfg, keep_video=True)  # what run_experiment passes for --spawn/--connect
    rows = log_experiment(res, tmp_path / "stream.rrd")
    # every frame is referenced (the AV1 film; video_decimation applies only to JPEG stills)
    assert res.video.kind == "av1" and rows["experiment/video"] == n_frames
    assert read_rrd_summary(tmp_path / "stream.rrd")["/experiment/video"] >= n_frames
    assert analyse_experiment(cfg).video is None  # no Rerun output: nothing kept
