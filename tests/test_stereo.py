"""Two-camera 3D tracking on a rendered stereo session with exact truth (calibration, sync, 3D, audit)."""

from __future__ import annotations

import json
import shutil
import math
import re

import numpy as np
import pandas as pd
import pytest

from rocklab._diagnostics import collecting
from rocklab._errors import InputError
from rocklab.synth import synth_stereo
from rocklab.tracking.rigid import kabsch, track_points3d
from rocklab.tracking.stereo import calibrate_stereo, load_rig, stereo_point_series, track_dots_stereo

OFFSET_S = 0.0027


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    # odd frame size; a short test (eta 0.8) with a 1 mm slide at impact 3
    d = tmp_path_factory.mktemp("stereo")
    r = synth_stereo(
        d,
        size=(961, 703),
        f_px=1200.0,
        fps=150.0,
        offset_s=OFFSET_S,
        n_board=20,
        seed=3,
        restitution=0.8,
        theta0_rad=0.12,
        slide=(3, 1e-3),
    )
    rig = calibrate_stereo(d / "calib_cam1.mkv", d / "calib_cam2.mkv")
    sp = track_dots_stereo(d / "cam1.mkv", d / "cam2.mkv", rig)
    return d, r, rig, sp


def test_calibration_reprojection_and_baseline(session):
    d, r, rig, _ = session
    c1, c2 = r["cameras"]
    true_baseline = np.linalg.norm(-c2.R.T @ c2.t + c1.R.T @ c1.t)
    assert max(rig.rms_px.values()) <= 0.3
    assert rig.baseline_m == pytest.approx(true_baseline, rel=0.002)
    np.testing.assert_allclose(np.diag(rig.K1)[:2], np.diag(c1.K)[:2], rtol=0.002)
    # the saved file reads back the same rig
    back = load_rig(rig.save(d / "stereo.json"))
    np.testing.assert_allclose(back.T, rig.T)


def test_sync_offset_without_shared_trigger(session):
    _, _, _, sp = session
    assert sp.sync.offset_s == pytest.approx(OFFSET_S, abs=1e-3)  # the bound: 1 ms at 150 fps
    assert abs(sp.sync.offset_s - OFFSET_S) < 0.2e-3  # what it does: 0.02-0.08 ms
    assert 0 < sp.sync.sigma_s < 0.5e-3


def test_triangulated_targets_match_truth(session):
    d, r, rig, sp = session
    c1 = r["cameras"][0]
    X1 = r["X1"] @ c1.R.T + c1.t  # truth in camera 1's axes
    n = sp.xyz_m.shape[0]
    # each triangulated target is the nearest true target (in a frame where all are seen)
    k = int(np.flatnonzero(np.isfinite(sp.xyz_m).all(axis=(1, 2)))[0])
    idx = [int(np.argmin(np.linalg.norm(X1[k] - x, axis=1))) for x in sp.xyz_m[k]]
    assert sorted(idx) == list(range(X1.shape[1]))  # every target once
    A = X1[:n, idx].reshape(-1, 3)
    B = sp.xyz_m.reshape(-1, 3)
    ok = np.isfinite(B).all(axis=1)
    assert ok.mean() > 0.99
    # the calibrated camera-1 axes differ from the true ones by a small rigid motion (principal point):
    # compare shapes after the best rigid alignment
    R, t, rms = kabsch(B[ok], A[ok])
    assert rms < 1.5e-4  # 0.12 mm at f = 1200 px, 1 m


