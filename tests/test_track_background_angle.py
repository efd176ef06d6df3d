"""A region whose angle comes from a still background, not from the object (issue 25).

A pendulum's disc is round: its outline tells no angle. Its rod does, thinly. A box drawn round
the disc by eye also holds the wall behind it: a bracket's corner and a post's edge, which do not
move with the pendulum and carry more turning information than the rod. The registration then
turns the template to keep that still corner matched as the disc swings past it, and reported
the angle 20-50 deg off with a sigma of 0.5 deg and status ``ok``, and the box's centre (off the
disc's) carried by that wrong angle more than 1 % of the width off (KatieButler/Non-Linear's
hand-held film, review 16). Here: the same scene rendered, and that film with hand labels.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from _mirror import mirror_file
from rocklab._diagnostics import collecting
from rocklab.config import TrackConfig
from rocklab.tracking import assemble_tracks, track_frames

FPS = 30.0
W, H = 480, 320
PIVOT = np.array([250.0, -120.0])  # px, above the picture
ROD_PX = 290.0  # pivot to the disc's centre
SS = 4  # supersampling of the drawing
#: round the disc, its rod and the wall beside it, as drawn by eye; shifted, larger, smaller
BOXES = [(188, 118, 62, 82), (194, 126, 62, 82), (182, 110, 74, 98), (194, 126, 50, 66)]


def _wall():
    """The still background: a light wall, a post's edge on the left, a bracket's corner on the right."""
    img = np.full((H * SS, W * SS), 205.0, np.float32)
    img[:, 160 * SS : 191 * SS] = 150.0  # the post
    img[140 * SS :, 240 * SS : 248 * SS] = 120.0  # the bracket's upright
    img[140 * SS : 148 * SS, 240 * SS :] = 120.0  # and its arm
    return img


def _frame(wall, phi, shake, rng):
    """The pendulum at image angle ``phi`` (rad, clockwise as seen) in front of ``wall``, the whole
    picture moved by ``shake`` (px, a hand-held camera)."""
    img = wall.copy()
    c = PIVOT + ROD_PX * np.array([math.sin(-phi), math.cos(phi)])
    s = lambda p: (int(round(p[0] * SS * 16)), int(round(p[1] * SS * 16)))  # noqa: E731
    cv2.line(img, s(PIVOT), s(c), 60.0, 3 * SS, cv2.LINE_AA, 4)
    cv2.circle(img, s(c), 26 * SS * 16, 35.0, -1, cv2.LINE_AA, 4)
    cv2.circle(img, s(c), 6 * SS * 16, 190.0, -1, cv2.LINE_AA, 4)
    img = cv2.resize(img, (W, H), interpolation=cv2.INTER_AREA)
    img = cv2.warpAffine(img, np.float32([[1, 0, shake[0]], [0, 1, shake[1]]]), (W, H), borderMode=cv2.BORDER_REPLICATE)
    img = cv2.GaussianBlur(img, (0, 0), 0.7) + rng.normal(0, 2.0, img.shape)
    return np.clip(np.rint(img), 0, 255).astype(np.uint8), c + shake


def _film(n=75):
    rng = np.random.default_rng(3)
    wall = _wall()
    t = np.arange(n) / FPS
    phi = math.radians(6.0) * np.cos(2 * np.pi * t / 1.2)
    shake = np.column_stack((3.0 * np.sin(2 * np.pi * t / 0.9), 4.0 * np.sin(2 * np.pi * t / 0.7 + 1.0)))
    frames, centres = zip(*(_frame(wall, p, s, rng) for p, s in zip(phi, shake)))
    return list(frames), phi, shake


def _expected(box, phi, shake):
    """Where the box's centre is carried by the pendulum's turn about its pivot, px (n, 2)."""
    c0 = np.array([box[0] + box[2] / 2, box[1] + box[3] / 2])
    out = []
    for p, s in zip(phi, shake):
        d = p - phi[0]
        R = np.array([[math.cos(d), -math.sin(d)], [math.sin(d), math.cos(d)]])
        out.append(PIVOT + s + R @ (c0 - PIVOT - shake[0]))
    return np.array(out)


def _wrong(res, box, phi, shake, width):
    """(ok frames, ok frames off in place by over 1 % of ``width``, ok frames whose angle is off by
    more than max(3 sigma, 2 deg)); the angle is ccw as seen, the image's clockwise turn negated."""
    ok = res.status == "ok"
    err = np.hypot(*(np.column_stack((res.x_px, res.y_px)) - _expected(box, phi, shake)).T)
    dth = np.abs(res.theta_rad - (-(phi - phi[0])))
    tol = np.maximum(3 * res.sigma_theta_rad, math.radians(2.0))
    th_bad = ok & np.isfinite(res.theta_rad) & ~(dth <= tol)
    return int(ok.sum()), int(np.sum(ok & (err > 0.01 * width))), int(th_bad.sum())


