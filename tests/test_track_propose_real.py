"""``rocklab track init`` without markers or regions on real footage: the shared pendulum film
(``../shared/data/video/pendulum_film2_vga.mp4``). In a file of its own, apart from the rendered
films of tests/test_track_propose.py, so that the two can run on different xdist workers (the
suite runs a file on one worker): tracking the whole film, 1844 frames, took 29 s of CPU of the
95 s the two files took together (measured, session 18)."""

from __future__ import annotations

import json
import tomllib

import pandas as pd


def test_proposal_on_real_footage(shared_data, tmp_path, run_cli):
    """The pendulum film: the ball (a box of 70 x 74 px round it at 310, 66 in the first frame)
    is the one proposal; a soft shadow sweeping the lower left is not."""
    video = shared_data / "video" / "pendulum_film2_vga.mp4"
    cfg = tmp_path / "p.toml"
    rc, out, err = run_cli("track", "init", video, "-o", cfg, "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert len(d["proposed"]) == 1
    x, y, w, h = (float(v) for v in d["proposed"][0].split("=")[1].split(","))
    assert x <= 345 <= x + w and y <= 103 <= y + h  # the ball's centre
    assert w * h <= 3 * 70 * 74 and w * h >= 0.5 * 70 * 74
    rc, out, err = run_cli("track", video, "--config", cfg, "-o", tmp_path / "p.csv")
    assert rc == 0, err
    tr = pd.read_csv(tmp_path / "p.csv")
    assert (tr.status == "ok").mean() >= 0.95
    # no table and a ball that never rests: init saw it still swinging at the film's end and wrote
    # level = "none" with a note (it wrote "rest", and this run warned W-LEVEL-NONE)
    assert tomllib.loads(cfg.read_text())["reference"]["level"] == "none"
    assert "W-LEVEL" not in err
