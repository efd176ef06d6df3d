"""`rocklab track` CLI, tracks.csv layout, and one-line errors on bad input."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pandas as pd
import pytest

from _render import Scene, marker_texture, write_video

FPS = 25.0
TOML = """\
[targets]
style = "aruco"
dictionary = "DICT_4X4_50"
marker_size_m = 0.08
[reference]
level = "table"
[[objects]]
id = "block_1"
kind = "block"
markers = [1]
[[objects]]
id = "table"
kind = "table"
markers = [0]
marker_size_m = 0.05
"""


def _frames(n=40, W=400, H=300, k=800.0):
    sc = Scene(W, H, px_per_m=k, noise=1.5, blur=0.6, seed=2)
    sc.add(*marker_texture([1], [(0.0, 0.0)], 0.08, (0.12, 0.2), origin_m=(-0.06, -0.1)))
    sc.add(*marker_texture([0], [(0.0, 0.0)], 0.05, (0.4, 0.07), origin_m=(-0.2, -0.035)))
    t = np.arange(n) / FPS
    th = 0.05 * np.sin(2 * np.pi * t)
    x = 0.01 * np.sin(2 * np.pi * t / 1.2)
    return [sc.render([(x[i], 0.04, th[i]), (x[i], -0.11, 0.0)]) for i in range(n)], th, x


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    d = tmp_path_factory.mktemp("sess")
    frames, th, x = _frames()
    write_video(d / "video.mkv", frames, FPS)
    (d / "track.toml").write_text(TOML)
    return d, frames, th, x


def test_cli_writes_tracks_and_table_motion(session, run_cli, tmp_path):
    d, frames, th, x = session
    out = tmp_path / "out" / "tracks.csv"
    rc, stdout, err = run_cli("track", d / "video.mkv", "-o", out, "--json")
    assert rc == 0, err
    summary = json.loads(stdout)
    assert summary["fps"] == FPS and summary["objects"]["block_1"]["n_ok"] == len(frames)
    df = pd.read_csv(out)
    assert list(df.columns) == [
        "frame",
        "t_s",
        "object",
        "x_px",
        "y_px",
        "x_m",
        "y_m",
        "theta_rad",
        "sigma_theta_rad",
        "quality",
        "status",
    ]
    blk = df[df.object == "block_1"]
    assert np.sqrt(np.mean(np.degrees(blk.theta_rad.to_numpy() - th) ** 2)) < 0.15
    tab = pd.read_csv(summary["table_motion"]["csv"])
    assert list(tab.columns) == ["t_s", "x_m", "vx_m_s", "ax_m_s2"]
    np.testing.assert_allclose(tab.x_m, x - x[0], atol=3e-4)
    # config found next to the video by default; text mode prints one line per object
    rc, stdout, err = run_cli("track", d / "video.mkv", "-o", tmp_path / "t2.csv")
    assert rc == 0 and stdout.count("frames ok") == 2


def test_plot_draws_every_object_and_never_replaces_an_input(session, run_cli, tmp_path):
    """--plot: one column of panels per object (two here: the PNG is wider than tall); a plot named
    as the film or the config is refused, exit 2, and the file keeps its bytes."""
    d, frames, th, x = session
    png = tmp_path / "tracks.png"
    rc, stdout, err = run_cli("track", d / "video.mkv", "-o", tmp_path / "t.csv", "--plot", png, "--json")
    assert rc == 0, err
    assert json.loads(stdout)["plot"] == str(png)
    img = cv2.imread(str(png))
    assert img is not None and img.shape[1] > 1.3 * img.shape[0]
    for victim in (d / "video.mkv", d / "track.toml"):
        before = victim.read_bytes()
        rc, _, err = run_cli("track", d / "video.mkv", "-o", tmp_path / "t3.csv", "--plot", victim)
        assert rc == 2 and len(err.strip().splitlines()) == 1 and "--plot" in err, err
        assert victim.read_bytes() == before


def _one_line_error(run_cli, *argv, match):
    rc, out, err = run_cli("track", *argv)
    assert rc == 2
    assert err.count("\n") == 1 and match in err, err
    return err


def test_bad_video_inputs(tmp_path, run_cli, session):
    (tmp_path / "track.toml").write_text(TOML)
    garbage = tmp_path / "garbage.mkv"
    garbage.write_bytes(b"not a video at all" * 10)
    _one_line_error(run_cli, garbage, "--config", tmp_path / "track.toml", match="garbage.mkv")
    _one_line_error(run_cli, tmp_path / "missing.mkv", match="not found")
    empty = tmp_path / "empty.mkv"
    vw = cv2.VideoWriter(str(empty), cv2.VideoWriter_fourcc(*"FFV1"), FPS, (64, 48), True)
    vw.release()
    _one_line_error(run_cli, empty, "--config", tmp_path / "track.toml", match="empty.mkv")


def test_fps_missing_requires_flag(tmp_path, run_cli, session):
    frames = session[1][:8]
    for i, f in enumerate(frames):
        cv2.imwrite(str(tmp_path / f"f{i:03d}.png"), f)
    (tmp_path / "track.toml").write_text(TOML)
    seq = tmp_path / "f%03d.png"
    _one_line_error(run_cli, seq, match="--fps")
    rc, out, err = run_cli("track", seq, "--fps", 25, "--json", "-o", tmp_path / "t.csv")
    assert rc == 0, err
    assert json.loads(out)["n_frames"] == 8


def test_unknown_marker_and_unseen_object(tmp_path, run_cli, session):
    d = session[0]
    bad = tmp_path / "bad.toml"
    bad.write_text(TOML.replace("markers = [1]", "markers = [77]"))
    err = _one_line_error(run_cli, d / "video.mkv", "--config", bad, match="77")
    assert "DICT_4X4_50" in err
    unseen = tmp_path / "unseen.toml"
    unseen.write_text(TOML.replace("markers = [1]", "markers = [7]"))
    _one_line_error(
        run_cli, d / "video.mkv", "--config", unseen, "-o", tmp_path / "x.csv", match="'block_1' is never seen"
    )
    assert not (tmp_path / "x.csv").exists()


def test_progress_bar_goes_to_stderr(session, run_cli, tmp_path):
    d = session[0]
    rc, out, err = run_cli("track", d / "video.mkv", "--progress", "--json", "-o", tmp_path / "t.csv")
    assert rc == 0
    json.loads(out)  # stdout stays one JSON object
    assert "track" in err and "frame" in err


def test_a_missing_video_is_named_before_a_missing_config(tmp_path, run_cli):
    # it said "track.toml: tracking config not found" for a mistyped film name
    for cmd in (("track",), ("track", "preview")):
        rc, _, err = run_cli(*cmd, tmp_path / "nothere.mp4")
        assert rc == 2 and "nothere.mp4" in err and "not found" in err and "track.toml" not in err
