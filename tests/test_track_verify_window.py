"""The verifier's learned limits read their statistics from a kept-sorted window (issue 25: the
cost of verification); they must be numpy's own, bit for bit, or a verdict could change.

The reference is ``np.median`` and ``np.percentile`` (linear) of the same last values, recomputed
from scratch at every step; the windows roll past their length, hold ties (integer values),
values spread over orders of magnitude, and NaNs (numpy then answers NaN).
"""

from __future__ import annotations

import collections
import math

import numpy as np
import pytest

from rocklab.tracking.video.targets._verify import Window


def _same(a: float, b: float) -> bool:
    return a == b or (math.isnan(a) and math.isnan(b))


@pytest.mark.parametrize("kind", ["uniform", "ties", "lognormal", "nans"])
def test_window_statistics_are_numpys(kind):
    rng = np.random.default_rng(len(kind))
    for maxlen in (1, 2, 7, 300):
        w, ref = Window(maxlen), collections.deque(maxlen=maxlen)
        for _ in range(2 * maxlen + 40):
            x = {
                "uniform": lambda: rng.random(),
                "ties": lambda: float(rng.integers(0, 4)),
                "lognormal": lambda: rng.lognormal(0.0, 3.0),
                "nans": lambda: math.nan if rng.random() < 0.05 else rng.normal(0.0, 1e3),
            }[kind]()
            w.append(x)
            ref.append(float(x))
            assert len(w) == len(ref) and all(_same(a, b) for a, b in zip(w, ref))
            assert _same(w.median(), float(np.median(ref)))
            for q in (99, 50, 1, 37.3):
                assert _same(w.percentile(q), float(np.percentile(ref, q))), (maxlen, q)


def test_empty_window_has_no_statistics():
    w = Window(5)
    assert math.isnan(w.median()) and math.isnan(w.percentile(99)) and len(w) == 0


def test_snapshot_warp_keeps_the_frames_patch():
    """The verifier's background check warps a scene snapshot by the pose being checked; the
    frame's own patch, which the tracker's later steps read for the same pose, stays cached (the
    same array is returned, not warped again) and equals a fresh warp."""
    from _ball_scene import PATH, pose, striped_ball, striped_wall

    from rocklab.config import TrackConfig
    from rocklab.tracking.video import PlaneMap
    from rocklab.tracking.video.targets import MarkerlessTracker

    wall = striped_wall()
    cfg = TrackConfig.from_dict(
        {
            "targets": {"style": "markerless"},
            "reference": {"level": "none"},
            "objects": [{"id": "b", "roi": [42, 102, 36, 36]}],
        }
    )
    tr = MarkerlessTracker(cfg.objects[0], PlaneMap(*wall.shape[::-1]), striped_ball(wall, PATH[0]))
    gray, snap = striped_ball(wall, PATH[3], seed=2), striped_ball(wall, PATH[9], seed=3)
    W = pose(tr, PATH[3])
    patch = tr._warp_back(gray, W)
    other = tr._warp_back(snap, W, keep=False)
    assert tr._warp_back(gray, W) is patch
    assert np.abs(other - patch).mean() > 5.0  # the snapshot shows the wall there, not the ball
    tr._back = (None, None, None)
    assert np.array_equal(tr._warp_back(gray, W), patch)


def test_patch_statistics_are_numpys():
    """The patch statistics the verifier takes every frame (a patch's contrast, its correlation
    with another, the share of unchanged pixels) are numpy's ``std``, ``mean`` and sums of the
    float32 arrays, bit for bit, on whole patches and on windows cut from a larger one."""
    from rocklab.tracking.video.targets._verify import _ncc, _share, _std

    rng = np.random.default_rng(7)
    for k in range(300):
        big = (rng.random((94, 90)) * rng.uniform(0.01, 255)).astype(np.float32)
        a = big[10:-10, 10:-10] if k % 2 else big[10:-10, 10:-10].ravel()
        b = (rng.random(a.shape) * rng.uniform(0.01, 255)).astype(np.float32) + np.float32(rng.uniform(-1, 1)) * a
        da, db = a - a.mean(), b - b.mean()
        ref = float((da * db).sum() / (math.sqrt(float((da * da).sum()) * float((db * db).sum())) + 1e-9))
        assert _ncc(a, b) == ref
        assert _std(a) == float(a.std())
        m = np.abs(a - b) < 10.0
        assert _share(m) == float(np.mean(m))
