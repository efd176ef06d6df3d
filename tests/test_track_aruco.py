"""ArUco tracking against rendered frames with exactly known poses (tests/_render.py)."""

from __future__ import annotations

import numpy as np
import pytest

from _render import Scene, marker_texture, write_video
from rocklab._diagnostics import collecting
from rocklab.config import TrackConfig
from rocklab.tracking import assemble_tracks, track_frames, track_video

FPS = 50.0


def _config(**extra):
    d = {
        "targets": {"style": "aruco", "marker_size_m": 0.08},
        "objects": [
            {"id": "block_1", "markers": [1]},
            {"id": "table", "kind": "table", "markers": [0], "marker_size_m": 0.05},
        ],
    }
    for k, v in extra.items():
        d.setdefault(k, {}).update(v)
    return TrackConfig.from_dict(d)


def _scene(width, height, px_per_m, roll=0.0, seed=0):
    sc = Scene(width, height, px_per_m=px_per_m, roll_rad=roll, noise=2.0, blur=0.7, seed=seed)
    # Block face 0.12 x 0.2 m with its marker centre as the object origin.
    sc.add(*marker_texture([1], [(0.0, 0.0)], 0.08, (0.12, 0.2), origin_m=(-0.06, -0.1)))
    sc.add(*marker_texture([0], [(0.0, 0.0)], 0.05, (0.5, 0.07), origin_m=(-0.25, -0.035)))
    return sc


def _truth(n, fps=FPS):
    t = np.arange(n) / fps
    theta = 0.08 * np.sin(2 * np.pi * t / 0.8)  # rocking-like, up to 4.6 degrees
    xt = 0.02 * np.sin(2 * np.pi * t / 0.6)  # table displacement, m
    return t, theta, xt


def test_full_hd_rotation_and_table_accuracy():
    """0.2 m block filling a third of a 1920x1080 frame (1800 px/m), camera rolled 0.6°.

    Issue 4 targets: rotation RMS <= 0.05°, table displacement RMS <= 0.1 mm.
    """
    roll = 0.01
    sc = _scene(1920, 1080, 1800.0, roll=roll)
    n = 30
    t, theta, xt = _truth(n)
    frames = [sc.render([(xt[i], 0.05, theta[i]), (xt[i], -0.2, 0.0)]) for i in range(n)]
    cfg = _config()
    res = assemble_tracks(track_frames(frames, cfg), cfg, FPS, 1920, 1080)
    assert res.level_rad == pytest.approx(roll, abs=2e-4)
    b = res["block_1"]
    assert np.all(b.status == "ok")
    err_deg = np.degrees(b.theta_rad - theta)
    assert np.sqrt(np.mean(err_deg**2)) <= 0.05
    # The reported sigma is an honest 1-sigma figure: the same order as the real error.
    ratio = np.sqrt(np.mean(err_deg**2)) / np.degrees(np.median(b.sigma_theta_rad))
    assert 0.3 < ratio < 5
    tab = res["table"]
    dx = (tab.x_m - tab.x_m[0]) - (xt - xt[0])
    assert np.sqrt(np.mean(dx**2)) <= 1e-4
    # Block position follows the table; its origin is the marker centre (world y = 0.05 m).
    assert np.sqrt(np.mean(((b.x_m - b.x_m[0]) - (xt - xt[0])) ** 2)) <= 1e-4
    assert b.m_per_unit == pytest.approx(1 / 1800.0, rel=5e-3)
    assert tab.m_per_unit == pytest.approx(1 / 1800.0, rel=5e-3)


