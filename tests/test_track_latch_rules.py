"""The rules that give pixels two trackers share to one object, and that refuse a tracker found
again where its object cannot be, on constructed tracks with a known truth (the real-film tests
skip without the PhysTrack mirror, and there the verifier may lose the frames first)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from rocklab._diagnostics import collecting
from rocklab.tracking.video._checks import settle_latches, settle_reacquisitions

N = 100
W, H = 320, 240


class _Pixels:
    """A plane map whose plane is the image."""

    def to_image(self, xy):
        return np.asarray(xy, float)


def _obj(oid, x, y, side=20):
    return SimpleNamespace(id=oid, kind="block", roi=(x - side / 2, y - side / 2, side, side))


def _series(xy, ok):
    """One object's raw series: positions (n, 2) px, ok mask (n,); not-ok frames NaN, as assembled."""
    xy = np.array(xy, float)
    a = {k: np.full(N, np.nan) for k in ("X", "Y", "th", "sig", "scale", "q")}
    a["X"][ok], a["Y"][ok] = xy[ok, 0], xy[ok, 1]
    a["th"][ok], a["sig"][ok], a["q"][ok] = 0.0, 0.01, 0.95
    st = np.where(ok, "ok", "lost").astype(object)
    return a, st, False


def _settle(config, raw):
    with collecting() as said:
        settle_reacquisitions(raw, config, _Pixels(), np.arange(N), "film", W, H)
        settle_latches(raw, config, _Pixels(), np.arange(N), "film")
    return [d.message for d in said]


def test_the_tracker_that_jumped_onto_a_resting_object_loses_the_shared_frames():
    # b rests at (200, 100) throughout; a falls from (100, 50) at 2 px/frame, is lost for 10
    # frames, then sits on b's pixels: b's own track runs on into them, a's does not
    t = np.arange(N)
    b_xy = np.column_stack((np.full(N, 200.0), np.full(N, 100.0)))
    a_xy = np.column_stack((np.full(N, 100.0), 50.0 + 2.0 * t))
    a_xy[50:] = (200.5, 100.5)
    a_ok = (t < 40) | (t >= 50)
    config = SimpleNamespace(objects=[_obj("a", 100, 50), _obj("b", 200, 100)])
    raw = {"a": _series(a_xy, a_ok), "b": _series(b_xy, np.ones(N, bool))}
    said = _settle(config, raw)
    assert np.all(raw["a"][1][50:] == "latch") and np.all(raw["a"][1][:40] == "ok")
    assert np.isnan(raw["a"][0]["X"][50:]).all()
    assert np.all(raw["b"][1] == "ok")
    assert len(said) == 1 and "'a'" in said[0] and "'b' keeps them" in said[0], said


def test_two_objects_a_size_apart_keep_their_frames():
    # the same two objects, a stopping 12 px from b (more than half the 20 px side): no latch
    t = np.arange(N)
    b_xy = np.column_stack((np.full(N, 200.0), np.full(N, 100.0)))
    a_xy = np.column_stack((np.minimum(100.0 + 2.0 * t, 188.0), np.full(N, 100.0)))
    config = SimpleNamespace(objects=[_obj("a", 100, 100), _obj("b", 200, 100)])
    raw = {"a": _series(a_xy, np.ones(N, bool)), "b": _series(b_xy, np.ones(N, bool))}
    assert _settle(config, raw) == []
    assert np.all(raw["a"][1] == "ok") and np.all(raw["b"][1] == "ok")


@pytest.mark.parametrize("back, latched", [((160.0, 120.0), True), ((6.0, 100.0), False), ((8.0, 60.0), False)])
def test_an_object_that_left_through_an_edge_comes_back_through_one(back, latched):
    # a moves left at 3 px/frame and leaves at the left edge (x = 3 px at frame 19); found again
    # from frame 30 in the middle of the picture (latch), or at the edge again (ok)
    t = np.arange(N)
    xy = np.column_stack((60.0 - 3.0 * t, np.full(N, 100.0)))
    xy[30:] = back
    ok = (t < 20) | (t >= 30)
    config = SimpleNamespace(objects=[_obj("a", 60, 100)])
    raw = {"a": _series(xy, ok)}
    said = _settle(config, raw)
    assert np.all(raw["a"][1][30:] == ("latch" if latched else "ok"))
    assert np.all(raw["a"][1][:20] == "ok")
    assert len(said) == int(latched) and all("found again at frame 30" in s for s in said), said


