"""Image folders and high-speed formats as films: the same probe and frames as a video file, 16-bit
frames scaled (not truncated), and one-line errors for folders that are no film."""

from __future__ import annotations

import json

import cv2
import numpy as np
import pandas as pd
import pytest

from rocklab import InputError
from rocklab.tracking import iter_video_frames, probe_video


@pytest.fixture(scope="module")
def synth(tmp_path_factory):
    """A rendered session (ArUco block and table, 50 fps) and its grey frames as decoded."""
    from rocklab.pipelines import main

    d = tmp_path_factory.mktemp("imgseq") / "s"
    rc = main(["synth", "--out", str(d), "--seed", "3", "--size", "480x270", "--duration", "2", "--no-imu"])
    assert rc == 0
    frames = [(g, img) for _, g, img in iter_video_frames(d / "video.mkv", color=True)]
    return d, frames


def _dump(folder, frames, kind):
    folder.mkdir()
    for i, (g, img) in enumerate(frames):
        if kind == "png16":  # a 12-bit camera in 16-bit words, 0..4080
            cv2.imwrite(str(folder / f"frame_{i:05d}.png"), g.astype(np.uint16) * 16)
        elif kind == "tif16":
            cv2.imwrite(str(folder / f"cam{i + 1}.tif"), g.astype(np.uint16) * 257)
        else:  # JPEG, lossy, numbered from 1 without zero padding (sorted as numbers)
            cv2.imwrite(str(folder / f"img{i + 1}.jpg"), img, [cv2.IMWRITE_JPEG_QUALITY, 92])
    return folder


def _track(run_cli, video, d, out, *extra):
    rc, stdout, err = run_cli("track", video, "--config", d / "track.toml", "-o", out, "--json", *extra)
    assert rc == 0, err
    return json.loads(stdout), pd.read_csv(out)


def test_a_16bit_png_folder_tracks_exactly_as_its_film(synth, run_cli, tmp_path):
    d, frames = synth
    folder = _dump(tmp_path / "png16", frames, "png16")
    info = probe_video(folder)
    assert (info.width_px, info.height_px, info.n_frames, info.fps) == (480, 270, len(frames), None)
    # the 16-bit frames come back as the 8-bit ones they were made from (x16 then /16), not their low byte
    got = [g for _, g in iter_video_frames(folder, 5, 8)]
    assert len(got) == 3 and all(np.array_equal(a, frames[5 + k][0]) for k, a in enumerate(got))
    _, film = _track(run_cli, d / "video.mkv", d, tmp_path / "film.csv")
    s, seq = _track(run_cli, folder, d, tmp_path / "seq.csv", "--fps", 50)
    assert s["fps"] == 50 and len(seq) == len(film)
    for col in ("t_s", "theta_rad", "x_px", "y_px"):
        np.testing.assert_array_equal(seq[col].to_numpy(), film[col].to_numpy())
    assert (seq.status == "ok").mean() == 1.0


def test_a_jpeg_folder_with_timestamps_tracks_the_truth(synth, run_cli, tmp_path):
    d, frames = synth
    folder = _dump(tmp_path / "jpg", frames, "jpg")
    n = len(frames)
    t = 0.01 + np.arange(n) / 50.0 + np.where(np.arange(n) >= 40, 0.02, 0.0)  # one frame lost after the 40th
    pd.DataFrame({"file": [f"img{i + 1}.jpg" for i in range(n)][::-1], "t_s": t[::-1]}).sort_values("t_s").to_csv(
        folder / "timestamps.csv", index=False
    )
    info = probe_video(folder)
    assert info.n_dropped == 1 and info.fps == pytest.approx((n - 1) / (t[-1] - t[0]))
    s, seq = _track(run_cli, folder, d, tmp_path / "seq.csv")
    b = seq[seq.object == "block_1"]
    np.testing.assert_allclose(b.t_s.to_numpy(), t - t[0], atol=1e-9)
    truth = pd.read_csv(d / "truth.csv")
    tb = truth[truth.object == "block_1"].theta_rad.to_numpy()[:n]
    ok = (b.status == "ok").to_numpy()
    assert ok.mean() >= 0.99
    err = np.abs(b.theta_rad.to_numpy()[ok] - tb[ok])
    assert np.median(err) < 2e-3 and err.max() < 1e-2  # JPEG at quality 92: within a tenth of a degree


def test_a_16bit_tiff_folder_is_read_with_one_gain(synth, tmp_path):
    _, frames = synth
    folder = _dump(tmp_path / "tif", frames[:12], "tif16")
    info = probe_video(folder)
    assert info.n_frames == 12
    got = [g for _, g in iter_video_frames(folder, prefetch=0)]
    # x257 fills 16 bits: one gain for the sequence, /256 (not the low byte: that would be the picture itself
    # only by accident of the x257, and garbage for any other 16-bit camera)
    for k, g in enumerate(got):
        want = np.minimum(np.rint(frames[k][0].astype(float) * 257 / 256), 255)
        np.testing.assert_array_equal(g, want.astype(np.uint8))
        assert np.mean(g != frames[k][0]) > 0.01  # the gain is not 1