def _cfg(box):
    return TrackConfig.from_dict(
        {
            "targets": {"style": "markerless"},
            "reference": {"level": "none", "m_per_px": 1e-3},
            "objects": [{"id": "p", "roi": box}],
        }
    )


@pytest.mark.parametrize("box", BOXES)
def test_rendered_pendulum_before_a_still_corner_is_never_wrong_and_ok(box):
    frames, phi, shake = _film()
    with collecting():  # W-TRACK-THETA says where the angle is not measured
        res = assemble_tracks(track_frames(frames, _cfg(list(box))), _cfg(list(box)), FPS, W, H)["p"]
    n_ok, off, th_bad = _wrong(res, box, phi, shake, W)
    assert off == 0 and th_bad == 0, (n_ok, off, th_bad)
    # the disc is followed all along: frames are kept, not thrown away to be safe
    assert n_ok >= 0.9 * len(frames), n_ok


#: KatieButler/Non-Linear at fab8bd78 (no licence stated: read from the mirror, never shipped),
#: ``pendulum.MOV``: 568x320 H.264, two rigid pendula with black discs, a hand-held camera.
KATIE = ("KatieButler/Non-Linear", "pendulum.MOV", "fab8bd78cb2aa82e49b139e37b8a477ea87a9196")
#: The right pendulum's rod angle from the vertical read by hand off 2x crops (rod end points),
#: deg, by frame (review 16); positive leans the disc to the left as seen.
KATIE_ROD_DEG = {0: 6.7, 10: -4.5, 20: 1.2, 50: -3.6, 80: -5.0}


def _yellow_dot(frame_bgr, near):
    """The centroid of the disc's yellow centre dot (HSV threshold) within 40 px of ``near``, px."""
    hsv = cv2.cvtColor(frame_bgr, cv2.COLOR_BGR2HSV)
    m = cv2.inRange(hsv, (20, 100, 100), (40, 255, 255))
    ys, xs = np.nonzero(m)
    keep = np.hypot(xs - near[0], ys - near[1]) < 40
    return np.array([xs[keep].mean(), ys[keep].mean()])


def test_hand_held_pendulum_film_angle_right_or_nan_and_place_right(tmp_path_factory):
    """The reviewer's box round the right pendulum's disc (287, 205, 46, 73) holds the disc, a
    stretch of its rod and the wall's bracket and post. Before: every frame ``ok``, theta 20-50
    deg off the hand labels with sigma 0.5 deg, the box's centre up to 11.6 px off (2 % of the
    width). Now, on the labelled frames: theta within max(3 sigma, 2 deg) of the hand labels or
    NaN with W-TRACK-THETA, and the point within 1 % of the width of where the disc's yellow dot
    (a colour threshold) and the hand-labelled turn put the box's centre."""
    import av

    path = mirror_file(tmp_path_factory, *KATIE)
    box = (287, 205, 46, 73)
    cfg = TrackConfig.from_dict(
        {
            "video": {"stop_frame": 81},
            "targets": {"style": "markerless"},
            "reference": {"level": "none", "m_per_px": 1e-3},
            "objects": [{"id": "p", "roi": list(box)}],
        }
    )
    from rocklab.tracking import track_video

    with collecting() as diags:
        res = track_video(path, cfg)
    tr = res["p"]
    assert "W-TRACK-THETA" in {d.code for d in diags}
    status, th, sg = np.asarray(tr.status), np.asarray(tr.theta_rad), np.asarray(tr.sigma_theta_rad)
    assert (status == "ok").mean() >= 0.9
    frames = {}
    with av.open(str(path)) as c:
        for k, f in enumerate(c.decode(video=0)):
            if k in KATIE_ROD_DEG:
                frames[k] = f.to_ndarray(format="bgr24")
            if k >= max(KATIE_ROD_DEG):
                break
    c0 = np.array([box[0] + box[2] / 2, box[1] + box[3] / 2])
    dot0 = _yellow_dot(frames[0], (310, 258))
    n_theta = 0
    for k, rod in KATIE_ROD_DEG.items():
        if status[k] != "ok":
            continue
        d = math.radians(rod - KATIE_ROD_DEG[0])  # the image turns clockwise as seen when rod grows
        dot = _yellow_dot(frames[k], (tr.x_px[k], tr.y_px[k] + 16))
        R = np.array([[math.cos(d), -math.sin(d)], [math.sin(d), math.cos(d)]])
        expected = dot + R @ (c0 - dot0)
        assert np.hypot(tr.x_px[k] - expected[0], tr.y_px[k] - expected[1]) <= 0.01 * res.width_px, k
        if np.isfinite(th[k]):
            n_theta += 1
            assert abs(th[k] - (-d)) <= max(3 * sg[k], math.radians(2.0)), (k, math.degrees(th[k]), -rod)
    assert n_theta >= 1
    # the angle is not dropped everywhere: it is kept where what tells it still matches
    assert np.sum(np.isfinite(th[status == "ok"])) >= 5
