"""What the container says and OpenCV does not: per-frame timestamps (variable frame rate) and
non-square pixels (SD camcorder footage). Videos are written with PyAV with known truth."""

from __future__ import annotations

import math
from fractions import Fraction

import cv2
import numpy as np
import pytest

from rocklab._diagnostics import RocklabWarning
from rocklab.config import TrackConfig
from rocklab.tracking import probe_video, track_video
from rocklab.tracking import iter_video_frames

av = pytest.importorskip("av")

W, H = 401, 301  # odd sizes: nothing may assume even frames
MARKER_PX = 90
CFG = {
    "targets": {"style": "aruco", "marker_size_m": 0.05},
    "reference": {"level": "none"},  # rendered level
    "objects": [{"id": "block_1", "markers": [3]}],
}


def _marker_frame(theta_rad: float, w: int = W, h: int = H) -> np.ndarray:
    """ArUco 4x4_50 id 3 on white, rotated counter-clockwise by ``theta_rad`` about the centre."""
    d = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50)
    m = cv2.aruco.generateImageMarker(d, 3, MARKER_PX, borderBits=1)
    img = np.full((h, w), 255, np.uint8)
    y0, x0 = (h - MARKER_PX) // 2, (w - MARKER_PX) // 2
    img[y0 : y0 + MARKER_PX, x0 : x0 + MARKER_PX] = m
    R = cv2.getRotationMatrix2D(((w - 1) / 2, (h - 1) / 2), math.degrees(theta_rad), 1.0)
    return cv2.warpAffine(img, R, (w, h), flags=cv2.INTER_CUBIC, borderValue=255)


def _write(path, frames, pts, time_base, sar=None, codec="ffv1"):
    with av.open(str(path), "w") as c:
        s = c.add_stream(codec, rate=Fraction(1, time_base))
        s.width, s.height = frames[0].shape[1], frames[0].shape[0]
        s.pix_fmt = "gray" if codec == "ffv1" else "yuv420p"
        if codec == "libx264":
            s.options = {"crf": "0"}  # lossless luma
        s.time_base = time_base
        if sar is not None:
            s.codec_context.sample_aspect_ratio = sar
        for f, p in zip(frames, pts):
            vf = av.VideoFrame.from_ndarray(f, format="gray")
            vf.pts, vf.time_base = int(p), time_base
            for pkt in s.encode(vf):
                c.mux(pkt)
        for pkt in s.encode():
            c.mux(pkt)


def test_variable_frame_rate_times_come_from_the_container(tmp_path):
    """Phone footage: frame intervals alternate 20 ms / 40 ms; t_s is each frame's own time."""
    n = 24
    dt_ms = np.where(np.arange(n) % 2 == 0, 20, 40)
    pts_ms = np.concatenate(([0], np.cumsum(dt_ms[:-1])))
    theta = 0.2 * np.sin(2 * np.pi * pts_ms / 1000.0)  # a function of the true time
    path = tmp_path / "vfr.mkv"
    _write(path, [_marker_frame(t) for t in theta], pts_ms, Fraction(1, 1000))
    info = probe_video(path)
    assert info.frame_times_s is not None and info.variable_rate
    np.testing.assert_allclose(info.frame_times_s[:n], pts_ms / 1000.0, atol=1e-9)
    tr = track_video(path, TrackConfig.from_dict(CFG))
    b = tr["block_1"]
    np.testing.assert_allclose(b.t_s, pts_ms / 1000.0, atol=1e-9)
    # θ lines up with the truth at those times (at a constant 1/fps the phase would drift)
    assert np.nanmax(np.abs(b.theta_rad - theta)) < math.radians(0.3)
    # --fps still overrides the container (a file whose clock is known to be wrong), and says so
    with pytest.warns(RocklabWarning, match="W-VIDEO-FPS"):
        tr30 = track_video(path, TrackConfig.from_dict(CFG), fps=30.0)
    np.testing.assert_allclose(tr30["block_1"].t_s, np.arange(n) / 30.0, atol=1e-12)


def test_constant_rate_file_keeps_frame_over_fps(tmp_path):
    n = 6
    path = tmp_path / "cfr.mkv"
    _write(path, [_marker_frame(0.1)] * n, np.arange(n) * 40, Fraction(1, 1000))
    info = probe_video(path)
    assert not info.variable_rate and info.fps == pytest.approx(25.0)
    tr = track_video(path, TrackConfig.from_dict(CFG))
    np.testing.assert_allclose(tr["block_1"].t_s, np.arange(n) / 25.0, atol=1e-9)


@pytest.mark.parametrize("sar", [Fraction(16, 15), Fraction(8, 9)])
def test_non_square_pixels_are_made_square_before_any_geometry(tmp_path, sar):
    """SD camcorders store 4:3 or 16:9 pictures with non-square pixels (PAL 16:15, NTSC 8:9).
    A marker turned by 20° is filmed squeezed; read as square pixels it would measure
    atan(sar · tan 20°); the container's aspect ratio restores 20°."""
    theta = math.radians(20.0)
    square = _marker_frame(theta, 480, 360)  # 4:2:0 H.264 (as camcorders write) needs even sizes
    stored_w = int(round(square.shape[1] / float(sar)))
    stored = cv2.resize(square, (stored_w, square.shape[0]), interpolation=cv2.INTER_AREA)
    path = tmp_path / "sd.mp4"  # the aspect ratio travels in the H.264 stream (VUI), as from a camera
    _write(path, [stored] * 3, np.arange(3) * 40, Fraction(1, 1000), sar=sar, codec="libx264")
    info = probe_video(path)
    assert info.pixel_aspect == pytest.approx(float(sar), rel=1e-9)
    assert info.width_px == int(round(stored_w * float(sar)))  # the square-pixel picture's width
    tr = track_video(path, TrackConfig.from_dict(CFG))
    th = tr["block_1"].theta_rad
    assert np.all(np.abs(th - theta) < math.radians(0.15)), np.degrees(th)
    naive = math.atan(math.tan(theta) * float(sar))
    assert abs(naive - theta) > math.radians(0.6)  # the error the correction removes


