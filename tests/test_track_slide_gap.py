"""A pose found after lost frames that followed a slide is doubted like any pose found after lost
frames: its round trip runs (issue 25).

On a ball thrown from the hand (trflorian_ball4.mp4, a film nobody tuned on) the outline check
refused a slide (``drift``), which makes the motion checks forget the slide's poses; four frames
later the keyframe, cut while ball and fingers flew together, matched the empty hand at 0.95,
116 px from the ball, and the pose was ``ok``: with no anchor the verifier counted a gap of one
frame, so a correlation that high was not doubtful and the forward-backward check, which had
refused the hand on the frame before (its round trip landed at the edge of the search), did not
run. Here: a tracker verifies 16 frames of a rendered ball, slides, loses 3 frames, and is offered
the ball where the keyframe's own frame showed it a few px aside (so the round trip misses);
that pose is ``roundtrip``, the same pose with a keyframe frame that agrees passes.
"""

from __future__ import annotations

import numpy as np
import pytest

from rocklab.config import TrackConfig
from rocklab.tracking.video import PlaneMap
from rocklab.tracking.video.targets import MarkerlessTracker

W, H, R = 320, 240, 14


def _wall(seed=0):
    import cv2

    rng = np.random.default_rng(seed)
    return cv2.GaussianBlur((rng.random((H, W)) * 30 + 140).astype(np.float32), (0, 0), 5)


def _frame(wall, centre, seed=1):
    import cv2

    yy, xx = np.mgrid[0:H, 0:W].astype(np.float32)
    nx, ny = (xx - centre[0]) / R, (yy - centre[1]) / R
    img = np.where(nx**2 + ny**2 < 1, 60 + 40 * (1 - ny) + 60 * (np.sin(4 * nx + 2 * ny) > 0), wall)
    img = cv2.GaussianBlur(img, (0, 0), 0.7) + np.random.default_rng(seed).normal(0, 1.5, (H, W))
    return np.clip(img, 0, 255).astype(np.uint8)


def _pose(tr, centre):
    return np.array([[1, 0, centre[0] - tr.centre0[0]], [0, 1, centre[1] - tr.centre0[1]]], np.float32)


@pytest.fixture()
def slid():
    wall = _wall()
    path = [(60.0 + 3 * k, 120.0 + 0.5 * k) for k in range(16)]
    cfg = TrackConfig.from_dict(
        {
            "targets": {"style": "markerless"},
            "reference": {"level": "none"},
            "objects": [{"id": "ball", "roi": [42, 102, 36, 36]}],
        }
    )
    tr = MarkerlessTracker(cfg.objects[0], PlaneMap(W, H), _frame(wall, path[0]))
    v = tr.verifier
    for k, c in enumerate(path):
        g = _frame(wall, c, seed=k + 2)
        assert v.verify(tr, g, _pose(tr, c), k, 0.97) is None, k
        v.confirm(g, tr.size)
    v.recent = []  # a slide (``drift``): the motion checks forget its poses
    return tr, wall, path[-1], 16 + 3


@pytest.mark.parametrize("aside", [(6.0, 0.0), (0.0, -7.0), (5.0, 5.0)])
def test_after_a_slide_and_lost_frames_the_round_trip_runs(slid, aside):
    tr, wall, at, frame = slid
    c = (at[0] + 4.0, at[1])
    # the keyframe was cut at the pose ``c`` from a frame that showed the ball ``aside`` of it
    tr.verifier.fb.keyframe(tr, _frame(wall, (c[0] + aside[0], c[1] + aside[1]), seed=70), _pose(tr, c))
    g = _frame(wall, c, seed=71)
    assert tr.verifier.verify(tr, g, _pose(tr, c), frame, 0.97) == "roundtrip"
    assert tr.verifier.fb.last_miss > tr.verifier.fb.limit()


def test_the_same_pose_with_a_keyframe_that_agrees_passes(slid):
    tr, wall, at, frame = slid
    c = (at[0] + 4.0, at[1])
    tr.verifier.fb.keyframe(tr, _frame(wall, c, seed=70), _pose(tr, c))
    assert tr.verifier.verify(tr, _frame(wall, c, seed=71), _pose(tr, c), frame, 0.97) is None
