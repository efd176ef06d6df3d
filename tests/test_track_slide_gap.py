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

import pytest

from _ball_scene import PATH, striped_ball, striped_wall, watched_tracker
from _ball_scene import pose as _pose


def _frame(wall, centre, seed=1):
    return striped_ball(wall, centre, seed=seed)


@pytest.fixture()
def slid():
    wall = striped_wall()
    tr = watched_tracker(lambda c, seed: _frame(wall, c, seed))
    tr.verifier.recent = []  # a slide (``drift``): the motion checks forget its poses
    return tr, wall, PATH[-1], 16 + 3


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