def test_rocking_from_stereo_and_the_audit(session):
    d, r, rig, sp = session
    series, bodies, notes = stereo_point_series(sp, "cam1")
    assert sorted(len(v) for v in bodies.values()) == [4, 8] and "table" in bodies and not notes
    with collecting() as diags:
        res = track_points3d(series, bodies, up="z")
    b = res["block"]
    truth = pd.read_csv(d / "truth.csv")
    # compared by time, not by sample: Matroska's 1 ms ticks store 150 fps as 7, 7, 6 ms steps,
    # and a rate rounded from them (142.857 fps) would stretch the test by 5 %
    np.testing.assert_allclose(sp.t_s, np.arange(len(sp.t_s)) / 150.0, rtol=0, atol=1e-9)
    th = np.interp(b.t_s, truth.t_s, truth.theta_rad)
    sign = np.sign(np.nansum(b.theta_rad * th))
    assert np.sqrt(np.nanmean((b.theta_rad - sign * th) ** 2)) < math.radians(0.02)
    assert np.sqrt(np.nanmean(b.twist_rad**2)) < math.radians(0.05)
    assert np.sqrt(np.nanmean(b.out_of_plane_rad**2)) < math.radians(0.05)
    assert b.geometry.base_width_m == pytest.approx(0.1, abs=1e-3)
    assert [(f.kind, f.impact) for f in b.audit.flags] == [("slide", 3)]
    assert b.audit.flags[0].value == pytest.approx(1e-3, rel=0.1)
    assert [x.code for x in diags] == ["W-AUDIT"]


def test_a_damaged_film_stays_paired_frame_by_frame(session, tmp_path):
    """20 kB of garbage in the middle of camera 2's Matroska film: the demuxer skips a stretch
    (empty slots of the 150 fps clock) and some packets do not decode; each lost frame is a frame
    without targets, so the films stay paired and θ stays right at its time, and both losses
    are named."""
    d, _, rig, _ = session
    data = bytearray((d / "cam2.mkv").read_bytes())
    mid = len(data) // 2
    data[mid : mid + 20000] = np.random.default_rng(1).integers(0, 256, 20000, dtype=np.uint8).tobytes()
    bad = tmp_path / "cam2.mkv"
    bad.write_bytes(bytes(data))
    with collecting() as diags:
        sp = track_dots_stereo(d / "cam1.mkv", bad, rig)
    codes = {x.code for x in diags}
    assert codes & {"W-VIDEO-DAMAGED", "W-VIDEO-DROPPED"} and codes <= {"W-VIDEO-DAMAGED", "W-VIDEO-DROPPED"}
    n_lost = int(np.sum(~np.isfinite(sp.xyz_m).all(axis=(1, 2))))
    assert 5 < n_lost < 60
    np.testing.assert_allclose(sp.t_s, np.arange(len(sp.t_s)) / 150.0, rtol=0, atol=1e-9)
    series, bodies, _ = stereo_point_series(sp, "cam1")
    with collecting():
        b = track_points3d(series, bodies, up="z")["block"]
    truth = pd.read_csv(d / "truth.csv")
    th = np.interp(b.t_s, truth.t_s, truth.theta_rad)
    sign = np.sign(np.nansum(b.theta_rad * th))
    assert np.sqrt(np.nanmean((b.theta_rad - sign * th) ** 2)) < math.radians(0.02)


def test_cli_stereo_calibrate_and_track(session, tmp_path, run_cli):
    d, _, _, _ = session
    rc, out, err = run_cli(
        "stereo", "calibrate", d / "calib_cam1.mkv", d / "calib_cam2.mkv", "-o", tmp_path / "stereo.json", "--json"
    )
    assert rc == 0, err
    cal = json.loads(out)
    assert cal["rms_px"]["stereo"] <= 0.3
    rc, out, err = run_cli(
        "stereo",
        "track",
        d / "cam1.mkv",
        d / "cam2.mkv",
        "--calib",
        tmp_path / "stereo.json",
        "-o",
        tmp_path / "t" / "tracks.csv",
        "--json",
    )
    assert rc == 0, err
    s = json.loads(out)
    assert s["verdict"] == "suspect" and abs(s["sync"]["offset_s"] - OFFSET_S) < 1e-3
    audit = json.loads((tmp_path / "t" / "audit.json").read_text())
    assert [(f["kind"], f["impact"]) for f in audit["flags"]] == [("slide", 3)]
    pts = pd.read_csv(tmp_path / "t" / "points.csv")
    assert list(pts.columns) == ["t_s", "point", "x_m", "y_m", "z_m"]
    # the table frame: the table's targets lie in z = 0
    tab = pts[pts.point.isin(s["bodies"]["table"])]
    assert tab.z_m.abs().max() < 2e-4


