"""A ball let go from the hand drawn into its box, a real film nobody tuned on
(IzhanAlam/Object-Tracking-With-Kalman-Filter, ball.mp4 at d72e1e9, no licence file: read from the
fetch mirror, never shipped; skipped without it).

An orange ball held in a hand in frame 0 is dropped: it falls from frame ~6, bounces on the floor at
~10 and rises again at 12-14 while the hand, which held it from above, goes up. The box drawn round
the ball in the hand (272,67,84,84) holds the fingers as well. The verifier's limits are cold for
the first 15 verified frames (the correlation floor is 0.2), so the keyframe followed the fingers
at 0.77-0.96 and the tracker reported them ``ok`` on frames 7-14, up to 248 px from the ball in
plain view. Independent reference (the session-18 review kit's ``reference.py``): the largest blob
of orange pixels (HSV hue 3-22, saturation and value >= 150, opened by a 7 px ellipse); its centroid
was checked by eye within 2 px of the disc's centre on frames 14, 40, 60, 80 and 100. Frames 0-6
(the ball in the hand, the fingers over it) are not judged. The boxes: as drawn, moved by 10 % of
its size, and 120 % of it about its centre.
"""

from __future__ import annotations

import numpy as np
import pytest

from _blob import ball_config, moved_box
from _mirror import mirror_file

from rocklab._diagnostics import collecting
from rocklab.tracking import iter_video_frames, track_video

STOP, BOX = 30, (272, 67, 84, 84)


@pytest.fixture(scope="module")
def film(tmp_path_factory):
    return mirror_file(
        tmp_path_factory,
        "IzhanAlam/Object-Tracking-With-Kalman-Filter",
        "ball.mp4",
        "d72e1e9a0838bf09c53c384a3eaff4bca80e4713",
    )


def _orange_blobs(film):
    """{frame: centroid (2,)} of the largest orange blob (no rocklab in the measure)."""
    import cv2

    k = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (7, 7))
    out = {}
    for f, _, bgr in iter_video_frames(film, 0, STOP, color=True):
        m = cv2.inRange(cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV), (3, 150, 150), (22, 255, 255))
        n, _, st, cen = cv2.connectedComponentsWithStats(cv2.morphologyEx(m, cv2.MORPH_OPEN, k))
        if n > 1:
            i = 1 + int(np.argmax(st[1:, cv2.CC_STAT_AREA]))
            if st[i, cv2.CC_STAT_AREA] >= 400:
                out[f] = np.asarray(cen[i])
    return out


@pytest.mark.slow
@pytest.mark.parametrize("dx, dy, scale", [(0.0, 0.0, 1.0), (0.1, 0.1, 1.0), (0.0, 0.0, 1.2)])
def test_a_ball_let_go_is_never_ok_on_the_fingers(film, dx, dy, scale):
    box = moved_box(BOX, dx, dy, scale)
    cfg = ball_config(box, stop_frame=STOP)
    with collecting():  # lost frames and unmeasured angles are warned of: not what is checked here
        ball = track_video(film, cfg)["ball"]
    blobs = _orange_blobs(film)
    # the reference agrees with the hand-checked crosses of the review kit (ref/izhan_ball.csv)
    assert np.hypot(*(blobs[14] - (315.1, 158.7))) < 2.0, blobs[14]
    # 1 % of the frame's width, the tolerance
    off = [
        (int(k), round(float(np.hypot(px - blobs[k][0], py - blobs[k][1]))))
        for k, px, py, ok in zip(ball.frame, ball.x_px, ball.y_px, ball.ok)
        if ok and k >= 7 and k in blobs and np.hypot(px - blobs[k][0], py - blobs[k][1]) > 6.4
    ]
    assert not off, off
    # the ball held in the hand is followed until it is let go
    assert np.all(ball.ok[:6])
