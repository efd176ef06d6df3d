"""A cart that bounces off a spring (a sudden reversal) is tracked through the bounce, and a
re-acquisition a size from the frame's edge is not called "left the frame" (issue 25).

Found on a real film (a lab cart on an inclined track reversing at ~28 px/frame against a spring,
its whole region in view a size from the left edge): every box lost the cart at the first bounce
as ``jump`` (off the constant-velocity prediction), then W-TRACK-LATCH said it was "found again ...
away from where it left the frame" and the rest of the film was ``latch``. Here the truth is set by
construction: a textured cart rendered under a known motion, accelerating left, reversing
elastically at a wall within one frame, then slowing as it climbs back."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from _render import TEX, Scene
from rocklab._diagnostics import collecting
from rocklab.config import TrackConfig
from rocklab.tracking import assemble_tracks, track_frames
from rocklab.tracking.video import PlaneMap

FPS = 30.0
W, H, K = 480, 240, 1000.0  # px, px, px per m
N = 60


def _cart():
    rng = np.random.default_rng(11)
    tex = (rng.random((int(0.05 * TEX), int(0.12 * TEX))) * 255).astype(np.uint8)
    return cv2.normalize(cv2.GaussianBlur(tex, (0, 0), 4), None, 40, 240, cv2.NORM_MINMAX)


def _motion(wall_m, v_hit_px):
    """x (m) of the cart's centre per frame, and the first bounce's frame: released at rest at
    0.12 m, accelerating left, hitting the wall at ``v_hit_px`` px/frame, going back with the same
    speed, slowing to rest at 0.12 m and bouncing again (an incline and an elastic wall: the
    bounces are the only sudden changes)."""
    x0 = 0.12
    d = x0 - wall_m  # m run down before a bounce
    a = (v_hit_px / K * FPS) ** 2 / (2 * d)  # m/s^2
    t_hit = np.sqrt(2 * d / a)
    t = (np.arange(N) + 0.37) / FPS  # the bounces fall between frames
    s = t - 2 * t_hit * np.round(t / (2 * t_hit))  # s from the nearest rest at the top
    return x0 - 0.5 * a * s**2, int(np.searchsorted(t, t_hit))


def _track(wall_m, v_hit_px):
    sc = Scene(W, H, px_per_m=K, noise=1.5, blur=0.6, seed=5)
    sc.add(_cart(), (0.06 * TEX - 0.5, 0.025 * TEX - 0.5))
    x, hit = _motion(wall_m, v_hit_px)
    frames = [sc.render([(float(xi), 0.0, 0.0)]) for xi in x]
    a, b = sc.world_to_image([(x[0] - 0.06, 0.025), (x[0] + 0.06, -0.025)])
    roi = [float(a[0]), float(a[1]), float(b[0] - a[0]), float(b[1] - a[1])]
    cfg = TrackConfig.from_dict(
        {
            "targets": {"style": "markerless"},
            "reference": {"level": "none"},
            "objects": [{"id": "cart", "kind": "block", "roi": roi}],
        }
    )
    with collecting() as said:
        res = assemble_tracks(track_frames(frames, cfg), cfg, FPS, W, H, plane_map=PlaneMap(W, H), source="film")
    truth_u = sc.world_to_image(np.column_stack((x, np.zeros(N))))[:, 0]
    return res["cart"], truth_u, hit, [d.message for d in said if d.code == "W-TRACK-LATCH"]


def _bounces(truth_u):
    """Frames where the true motion turns (the frames either side of a bounce)."""
    turn = np.flatnonzero(np.diff(np.sign(np.diff(truth_u))) > 0) + 1
    return set(turn.tolist()) | set((turn + 1).tolist())


@pytest.mark.parametrize("wall_m, v_hit_px", [(-0.125, 24.0), (-0.12, 28.0), (-0.13, 20.0)])
def test_a_cart_is_tracked_through_its_bounce(wall_m, v_hit_px):
    c, truth_u, hit, latch = _track(wall_m, v_hit_px)
    # the cart's region (120 px wide) stays whole in view: its left edge > 45 px from the border
    assert truth_u.min() - 60 > 45
    ok = c.status == "ok"
    err = np.abs(c.x_px - (truth_u - truth_u[0] + c.x_px[0]))
    # at most the one frame that straddles each bounce is not ok (its last step's speed, taken
    # across the bounce, understates the speed the cart comes back with); every other frame is,
    # after the bounce too, on the cart within 1 px, and nothing is latch
    lost = set(np.flatnonzero(~ok).tolist())
    assert lost <= _bounces(truth_u) and len(lost) <= len(_bounces(truth_u)) // 2, sorted(lost)
    assert ok[0] and float(np.nanmax(err[ok])) < 1.0, float(np.nanmax(err[ok]))
    assert latch == [] and not np.any(c.status == "latch"), latch
    assert 10 < hit < N - 10 and np.all(ok[hit + 2 :])


def test_a_cart_that_stops_dead_is_not_lost():
    # the wall takes all its speed (a stop, not a reversal): the cart rests there from the hit on
    sc = Scene(W, H, px_per_m=K, noise=1.5, blur=0.6, seed=8)
    sc.add(_cart(), (0.06 * TEX - 0.5, 0.025 * TEX - 0.5))
    x, hit = _motion(-0.125, 24.0)
    x = np.where(np.arange(N) >= hit, -0.125, x)
    frames = [sc.render([(float(xi), 0.0, 0.0)]) for xi in x]
    a, b = sc.world_to_image([(x[0] - 0.06, 0.025), (x[0] + 0.06, -0.025)])
    roi = [float(a[0]), float(a[1]), float(b[0] - a[0]), float(b[1] - a[1])]
    cfg = TrackConfig.from_dict(
        {"targets": {"style": "markerless"}, "reference": {"level": "none"}, "objects": [{"id": "cart", "roi": roi}]}
    )
    with collecting():
        res = assemble_tracks(track_frames(frames, cfg), cfg, FPS, W, H, plane_map=PlaneMap(W, H), source="film")
    c = res["cart"]
    truth_u = sc.world_to_image(np.column_stack((x, np.zeros(N))))[:, 0]
    ok = c.status == "ok"
    assert np.sum(~ok) <= 1 and np.all(ok[hit + 1 :]), c.status
    assert float(np.nanmax(np.abs(c.x_px - (truth_u - truth_u[0] + c.x_px[0]))[ok])) < 1.0


def _settled(u_last, step, u_back, side=155.0, width=640):
    """The re-acquisition rule on one object moving left ``step`` px/frame to ``u_last`` at frame
    22, lost over frames 23-28, found again at ``u_back`` from frame 29 (the film's numbers: a
    155 px cart at 122 px, 28 px/frame, found at 262 px)."""
    from types import SimpleNamespace

    from rocklab.tracking.video._checks import settle_reacquisitions

    n = 60
    t = np.arange(n)
    u = u_last + step * (22 - t).astype(float)
    u[29:] = u_back
    ok = (t <= 22) | (t >= 29)
    a = {k: np.full(n, np.nan) for k in ("X", "Y", "th", "sig", "scale", "q")}
    a["X"][ok], a["Y"][ok], a["th"][ok], a["sig"][ok], a["q"][ok] = u[ok], 240.0, 0.0, 0.01, 0.95
    raw = {"c": (a, np.where(ok, "ok", "jump").astype(object), False)}

    class _Pixels:
        def to_image(self, xy):
            return np.asarray(xy, float)

    cfg = SimpleNamespace(objects=[SimpleNamespace(id="c", kind="block", roi=(u[0] - side / 2, 212, side, 55))])
    with collecting() as said:
        settle_reacquisitions(raw, cfg, _Pixels(), t, "film", width, 480)
    return raw["c"][1], [d.message for d in said]


@pytest.mark.parametrize("u_last", [122.0, 110.0, 140.0])
def test_a_cart_found_again_after_a_bounce_in_view_is_not_a_latch(u_last):
    st, said = _settled(u_last, 28.0, 262.0)
    assert np.all(st[29:] == "ok") and said == []


def test_a_fast_ball_a_long_step_from_the_edge_has_not_left():
    # review 16's dropped ball: an 81 px region 145 px from the edge at 128 px/frame (the floor
    # stops it): one step would cross the border, but its centre is more than a size from it
    st, said = _settled(145.0, 128.0, 262.0 + 300.0, side=81.0, width=1920)
    assert np.all(st[29:] == "ok") and said == []


@pytest.mark.parametrize("u_last", [60.0, 90.0])
def test_a_cart_whose_region_reaches_the_border_still_left(u_last):
    # its region (77.5 px each side) one 28 px step from the border or over it: it may have left
    st, said = _settled(u_last, 28.0, 262.0)
    assert np.all(st[29:] == "latch") and len(said) == 1
    assert "not through an edge" in said[0] and "frame 29" in said[0]