def _bad_folder(tmp_path, names, sizes=None):
    f = tmp_path / "bad"
    f.mkdir()
    for k, n in enumerate(names):
        w, h = sizes[k] if sizes else (32, 24)
        cv2.imwrite(str(f / n), np.full((h, w), 100, np.uint8))
    return f


@pytest.mark.parametrize(
    "names, sizes, words",
    [
        (["f_001.png", "f_002.png", "f_005.png"], None, ["jump from 2 (f_002.png) to 5", "2 frame(s) missing"]),
        (["f_1.png", "f_2.png", "f_3.png"], [(32, 24), (32, 24), (40, 24)], ["f_3.png: 40x24 px", "same size"]),
        (["a_1.png", "b_2.png"], None, ["named in 2 ways"]),
        (["f_1.png", "f_2.jpg"], None, ["several kinds"]),
        (["notes.txt"], None, ["no frames in the folder"]),
        (["f_1.png", "f_01.png"], None, ["the same frame number"]),
    ],
)
def test_a_folder_that_is_no_film_is_one_line_naming_it(tmp_path, names, sizes, words):
    if names == ["notes.txt"]:
        f = tmp_path / "bad"
        f.mkdir()
        (f / "notes.txt").write_text("x")
    else:
        f = _bad_folder(tmp_path, names, sizes)
    with pytest.raises(InputError) as e:
        probe_video(f)
    msg = str(e.value)
    assert "\n" not in msg and str(f) in msg and all(w in msg for w in words)


def test_cli_folder_without_rate_or_with_bad_timestamps_exits_2(tmp_path, run_cli):
    f = _bad_folder(tmp_path, ["f_1.png", "f_2.png", "f_3.png"])
    toml = tmp_path / "track.toml"
    toml.write_text('[targets]\nstyle = "aruco"\n[[objects]]\nid = "b"\nkind = "block"\nmarkers = [1]\n')
    rc, _, err = run_cli("track", f, "--config", toml, "-o", tmp_path / "t.csv")
    assert rc == 2 and "no frame rate" in err and "--fps" in err and "timestamps.csv" in err
    for text, word in (
        ("time\n0\n1\n2\n", "no column t_s"),
        ("t_s\n0\n0.01\n", "2 times for 3 frames"),
        ("t_s\n0\n0.02\n0.01\n", "line 4: t_s does not increase"),
        ("file,t_s\nf_1.png,0\nf_2.png,0.01\n", "no time for f_3.png"),
    ):
        (f / "timestamps.csv").write_text(text)
        rc, _, err = run_cli("track", f, "--config", toml, "-o", tmp_path / "t.csv")
        assert rc == 2 and word in err and len(err.strip().splitlines()) == 1, err


def test_an_mraw_round_trip_is_frame_exact(synth, tmp_path):
    pymraw = pytest.importorskip("pyMRAW")
    _, frames = synth
    stack = np.stack([g for g, _ in frames[:20]])
    for bits, scale in ((8, 1), (16, 16)):
        _, cih = pymraw.save_mraw(
            stack.astype(np.uint16) * scale,
            str(tmp_path / f"f{bits}.cih"),
            bit_depth=bits,
            info_dict={"Record Rate(fps)": 2000},
        )
        info = probe_video(cih)
        assert (info.n_frames, info.fps, info.width_px, info.height_px) == (20, 2000.0, 480, 270)
        got = np.stack([g for _, g in iter_video_frames(tmp_path / f"f{bits}.mraw")])
        np.testing.assert_array_equal(got, stack)


def test_highspeed_formats_name_their_package_when_it_is_missing(tmp_path, monkeypatch):
    import sys

    for mod in ("pyMRAW", "pycine", "pycine.file", "pycine.raw"):
        monkeypatch.setitem(sys.modules, mod, None)  # import fails as when the package is absent
    (tmp_path / "a.cine").write_bytes(b"CI" + bytes(100))
    (tmp_path / "b.cih").write_text("Record Rate(fps) : 1000\n")
    (tmp_path / "b.mraw").write_bytes(bytes(10))
    for f, pkg in (("a.cine", "pycine-lite"), ("b.cih", "pymraw")):
        with pytest.raises(InputError, match=f"needs the package {pkg}; install it"):
            probe_video(tmp_path / f)


