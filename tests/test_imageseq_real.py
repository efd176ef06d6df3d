"""Real films as image folders and high-speed files: a Photron MRAW and a Phantom CINE from pyIDI's
tests (tests/data/highspeed/README.md), and frames of the shared pendulum film."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from rocklab.tracking import iter_video_frames, probe_video

DATA = Path(__file__).parent / "data" / "highspeed"
DOT = '[targets]\nstyle = "markerless"\n[reference]\nlevel = "none"\n[[objects]]\nid = "dot"\nkind = "point"\n'


def test_a_real_mraw_reads_its_bytes_at_the_saved_rate():
    pytest.importorskip("pyMRAW")
    info = probe_video(DATA / "data_showcase.cih")
    # 15 000 fps recorded, every 100th frame saved: the film runs at 150 frames/s
    assert (info.n_frames, info.width_px, info.height_px, info.fps) == (75, 640, 40, 150.0)
    raw = np.fromfile(DATA / "data_showcase.mraw", np.uint8).reshape(75, 40, 640)  # 8-bit words, as stored
    got = np.stack([g for _, g in iter_video_frames(DATA / "data_showcase.mraw")])  # the .mraw names its header
    np.testing.assert_array_equal(got, raw)


def _cine_folder(tmp_path):
    """The CINE's frames as a folder of 16-bit PNGs (its 12-bit values as decoded by pycine)."""
    import cv2

    pytest.importorskip("pycine")
    from pycine.file import read_header
    from pycine.raw import frame_reader

    f = DATA / "data_small_cine.cine"
    folder = tmp_path / "cine_frames"
    folder.mkdir()
    for k, img in enumerate(frame_reader(str(f), read_header(str(f)), start_frame=1)):
        cv2.imwrite(str(folder / f"dot_{k:04d}.png"), img)
    return folder


def test_a_real_cine_with_a_damaged_last_time_stamp_runs_on_its_rate(tmp_path, run_cli):
    pytest.importorskip("pycine")
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        info = probe_video(DATA / "data_small_cine.cine")
    assert (info.n_frames, info.width_px, info.height_px, info.fps) == (235, 256, 32, 100.0)
    assert info.frame_times_s is None and any("W-VIDEO-TIMES" in str(x.message) for x in w)
    assert any("frame 234 2.52806e+07 s after frame 233" in str(x.message) for x in w)
    folder = _cine_folder(tmp_path)
    toml = tmp_path / "dot.toml"
    toml.write_text(DOT + "roi = [118, 2, 42, 28]\n")
    rc, out, err = run_cli("track", DATA / "data_small_cine.cine", "--config", toml, "-o", tmp_path / "c.csv", "--json")
    assert rc == 0, err
    cine = pd.read_csv(tmp_path / "c.csv")
    rc, out2, err = run_cli("track", folder, "--config", toml, "--fps", 100, "-o", tmp_path / "f.csv", "--json")
    assert rc == 0, err
    seq = pd.read_csv(tmp_path / "f.csv")
    # the real image sequence: the dot on every frame but the saturated last one (234/235 = 99.6 %)
    ok = seq.status == "ok"
    assert ok.mean() >= 0.99 and not ok.iloc[-1]
    assert "W-VIDEO-TIMES" in {d["code"] for d in json.loads(out)["warnings"]}
    # the two readers give the tracker the same frames: the same track, on the same clock
    np.testing.assert_array_equal(seq.x_px.to_numpy(), cine.x_px.to_numpy())
    np.testing.assert_allclose(cine.t_s.to_numpy(), np.arange(235) / 100.0, atol=1e-12)
    # the dot is still but for the plate's vibration: every ok position within 0.2 px of the median
    assert np.max(np.abs(seq.x_px[ok] - seq.x_px[ok].median())) < 0.2


def test_frames_of_the_real_pendulum_film_track_as_the_film(shared_data, tmp_path, run_cli):
    import cv2

    film = shared_data / "video" / "pendulum_film2_vga.mp4"
    n = 240
    folder = tmp_path / "pendulum"
    folder.mkdir()
    for i, _, img in iter_video_frames(film, 0, n, color=True):
        cv2.imwrite(str(folder / f"{i:05d}.jpg"), img, [cv2.IMWRITE_JPEG_QUALITY, 95])
    fps = probe_video(film).fps
    toml = tmp_path / "ball.toml"
    toml.write_text(DOT.replace('"dot"', '"ball"') + f"roi = [310, 66, 70, 74]\n[video]\nstop_frame = {n}\n")
    rc, _, err = run_cli("track", film, "--config", toml, "-o", tmp_path / "film.csv")
    assert rc == 0, err
    rc, _, err = run_cli("track", folder, "--config", toml, "--fps", fps, "-o", tmp_path / "seq.csv")
    assert rc == 0, err
    a, b = pd.read_csv(tmp_path / "film.csv"), pd.read_csv(tmp_path / "seq.csv")
    assert len(a) == len(b) == n and (b.status == "ok").mean() >= 0.99
    np.testing.assert_allclose(b.t_s.to_numpy(), a.t_s.to_numpy(), atol=1e-9)
    both = (a.status == "ok") & (b.status == "ok")
    d = np.hypot(a.x_px - b.x_px, a.y_px - b.y_px)[both]
    # the ball swings ~100 px; a JPEG copy of each frame moves the track by a fraction of a pixel
    assert np.ptp(a.x_px[both]) > 50 and np.median(d) < 0.3 and d.max() < 2.0