def test_occlusion_is_nan_and_elsewhere_unchanged():
    """A 1 s occluder over the block: NaN + status there, identical error elsewhere."""
    W, H, k = 480, 320, 900.0
    n = 100
    t, theta, xt = _truth(n)
    cfg = _config()
    sc = _scene(W, H, k, seed=3)
    clean_frames = [sc.render([(xt[i], 0.05, theta[i]), (xt[i], -0.12, 0.0)]) for i in range(n)]
    gap = (np.arange(n) >= 25) & (np.arange(n) < 75)
    occl_frames = [f.copy() for f in clean_frames]
    for i in np.flatnonzero(gap):
        occl_frames[i][:170, 150:330] = 60  # a hand in front of the block marker
    clean = assemble_tracks(track_frames(clean_frames, cfg), cfg, FPS, W, H)
    occl = assemble_tracks(track_frames(occl_frames, cfg), cfg, FPS, W, H)
    b = occl["block_1"]
    assert np.all(np.isnan(b.theta_rad[gap])) and np.all(np.isnan(b.x_m[gap]))
    assert np.all(b.status[gap] == "occluded") and np.all(b.status[~gap] == "ok")
    e_clean = clean["block_1"].theta_rad[~gap] - theta[~gap]
    b_err = b.theta_rad[~gap] - theta[~gap]
    # Only the first frame after the gap may differ, by the sub-pixel refinement of a
    # full-frame (instead of windowed) search: far below the noise.
    np.testing.assert_allclose(b_err, e_clean, atol=1e-6)
    assert np.sqrt(np.mean(np.degrees(b_err) ** 2)) < 0.1
    # The table is untouched by the occluder.
    assert np.all(occl["table"].status == "ok")
    # Interpolation happens only when asked, and is labelled.
    cfg_i = _config(motion={"interpolate_max_gap_frames": 60})
    bi = assemble_tracks(track_frames(occl_frames, cfg_i), cfg_i, FPS, W, H)["block_1"]
    assert np.all(bi.status[gap] == "interpolated") and np.all(np.isfinite(bi.theta_rad[gap]))
    np.testing.assert_array_equal(bi.theta_rad[~gap], b.theta_rad[~gap])


def test_multi_marker_layout_learnt_and_partial_occlusion(tmp_path):
    """Two markers on one block: layout learnt from frame 0; losing one keeps the pose."""
    W, H, k = 520, 360, 700.0
    sc = Scene(W, H, px_per_m=k, noise=1.5, blur=0.6, seed=5)
    # Origin at the first marker; second marker 0.18 m above it.
    sc.add(*marker_texture([3, 4], [(0.0, 0.0), (0.0, 0.18)], 0.07, (0.12, 0.32), origin_m=(-0.06, -0.06)))
    n = 20
    theta = np.linspace(-0.1, 0.12, n)
    frames = []
    for i in range(n):
        f = sc.render([(0.0, -0.1, theta[i])])
        if i >= 10:
            f[:160, :] = 100  # hide the upper marker (image rows 99..148)
        frames.append(f)
    cfg = TrackConfig.from_dict(
        {
            "targets": {"marker_size_m": 0.07},
            "reference": {"level": "none"},
            "objects": [{"id": "b", "markers": [3, 4]}],
        }
    )
    res = assemble_tracks(track_frames(frames, cfg), cfg, FPS, W, H)
    b = res["b"]
    assert np.all(b.status == "ok")
    assert np.sqrt(np.mean(np.degrees(b.theta_rad - theta) ** 2)) < 0.1
    # Fewer points -> lower quality and larger sigma once one marker is hidden.
    assert np.median(b.quality[10:]) < 0.6 * np.median(b.quality[:10])
    assert np.median(b.sigma_theta_rad[10:]) > 1.5 * np.median(b.sigma_theta_rad[:10])
    # The position is the first marker's centre throughout.
    assert np.all(np.abs(b.x_m - 0.0) < 1e-3) and np.all(np.abs(b.y_m + 0.1) < 1e-3)


def test_track_video_file_matches_in_memory(tmp_path):
    W, H, k = 400, 300, 800.0
    sc = _scene(W, H, k, seed=1)
    n = 12
    t, theta, xt = _truth(n)
    frames = [sc.render([(xt[i], 0.04, theta[i]), (xt[i], -0.11, 0.0)]) for i in range(n)]
    write_video(tmp_path / "v.mkv", frames, FPS)
    cfg = _config()
    res = track_video(tmp_path / "v.mkv", cfg)
    assert res.fps == FPS and res.n_frames == n
    mem = assemble_tracks(track_frames(frames, cfg), cfg, FPS, W, H)
    np.testing.assert_allclose(res["block_1"].theta_rad, mem["block_1"].theta_rad, atol=1e-12)
    df = res.to_frame()
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
    assert len(df) == 2 * n
    np.testing.assert_allclose(df.loc[df.object == "block_1", "t_s"], np.arange(n) / FPS)
    # a frame range keeps absolute frame numbers and times
    part = track_video(tmp_path / "v.mkv", _config(video={"start_frame": 4, "stop_frame": 9}))
    np.testing.assert_array_equal(part["block_1"].frame, np.arange(4, 9))
    # (the level is the median table angle over the tracked frames, so compare unlevelled)
    np.testing.assert_allclose(
        part["block_1"].theta_rad + part.level_rad, mem["block_1"].theta_rad[4:9] + mem.level_rad, atol=1e-5
    )


