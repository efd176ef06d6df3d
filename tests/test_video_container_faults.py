"""The container is believed: frame times on its exact clock (coarse ticks, dropped frames,
variable rate), its display rotation, and the frames after a damaged packet. Films are written
with PyAV from a marker turned by a known angle at a known time."""

from __future__ import annotations

import math
from fractions import Fraction

import cv2
import numpy as np
import pytest

from rocklab._diagnostics import RocklabWarning, collecting
from rocklab.config import TrackConfig
from rocklab.tracking import probe_video, track_video
from rocklab.tracking import iter_video_frames

from test_video_container import CFG, _marker_frame, _write

av = pytest.importorskip("av")


def _theta(t_s):
    return 0.2 * np.sin(2 * np.pi * np.asarray(t_s) / 0.4)


def test_coarse_ticks_and_a_dropped_frame_keep_the_exact_clock(tmp_path):
    """150 fps in Matroska's 1 ms ticks (steps of 7, 7, 6 ms) with frame 25 dropped: the rate is
    150 exactly (a median step would say 142.857), every time is its slot / 150, and the gap is a
    dropped frame (a note), not a stretch of the test."""
    slots = np.delete(np.arange(61), 25)
    t_true = slots / 150.0
    path = tmp_path / "drop.mkv"
    _write(path, [_marker_frame(t) for t in _theta(t_true)], np.rint(t_true * 1000), Fraction(1, 1000))
    info = probe_video(path)
    assert info.fps == 150.0 and info.n_frames == 60 and info.n_dropped == 1
    np.testing.assert_allclose(info.frame_times_s, t_true, rtol=0, atol=1e-12)
    with collecting() as diags:
        b = track_video(path, TrackConfig.from_dict(CFG))["block_1"]
    assert [d.code for d in diags] == ["W-VIDEO-DROPPED"] and diags[0].severity == "note"
    assert "dropped 1 frame" in diags[0].message and "t = 0.1600" in diags[0].message
    np.testing.assert_allclose(b.t_s, t_true, rtol=0, atol=1e-12)
    assert np.nanmax(np.abs(b.theta_rad - _theta(b.t_s))) < math.radians(0.3)


def test_variable_rate_matroska_keeps_its_packet_times(tmp_path):
    """A phone's variable rate (31-36 ms steps) in Matroska: OpenCV's duration x rate estimate is
    no frame count; t_s is each packet's time and θ lines up with the truth there."""
    rng = np.random.default_rng(5)
    pts_ms = np.concatenate(([0], np.cumsum(rng.integers(31, 37, 79))))
    path = tmp_path / "phone.mkv"
    _write(path, [_marker_frame(t) for t in _theta(pts_ms / 1000.0)], pts_ms, Fraction(1, 1000))
    info = probe_video(path)
    assert info.n_frames == 80 and info.n_dropped == 0 and info.variable_rate
    with collecting() as diags:
        b = track_video(path, TrackConfig.from_dict(CFG))["block_1"]
    assert [d.code for d in diags] == []
    np.testing.assert_allclose(b.t_s, pts_ms / 1000.0, rtol=0, atol=1e-9)
    assert np.nanmax(np.abs(b.theta_rad - _theta(b.t_s))) < math.radians(0.3)
    # the same frames at frame / mean rate would be over a degree off somewhere
    t_even = np.arange(80) * pts_ms[-1] / 79 / 1000.0
    assert np.nanmax(np.abs(b.theta_rad - _theta(t_even))) > math.radians(1.0)


def test_display_rotation_is_applied_for_every_reader(tmp_path):
    """A phone films sideways and stores a display matrix (+90 deg): grey (PyAV luma), colour
    (PyAV) and OpenCV frames are one upright picture, and θ is the upright marker's."""
    n = 12
    t = np.arange(n) / 25.0
    path = tmp_path / "phone.mp4"
    with av.open(str(path), "w") as c:
        s = c.add_stream("libx264", rate=25)
        s.width, s.height, s.pix_fmt = 302, 402, "yuv420p"
        s.options = {"crf": "0"}
        s.set_display_rotation(90)
        for th in _theta(t):
            up = np.pad(_marker_frame(th), ((0, 1), (0, 1)), mode="edge")  # 302 rows x 402 columns
            stored = np.ascontiguousarray(np.rot90(up, -1))  # turned clockwise, shown upright by +90
            for pkt in s.encode(av.VideoFrame.from_ndarray(stored, format="gray")):
                c.mux(pkt)
        for pkt in s.encode():
            c.mux(pkt)
    info = probe_video(path)
    assert (info.width_px, info.height_px, info.rotation_deg) == (402, 302, 90)
    grey = next(iter(iter_video_frames(path, prefetch=0)))[1]
    _, grey_c, colour = next(iter(iter_video_frames(path, prefetch=0, color=True)))
    ok, ref = cv2.VideoCapture(str(path)).read()
    assert ok and grey.shape == grey_c.shape == ref.shape[:2] == (302, 402)
    assert np.array_equal(grey, grey_c)
    assert np.abs(grey.astype(int) - cv2.cvtColor(ref, cv2.COLOR_BGR2GRAY)).max() <= 3
    b = track_video(path, TrackConfig.from_dict(CFG))["block_1"]
    assert np.all(b.status == "ok")
    assert np.nanmax(np.abs(b.theta_rad - _theta(t))) < math.radians(0.3)


