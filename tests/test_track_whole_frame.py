"""The whole-frame search skips bare background and tries its next-best matches (issue 25).

On necros_ball.mp4 (a red ball on a string, a film nobody tuned on), with a 35 x 48 px box, the
ball slid off its outline at frame 178 and the whole-frame search's best match was a patch of the
wall on nearly every frame after: the check found it was the wall (``background``), and the ball,
in plain view, was never tried (177 frames lost). In grey the red ball is a smooth shading on a
beige wall, and its template matches bare wall (0.86-0.88) better than the ball (0.84-0.86).
Here it is rendered: the ball's scene (``_ball_scene``) with a copy of the ball painted on the wall
from the first frame on (so it is the still background), or a faint print of it that appears
later (a shadow-like copy: it fails the contrast check); after a slide and lost frames the ball
is back near where it was lost, its texture changed a little, so either copy matches the template
better than the ball does.
"""

from __future__ import annotations

import numpy as np
import pytest

from _ball_scene import striped_ball, striped_wall, watched_tracker

#: where the copy of the ball sits, and where the ball is found again (px)
COPY, BACK = (250.0, 60.0), (112.0, 131.0)


def _tracker(wall):
    """A tracker that watched the ball move on ``wall`` for 16 frames, then slid (its motion
    anchors forgotten) and lost it for 12 frames; and the frame number now."""
    tr = watched_tracker(lambda c, seed: striped_ball(wall, c, seed=seed))
    tr.verifier.recent = []
    return tr, 16 + 12


@pytest.fixture()
def painted():
    """The ball painted on the wall from the first frame on."""
    wall = striped_ball(striped_wall(), COPY, seed=50).astype(np.float32)
    return (*_tracker(wall), wall)


@pytest.fixture()
def printed():
    """A plain wall on which a faint print of the ball (a quarter of its contrast) appears later."""
    wall = striped_wall()
    tr, frame = _tracker(wall)
    ball = striped_ball(wall, COPY, seed=50).astype(np.float32)
    with_print = wall + 0.25 * (ball - wall)
    return tr, frame, striped_ball(with_print, BACK, look=0.4, seed=7)


def _centre(tr, W):
    return W[:, :2].astype(float) @ tr.centre0 + W[:, 2]


def test_bare_background_is_no_match_of_the_whole_frame_search(painted):
    from rocklab.tracking.video.targets import _verify

    tr, frame, wall = painted
    g = striped_ball(wall, BACK, look=0.25, seed=7)
    # without the background the painted copy is the best match, and its check says it is the wall
    first = _verify.whole_frame_peaks(tr, tr.key, g, 0.0)[0]
    assert np.hypot(*(_centre(tr, first) - COPY)) < 2.0
    assert tr.verifier.verify(tr, g, first, frame, 0.99) == "background"
    # with it, the ball is the best match, and the re-acquisition finds it
    first = _verify.whole_frame_peaks(tr, tr.key, g, 0.0, changed=tr.verifier._changed(g))[0]
    assert np.hypot(*(_centre(tr, first) - BACK)) < 2.0
    found = tr.verifier.reacquire(tr, g, frame, 0.6)
    assert found is not None and np.hypot(*(_centre(tr, found[0]) - BACK)) < 1.5


def test_the_ball_is_found_past_a_better_matching_faint_print(printed, monkeypatch):
    from rocklab.tracking.video.targets import _verify

    tr, frame, g = printed
    peaks = _verify.whole_frame_peaks(tr, tr.key, g, 0.0, changed=tr.verifier._changed(g))
    assert np.hypot(*(_centre(tr, peaks[0]) - COPY)) < 2.0  # the print matches best, and is faint
    assert tr.verifier.verify(tr, g, peaks[0], frame, 0.99) == "mismatch"
    found = tr.verifier.reacquire(tr, g, frame, 0.6)
    assert found is not None and np.hypot(*(_centre(tr, found[0]) - BACK)) < 1.5, found
    # the best match alone (the search before) loses the ball in plain view
    monkeypatch.setattr(_verify, "REACQUIRE_PEAKS", 1)
    assert tr.verifier.reacquire(tr, g, frame, 0.6) is None


def test_a_frame_without_the_ball_is_lost_whatever_the_peaks(painted):
    """Only the painted copy and bare wall: nothing is verified."""
    tr, frame, wall = painted
    g = np.clip(wall + np.random.default_rng(3).normal(0, 1.5, wall.shape), 0, 255).astype(np.uint8)
    assert tr.verifier.reacquire(tr, g, frame, 0.6) is None
