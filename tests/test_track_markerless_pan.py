"""A lit disc that turns its face dark while a hand-held camera pans (issue 25, kx_pendulum).

A rendered scene: a disc with a lit, textured face and a bright rim swings across a textured wall;
over 45 frames a dark front sweeps across its face (a watch on a chain turning its lit face away,
as review19's kx_pendulum does at f138-185 and f246-311), it stays dark for 10 frames and turns
lit again. The truth is the render's: the disc's centre, plus the camera's pan.

From a still camera the markerless tracker loses the dark frames (the keyframe is not renewed
from a view whose cells half match: :func:`._occlusion.partly_covered`), and no ok frame is off.
When the camera pans, the wall in the template's corners moves with it, the keyframe is renewed
on every frame of the sweep and follows the front: frames stay ``ok`` while their point lies up
to 4.6 px (1.4 % of the width) off the disc's centre; on the real film the same chain carried
the point 14-52 px onto the watch's rim (214 ok frames off at session 19's end). The panning
case is a strict xfail until that is fixed.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from rocklab.config import TrackConfig
from rocklab.tracking import assemble_tracks, track_frames

W, H, N, FPS = 320, 200, 100, 30.0
R = 30.0  # the disc's radius, px (its rim 4 px wide)
WRONG_PX = 0.01 * W  # an ok frame farther than 1 % of the width from the truth is wrong


def _centre(i: int) -> tuple[float, float]:
    """The disc's centre in the scene, px: a swing across the picture."""
    return 160.0 + 100.0 * math.sin(2 * math.pi * i / 80.0), 100.0 + 8.0 * math.cos(4 * math.pi * i / 80.0)


def _pan(i: int) -> tuple[float, float]:
    """The camera's pan, px (the whole scene moves by it)."""
    return 60.0 * math.sin(2 * math.pi * i / 140.0), 20.0 * math.sin(2 * math.pi * i / 100.0)


def _front(i: int) -> float:
    """Where the lit part of the face ends, px right of the disc's centre (R: all lit, -R: all dark)."""
    if i < 20:
        return R + 2
    if i < 65:
        return R + 2 - (i - 20) / 45 * (2 * R + 4)
    if i < 75:
        return -R - 2
    if i < 90:
        return -R - 2 + (i - 75) / 15 * (2 * R + 4)
    return R + 2


def _frames(pan: bool, seed: int = 0):
    """The film (grey uint8 frames) and the truth (N, 2): the disc's centre in the picture, px."""
    rng = np.random.default_rng(seed)
    face = cv2.GaussianBlur(rng.uniform(0, 1, (80, 80)).astype(np.float32), (0, 0), 1.5)
    face = 150 + 100 * (face - face.min()) / np.ptp(face)
    dark = 40 + 0.3 * (face - 150)
    yy, xx = np.mgrid[0:H, 0:W].astype(np.float32)
    wall = 90 + 0.1 * xx + 15 * np.sin(xx / 9.0) * np.sin(yy / 13.0)
    out, truth = [], []
    for i in range(N):
        px, py = _pan(i) if pan else (0.0, 0.0)
        cx, cy = _centre(i)
        cx, cy = cx + px, cy + py
        img = cv2.warpAffine(wall, np.float32([[1, 0, px], [0, 1, py]]), (W, H), borderMode=cv2.BORDER_REFLECT)
        dx, dy = xx - cx, yy - cy
        r = np.hypot(dx, dy)
        u, v = np.clip((dx + 40).astype(int), 0, 79), np.clip((dy + 40).astype(int), 0, 79)
        lit = np.where(dx < _front(i), face[v, u], dark[v, u])
        inside = np.clip(R - 4 - r + 0.5, 0, 1)
        rim = np.clip(R - r + 0.5, 0, 1) - inside
        img = img * (1 - inside - rim) + lit * inside + 200 * rim
        out.append(np.clip(img + rng.normal(0, 1.5, img.shape), 0, 255).astype(np.uint8))
        truth.append((cx, cy))
    return out, np.asarray(truth)


def _wrong_ok(pan: bool) -> tuple[int, int, float]:
    """(ok frames, ok frames off the truth by more than 1 % of the width, the largest such error px)."""
    frames, truth = _frames(pan)
    cx, cy = truth[0]
    cfg = TrackConfig.from_dict(
        {
            "targets": {"style": "markerless"},
            "reference": {"level": "none", "m_per_px": 1e-3},
            "objects": [{"id": "w", "kind": "block", "roi": [round(cx - 32), round(cy - 32), 64, 64]}],
        }
    )
    d = assemble_tracks(track_frames(frames, cfg), cfg, FPS, W, H)["w"]
    ok = np.asarray(d.status) == "ok"
    err = np.hypot(np.asarray(d.x_px) - truth[:, 0], np.asarray(d.y_px) - truth[:, 1])
    wrong = ok & (err > WRONG_PX)
    return int(ok.sum()), int(wrong.sum()), float(err[wrong].max()) if wrong.any() else 0.0


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_a_face_turning_dark_from_a_still_camera_is_lost_not_wrong():
    n_ok, n_wrong, worst = _wrong_ok(pan=False)
    assert n_ok >= 0.4 * N, n_ok  # the lit frames before the sweep and after it are tracked
    assert n_wrong == 0, (n_wrong, worst)


@pytest.mark.xfail(strict=True, reason="issue 25: under a pan the keyframe follows the dark front (kx_pendulum)")
@pytest.mark.filterwarnings("ignore::UserWarning")
def test_a_face_turning_dark_under_a_panning_camera_is_lost_not_wrong():
    n_ok, n_wrong, worst = _wrong_ok(pan=True)
    assert n_ok >= 0.4 * N, n_ok
    assert n_wrong == 0, (n_wrong, worst)