def test_real_film_shows_the_frames_its_edit_list_keeps(shared_data):
    """The real pendulum film (60 fps): its header counts 2057 frames, but an edit list cuts the
    first 213 (their packets flagged discard, one of them the only doubled interval); the film
    shows 1844 frames on an exact 60 fps clock, the frames every decoder (OpenCV too) gives."""
    path = shared_data / "video" / "pendulum_film2_vga.mp4"
    info = probe_video(path)
    assert (info.n_header, info.n_frames, info.fps, info.n_dropped) == (2057, 1844, 60.0, 0)
    np.testing.assert_allclose(info.frame_times_s, np.arange(1844) / 60.0, rtol=0, atol=1e-12)
    cap, n = cv2.VideoCapture(str(path)), 0
    while cap.grab():
        n += 1
    cap.release()
    assert n == info.n_frames
    # its stored pixels are 496:495, not square: 550 stored columns are 551 square ones
    assert info.pixel_aspect == pytest.approx(496 / 495, rel=1e-6) and info.width_px == 551


def test_interlaced_camcorder_video_is_read_field_by_field(tmp_path):
    """1080i-style footage (here 640x360, 25 frames/s, top field first, H.264 at a camcorder's
    17 Mbit/s): each frame weaves two exposures 20 ms apart. Read field by field it is a 50 Hz
    measurement of the motion; read as frames, the two positions comb into one picture."""
    n_frames = 10
    t_field = np.arange(2 * n_frames) / 50.0
    theta = 0.25 * np.sin(2 * np.pi * t_field / 0.5)  # fast: 2 Hz, up to 3.6 deg between fields
    woven = []
    for k in range(n_frames):
        a, b = _marker_frame(theta[2 * k], 640, 360), _marker_frame(theta[2 * k + 1], 640, 360)
        f = a.copy()
        f[1::2] = b[1::2]  # top field (even rows) exposed first
        woven.append(f)
    path = tmp_path / "camcorder.mp4"
    with av.open(str(path), "w") as c:
        s = c.add_stream("libx264", rate=25)
        s.width, s.height, s.pix_fmt = 640, 360, "yuv420p"
        s.bit_rate = 17_000_000
        s.options = {"x264-params": "interlaced=1:tff=1"}
        for f in woven:
            for pkt in s.encode(av.VideoFrame.from_ndarray(f, format="gray")):
                c.mux(pkt)
        for pkt in s.encode():
            c.mux(pkt)
    info = probe_video(path)
    assert info.field_order == "tff" and info.n_frames == n_frames
    tr = track_video(path, TrackConfig.from_dict(CFG))
    b = tr["block_1"]
    assert tr.fps == pytest.approx(50.0) and len(b.t_s) == 2 * n_frames
    np.testing.assert_allclose(b.t_s, t_field, atol=1e-9)
    assert np.all(b.status == "ok")
    err = np.degrees(b.theta_rad - theta)
    assert np.sqrt(np.mean(err**2)) < 0.1, err  # each field its own instant


@pytest.mark.parametrize("pix_fmt", ["yuv420p", "yuvj420p"])
def test_grey_from_the_luma_plane_matches_opencv_and_a_seek_lands_on_its_frame(tmp_path, pix_fmt):
    """Grey frames come from PyAV's luma plane (stretched from 16..235 unless full range), not
    OpenCV's YUV -> BGR -> grey: the same picture to rounding. A start past 0 seeks to the key
    frame before it (B-frames, 12-frame GOP) and must deliver exactly the frame a full read has
    there."""
    n, path = 60, tmp_path / f"{pix_fmt}.mp4"
    rng = np.random.default_rng(3)
    base = cv2.GaussianBlur((rng.random((H, W)) * 255).astype(np.uint8), (0, 0), 3)
    with av.open(str(path), "w") as c:
        s = c.add_stream("libx264", rate=25)
        s.width, s.height, s.pix_fmt = W + 1, H + 1, pix_fmt  # x264 needs even sizes
        s.options = {"g": "12", "bf": "2", "crf": "18"}
        for k in range(n):
            f = np.pad(base, ((0, 1), (0, 1)), mode="edge")
            f[:, 5 * k : 5 * k + 4] = 250  # a bar that walks: every frame is told apart
            for pkt in s.encode(av.VideoFrame.from_ndarray(f, format="gray")):
                c.mux(pkt)
        for pkt in s.encode():
            c.mux(pkt)
    ours = list(iter_video_frames(path))
    cap, ref = cv2.VideoCapture(str(path)), []
    while (got := cap.read())[0]:
        ref.append(cv2.cvtColor(got[1], cv2.COLOR_BGR2GRAY))
    cap.release()
    assert len(ours) == len(ref) == n
    diff = max(int(np.abs(g.astype(int) - r.astype(int)).max()) for (_, g), r in zip(ours, ref))
    assert diff <= 3, f"luma vs OpenCV's grey differ by {diff} grey levels"
    for start in (1, 13, 37, 59):
        first = next(iter(iter_video_frames(path, start, prefetch=0)))
        assert first[0] == start
        assert np.array_equal(first[1], ours[start][1]), f"start {start}: not the frame a full read has there"
    assert list(iter_video_frames(path, n)) == []
