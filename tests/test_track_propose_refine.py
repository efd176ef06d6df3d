"""``track init`` proposals on scenes the first-frame change mask alone gets wrong: a disc turning
on a pin (only its mark moves), an object that starts to move late (a struck puck), and an
object a hand holds at first and lets go of (the hand leaves the frame).

Rendered scenes with their truth boxes; the real films (PhysTrack's RollingCylinder and
RotationOnAFixedPivot/R1, read from the fetch mirror, never shipped; skipped without it) with
boxes hand-labelled on their first frame."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests._mirror import mirror_file


def _iou(a, b):
    ix = max(0.0, min(a[0] + a[2], b[0] + b[2]) - max(a[0], b[0]))
    iy = max(0.0, min(a[1] + a[3], b[1] + b[3]) - max(a[1], b[1]))
    return ix * iy / (a[2] * a[3] + b[2] * b[3] - ix * iy)


def _wall(rng, H, W):
    import cv2

    yy, xx = np.mgrid[0:H, 0:W].astype(np.float32)
    return 70 + 20 * xx / W + cv2.GaussianBlur(rng.uniform(0, 30, (H, W)).astype(np.float32), (0, 0), 3)


def _finish(f, rng):
    import cv2

    f = cv2.GaussianBlur(f.astype(np.float32), (0, 0), 0.7) + rng.normal(0, 1.5, f.shape)
    return np.clip(f, 0, 255).astype(np.uint8)


def _turning_disc(centre, R, deg_per_frame, n=45, size=(240, 320), seed=0):
    """A bright disc of radius ``R`` px on a pin at ``centre``, a dark mark at 0.8 R, at rest for
    5 frames and then turning ``deg_per_frame``; its outline never moves. Frames, disc box."""
    import cv2

    rng = np.random.default_rng(seed)
    H, W = size
    wall = _wall(rng, H, W)
    cx, cy = centre
    frames = []
    for k in range(n):
        f = wall.copy()
        cv2.circle(f, (int(cx * 16), int(cy * 16)), int(R * 16), 215.0, -1, cv2.LINE_AA, 4)
        cv2.circle(f, (int(cx * 16), int(cy * 16)), 2 * 16, 40.0, -1, cv2.LINE_AA, 4)  # the pin
        a = np.radians(-90 + deg_per_frame * max(k - 5, 0))
        mx, my = cx + 0.8 * R * np.cos(a), cy + 0.8 * R * np.sin(a)
        cv2.circle(f, (int(round(mx * 16)), int(round(my * 16))), int(0.09 * R * 16), 35.0, -1, cv2.LINE_AA, 4)
        frames.append(_finish(f, rng))
    return frames, (cx - R, cy - R, 2 * R, 2 * R)


@pytest.mark.parametrize("centre, R, speed", [((160, 120), 70, 9.0), ((200, 110), 55, -6.0), ((130, 125), 85, 12.0)])
def test_a_disc_turning_on_a_pin_is_proposed_whole(centre, R, speed):
    """Only the mark moves: the change mask proposed the mark's first place, a box of 0.01-0.02
    of the disc's (IoU 0.01-0.03); the disc is proposed (IoU >= 0.8), and nothing else."""
    from rocklab.tracking.video import propose_objects

    frames, truth = _turning_disc(centre, R, speed)
    p = propose_objects(frames[0], frames[1:])
    assert len(p.blocks) == 1, p
    assert _iou(p.blocks[0], truth) >= 0.8, (p.blocks, truth)


def test_a_mark_moving_over_a_still_panel_is_no_turning_disc():
    """The same bright disc, still, with a mark sliding straight across it: what changes inside
    keeps no distance from its centre, so the mark is proposed, not the disc."""
    import cv2

    from rocklab.tracking.video._propose import moving_boxes, turning_region

    rng = np.random.default_rng(1)
    wall = _wall(rng, 240, 320)
    frames = []
    for k in range(40):
        f = wall.copy()
        cv2.circle(f, (160, 120), 70, 215.0, -1, cv2.LINE_AA)
        cv2.circle(f, (int(110 + 2.5 * k), 100), 6, 35.0, -1, cv2.LINE_AA)
        frames.append(_finish(f, rng))
    boxes, _ = moving_boxes(frames[0], frames[1:])
    changed, scale = moving_boxes(frames[0], frames[1:], masks=True)
    assert boxes and all(turning_region(frames[0], changed, scale, b) is None for b in boxes)


def _square(f, x, y, tex):
    s = tex.shape[0]
    x, y = int(round(x)), int(round(y))
    f[y : y + s, x : x + s] = tex