def test_run_takes_an_image_folder_as_its_film(synth, run_cli, tmp_path):
    import re
    import shutil

    d, frames = synth
    s = tmp_path / "s"
    shutil.copytree(d, s)
    _dump(s / "frames", frames, "png16")
    toml = re.sub(r'path = "video\.mkv"', 'path = "frames"\nfps = 50', (s / "experiment.toml").read_text())
    (s / "experiment.toml").write_text(toml + "\n[output]\nrrd = false\nfigures = false\n")
    rc, _, err = run_cli("run", s / "experiment.toml", "--out", tmp_path / "out")
    assert rc == 0, err
    rep = json.loads((tmp_path / "out" / "report.json").read_text())
    assert rep["fit"]["eta_e"] == pytest.approx(rep["truth"]["eta"], abs=0.01)
    assert rep["truth"]["theta_rms_error_rad"] < 2e-3


def test_a_damaged_frame_in_the_middle_stops_the_run_naming_it(synth, run_cli, tmp_path):
    d, frames = synth
    folder = _dump(tmp_path / "png16", frames[:30], "png16")
    (folder / "frame_00017.png").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(40))  # cut short by a failed copy
    rc, _, err = run_cli("track", folder, "--config", d / "track.toml", "--fps", 50, "-o", tmp_path / "t.csv")
    assert rc == 2 and "frame_00017.png: cannot decode the image" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "t.csv").exists()


def _moving_patch_folder(tmp_path, n=8, step_px=2):
    """PNG frames (160x120) of a random-textured 24x24 patch moving ``step_px`` right per frame."""
    rng = np.random.default_rng(7)
    patch = rng.integers(30, 230, (24, 24)).astype(np.uint8)
    f = tmp_path / "frames"
    f.mkdir()
    for i in range(n):
        g = np.full((120, 160), 128, np.uint8)
        g[48:72, 40 + step_px * i : 64 + step_px * i] = patch
        cv2.imwrite(str(f / f"f_{i:03d}.png"), g)
    return f


@pytest.mark.parametrize("rate", [12.5, 30.0])
def test_track_init_on_a_folder_without_a_rate_exits_2_and_fps_sets_the_times(tmp_path, run_cli, rate):
    f = _moving_patch_folder(tmp_path)
    toml = tmp_path / "track.toml"
    rc, _, err = run_cli("track", "init", f, "--object", "p=36,44,32,32", "-o", toml)
    # no guessed 50 fps: every time, velocity and frequency would be off by 50 / rate
    assert rc == 2 and not toml.exists()
    assert err.count("\n") == 1 and str(f) in err and "no frame rate" in err and "--fps N" in err
    assert "Traceback" not in err
    rc, _, err = run_cli("track", "init", f, "--object", "p=36,44,32,32", "-o", toml, "--fps", rate)
    assert rc == 0, err
    rc, _, err = run_cli("track", f, "--config", toml, "-o", tmp_path / "t.csv")
    assert rc == 0, err
    t = pd.read_csv(tmp_path / "t.csv")
    np.testing.assert_allclose(t.t_s.to_numpy(), t.frame.to_numpy() / rate, rtol=1e-12)
    # the patch moves 2 px a frame: rate * 2 px/s, measured from the track
    v = np.polyfit(t.t_s, t.x_px, 1)[0]
    assert v == pytest.approx(2.0 * rate, rel=0.02)


def test_an_old_configs_placeholder_fps_is_not_read_as_the_rate(tmp_path, run_cli):
    from rocklab.config import FPS_PLACEHOLDER_NOTE, load_track_config

    f = _moving_patch_folder(tmp_path)
    toml = tmp_path / "track.toml"
    assert run_cli("track", "init", f, "--object", "p=36,44,32,32", "-o", toml, "--fps", 50)[0] == 0
    text = toml.read_text()
    assert "fps = 50.0" in text and FPS_PLACEHOLDER_NOTE not in text  # a rate given is a rate
    assert load_track_config(toml).video.fps == 50.0
    old = tmp_path / "old.toml"  # as 'track init' wrote it for a film without a rate, before session 19
    old.write_text(f"# {FPS_PLACEHOLDER_NOTE}\n" + text)
    assert load_track_config(old).video.fps is None
    rc, _, err = run_cli("track", f, "--config", old, "-o", tmp_path / "t.csv")
    assert rc == 2 and err.count("\n") == 1 and str(old) in err and "--fps N" in err and "delete that note" in err
    rc, _, err = run_cli("track", f, "--config", old, "-o", tmp_path / "t.csv", "--fps", 25)
    assert rc == 0, err
    t = pd.read_csv(tmp_path / "t.csv")
    np.testing.assert_allclose(t.t_s.to_numpy(), t.frame.to_numpy() / 25.0, rtol=1e-12)
    # another rate under the note is the user's correction: read
    old.write_text(old.read_text().replace("fps = 50.0", "fps = 22.67"))
    assert load_track_config(old).video.fps == 22.67
