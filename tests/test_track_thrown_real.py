"""A ball thrown and caught by hand, a real film nobody tuned on (trflorian/ball-tracking-live-plot,
media/ball4.mp4 at 2c6270af, MIT; read from the fetch mirror, never shipped; skipped without it).

The box is drawn round the green ball held in the hand on frame 140 (840,270,110,125: ball and
fingers). After the throw the keyframe, renewed while the ball flew and blurred, matched bare
wall beside the forearm at 0.90-0.99 (rotated 55-62 deg; a patch with a tenth of the ball's
contrast) and the tracker reported it ``ok`` 350-540 px from the ball on 15 frames. Independent
reference: the largest blob of green pixels per frame (HSV hue 35-90, saturation >= 50, value
>= 40, opened by 5 px; the session-16 review kit's ``ref_color.py``, its centroid checked by eye on
the ball on frames 140, 200 and 260). An ``ok`` frame is off the ball when its point is farther than
the ball's radius (from the blob's area) from both the blob's centroid and the centroid carried
by the box's offset in the first frame. Still not done: the point slides 13-23 px over the ball
held in the turning hand (the fingers are half the template), which this bound lets pass.
"""

from __future__ import annotations

import numpy as np
import pytest

from _mirror import mirror_file

from rocklab._diagnostics import collecting
from rocklab.config import TrackConfig
from rocklab.tracking import iter_video_frames, track_video

START, STOP, BOX = 140, 261, (840, 270, 110, 125)


@pytest.fixture(scope="module")
def film(tmp_path_factory):
    return mirror_file(tmp_path_factory, "trflorian/ball-tracking-live-plot", "media/ball4.mp4")


def _green_blobs(film):
    """{frame: (centroid (2,), radius px)} of the largest green blob (no rocklab in the measure)."""
    import cv2

    out = {}
    for k, _, bgr in iter_video_frames(film, START, STOP, color=True):
        hsv = cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV)
        m = cv2.morphologyEx(cv2.inRange(hsv, (35, 50, 40), (90, 255, 255)), cv2.MORPH_OPEN, np.ones((5, 5), np.uint8))
        n, _, st, cen = cv2.connectedComponentsWithStats(m)
        if n > 1:
            i = 1 + int(np.argmax(st[1:, cv2.CC_STAT_AREA]))
            out[k] = (np.asarray(cen[i]), float(np.sqrt(st[i, cv2.CC_STAT_AREA] / np.pi)))
    return out


@pytest.mark.slow
def test_a_thrown_ball_is_never_ok_off_the_ball(film):
    cfg = TrackConfig.from_dict(
        {
            "video": {"start_frame": START, "stop_frame": STOP},
            "targets": {"style": "markerless"},
            "reference": {"level": "none"},
            "objects": [{"id": "ball", "roi": list(BOX)}],
        }
    )
    with collecting():  # lost frames and unmeasured angles are warned of: not what is checked here
        ball = track_video(film, cfg)["ball"]
    blobs = _green_blobs(film)
    # the reference agrees with the review kit's (ref/trflorian_ball4.csv, whose cross the reviewer
    # checked on the ball by eye on these frames)
    for k, at in ((140, (891.2, 343.0)), (200, (704.5, 559.2)), (260, (375.2, 520.9))):
        assert np.hypot(*(blobs[k][0] - at)) < 6.0, (k, blobs[k][0])
    c0, r0 = np.array([BOX[0] + BOX[2] / 2, BOX[1] + BOX[3] / 2]), blobs[START][0]
    off = []
    for k, x, y, ok in zip(ball.frame, ball.x_px, ball.y_px, ball.ok):
        if ok and k in blobs:
            ref, rad = blobs[k]
            e = min(np.hypot(x - ref[0], y - ref[1]), np.hypot(*(np.array([x, y]) - ref - (c0 - r0))))
            if e > rad:
                off.append((int(k), round(float(e))))
    assert not off, off
    # the ball held before the throw is followed (frames 140-152 were ok before and are now)
    assert np.all(ball.ok[:13])
