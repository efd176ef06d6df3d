"""A tracker that lost its puck at a collision and found a puck again: which of two look-alikes it
is, told by how both moved before the loss (rocklab.tracking.video.targets._twins); and an angle
that steps and goes on from the step reports no angle from there (W-TRACK-THETA).

Constructed scenes with a known truth (fast); the real film is PhysTrack's CaromPuck/Rotation.MP4
(benchmarks/phystrack_films.py ``Rotation S base``), read through the mirror where it is."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from _mirror import mirror_file

from rocklab._diagnostics import collecting
from rocklab.config import TrackConfig
from rocklab.tracking import track_video
from rocklab.tracking.video._track import Observation, assemble_tracks
from rocklab.tracking.video.targets._twins import TwinGuard, match_peaks

R = 9  # puck radius, px


def _scene(pucks, seed=0):
    """A 240x320 grey frame: a textured table and white pucks with two dark dots, each given as
    ((x, y) px, dots' angle deg)."""
    rng = np.random.default_rng(seed)
    img = cv2.GaussianBlur((90 + 40 * rng.random((240, 320))).astype(np.float32), (0, 0), 2)
    for (x, y), a in pucks:
        cv2.circle(img, (int(round(x * 8)), int(round(y * 8))), R * 8, 230.0, -1, cv2.LINE_AA, 3)
        for s in (-1, 1):
            dx, dy = s * 4 * math.cos(math.radians(a)), s * 4 * math.sin(math.radians(a))
            cv2.circle(img, (int(round((x + dx) * 8)), int(round((y + dy) * 8))), 12, 40.0, -1, cv2.LINE_AA, 3)
    return np.clip(img, 0, 255).astype(np.uint8)


def _template(gray, c):
    x, y = int(round(c[0])), int(round(c[1]))
    return gray[y - R - 1 : y + R + 2, x - R - 1 : x + R + 2].astype(np.float32)


def _guard_after_contact():
    """A striker at 3 px/frame along +x meets a resting look-alike head on at frame 10 (centres
    19 px apart): the guard has seen frames 9 and 10; the template is the striker's."""
    g = TwinGuard((2 * R + 3, 2 * R + 3))
    rest = ((150.0, 100.0), 40.0)
    f9 = _scene([((128.0, 100.0), 0.0), rest])
    f10 = _scene([((131.0, 100.0), 10.0), rest])
    g.remember(9, f9, (128.0, 100.0))
    g.remember(10, f10, (131.0, 100.0))
    return g, _template(f10, (131.0, 100.0))


def test_the_look_alike_is_found_at_the_start():
    """The peaks are where the pucks are, either turned: the reference the guard stands on."""
    img = _scene([((60.0, 50.0), 0.0), ((200.0, 160.0), 70.0)])
    peaks = match_peaks(img, _template(img, (60.0, 50.0)), (130.0, 105.0), 150.0)
    got = sorted(tuple(np.round(p[1])) for p in peaks[:2])
    assert np.allclose(got, [(60, 50), (200, 160)], atol=1.5), got
    assert peaks[1][0] > 0.8  # the turned look-alike matches nearly as well


@pytest.mark.parametrize("gap", [6, 10])
def test_after_a_head_on_collision_the_puck_that_moves_on_is_the_struck_one(gap):
    """Equal masses head on: the striker stops where it struck, the struck puck goes on at the
    striker's speed. Found on the struck puck (the better match of a resting template), the guard
    swaps to the striker; found on the striker, it keeps it."""
    g, tmpl = _guard_after_contact()
    striker, struck = (131.0, 100.0), (150.0 + 3.0 * gap, 100.0)
    now = _scene([(striker, 75.0), (struck, 40.0 + 7 * gap)])
    verdict, rival = g.judge(tmpl, now, 10 + gap, struck, 0.6)
    assert verdict == "swap"
    assert np.hypot(*(rival[1] - striker)) < 2.0, rival
    assert g.judge(tmpl, now, 10 + gap, striker, 0.6) == ("keep", None)


def test_without_a_look_alike_a_puck_found_again_is_kept():
    g, tmpl = _guard_after_contact()
    now = _scene([((136.0, 104.0), 20.0)])
    assert g.judge(tmpl, now, 16, (136.0, 104.0), 0.6) == ("keep", None)


def test_two_look_alikes_continuity_cannot_tell_apart_are_not_trusted():
    """No look-alike before the loss (one puck at rest), two found after at the same distance
    from where it rested: neither is known to be it."""
    g = TwinGuard((2 * R + 3, 2 * R + 3))
    f = _scene([((150.0, 100.0), 0.0)])
    g.remember(0, f, (150.0, 100.0))
    g.remember(1, f, (150.0, 100.0))
    now = _scene([((135.0, 100.0), 30.0), ((165.0, 100.0), 60.0)])
    assert g.judge(_template(f, (150.0, 100.0)), now, 9, (165.0, 100.0), 0.6) == ("twin", None)


def _obs(frame, theta):
    return Observation(frame, "b", 1.0 * frame, 0.0, theta, 0.01, 1.0, 0.1, 0.99, "ok", False, "image")


@pytest.mark.parametrize("kept", [True, False])
def test_an_angle_that_steps_and_goes_on_from_the_step_is_not_reported(kept):
    """An angle stepping by 0.5 rad (no rocking block turns so in a frame): a frame alone that
    comes back is an outlier; one the later frames go on from leaves no angle from there."""
    th = np.linspace(0.0, 0.4, 40)
    th[20:] -= 0.5 if kept else 0.0
    if not kept:
        th[20] -= 0.5
    cfg = TrackConfig.from_dict(
        {
            "targets": {"style": "markerless"},
            "reference": {"level": "none"},
            "objects": [{"id": "b", "roi": [0, 0, 10, 10]}],
        }
    )
    with collecting() as found:
        res = assemble_tracks([[_obs(i, t)] for i, t in enumerate(th)], cfg, 30.0, 320, 240)
    t = res["b"]
    # the step's frame is an outlier (and a lone misfit's next frame, which steps back)
    n_ok = 39 if kept else 38
    assert t.status[20] == "outlier" and np.sum(t.status == "ok") == n_ok
    codes = [d.code for d in found if d.code == "W-TRACK-THETA"]
    if kept:
        assert np.all(np.isfinite(t.theta_rad[:20])) and np.all(np.isnan(t.theta_rad[20:]))
        assert codes and "frame 20 on (19 ok frames)" in found[[d.code for d in found].index("W-TRACK-THETA")].message
    else:
        assert np.sum(np.isfinite(t.theta_rad)) == n_ok and not codes


@pytest.fixture(scope="module")
def rotation(tmp_path_factory):
    return mirror_file(tmp_path_factory, "umartechboy/PhysTrack", "SampleVideos/CaromPuck/Rotation.MP4")


def test_the_striker_is_not_ok_on_the_struck_puck(rotation):
    """CaromPuck/Rotation.MP4 (GPL-2.0, not shipped), the striker tracked from frame 205 over the
    collision (~238) to 290: before, it was found again on the struck puck at frame 246 and ok
    there on every later frame. Reference: the pucks' white blobs (benchmarks/phystrack_films.py
    ``puck_reference``, checked by eye on crops of frames 228-250): the struck puck at frames 250
    (166.8, 111.6) and 260 (183.0, 110.0), the striker at (135.8, 129.8) and (139.7, 140.5); the
    struck puck is right of x = 150 px from frame 242 on, the striker left of it until 290."""
    cfg = TrackConfig.from_dict(
        {
            "video": {"start_frame": 205, "stop_frame": 290},
            "targets": {"style": "markerless"},
            "reference": {"level": "none"},
            "objects": [{"id": "s", "roi": [32, 68, 19, 19]}],
        }
    )
    with collecting():
        tr = track_video(rotation, cfg)["s"]
    f = np.asarray(tr.frame)
    for at, struck, striker in ((250, (166.8, 111.6), (135.8, 129.8)), (260, (183.0, 110.0), (139.7, 140.5))):
        i = int(np.flatnonzero(f == at)[0])
        if tr.ok[i]:
            assert np.hypot(tr.x_px[i] - striker[0], tr.y_px[i] - striker[1]) < 3.2
        assert not (tr.ok[i] and np.hypot(tr.x_px[i] - struck[0], tr.y_px[i] - struck[1]) < 10)
    # never ok within half a puck of the struck puck after the collision
    assert not np.any(tr.ok[f >= 246] & (tr.x_px[f >= 246] > 150))
