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


#: The reviewer's box and the same box 0.8x about its centre (review 16's ``small80``: the disc's
#: bottom cut off, the rod and the wall at the top), and the least share of frames ``ok`` (measured
#: 81/81 and 65/81: the small box is lost where the disc swings past the post).
KATIE_BOXES = {"base": ((287, 205, 46, 73), 0.9), "small80": ((292, 212, 37, 58), 0.75)}


@pytest.mark.parametrize("which", sorted(KATIE_BOXES))
def test_hand_held_pendulum_film_angle_right_or_nan_and_place_right(tmp_path_factory, which):
    """The reviewer's box round the right pendulum's disc (287, 205, 46, 73) holds the disc, a
    stretch of its rod and the wall's bracket and post. Before: every frame ``ok``, theta 20-50
    deg off the hand labels with sigma 0.5 deg, the box's centre up to 11.6 px off (2 % of the
    width). Now, on the labelled frames: theta within max(3 sigma, 2 deg) of the hand labels or
    NaN with W-TRACK-THETA, and the point within 1 % of the width of where the disc's yellow dot
    (a colour threshold) and the hand-labelled turn put the box's centre. The smaller box's round
    disc matched the pose turned 13-43 deg off while its rod did not (frame 20: theta 24 deg off,
    the point 6.4 px off): the matching part's own turning information tells it from a block."""
    import av

    path = mirror_file(tmp_path_factory, *KATIE)
    box, min_ok = KATIE_BOXES[which]
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
    assert (status == "ok").mean() >= min_ok
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


def _disc_region(dy, r, seed):
    """A 48 x 64 region round a dark disc of radius ``r`` px, ``dy`` px under the region's centre,
    its rod up to the top edge and a still corner in the top-left, grey levels."""
    img = np.full((64, 48), 200.0, np.float32)
    img[:8, :10] = 150.0
    c = (24, 32 + dy)
    cv2.line(img, (24, 0), c, 60.0, 2, cv2.LINE_AA)
    cv2.circle(img, c, r, 35.0, -1, cv2.LINE_AA)
    return img + np.random.default_rng(seed).normal(0, 1.0, img.shape)


def _block_region(margin, seed, side=64):
    """A ``side`` px region round a textured block, ``margin`` px of plain wall round it."""
    rng = np.random.default_rng(seed)
    img = np.full((side, side), 200.0, np.float32)
    face = rng.uniform(40, 160, (side - 2 * margin,) * 2).astype(np.float32)
    img[margin : side - margin, margin : side - margin] = cv2.GaussianBlur(face, (0, 0), 2.0)
    return img + rng.normal(0, 1.0, img.shape)


def test_a_round_disc_matching_under_a_rod_that_does_not_is_told_from_a_blocks_corners():
    """The rule on arrays. A round disc low in its region, its rod and a still corner in the top row
    of cells, that row not matching: about the region's centre the row holds 0.39-0.54 of the turning
    information (under :data:`MAX_UNMATCHED_TURN` on most: the angle kept, as on the hand-held
    film's small box), about the point the disc's cells turn about 0.73-0.83 (the disc's own outline
    tells none). A textured block with 1-3 of its corner cells not matching (wall leaving as it
    turns): the block's face turns about the region's centre, the two shares are about equal, and
    the second never exceeds :data:`MAX_UNMATCHED_ABOUT_MATCHED` where the first is within
    :data:`MAX_UNMATCHED_TURN`."""
    import itertools

    from rocklab.tracking.video.targets._observability import (
        MAX_UNMATCHED_ABOUT_MATCHED,
        MAX_UNMATCHED_TURN,
        cell_turn_info,
        unmatched_turn_share,
    )

    top_row = np.ones((4, 4))
    top_row[0, :] = 0.0
    about_centre = []
    for dy, r, seed in itertools.product((12, 14, 16), (18, 21, 23), (0, 1)):
        share, share_at, _ = unmatched_turn_share(cell_turn_info(_disc_region(dy, r, seed), 4), top_row)
        assert share_at > MAX_UNMATCHED_ABOUT_MATCHED, (dy, r, share, share_at)
        about_centre.append(share)
    assert np.mean(np.array(about_centre) <= MAX_UNMATCHED_TURN) >= 0.5, about_centre
    corners = [(0, 0), (0, 3), (3, 0), (3, 3)]
    for margin, seed in itertools.product((6, 10, 14), (0, 1)):
        info = cell_turn_info(_block_region(margin, seed), 4)
        for k in (1, 2, 3):
            for cells in itertools.combinations(corners, k):
                cc = np.ones((4, 4))
                cc[tuple(np.array(cells).T)] = 0.0
                share, share_at, _ = unmatched_turn_share(info, cc)
                assert abs(share_at - share) < 0.1, (margin, cells, share, share_at)
                assert share > MAX_UNMATCHED_TURN or share_at <= MAX_UNMATCHED_ABOUT_MATCHED, (margin, cells)