def test_a_damaged_packet_loses_only_its_frames_and_says_so(tmp_path):
    """20 kB of garbage in the middle of an H.264 film: the reading goes on past it, the frames
    after keep their times, frames predicted from a lost picture are dropped to the next key frame
    (they decode concealed, 10 deg off), and the loss is W-VIDEO-DAMAGED (suspect)."""
    n, fps = 200, 50
    t = np.arange(n) / fps
    path = tmp_path / "clean.mp4"
    with av.open(str(path), "w") as c:
        s = c.add_stream("libx264", rate=fps)
        s.width, s.height, s.pix_fmt = 402, 302, "yuv420p"
        s.options = {"g": "25", "crf": "18"}
        for th in _theta(t):
            f = np.pad(_marker_frame(th), ((0, 1), (0, 1)), mode="edge")
            for pkt in s.encode(av.VideoFrame.from_ndarray(f, format="gray")):
                c.mux(pkt)
        for pkt in s.encode():
            c.mux(pkt)
    data = bytearray(path.read_bytes())
    mid = len(data) // 2
    data[mid : mid + 20000] = np.random.default_rng(1).integers(0, 256, 20000, dtype=np.uint8).tobytes()
    bad = tmp_path / "damaged.mp4"
    bad.write_bytes(bytes(data))
    with collecting() as diags:
        b = track_video(bad, TrackConfig.from_dict(CFG))["block_1"]
    m = len(b.t_s)
    assert 100 < m < n and b.t_s[-1] == pytest.approx((n - 1) / fps)  # the film's end is read
    assert set(np.round(b.t_s * fps).astype(int)) < set(range(n))
    assert [d.code for d in diags] == ["W-VIDEO-DAMAGED"] and diags[0].severity == "suspect"
    assert f"{n - m} of the {n} frames" in diags[0].message
    assert np.all(b.status == "ok")

    assert np.nanmax(np.abs(b.theta_rad - _theta(b.t_s))) < math.radians(0.3)


def test_a_given_rate_that_contradicts_the_container_is_a_warning(tmp_path):
    path = tmp_path / "cfr.mkv"
    _write(path, [_marker_frame(0.1)] * 6, np.arange(6) * 40, Fraction(1, 1000))
    cfg = TrackConfig.from_dict(dict(CFG, video={"fps": 50.0}))
    with pytest.warns(RocklabWarning, match=r"W-VIDEO-FPS.*50 frames/s.*constant 25 frames/s"):
        tr = track_video(path, cfg)
    np.testing.assert_allclose(tr["block_1"].t_s, np.arange(6) / 50.0)  # the given rate, as asked
    # the same rate as the container's: no warning
    with collecting() as diags:
        track_video(path, TrackConfig.from_dict(dict(CFG, video={"fps": 25.0})))
    assert diags == []