@pytest.mark.parametrize("with_K", [True, False])
def test_tilted_camera_plane_from_table_markers(with_K):
    """Camera pitched/yawed by ~3°: the table's two markers give the plane homography
    (planar PnP with K, else a homography fit), removing the perspective bias of θ."""
    W, H, k = 960, 540, 900.0
    sc = Scene(W, H, px_per_m=k, tilt_rad=(0.05, -0.045), roll_rad=0.008, noise=1.5, blur=0.6, seed=11)
    sc.add(*marker_texture([1], [(0.0, 0.0)], 0.08, (0.12, 0.2), origin_m=(-0.06, -0.1)))
    sc.add(*marker_texture([0, 7], [(-0.2, 0.0), (0.2, 0.0)], 0.05, (0.5, 0.07), origin_m=(-0.25, -0.035)))
    n = 16
    t, theta, xt = _truth(n)
    bx = 0.18  # block off-centre, where perspective distorts angles most
    frames = [sc.render([(bx + xt[i], 0.08, theta[i]), (xt[i], -0.15, 0.0)]) for i in range(n)]
    d = {
        "targets": {"marker_size_m": 0.08},
        "objects": [
            {"id": "block_1", "markers": [1]},
            {
                "id": "table",
                "kind": "table",
                "markers": [0, 7],
                "marker_size_m": 0.05,
                "marker_positions_m": [[-0.2, 0.0], [0.2, 0.0]],
            },
        ],
    }
    if with_K:
        d["video"] = {"camera_matrix": sc.K.tolist()}
    else:
        d["reference"] = {"plane": "table"}  # "auto" needs K for this; force the homography fit
    cfg = TrackConfig.from_dict(d)
    res = assemble_tracks(track_frames(frames, cfg), cfg, FPS, W, H)
    assert res.plane == "table"
    b, tab = res["block_1"], res["table"]
    rms = np.sqrt(np.mean(np.degrees(b.theta_rad - theta) ** 2))
    assert rms <= 0.05
    # positions are absolute in the table frame of the first frame (table origin at (0, -0.15))
    assert np.sqrt(np.mean((b.x_m - (bx + xt - xt[0])) ** 2 + (b.y_m - 0.23) ** 2)) < 3e-4
    assert np.sqrt(np.mean((tab.x_m - (xt - xt[0])) ** 2)) < 1e-4
    # the same frames through centred pixels (no plane): a visible perspective bias
    d["reference"] = {"plane": "image"}
    cfg_img = TrackConfig.from_dict(d)
    res_img = assemble_tracks(track_frames(frames, cfg_img), cfg_img, FPS, W, H)
    assert res_img.plane == "image"
    assert np.sqrt(np.mean(np.degrees(res_img["block_1"].theta_rad - theta) ** 2)) > 2 * rms


def test_blurred_frames_are_flagged_blur():
    import cv2

    W, H, k = 400, 300, 800.0
    sc = _scene(W, H, k, seed=4)
    n = 14
    t, theta, xt = _truth(n)
    frames = [sc.render([(0.0, 0.04, theta[i]), (0.0, -0.11, 0.0)]) for i in range(n)]
    for i in (6, 7, 8):
        frames[i] = cv2.GaussianBlur(frames[i], (0, 0), 7.0)  # a camera shake
    cfg = _config()
    res = assemble_tracks(track_frames(frames, cfg), cfg, FPS, W, H)
    st = res["block_1"].status
    assert list(st[6:9]) == ["blur"] * 3
    assert np.all(st[:6] == "ok") and np.all(st[9:] == "ok")