def test_an_object_found_where_another_ones_track_ended_is_a_latch():
    # b rests at (150, 100) and is lost from frame 30 on (struck away, out of view); a, lost at
    # frame 10 far from there, is "found" at b's last place from frame 40
    t = np.arange(N)
    b_xy = np.column_stack((np.full(N, 150.0), np.full(N, 100.0)))
    a_xy = np.column_stack((50.0 + 0.5 * t, np.full(N, 50.0)))
    a_xy[40:] = (151.0, 100.0)
    config = SimpleNamespace(objects=[_obj("a", 50, 50), _obj("b", 150, 100)])
    raw = {"a": _series(a_xy, (t < 10) | (t >= 40)), "b": _series(b_xy, t < 30)}
    said = _settle(config, raw)
    assert np.all(raw["a"][1][40:] == "latch") and np.all(raw["a"][1][:10] == "ok")
    assert np.all(raw["b"][1][:30] == "ok")
    assert len(said) == 1 and "where another object's track ended" in said[0], said
    # the same return far from b's last place stays ok
    a_xy[40:] = (60.0, 150.0)
    raw = {"a": _series(a_xy, (t < 10) | (t >= 40)), "b": _series(b_xy, t < 30)}
    assert _settle(config, raw) == [] and np.all(raw["a"][1][40:] == "ok")


def _two_bobs(found_at, b_ok):
    """Two bobs swinging side by side (sborquez/Pendulum-Tracking video2's layout, scaled to this
    frame): a about x = 80 px by +-40 px, b about x = 240 px by +-20 px, 20 frames a period. a is
    lost over frames 40-59 and found again at ``found_at`` (px) from frame 60; b is ok where
    ``b_ok`` says (never, on the film: its region too small to hold it)."""
    t = np.arange(N)
    a_xy = np.column_stack((80.0 + 40.0 * np.sin(2 * np.pi * t / 20), np.full(N, 120.0)))
    b_xy = np.column_stack((240.0 + 20.0 * np.sin(2 * np.pi * t / 20), np.full(N, 120.0)))
    a_xy[60:] = found_at
    config = SimpleNamespace(objects=[_obj("a", 80, 120), _obj("b", 240, 120)])
    raw = {"a": _series(a_xy, (t < 40) | (t >= 60)), "b": _series(b_xy, b_ok)}
    return config, raw


@pytest.mark.parametrize("b_seen", ["never", "until 30", "always"])
def test_a_bob_found_again_on_the_other_bob_is_not_ok(b_seen):
    # a is found again on b's place (b at its swing's right end): never ok for a, whether b is
    # tracked there, was last seen near there, or was only ever given as its first region
    t = np.arange(N)
    b_ok = {"never": t < 0, "until 30": t < 30, "always": t >= 0}[b_seen]
    config, raw = _two_bobs((255.0, 120.0), b_ok)
    said = _settle(config, raw)
    assert np.all(raw["a"][1][60:] == "latch") and np.all(raw["a"][1][:40] == "ok")
    assert np.all(raw["b"][1][b_ok] == "ok")
    assert len(said) == 1 and "'a' found again at frame 60" in said[0], said


@pytest.mark.parametrize("found_at", [(45.0, 121.0), (118.0, 119.0), (150.0, 120.0)])
def test_a_bob_found_again_across_its_own_swing_stays_ok(found_at):
    # found at either end of its own swing, or beyond it but nearer its last place than b's: ok
    config, raw = _two_bobs(found_at, np.arange(N) < 0)
    assert _settle(config, raw) == [] and np.all(raw["a"][1][60:] == "ok")