def test_stereo_bad_input(session, tmp_path, run_cli):
    from _render import write_video

    from rocklab.tracking import iter_video_frames

    d, _, rig, _ = session
    # films of dots are no calibration films: the board is never seen (every 10th of the 356 frames
    # searched: each search of a whole film for a board it does not hold cost 10 CPU-s)
    with pytest.raises(InputError, match=r"cam1.mkv: the board is seen .* in 0 of 36 pictures"):
        calibrate_stereo(d / "cam1.mkv", d / "cam2.mkv", every=10)
    # a calibration film against a test film (its first 40 frames, lossless): different lengths
    cut = tmp_path / "cam2.mkv"
    write_video(cut, [g for _, g in iter_video_frames(d / "cam2.mkv", stop=40)], 150.0)
    with pytest.raises(InputError, match=r"cam2.mkv: 40 frames, but calib_cam1.mkv has 20; .*trim them"):
        calibrate_stereo(d / "calib_cam1.mkv", cut)
    # one calibration film given twice (also as a copy under another name) calibrated to a
    # 5.5e-11 m baseline: refused, naming the cause
    shutil.copy(d / "calib_cam1.mkv", tmp_path / "copy.mkv")
    for second in (d / "calib_cam1.mkv", tmp_path / "copy.mkv"):
        with pytest.raises(
            InputError, match=r"sit where they sit in calib_cam1.mkv \(median 0 px apart\): the same film"
        ):
            calibrate_stereo(d / "calib_cam1.mkv", second)
    with pytest.raises(InputError, match=r"the films must cover the same test"):
        track_dots_stereo(d / "cam1.mkv", d / "calib_cam2.mkv", rig)
    rc, _, err = run_cli("stereo", "track", d / "cam1.mkv", d / "cam2.mkv", "--calib", tmp_path / "none.json")
    assert rc == 2 and "none.json: not found" in err and len(err.strip().splitlines()) == 1


def test_aruco_corners_in_stereo(tmp_path, run_cli):
    # two markers on the block's face, two on an upright plate at the table's edge; odd frame size
    d = tmp_path / "aruco"
    r = synth_stereo(
        d,
        size=(641, 463),
        f_px=800.0,
        fps=150.0,
        offset_s=OFFSET_S,
        n_board=16,
        seed=4,
        restitution=0.7,
        theta0_rad=0.1,
        targets="aruco",
    )
    rc, out, err = run_cli("stereo", "calibrate", d / "calib_cam1.mkv", d / "calib_cam2.mkv", "-o", d / "stereo.json")
    assert rc == 0, err
    rc, out, err = run_cli(
        "stereo",
        "track",
        d / "cam1.mkv",
        d / "cam2.mkv",
        "--calib",
        d / "stereo.json",
        "--targets",
        "aruco",
        "-o",
        tmp_path / "t" / "tracks.csv",
        "--json",
    )
    assert rc == 0, err
    s = json.loads(out)
    assert s["bodies"] == {
        "block": [f"M{m}c{k}" for m in (0, 1) for k in range(4)],
        "table": [f"M{m}c{k}" for m in (2, 3) for k in range(4)],
    }
    assert abs(s["sync"]["offset_s"] - OFFSET_S) < 0.5e-3
    assert s["verdict"] == "valid"
    tr = pd.read_csv(tmp_path / "t" / "tracks.csv")
    b = tr[tr.object == "block"]
    th = pd.read_csv(d / "truth.csv").theta_rad.to_numpy()[: len(b)]
    sign = np.sign(np.nansum(b.theta_rad.to_numpy() * th))
    assert np.sqrt(np.nanmean((b.theta_rad.to_numpy() - sign * th) ** 2)) < math.radians(0.02)
    # twist is seen over a 6 cm marker pair only: 0.1 deg here, against 0.02 deg with dots across the face
    assert np.sqrt(np.nanmean(b.twist_rad**2)) < math.radians(0.3)
    del r


