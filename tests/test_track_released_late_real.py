"""A ball let go from the hand after the verifier's limits are learned, from a real film nobody
tuned on (IzhanAlam/Object-Tracking-With-Kalman-Filter, ball.mp4 at d72e1e9, no licence file: read
from the fetch mirror, never shipped; skipped without it).

In the film the orange ball is held in a hand for frames 0-5 and dropped at 6-7: the release falls
inside the verifier's warm-up (15 verified frames), which tests/test_track_released_real.py covers.
Here the hold is made longer than the warm-up from the film's own frames: 0-5 played forwards and
backwards three times and forwards once more (36 frames of the hand holding the ball, moving a few
px), then the film from frame 6 on. Once warm, the learned correlation floor (the verified median
less six deviations of at least 0.05: 0.69) passed the fingers at 0.78 on the keyframe, and the
tracker reported them ``ok`` on film frames 7-14, 41-248 px from the ball (the box as drawn and the
box 120 % of it; the box moved by 10 % of its size: frame 7, 41 px). Independent reference: the
largest blob of orange pixels (HSV hue 3-22, saturation and value >= 150, opened by a 7 px ellipse),
whose centroid the session-18 review kit checked by eye within 2 px of the disc's centre on frames
14, 40, 60, 80 and 100. Film frames 0-6 (the ball in the hand, the fingers over it) are not judged.
"""

from __future__ import annotations

import numpy as np
import pytest

from _mirror import mirror_file

from rocklab._diagnostics import collecting
from rocklab.config import TrackConfig
from rocklab.tracking import iter_video_frames, track_video

#: the film's frames in the order played: the hold made longer, then the release and the fall
ORDER = [0, 1, 2, 3, 4, 5, 4, 3, 2, 1] * 3 + [0, 1, 2, 3, 4, 5] + list(range(6, 18))
BOX = (272, 67, 84, 84)


@pytest.fixture(scope="module")
def held(tmp_path_factory):
    """(folder of the frames as played, {film frame: the orange blob's centroid (2,)})."""
    import cv2

    film = mirror_file(
        tmp_path_factory,
        "IzhanAlam/Object-Tracking-With-Kalman-Filter",
        "ball.mp4",
        "d72e1e9a0838bf09c53c384a3eaff4bca80e4713",
    )
    frames = {f: bgr for f, _, bgr in iter_video_frames(film, 0, max(ORDER) + 1, color=True)}
    folder = tmp_path_factory.mktemp("held")
    for i, f in enumerate(ORDER):
        cv2.imwrite(str(folder / f"frame_{i:04d}.png"), frames[f])
    k = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (7, 7))
    blobs = {}
    for f, bgr in frames.items():  # no rocklab in the measure
        m = cv2.inRange(cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV), (3, 150, 150), (22, 255, 255))
        n, _, st, cen = cv2.connectedComponentsWithStats(cv2.morphologyEx(m, cv2.MORPH_OPEN, k))
        if n > 1:
            i = 1 + int(np.argmax(st[1:, cv2.CC_STAT_AREA]))
            if st[i, cv2.CC_STAT_AREA] >= 400:
                blobs[f] = np.asarray(cen[i])
    return folder, blobs


@pytest.mark.slow
@pytest.mark.parametrize("dx, dy, scale", [(0.0, 0.0, 1.0), (0.1, 0.1, 1.0), (0.0, 0.0, 1.2)])
def test_a_ball_let_go_after_the_warm_up_is_never_ok_on_the_fingers(held, dx, dy, scale):
    folder, blobs = held
    x, y, w, h = BOX
    cx, cy = x + w / 2 + dx * w, y + h / 2 + dy * h
    box = [round(cx - scale * w / 2), round(cy - scale * h / 2), round(scale * w), round(scale * h)]
    cfg = TrackConfig.from_dict(
        {
            "video": {"fps": 30.0},
            "targets": {"style": "markerless"},
            "reference": {"level": "none"},
            "objects": [{"id": "ball", "roi": box}],
        }
    )
    with collecting():  # lost frames and unmeasured angles are warned of: not what is checked here
        ball = track_video(folder, cfg)["ball"]
    # the reference agrees with the hand-checked crosses of the review kit (ref/izhan_ball.csv)
    assert np.hypot(*(blobs[14] - (315.1, 158.7))) < 2.0, blobs[14]
    released = ORDER.index(6)
    assert released > 15  # the verifier is warm when the hand lets go
    off = []
    for k, px, py, ok in zip(ball.frame, ball.x_px, ball.y_px, ball.ok):
        f = ORDER[int(k)]
        if ok and f >= 7 and (f not in blobs or np.hypot(px - blobs[f][0], py - blobs[f][1]) > 6.4):
            off.append((int(k), f, round(float(np.hypot(*(np.array([px, py]) - blobs.get(f, np.nan)))))))
    # 1 % of the frame's width, the tolerance; a frame without the ball in plain view
    # (the blob under 400 px: it is behind the fingers or a streak) has no ok pose to give
    assert not off, off
    # the ball held in the hand is followed until it is let go
    assert np.all(ball.ok[:released])
