"""A markerless pose that does not re-explain the image is lost, never ``ok``: three public films
nobody tuned the tracker on, against references that know nothing of it.

The films are read from the repositories' mirrors (``git show``; the tests skip without them);
the references are in ``tests/data/video_refs`` (its README says how each was made and checked
by hand). The tracked point is the point the first box's centre marks on the object, carried
by the reference's motion (scaled by the ball's width for the ball that swings towards the
camera); an ``ok`` frame more than 1 % of the frame's width from it is wrong.

Before the verifier's first-view and scene-snapshot checks (:mod:`rocklab.tracking.video.targets._verify`):

* arantxax ``20190829_150139.mp4`` (hand-held camera, the ball swings towards it, 20 -> 160 px):
  46, 39, 40 and 30 wrong ``ok`` frames for the drawn box and three boxes moved round it, a
  fluorescent lamp or the wall 40-320 px from the ball, quality 0.93-0.99 (the keyframe had
  learned the lamp from one re-acquisition at 0.77 while nothing was learned yet);
* Tracker's ``BallTossOut.mp4``: 3-6 wrong ``ok`` frames on the thrower's hand;
* PhysTrack's ``RollingCylinder.MP4``, a box 80 % of the disc: frames 287-530 ``ok`` on the
  disc's empty start place, 230-300 px from the disc (lost as ``background`` now).
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

from rocklab._diagnostics import collecting
from rocklab.config import TrackConfig
from rocklab.tracking import track_video

REFS = Path(__file__).parent / "data" / "video_refs"
MIRRORS = Path("/work/.mirror")


#: the commits the references were made on
COMMITS = {
    "arantxax+pendulumtracker": "7b0fa91c54ebcf8a057bf1bccdec5e006b81913e",
    "OpenSourcePhysics+tracker": "cc8888206d5b15b968716d4014c999d431630d16",
    "umartechboy+PhysTrack": "64b079af92f664de5cb6d4e5d11837090f0d7d89",
}


def _film(tmp_path, repo, path):
    """The film ``path`` of the mirrored repository ``repo`` (at :data:`COMMITS`) as a local
    file, or a skip."""
    git = MIRRORS / repo / "repo"
    if not git.is_dir():
        pytest.skip(f"{repo} is not mirrored here")
    got = subprocess.run(
        ["git", f"--git-dir={git}", "show", f"{COMMITS[repo]}:{path}"], capture_output=True, check=False
    )
    if got.returncode != 0 or not got.stdout:
        pytest.skip(f"{path} is not in the {repo} mirror")
    out = tmp_path / Path(path).name
    out.write_bytes(got.stdout)
    return out


def _boxes(box):
    """The drawn box and three moved round it: its centre 10 % of its size down-right; 20 %
    larger and 20 % up-left; 20 % smaller and 10 % down-right (x, y, w, h px)."""
    x, y, w, h = box
    return [
        box,
        (round(x + 0.1 * w), round(y + 0.1 * h), w, h),
        (round(x - 0.2 * w), round(y - 0.2 * h), round(1.2 * w), round(1.2 * h)),
        (round(x + 0.1 * w), round(y + 0.1 * h), round(0.8 * w), round(0.8 * h)),
    ]


def _track(film, box, start=0, stop=None):
    video = {"start_frame": start} | ({} if stop is None else {"stop_frame": stop})
    cfg = TrackConfig.from_dict(
        {
            "video": video,
            "targets": {"style": "markerless"},
            "reference": {"level": "none"},
            "objects": [{"id": "o", "roi": list(box)}],
        }
    )
    with collecting():
        res = track_video(film, cfg)
    return res["o"], res.width_px


def _judge(tr, width, ref_csv, box, first_ref=None, scale_col=None):
    """(wrong ok frames, right ok frames, reference frames): an ok frame is wrong when it is more
    than 1 % of ``width`` from the box centre carried by the reference (its offset from the
    reference's first point scaled by ``scale_col``'s ratio when given)."""
    ref = np.genfromtxt(ref_csv, delimiter=",", names=True)
    at = {int(f): i for i, f in enumerate(ref["frame"])}
    frames = np.asarray(tr.frame, int)
    k0 = int(np.argmin(np.abs(ref["frame"] - frames[0])))
    p0 = np.array(first_ref if first_ref is not None else (ref["x"][k0], ref["y"][k0]))
    off0 = np.array([box[0] + box[2] / 2, box[1] + box[3] / 2]) - p0
    wrong, right = [], []
    for f, st, x, y in zip(frames, tr.status, tr.x_px, tr.y_px):
        if st != "ok" or f not in at:
            continue
        i = at[f]
        s = 1.0 if scale_col is None else ref[scale_col][i] / ref[scale_col][k0]
        e = np.array([ref["x"][i], ref["y"][i]]) + s * off0
        (wrong if np.hypot(x - e[0], y - e[1]) > 0.01 * width else right).append(int(f))
    return wrong, right, len(at)


PEND = ("arantxax+pendulumtracker", "20190829_150139.mp4", (317, 328, 28, 28))


@pytest.mark.parametrize("box", _boxes(PEND[2]))
def test_a_ball_swinging_at_a_hand_held_camera_is_never_ok_elsewhere(tmp_path, box):
    """The ball grows from 20 to 150 px in a second while the camera pans: a rigid template
    cannot follow it, and every frame it is not on the ball must be lost (frames 12-39: the old
    tracker's wrong frames start at 24-33)."""
    tr, width = _track(_film(tmp_path, *PEND[:2]), box, start=12, stop=40)
    wrong, right, _ = _judge(tr, width, REFS / "arantxax_150139_ball.csv", box, scale_col="bw")
    assert wrong == [], wrong
    assert 12 in right  # the first frame is the box itself


TOSS = ("OpenSourcePhysics+tracker", "examples/BallTossOut.mp4", (103, 234, 11, 11))


@pytest.mark.parametrize("box", _boxes(TOSS[2]))
def test_a_tossed_ball_is_not_found_in_the_hand_that_threw_it(tmp_path, box):
    tr, width = _track(_film(tmp_path, *TOSS[:2]), box, start=9)
    wrong, right, _ = _judge(tr, width, REFS / "tracker_balltossout_ball.csv", box)
    assert wrong == [], wrong
    assert 9 in right


ROLL = ("umartechboy+PhysTrack", "SampleVideos/RollingCylinder.MP4", (277, 100, 31, 31))
#: the disc's centre in frame 0, read by hand (the reference's blob merges it with the hand there)
ROLL_CENTRE0 = (292.5, 115.0)


@pytest.mark.parametrize("which", [0, 3])
def test_a_rolled_disc_is_not_ok_on_its_empty_start_place(tmp_path, which):
    """Drawn box: the right frames stay ok. Box 20 % smaller: once the disc has rolled away, its
    empty start place (frames 287-299: ok at quality 0.998 before) is refused, as ``background``
    or, found far from where the disc was lost, as ``jump``."""
    box = _boxes(ROLL[2])[which]
    tr, width = _track(_film(tmp_path, *ROLL[:2]), box, stop=300)
    wrong, right, _ = _judge(tr, width, REFS / "phystrack_rollingcylinder_disc.csv", box, first_ref=ROLL_CENTRE0)
    st = np.asarray(tr.status)
    frames = np.asarray(tr.frame)
    if which == 0:
        # the old tracker: 0 wrong, 174 right on frames 0-299
        assert wrong == [] and len(right) >= 0.9 * 174, (wrong, len(right))
    else:
        # since the first region's background is learned again from every lost-frame median, the
        # small box follows the disc on to frame 280 (x 83 px) and the start place, found again
        # 200 px from where the disc was lost, is refused as a `jump` before the background check
        away = st[frames >= 290]
        assert not np.any(away == "ok") and np.mean(np.isin(away, ("background", "jump"))) > 0.9, dict(
            zip(*np.unique(away, return_counts=True))
        )


@pytest.mark.parametrize("which", [0, 1])
def test_a_rolled_discs_point_is_not_carried_by_its_unreported_angle(tmp_path, which):
    """Once the disc's outline is found round its angle is dropped (W-TRACK-THETA, "found at frame
    N"), so the point reported may not hang on it: it is where the box centre would be had the disc
    not turned (the reference's centre plus the box centre's first offset). Before: the drawn box
    (whole film) 14 ok frames 3.3-4.0 px off once the disc rested at the ramp's foot; the box moved by 10 % (frames 0-285) 127 of the 133 ok frames from the note on 8-9 px
    off, held at a texture angle stopped near -90 deg while the disc rolled on."""
    box = _boxes(ROLL[2])[which]
    stop = None if which == 0 else 286
    film = _film(tmp_path, *ROLL[:2])
    cfg = TrackConfig.from_dict(
        {
            "video": {} if stop is None else {"stop_frame": stop},
            "targets": {"style": "markerless"},
            "reference": {"level": "none"},
            "objects": [{"id": "o", "roi": list(box)}],
        }
    )
    with collecting() as diags:
        res = track_video(film, cfg)
    wrong, right, _ = _judge(
        res["o"], res.width_px, REFS / "phystrack_rollingcylinder_disc.csv", box, first_ref=ROLL_CENTRE0
    )
    found = [re.search(r"found at frame (\d+)", d.message) for d in diags if d.code == "W-TRACK-THETA"]
    found = [int(m.group(1)) for m in found if m is not None]
    assert found, [d.message for d in diags]
    if which == 0:
        assert wrong == [] and len(right) >= 250, (wrong, len(right))
    else:
        late = [f for f in wrong if f >= found[0]]
        late_right = [f for f in right if f >= found[0]]
        assert len(late_right) >= 100 and len(late) <= 0.05 * len(late_right), (late, len(late_right))


#: boxes round the disc that its first frame's outline misled on main (whole film, ok frames more
#: than 1 % of the width off): moved by 10 % (199: the hand joins the disc in frame 0, a disk of
#: 19.9 px 3 px towards it), a random box 6 % larger (339: its outline never found round, the point
#: held at -71 deg), and 20 % smaller (13)
ROLL_MISLED = [(280, 103, 31, 31), (279, 101, 33, 33), (280, 103, 25, 25)]


@pytest.mark.parametrize("box", ROLL_MISLED)
def test_a_rolled_discs_point_comes_from_its_outline_not_its_first_frame(tmp_path, box):
    """Frames 0-200: the disc is held, let go at frame ~30 and rolls from frame 78 (the
    reference's first frame with the disc alone). Its angle is dropped on the way (a round
    outline), so every ok frame must report the box centre carried by the disc's centre, the
    frames before the note included, and the disc's place must come from its own edge in the
    frames it is seen alone, not from the first frame where the hand joins it."""
    tr, width = _track(_film(tmp_path, *ROLL[:2]), box, stop=200)
    wrong, right, _ = _judge(tr, width, REFS / "phystrack_rollingcylinder_disc.csv", box, first_ref=ROLL_CENTRE0)
    assert np.all(~np.isfinite(np.asarray(tr.theta_rad))), "the angle is dropped on every frame"
    assert len(wrong) <= 2 and len(right) >= 80, (wrong, len(right))


def test_a_rolled_discs_point_before_its_disk_is_learned_comes_from_its_edge(tmp_path):
    """A box 20 % smaller than the disc and 2.8 px off its centre (``benchmarks/phystrack_films.py``
    ``Roll rnd2``), frames 0-169: the outline is found round at frame 101, but the disc's disk is
    learned from its own edge only at frame 158 (the first frame's blob is joined by the hand). On
    main the 57 ok frames between reported the point the texture's pose carried, chained over held
    keyframes, 3.3-5.8 px off (1 % of the width: 3.2 px); now the frames whose disk edge was seen
    report that edge's centre, and the frames from the note on are moved as the frames before it."""
    box = (282, 105, 25, 25)
    tr, width = _track(_film(tmp_path, *ROLL[:2]), box, stop=170)
    wrong, right, _ = _judge(tr, width, REFS / "phystrack_rollingcylinder_disc.csv", box, first_ref=ROLL_CENTRE0)
    late = [f for f in right if f >= 101]
    assert len(wrong) <= 2 and len(late) >= 50, (wrong, len(late))
