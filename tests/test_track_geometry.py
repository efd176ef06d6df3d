"""Geometry: similarity fit, board homography and camera calibration from rendered boards."""

from __future__ import annotations

import numpy as np
import pytest

from _render import Scene, checker_texture, marker_texture
from rocklab import InputError
from rocklab.config import BoardConfig, TrackConfig
from rocklab.tracking import assemble_tracks, calibrate_camera, fit_similarity, track_frames

BOARD = {"kind": "checkerboard", "squares_x": 9, "squares_y": 6, "square_m": 0.02}


def test_similarity_fit_exact_and_sigma_matches_monte_carlo():
    rng = np.random.default_rng(0)
    p = rng.uniform(-0.1, 0.1, (6, 2))
    th, k, t = 0.3, 950.0, np.array([12.0, -7.0])
    R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    q = k * p @ R.T + t
    f = fit_similarity(p, q)
    assert f.theta_rad == pytest.approx(th, abs=1e-12) and f.scale == pytest.approx(k, rel=1e-12)
    np.testing.assert_allclose(f.t, t, atol=1e-9)
    # with noise, the reported sigma is the scatter of theta over repeats
    sig = 0.3
    fits = [fit_similarity(p, q + rng.normal(0, sig, q.shape)) for _ in range(2000)]
    spread = np.std([g.theta_rad for g in fits])
    assert np.median([g.sigma_theta_rad for g in fits]) == pytest.approx(spread, rel=0.15)
    # a rigid fit keeps the given scale
    assert fit_similarity(p, q, scale=k).theta_rad == pytest.approx(th, abs=1e-12)


def test_board_gives_metric_plane_under_perspective():
    """A checkerboard in frame 0 fixes the plane (origin: its top-left inner corner, y up)."""
    W, H, k = 960, 540, 900.0
    sc = Scene(W, H, px_per_m=k, tilt_rad=(0.05, -0.045), roll_rad=0.01, noise=1.5, blur=0.6, seed=2)
    sc.add(*checker_texture(9, 6, 0.02))
    sc.add(*marker_texture([1], [(0.0, 0.0)], 0.08, (0.12, 0.2), origin_m=(-0.06, -0.1)))
    n = 8
    theta = np.linspace(-0.05, 0.05, n)
    # the board is shown in frame 0 only, then taken away
    frames = [sc.render([(-0.25, 0.1, 0.0) if i == 0 else (5.0, 5.0, 0.0), (0.2, 0.0, theta[i])]) for i in range(n)]
    cfg = TrackConfig.from_dict(
        {
            "video": {"camera_matrix": sc.K.tolist()},
            "targets": {"marker_size_m": 0.08},
            "reference": {"board": BOARD},
            "objects": [{"id": "b", "markers": [1]}],
        }
    )
    res = assemble_tracks(track_frames(frames, cfg), cfg, 50.0, W, H)
    assert res.plane == "board"
    b = res["b"]
    assert np.sqrt(np.mean(np.degrees(b.theta_rad - theta) ** 2)) <= 0.05
    # block marker at world (0.2, 0); board origin at world (-0.25, 0.1)
    assert np.sqrt(np.mean((b.x_m - 0.45) ** 2 + (b.y_m + 0.1) ** 2)) < 3e-4


def test_board_missing_is_an_input_error():
    sc = Scene(320, 240, px_per_m=600.0, seed=1)
    sc.add(*marker_texture([1], [(0.0, 0.0)], 0.08, (0.12, 0.2), origin_m=(-0.06, -0.1)))
    frames = [sc.render([(0.0, 0.0, 0.0)])]
    cfg = TrackConfig.from_dict(
        {"targets": {"marker_size_m": 0.08}, "reference": {"board": BOARD}, "objects": [{"id": "b", "markers": [1]}]}
    )
    with pytest.raises(InputError, match="checkerboard 9x6"):
        list(track_frames(frames, cfg))


def test_calibrate_camera_recovers_focal_length(tmp_path):
    W, H, f = 640, 480, 700.0
    frames = []
    for i, (ax, ay) in enumerate([(0.3, 0.0), (-0.3, 0.1), (0.0, 0.35), (0.2, -0.3), (-0.2, -0.25), (0.1, 0.2)]):
        sc = Scene(W, H, px_per_m=f, tilt_rad=(ax, ay), noise=1.0, blur=0.6, seed=i)
        sc.add(*checker_texture(9, 6, 0.03))
        frames.append((i, sc.render([(-0.12, 0.075, 0.0)])))
    K, dist, rms = calibrate_camera(
        frames, BoardConfig(squares_x=9, squares_y=6, square_m=0.03), every=1, out=tmp_path / "cal.npz"
    )
    assert rms < 0.1
    assert K[0, 0] == pytest.approx(f, rel=0.01) and K[1, 1] == pytest.approx(f, rel=0.01)
    with np.load(tmp_path / "cal.npz") as z:
        np.testing.assert_allclose(z["camera_matrix"], K)


def test_charuco_board_plane():
    import cv2

    from _render import TEX

    W, H, k = 960, 540, 900.0
    d = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50)
    tex = cv2.aruco.CharucoBoard((7, 5), 0.03, 0.022, d).generateImage((int(0.21 * TEX), int(0.15 * TEX)))
    sc = Scene(W, H, px_per_m=k, tilt_rad=(0.04, -0.03), roll_rad=0.01, noise=1.5, blur=0.6, seed=2)
    sc.add(tex, (-0.5, -0.5))  # origin: the board's top-left corner (OpenCV's board frame)
    sc.add(*marker_texture([30], [(0.0, 0.0)], 0.08, (0.12, 0.2), origin_m=(-0.06, -0.1)))
    n = 5
    theta = np.linspace(-0.05, 0.05, n)
    frames = [sc.render([(-0.4, 0.2, 0.0) if i == 0 else (5.0, 5.0, 0.0), (0.2, 0.0, theta[i])]) for i in range(n)]
    cfg = TrackConfig.from_dict(
        {
            "video": {"camera_matrix": sc.K.tolist()},
            "targets": {"marker_size_m": 0.08},
            "reference": {
                "board": {"kind": "charuco", "squares_x": 7, "squares_y": 5, "square_m": 0.03, "marker_m": 0.022}
            },
            "objects": [{"id": "b", "markers": [30]}],
        }
    )
    res = assemble_tracks(track_frames(frames, cfg), cfg, 50.0, W, H)
    b = res["b"]
    assert res.plane == "board"
    assert np.sqrt(np.mean(np.degrees(b.theta_rad - theta) ** 2)) <= 0.05
    assert np.sqrt(np.mean((b.x_m - 0.6) ** 2 + (b.y_m + 0.2) ** 2)) < 1e-3