def _phone_film(path, upright, turn_deg, hflip=False, vflip=False, sar=None):
    """A film whose display matrix (``turn_deg`` counter-clockwise, then the mirrors, as PyAV
    defines them) shows ``upright`` (frames, square pixels): each stored picture is the one
    those steps turn into the upright one, squeezed by ``sar`` along its stored rows."""

    def shown(s):
        d = np.rot90(s, turn_deg // 90)
        return d[:: -1 if vflip else 1, :: -1 if hflip else 1]

    # the stored picture among the 8 right-angle turns and mirrors of the upright one
    first = upright[0]
    cands = [(m, k) for m in (False, True) for k in range(4)]
    m, k = next((m, k) for m, k in cands if np.array_equal(shown(np.rot90(first[:, ::-1] if m else first, k)), first))
    stored = []
    for up in upright:
        st = np.rot90(up[:, ::-1] if m else up, k)
        if sar is not None:
            w = int(round(st.shape[1] / float(sar)))
            st = cv2.resize(st, (w, st.shape[0]), interpolation=cv2.INTER_AREA)
        stored.append(np.ascontiguousarray(st))
    with av.open(str(path), "w") as c:
        s = c.add_stream("libx264", rate=25)
        s.width, s.height = stored[0].shape[1], stored[0].shape[0]
        s.pix_fmt, s.options = "yuv420p", {"crf": "0"}
        if sar is not None:
            s.codec_context.sample_aspect_ratio = sar
        s.set_display_rotation(turn_deg, hflip=hflip, vflip=vflip)
        for st in stored:
            for pkt in s.encode(av.VideoFrame.from_ndarray(st, format="gray")):
                c.mux(pkt)
        for pkt in s.encode():
            c.mux(pkt)


@pytest.mark.parametrize("sar", [Fraction(16, 15), Fraction(8, 9)])
def test_a_turned_film_with_non_square_pixels_is_made_square_along_its_stored_rows(tmp_path, sar):
    """A film turned by 90 deg with non-square pixels: the pixel aspect belongs to the stored rows,
    which are the upright picture's columns (it was applied to the upright rows: 384x450, not
    360x480, the marker's square a rectangle)."""
    theta = math.radians(20.0)
    up = _marker_frame(theta, 360, 480)  # upright: 360 wide, 480 tall
    path = tmp_path / "sd_phone.mp4"
    _phone_film(path, [up] * 3, 90, sar=sar)
    info = probe_video(path)
    assert (info.width_px, info.height_px, info.rotation_deg, info.mirrored) == (360, 480, 90, False)
    g = next(iter(iter_video_frames(path, prefetch=0, pixel_aspect=info.pixel_aspect)))[1]
    assert g.shape == up.shape
    assert np.mean(np.abs(g.astype(int) - up)) < 2.0  # the upright picture, resampled once
    # the marker's outline is a square on the frames as read (its sides within 1 %)
    d = cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50))
    corners = d.detectMarkers(g)[0][0].reshape(4, 2)
    sides = np.linalg.norm(np.roll(corners, -1, axis=0) - corners, axis=1)
    assert sides.max() / sides.min() < 1.01, sides
    b = track_video(path, TrackConfig.from_dict(CFG))["block_1"]
    assert np.all(np.abs(b.theta_rad - theta) < math.radians(0.15))


@pytest.mark.parametrize("turn", [0, 90, 180, 270])
@pytest.mark.parametrize("flip", ["", "h", "v"])
def test_a_mirroring_display_matrix_is_shown_as_players_show_it_and_warned(tmp_path, turn, flip):
    """Every right-angle turn, plain or mirrored: the frames are the picture players show (they
    were turned only: a mirrored film was read mirrored from the shown one, every angle's sign
    reversed), and a mirror is W-VIDEO-MIRRORED (its sign depends on why the film was mirrored)."""
    n = 8
    t = np.arange(n) / 25.0
    upright = [np.pad(_marker_frame(th), ((0, 1), (0, 1)), mode="edge") for th in _theta(t + 0.05)]
    path = tmp_path / "film.mp4"
    _phone_film(path, upright, turn, hflip=flip == "h", vflip=flip == "v")
    info = probe_video(path)
    assert info.mirrored == bool(flip) and (info.width_px, info.height_px) == (402, 302)
    for (_, g), up in zip(iter_video_frames(path, prefetch=0), upright):
        assert np.abs(g.astype(int) - up).max() <= 2
    with collecting() as diags:
        b = track_video(path, TrackConfig.from_dict(CFG))["block_1"]
    assert [d.code for d in diags] == (["W-VIDEO-MIRRORED"] if flip else [])
    if flip:
        assert diags[0].severity == "suspect" and f"-display_rotation {info.rotation_deg}" in diags[0].message
    assert np.all(b.status == "ok")
    assert np.nanmax(np.abs(b.theta_rad - _theta(t + 0.05))) < math.radians(0.3)


def _av1_encoder():
    for name in ("libsvtav1", "libaom-av1", "librav1e"):
        try:
            av.codec.Codec(name, "w")
            return name
        except Exception:  # noqa: BLE001 - not built into this FFmpeg
            continue
    return None