def test_setup_errors_are_named_before_the_audit(session, tmp_path):
    # the same film twice triangulated to infinity and swapped films to a mirrored scene
    # behind the cameras; the audit then read them as slides and jumps
    d, _, rig, sp = session
    assert float(np.nanmedian(sp.xyz_m[..., 2])) > 0.3  # the right order: the scene in front
    shutil.copy(d / "cam1.mkv", tmp_path / "copy.mkv")
    with pytest.raises(InputError, match=r"copy.mkv: every target sits where it sits in .*cam1.mkv .*the same film"):
        track_dots_stereo(d / "cam1.mkv", tmp_path / "copy.mkv", rig, sync=False)
    # swapped films: 1.9 px off their epipolar lines in the order given, 0.014 px in the other
    with pytest.raises(
        InputError,
        match=r"cam2.mkv: the targets miss their epipolar lines by 1.* px in this order and by 0.0.*wrong order",
    ):
        track_dots_stereo(d / "cam2.mkv", d / "cam1.mkv", rig)


def test_no_sync_on_lagged_films_is_a_warning_and_silent_once_aligned(session):
    # --no-sync on films 2.7 ms (0.4 frame) apart skewed every moving target; the offset is
    # measured anyway and reported, and films aligned by that offset raise nothing
    from rocklab.tracking import match_tracks, sync_offset_stereo, track_dots_2d
    from rocklab.tracking.stereo._dots3d import _shift
    from rocklab.tracking.stereo._setup import check_unsynchronised
    from rocklab.tracking import iter_video_frames

    d, _, rig, _ = session
    with collecting() as diags:
        sp = track_dots_stereo(d / "cam1.mkv", d / "cam2.mkv", rig, sync=False)
    assert sp.sync is None
    nosync = [x for x in diags if x.code == "W-STEREO-NOSYNC"]
    assert len(nosync) == 1 and re.search(r"runs 2\.[5-9]\d* ms", nosync[0].message), nosync
    t1, t2 = (track_dots_2d((g for _, g in iter_video_frames(d / f)), f) for f in ("cam1.mkv", "cam2.mkv"))
    pairs, _ = match_tracks(rig, t1, t2, 0.0, max_px=5.0)
    found = sync_offset_stereo(rig, t1, t2, pairs, 150.0)
    aligned = type(t2)(_shift(t2.uv_px, found.offset_frames), t2.source)
    again = sync_offset_stereo(rig, t1, aligned, pairs, 150.0)
    assert abs(again.offset_s) < 0.2e-3
    with collecting() as diags:
        check_unsynchronised(again, "cam1.mkv", "aligned")
    assert not diags


def test_films_as_folders_of_frames_calibrate_and_track_as_the_films(session, tmp_path):
    import cv2

    from rocklab.tracking import iter_video_frames

    d, _, rig, sp = session
    folders = {}
    for name in ("calib_cam1", "calib_cam2", "cam1", "cam2"):
        f = folders[name] = tmp_path / name
        f.mkdir()
        for i, g in iter_video_frames(d / f"{name}.mkv"):  # 16-bit, as a 12-bit camera writes them
            cv2.imwrite(str(f / f"img_{i:05d}.png"), g.astype(np.uint16) * 16)
    rig2 = calibrate_stereo(folders["calib_cam1"], folders["calib_cam2"])
    assert rig2.rms_px == pytest.approx(rig.rms_px, rel=1e-9) and rig2.baseline_m == pytest.approx(rig.baseline_m)
    with pytest.raises(InputError, match="no frame rate.*timestamps.csv.*--fps"):
        track_dots_stereo(folders["cam1"], folders["cam2"], rig2)
    sp2 = track_dots_stereo(folders["cam1"], folders["cam2"], rig2, fps=150.0)
    np.testing.assert_allclose(sp2.t_s, sp.t_s, atol=1e-12)
    np.testing.assert_allclose(sp2.xyz_m, sp.xyz_m, atol=1e-9)