def _red_knob(frame_bgr):
    """The centroid of the red knob on the right pendulum's bracket (still in the lab: it carries
    the hand-held camera's shake), px; the largest red blob in the film's top band above the pivot."""
    hsv = cv2.cvtColor(frame_bgr[0:80, 300:380], cv2.COLOR_BGR2HSV)
    m = cv2.inRange(hsv, (0, 120, 80), (10, 255, 255)) | cv2.inRange(hsv, (170, 120, 80), (180, 255, 255))
    _, _, st, cen = cv2.connectedComponentsWithStats(m)
    i = 1 + int(np.argmax(st[1:, cv2.CC_STAT_AREA]))
    return cen[i] + np.array([300.0, 0.0])


#: review 16's four boxes round the right pendulum's disc (drawn, shifted 10 %, 1.2x, 0.8x)
KATIE_ALL_BOXES = {
    "base": (287, 205, 46, 73),
    "shift+10": (292, 212, 46, 73),
    "big120": (282, 198, 55, 88),
    "small80": (292, 212, 37, 58),
}
#: The pivot lies this far from the red knob, px (read by hand on frame 0 where the rod's line
#: meets the bracket, review 16); the rod's angle is that of pivot -> yellow dot.
KNOB_TO_PIVOT = np.array([1.0, 15.0])


@pytest.mark.parametrize("which", sorted(KATIE_ALL_BOXES))
def test_hand_held_pendulum_film_angle_at_its_turns_right_or_nan(tmp_path_factory, which):
    """Every ``ok`` frame's angle over the film's first 70 frames (two left turns of the swing, where
    the disc stands before the post's edge) against an independent reference: the rod's turn from
    pivot (the bracket's red knob + 15 px, carrying the camera's shake) to the disc's yellow dot,
    both colour thresholds. Before: at each left turn the fit turned the region to keep the post's
    edge matched while the rod did not, 8-12 deg past the turn with sigma 0.5 deg (box ``base``:
    frames 27-32 and 62-66; ``small80`` frame 32, 9 deg). Now the rotation check also runs where the
    cells that do not match hold a quarter of the turning information (it fails frames 27 and 62),
    and the fits that go on from a frame whose angle was no measurement, off the last angle measured,
    report none until they come back to it or the check confirms them: those angles are NaN, and
    every angle reported lies within max(3 sigma, 2.5 deg) of the reference (it agrees with hand
    labels to 1.6 deg, review 16, so 2.5 deg is what it can tell apart; the errors before were 6-12)."""
    import av

    path = mirror_file(tmp_path_factory, *KATIE)
    box = KATIE_ALL_BOXES[which]
    n = 70
    cfg = TrackConfig.from_dict(
        {
            "video": {"stop_frame": n},
            "targets": {"style": "markerless"},
            "reference": {"level": "none", "m_per_px": 1e-3},
            "objects": [{"id": "p", "roi": list(box)}],
        }
    )
    from rocklab.tracking import track_video

    with collecting():
        tr = track_video(path, cfg)["p"]
    rod = []
    with av.open(str(path)) as c:
        for k, f in enumerate(c.decode(video=0)):
            if k >= n:
                break
            img = f.to_ndarray(format="bgr24")
            d = _yellow_dot(img, (310, 258) if not rod else rod[-1][1]) - (_red_knob(img) + KNOB_TO_PIVOT)
            rod.append((math.atan2(d[1], d[0]), d + _red_knob(img) + KNOB_TO_PIVOT))
    phi = np.array([a for a, _ in rod])
    expected = -(phi - phi[0])  # ccw as seen: the image angle's change negated
    ok = np.asarray(tr.status) == "ok"
    th, sg = np.asarray(tr.theta_rad), np.asarray(tr.sigma_theta_rad)
    measured = ok & np.isfinite(th)
    err = np.abs(th - expected)
    wrong = measured & ~(err <= np.maximum(3 * sg, math.radians(2.5)))
    assert not wrong.any(), [
        (k, round(math.degrees(err[k]), 1), round(math.degrees(sg[k]), 2)) for k in np.flatnonzero(wrong)
    ]
    # frames are kept, and the angle is kept where it is right (about the frame-0 place)
    assert ok.mean() >= 0.7, ok.mean()
    assert measured.sum() >= 5, measured.sum()