@pytest.mark.parametrize("ext", ["mp4", "mkv", "webm"])
def test_an_av1_film_is_read_by_pyav_where_opencv_cannot(tmp_path, run_cli, ext):
    """An AV1 film (phones and screen recorders write them): OpenCV's FFmpeg here has no AV1
    decoder, so the probe refused it ("no decodable frame") though PyAV decodes it. `rocklab
    track` reads it with the container's times and the true angle."""
    enc = _av1_encoder()
    if enc is None:
        pytest.skip("this PyAV's FFmpeg has no AV1 encoder (libsvtav1, libaom-av1, librav1e)")
    n, fps = 30, 30
    t = np.arange(n) / fps
    path = tmp_path / f"film.{ext}"
    with av.open(str(path), "w") as c:
        s = c.add_stream(enc, rate=fps)
        s.width, s.height, s.pix_fmt = 320, 240, "yuv420p"
        s.options = {"crf": "20", "preset": "10"} if enc == "libsvtav1" else {"crf": "20"}
        for th in _theta(t + 0.05):
            for pkt in s.encode(av.VideoFrame.from_ndarray(_marker_frame(th, 320, 240), format="gray")):
                c.mux(pkt)
        for pkt in s.encode():
            c.mux(pkt)
    with av.open(str(path)) as c:
        assert c.streams.video[0].codec_context.name in ("av1", "libdav1d", "libaom-av1")
    info = probe_video(path)
    assert (info.n_frames, info.fps, info.width_px, info.height_px) == (n, fps, 320, 240)
    cfg = tmp_path / "t.toml"
    cfg.write_text(
        '[targets]\nstyle = "aruco"\nmarker_size_m = 0.05\n[reference]\nlevel = "none"\n'
        '[[objects]]\nid = "block_1"\nmarkers = [3]\n'
    )
    rc, out, err = run_cli("track", path, "--config", cfg, "-o", tmp_path / "tracks.csv")
    assert rc == 0 and "W-" not in err, err
    import pandas as pd

    tr = pd.read_csv(tmp_path / "tracks.csv")
    np.testing.assert_allclose(tr["t_s"], t, rtol=0, atol=1e-9)
    assert (tr["status"] == "ok").all()
    assert np.max(np.abs(tr["theta_rad"] - _theta(t + 0.05))) < math.radians(0.3)


def test_a_film_whose_packets_carry_no_times_is_counted_not_timed(tmp_path, monkeypatch):
    """Every packet at time 0 (a muxer that wrote no times): the frames are counted and timed by the
    given rate (was a ZeroDivisionError, exit 3, even with --fps)."""
    import dataclasses

    from rocklab.tracking.video import _video

    path = tmp_path / "cfr.mkv"
    _write(path, [_marker_frame(t) for t in _theta(np.arange(12) / 30.0)], np.arange(12) * 33, Fraction(1, 1000))
    real = _video.container_info

    def timeless(p):
        ci = real(p)
        return dataclasses.replace(ci, frame_times_s=np.zeros(len(ci.frame_times_s)), rate_hz=None)

    monkeypatch.setattr(_video, "container_info", timeless)
    info = probe_video(path)
    assert info.n_frames == 12 and info.frame_times_s is None
    b = track_video(path, TrackConfig.from_dict(CFG), fps=30.0)["block_1"]
    np.testing.assert_allclose(b.t_s, np.arange(12) / 30.0)
    assert np.nanmax(np.abs(b.theta_rad - _theta(b.t_s))) < math.radians(0.3)


def test_an_mp4_cut_before_its_index_names_the_cause(tmp_path, run_cli):
    """An MP4 whose index (moov, written last) was cut off: exit 2 saying so and to copy it again
    (was "convert it to .mkv/.mp4" for a file that is one)."""
    import av

    path = tmp_path / "cut.mp4"
    with av.open(str(path), "w") as c:
        s = c.add_stream("libx264", rate=25)
        s.width, s.height, s.pix_fmt = 160, 120, "yuv420p"
        for k in range(25):
            f = np.full((120, 160), 40 + 4 * k, np.uint8)
            for pkt in s.encode(av.VideoFrame.from_ndarray(f, format="gray")):
                c.mux(pkt)
        for pkt in s.encode():
            c.mux(pkt)
    data = path.read_bytes()
    assert data.find(b"moov") > data.find(b"mdat") > 0  # the index at the end, as cameras write it
    path.write_bytes(data[: data.find(b"moov") - 4])
    (tmp_path / "t.toml").write_text('[targets]\nstyle = "aruco"\n[[objects]]\nid = "b"\nmarkers = [1]\n')
    rc, out, err = run_cli("track", path, "--config", tmp_path / "t.toml")
    assert rc == 2 and len(err.strip().splitlines()) == 1, err
    assert "without its index" in err and "copy it again" in err and "convert" not in err