def test_plane_table_without_what_it_needs_is_an_input_error():
    from rocklab import InputError

    sc = _scene(320, 240, 600.0)
    frames = [sc.render([(0.0, 0.04, 0.0), (0.0, -0.11, 0.0)])]
    cfg = _config(reference={"plane": "table"})  # one table marker, no camera matrix
    with pytest.raises(InputError, match="'reference.plane'"):
        list(track_frames(frames, cfg))


def _small_marker_film(n=30):
    """A B9M-like face (two 28 mm markers 0.186 m apart) at 550 px/m: 15 px markers, 2.6 px per
    cell, rocking to 5.7 deg, each frame through JPEG (quality 95) as a camcorder's compression."""
    import cv2

    sc = Scene(480, 270, px_per_m=550.0, noise=2.0, blur=0.6, seed=1)
    sc.add(*marker_texture([1, 2], [(0.0, -0.093), (0.0, 0.093)], 0.028, (0.046, 0.372), origin_m=(-0.023, -0.186)))
    theta = 0.1 * np.sin(2 * np.pi * (np.arange(n) / FPS) / 0.9)
    frames = []
    for th in theta:
        jpg = cv2.imencode(".jpg", sc.render([(0.0, 0.0, th)]), [cv2.IMWRITE_JPEG_QUALITY, 95])[1]
        frames.append(cv2.imdecode(jpg, cv2.IMREAD_GRAYSCALE))
    cfg = TrackConfig.from_dict(
        {
            "targets": {"style": "aruco", "marker_size_m": 0.028},
            "objects": [{"id": "b", "markers": [1, 2], "marker_positions_m": [[0.0, -0.093], [0.0, 0.093]]}],
        }
    )
    return frames, theta, cfg


def _markers_found(frames, cfg):
    from rocklab.tracking.video._plane import make_plane_map
    from rocklab.tracking.video.targets._aruco import ArucoDetector

    det = ArucoDetector(cfg, make_plane_map(cfg, 480, 270, frames[0]))
    return np.array([len(det.find(g, i)) for i, g in enumerate(frames)])


@pytest.mark.parametrize("upscale, below_px", [(3, 40.0), (3, 20.0), (4, 40.0)])
def test_small_markers_found_together_and_poses_within_half_a_degree(monkeypatch, upscale, below_px):
    """Issue 25: the demo's B9M markers (13 px) were missed one at a time under H.264; the angle then
    came from one small marker (1.5-2.5 deg off), 33 of 200 poses were refused and some passed.
    A missed small marker is decoded again from an upscaled window, and one marker's pose puts its
    sibling's window. Here: both markers on 27 of 30 frames (8 of 30 without), 27 poses ok, the
    largest error 0.14 deg (0.34 deg with 4x). A frame showing one of the two small markers gives
    no pose (``one_marker``): from one marker the angle was 0.8 deg off under JPEG quality 85."""
    from rocklab.tracking.video.targets import _aruco

    frames, theta, cfg = _small_marker_film()
    monkeypatch.setattr(_aruco, "UPSCALE", upscale)
    monkeypatch.setattr(_aruco, "UPSCALE_BELOW_PX", below_px)
    n_found = _markers_found(frames, cfg)
    assert np.sum(n_found == 2) >= 24
    with collecting():
        obs = [o[0] for o in track_frames(frames, cfg)]
    status = np.array([o.status for o in obs])
    ok = status == "ok"
    err = np.rad2deg(np.array([o.theta_rad for o in obs]) - theta)
    assert ok.sum() >= 24 and np.max(np.abs(err[ok])) <= 0.5
    assert np.all(status[n_found == 1] == "one_marker") and np.all(n_found[ok] == 2)
    # without either (the window's two detectors and the full frame only): most frames show one marker
    monkeypatch.setattr(_aruco, "UPSCALE_BELOW_PX", 0.0)
    monkeypatch.setattr(_aruco.ArucoDetector, "_from_sibling", lambda self, o, m, found: None)
    assert np.sum(_markers_found(frames, cfg) == 2) <= 15
