"""A rendered ball that a markerless tracker's verifier has watched move: the scene the verifier
tests share (far re-acquisitions, slides, contrast). 320 x 240 px, ball radius 14 px; the ball
moves 3 px right and 0.5 px down a frame for 16 verified frames from (60, 120)."""

from __future__ import annotations

import cv2
import numpy as np

from rocklab.config import TrackConfig
from rocklab.tracking.video import PlaneMap
from rocklab.tracking.video.targets import MarkerlessTracker

W, H, R = 320, 240, 14
#: the 16 verified centres (px)
PATH = [(60.0 + 3 * k, 120.0 + 0.5 * k) for k in range(16)]


def striped_wall(seed=0):
    """A smooth wall, grey 140-170, shape (H, W) float32."""
    rng = np.random.default_rng(seed)
    return cv2.GaussianBlur((rng.random((H, W)) * 30 + 140).astype(np.float32), (0, 0), 5)


def striped_ball(wall, centre, look=0.0, seed=1):
    """The wall with a ball at ``centre`` (px): shaded top to bottom, its texture stripes turned
    by ``look`` (0: the ball; 1: a look-alike of the same size and shading, other stripes; 0.5:
    half of each); uint8, shape (H, W)."""
    yy, xx = np.mgrid[0:H, 0:W].astype(np.float32)
    nx, ny = (xx - centre[0]) / R, (yy - centre[1]) / R
    stripes = (1 - look) * (np.sin(4 * nx + 2 * ny) > 0) + look * (np.cos(5 * ny - 3 * nx) > 0)
    img = np.where(nx**2 + ny**2 < 1, 60 + 40 * (1 - ny) + 60 * stripes, wall)
    img = cv2.GaussianBlur(img, (0, 0), 0.7) + np.random.default_rng(seed).normal(0, 1.5, (H, W))
    return np.clip(img, 0, 255).astype(np.uint8)


def pose(tr, centre):
    """The upright pose that puts the template's centre at ``centre`` (px), shape (2, 3)."""
    return np.array([[1, 0, centre[0] - tr.centre0[0]], [0, 1, centre[1] - tr.centre0[1]]], np.float32)


def watched_tracker(frame, score=None):
    """A markerless tracker (box 36 x 36 px round the ball's first centre) whose verifier has
    verified and confirmed the ball on :data:`PATH`; ``frame(centre, seed)`` renders a frame,
    ``score(tracker, gray, centre)`` the fit's correlation (default 0.97)."""
    cfg = TrackConfig.from_dict(
        {
            "targets": {"style": "markerless"},
            "reference": {"level": "none"},
            "objects": [{"id": "ball", "roi": [42, 102, 36, 36]}],
        }
    )
    tr = MarkerlessTracker(cfg.objects[0], PlaneMap(W, H), frame(PATH[0], 1))
    v = tr.verifier
    for k, c in enumerate(PATH):
        g = frame(c, k + 2)
        cc = 0.97 if score is None else score(tr, g, c)
        assert v.verify(tr, g, pose(tr, c), k, cc) is None, k
        v.confirm(g, tr.size)
    return tr