def test_an_object_that_starts_late_is_proposed_too():
    """Square A slides from frame 3; square B rests until frame 20 of 36, when A reaches it, then
    slides on. B left its place in 16 of 35 samples, fewer than half: it was not proposed. Both
    are now, each round its own square (to 4 px: the blur and the closing of gaps pad each side by 2)."""
    from rocklab.tracking.video import propose_objects

    rng = np.random.default_rng(3)
    wall = _wall(rng, 240, 320)
    ta, tb = rng.uniform(120, 250, (30, 30)), rng.uniform(120, 250, (26, 26))
    frames = []
    for k in range(36):
        f = wall.copy()
        _square(f, 20 + 3.0 * min(max(k - 3, 0), 17), 100, ta)
        _square(f, 170 + 4.0 * max(k - 20, 0), 102, tb)
        frames.append(_finish(f, rng))
    p = propose_objects(frames[0], frames[1:])
    assert len(p.blocks) == 2, p.blocks
    for box, truth in zip(sorted(p.blocks), [(20, 100, 30, 30), (170, 102, 26, 26)]):
        assert np.allclose(box, truth, atol=4), (p.blocks, truth)


def _hand_scene(n=45, size=(240, 320), seed=4, obj=(200, 90), side=36):
    """A textured square held at its right side by a hand-like blob (a skin-grey ellipse and an
    arm out to the frame's right edge) for 6 frames; the hand then pulls out of the frame at 8 px
    a frame and the square slides left at 1.5 px a frame. Frames, the square's first box."""
    import cv2

    rng = np.random.default_rng(seed)
    H, W = size
    wall = _wall(rng, H, W)
    tex = rng.uniform(150, 250, (side, side))
    skin = cv2.GaussianBlur(rng.uniform(110, 170, (H, W)).astype(np.float32), (0, 0), 1.5)
    frames = []
    for k in range(n):
        f = wall.copy()
        _square(f, obj[0] - 1.5 * max(k - 6, 0), obj[1], tex)
        hx = obj[0] + side - 4 + 8 * max(k - 6, 0)
        hand = np.zeros((H, W), np.uint8)
        cv2.ellipse(hand, (int(hx + 14), obj[1] + side // 2), (16, 22), 0, 0, 360, 1, -1)
        cv2.rectangle(hand, (int(hx + 14), obj[1] + 4), (W, obj[1] + side - 4), 1, -1)
        f = np.where(hand > 0, skin, f)
        frames.append(_finish(f, rng))
    return frames, (obj[0], obj[1], side, side)


@pytest.mark.parametrize("seed, obj, side", [(4, (200, 90), 36), (5, (180, 120), 44)])
def test_the_hand_that_lets_go_is_not_in_the_proposal(seed, obj, side):
    """The first-frame change mask holds the square and the hand that leaves: one box from the
    square to the frame's edge (IoU with the square 0.18-0.23). The square, found in the first
    frame as it moves on alone, is proposed (IoU >= 0.7)."""
    from rocklab.tracking.video import propose_objects

    frames, truth = _hand_scene(seed=seed, obj=obj, side=side)
    p = propose_objects(frames[0], frames[1:])
    assert len(p.blocks) == 1, p.blocks
    assert _iou(p.blocks[0], truth) >= 0.7, (p.blocks, truth)


def _proposed(run_cli, film, tmp_path):
    """The proposed objects' boxes and whether a note calls one a turning disc."""
    rc, out, err = run_cli("track", "init", film, "-o", tmp_path / "t.toml", "--json")
    assert rc == 0, err
    d = json.loads(out)
    boxes = [[float(v) for v in p.split("=")[1].split(",")] for p in d["proposed"] if "--object" in p]
    return boxes, any("turning on a pin" in n for n in d["notes"])


def test_real_films_turning_disc_and_released_disc(tmp_path_factory, tmp_path, run_cli):
    """PhysTrack's disc turning on a pin (RotationOnAFixedPivot/R1.MP4; only its mark moves; before:
    the mark's 11 x 11 px box and a 13 x 14 px box on its rim) and its disc rolling down a slope
    from a hand (RollingCylinder.MP4; before: one 52 x 50 px box of the disc and the fingers to the
    frame's edge). Hand-labelled on frame 0: R1's disc spans x 103-293, y 12-208 px; the rolling
    disc x 277-306, y 100-130 px, the fingers from x 300 to the edge at 320."""
    r1 = mirror_file(tmp_path_factory, "umartechboy/PhysTrack", "SampleVideos/RotationOnAFixedPivot/R1.MP4")
    (box,), turning = _proposed(run_cli, r1, tmp_path)
    assert _iou(box, (103, 12, 190, 196)) >= 0.8 and turning, box
    # its angle is not what the whole disc's registration gives (within 2 deg through 9.6 turns):
    # the config tracks its position only
    assert 'kind = "point"' in (tmp_path / "t.toml").read_text()
    roll = mirror_file(tmp_path_factory, "umartechboy/PhysTrack", "SampleVideos/RollingCylinder.MP4")
    (box,), turning = _proposed(run_cli, roll, tmp_path)
    assert box[0] + box[2] < 320 and _iou(box, (277, 100, 29, 30)) >= 0.6 and not turning, box
    assert 'kind = "point"' not in (tmp_path / "t.toml").read_text()
