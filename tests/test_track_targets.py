"""Dot targets, markerless edges and the region tracker against rendered truth."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from _render import TEX, Scene, dots_texture, plain_texture
from rocklab._diagnostics import RocklabWarning
from rocklab.config import TrackConfig
from rocklab.tracking import assemble_tracks, track_frames
from rocklab.tracking.video.targets import dot_centroid

FPS = 50.0
ROLL = 0.01  # camera roll, rad: levelling from the table must remove it


def _truth(n):
    t = np.arange(n) / FPS
    return 0.08 * np.sin(2 * np.pi * t / 0.8), 0.02 * np.sin(2 * np.pi * t / 0.6)


def _textured_table(w_m=0.6, h_m=0.05, seed=1):
    rng = np.random.default_rng(seed)
    tt = (rng.random((int(h_m * TEX), int(w_m * TEX))) * 255).astype(np.uint8)
    tt = cv2.normalize(cv2.GaussianBlur(tt, (0, 0), 6), None, 60, 230, cv2.NORM_MINMAX)
    return tt, (w_m / 2 * TEX - 0.5, h_m / 2 * TEX - 0.5)  # origin at the table's centre


def _roi(sc, corner_a, corner_b):
    uv = sc.world_to_image([corner_a, corner_b])
    return [float(uv[0, 0]), float(uv[0, 1]), float(uv[1, 0] - uv[0, 0]), float(uv[1, 1] - uv[0, 1])]


def test_dot_centroid_is_subpixel():
    rng = np.random.default_rng(0)
    errs = []
    for _ in range(20):
        c = rng.uniform(30, 34, 2)
        img = np.full((64, 64), 200.0, np.float32)
        big = np.full((256, 256), 200, np.uint8)
        cv2.circle(
            big,
            (int(round((c[0] * 4 + 1.5) * 16)), int(round((c[1] * 4 + 1.5) * 16))),
            9 * 4 * 16,
            30,
            -1,
            cv2.LINE_AA,
            4,
        )
        img = cv2.resize(big, (64, 64), interpolation=cv2.INTER_AREA).astype(np.float32)
        img += rng.normal(0, 2.0, img.shape)
        u, v, d, _ = dot_centroid(np.clip(img, 0, 255).astype(np.uint8), c + 1.5, 16)
        errs.append(np.hypot(u - c[0], v - c[1]))
        assert d == pytest.approx(18, rel=0.1)
    assert np.sqrt(np.mean(np.square(errs))) < 0.03  # px


def test_dots_full_hd_rotation_accuracy():
    """Three dots on a 0.2 m block at 1800 px/m (a third of 1080 rows): RMS <= 0.05°."""
    sc = Scene(1920, 1080, px_per_m=1800.0, roll_rad=ROLL, noise=2.0, blur=0.7, seed=4)
    dots = [(0.0, 0.0), (0.0, 0.15), (0.06, 0.07)]
    sc.add(*dots_texture(dots, 0.02, (0.12, 0.2), origin_m=(-0.03, -0.025)))
    tdots = [(-0.15, 0.0), (0.15, 0.0)]
    sc.add(*dots_texture(tdots, 0.02, (0.5, 0.05), origin_m=(-0.25, -0.025)))
    n = 20
    theta, xt = _truth(n)
    frames = [sc.render([(xt[i], -0.05, theta[i]), (xt[i], -0.2, 0.0)]) for i in range(n)]
    cfg = TrackConfig.from_dict(
        {
            "targets": {"style": "dots", "dot_diameter_m": 0.02},
            "objects": [{"id": "b", "dots": dots}, {"id": "table", "kind": "table", "dots": tdots}],
        }
    )
    res = assemble_tracks(track_frames(frames, cfg), cfg, FPS, 1920, 1080)
    b, tab = res["b"], res["table"]
    assert np.all(b.status == "ok") and np.all(tab.status == "ok")
    assert res.level_rad == pytest.approx(ROLL, abs=1e-4)
    assert np.sqrt(np.mean(np.degrees(b.theta_rad - theta) ** 2)) <= 0.05
    assert np.sqrt(np.mean((tab.x_m - tab.x_m[0] - (xt - xt[0])) ** 2)) <= 1e-4
    # the dot layout gives the scale: block origin 0.05 m below the image centre
    assert np.mean(b.y_m) == pytest.approx(-0.05, abs=3e-4)


def test_edges_full_hd_rotation_accuracy():
    """Plain light block on a dark background, table levelled from its top edge: RMS <= 0.15°."""
    sc = Scene(1920, 1080, px_per_m=1800.0, roll_rad=ROLL, noise=2.0, blur=0.7, seed=5, background=(40, 70))
    sc.add(*plain_texture((0.1, 0.2), grey=215, origin_m=(-0.05, -0.1)))
    sc.add(*_textured_table())
    n = 20
    theta, xt = _truth(n)
    frames = [sc.render([(xt[i], -0.05, theta[i]), (xt[i], -0.2, 0.0)]) for i in range(n)]
    cfg = TrackConfig.from_dict(
        {
            "targets": {"style": "edges"},
            "objects": [
                {"id": "b", "roi": _roi(sc, (-0.06, 0.06), (0.06, -0.16)), "size_m": [0.1, 0.2]},
                {"id": "table", "kind": "table", "roi": _roi(sc, (-0.25, -0.16), (0.25, -0.21))},
            ],
        }
    )
    res = assemble_tracks(track_frames(frames, cfg), cfg, FPS, 1920, 1080)
    b, tab = res["b"], res["table"]
    assert np.all(b.status == "ok") and np.all(tab.status == "ok")
    assert res.level_rad == pytest.approx(ROLL, abs=5e-4)
    assert np.sqrt(np.mean(np.degrees(b.theta_rad - theta) ** 2)) <= 0.15
    # block centre position (size_m gives the scale), table motion from the region tracker
    assert np.sqrt(np.mean((b.x_m - xt) ** 2 + (b.y_m + 0.05) ** 2)) < 2e-4
    assert np.sqrt(np.mean((tab.x_m - tab.x_m[0] - (xt - xt[0])) ** 2)) <= 1e-4


def test_region_tracker_rotation_and_scale_from_m_per_px():
    W, H, k = 480, 360, 1000.0
    sc = Scene(W, H, px_per_m=k, noise=1.5, blur=0.6, seed=6)
    rng = np.random.default_rng(7)
    tex = (rng.random((int(0.15 * TEX), int(0.1 * TEX))) * 255).astype(np.uint8)
    tex = cv2.normalize(cv2.GaussianBlur(tex, (0, 0), 5), None, 40, 240, cv2.NORM_MINMAX)
    sc.add(tex, (0.05 * TEX - 0.5, 0.075 * TEX - 0.5))
    n = 25
    _, xt = _truth(n)
    theta = 0.35 * np.sin(2 * np.pi * np.arange(n) / FPS / 1.0)  # up to 20°: beyond LK windows
    frames = [sc.render([(xt[i], 0.0, theta[i])]) for i in range(n)]
    roi = _roi(sc, (-0.035, 0.05), (0.035, -0.05))
    cfg = TrackConfig.from_dict(
        {
            "targets": {"style": "region"},
            "reference": {"m_per_px": 1 / k, "level": "none"},
            "objects": [{"id": "b", "roi": roi, "theta0_rad": float(theta[0])}],
        }
    )
    res = assemble_tracks(track_frames(frames, cfg), cfg, FPS, W, H)
    b = res["b"]
    assert np.all(b.status == "ok")
    assert np.sqrt(np.mean(np.degrees(b.theta_rad - theta) ** 2)) <= 0.1
    assert np.sqrt(np.mean((b.x_m - xt) ** 2)) < 2e-4


def test_region_without_any_scale_keeps_pixels_and_leaves_metres_empty():
    sc = Scene(200, 150, px_per_m=500.0, seed=8)
    sc.add(*_textured_table(0.2, 0.1))
    frames = [sc.render([(0.01 * i, 0.0, 0.0)]) for i in range(3)]
    cfg = TrackConfig.from_dict(
        {
            "targets": {"style": "region"},
            "reference": {"level": "none"},
            "objects": [{"id": "t", "kind": "table", "roi": [60, 40, 80, 60]}],
        }
    )
    with pytest.warns(RocklabWarning, match="W-TRACK-NOSCALE"):  # never a made-up scale
        res = assemble_tracks(track_frames(frames, cfg), cfg, FPS, 200, 150)
    t = res["t"]
    assert np.all(np.isnan(t.x_m)) and np.isnan(t.m_per_unit)
    # the roi centre in pixels, moving 5 px per frame (0.01 m at 500 px/m)
    np.testing.assert_allclose(t.x_px, 100.0 + 5.0 * np.arange(3), atol=0.05)
    np.testing.assert_allclose(t.y_px, 70.0, atol=0.05)
    df = res.to_frame()
    assert list(df.columns[:7]) == ["frame", "t_s", "object", "x_px", "y_px", "x_m", "y_m"]


def test_apriltag_style():
    from _render import marker_texture

    W, H, k = 640, 400, 900.0
    sc = Scene(W, H, px_per_m=k, noise=1.5, blur=0.6, seed=1)
    sc.add(
        *marker_texture([5], [(0.0, 0.0)], 0.08, (0.12, 0.2), origin_m=(-0.06, -0.1), dictionary="DICT_APRILTAG_36h11")
    )
    n = 10
    theta = np.linspace(-0.1, 0.1, n)
    frames = [sc.render([(0.0, 0.0, theta[i])]) for i in range(n)]
    cfg = TrackConfig.from_dict(
        {
            "targets": {"style": "apriltag", "marker_size_m": 0.08},
            "reference": {"level": "none"},
            "objects": [{"id": "b", "markers": [5]}],
        }
    )
    assert cfg.targets.dictionary == "DICT_APRILTAG_36h11"  # the style's default
    res = assemble_tracks(track_frames(frames, cfg), cfg, FPS, W, H)
    b = res["b"]
    assert np.sqrt(np.mean(np.degrees(b.theta_rad - theta) ** 2)) <= 0.05
    assert b.m_per_unit == pytest.approx(1 / k, rel=2e-3)
