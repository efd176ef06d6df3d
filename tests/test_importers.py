"""Imports from other tools: Tracker projects (a real .trk), Kinovea exports and DLTdv points (synthetic cameras, and real DLTdv7 projects)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from rocklab._diagnostics import collecting
from rocklab._errors import InputError
from rocklab.series import read_tracks
from rocklab.tracking.imports import (
    PlanePoints,
    dlt_project,
    parse_plane_bodies,
    plane_tracks,
    read_dltdv,
    read_kinovea,
    read_trk,
)

TRK = Path(__file__).parent / "data" / "importers" / "diabolo_rotation.trk"
DT_S = 0.0125


@pytest.fixture(scope="module")
def diabolo():
    return read_trk(TRK)


def _datatool_columns(text: str) -> dict:
    """Tracker's Data Tool columns saved in the project: ``{name: values by row}``."""
    cols = {}
    for arr, name in re.findall(
        r'type="string">(\{\{[^<]*\}\})</property>\s*</property>(?:(?!y_name).)*?name="y_name" type="string">([^<]*)<',
        text,
        re.S,
    ):
        cols[name] = np.array([float(p.split(",")[1]) for p in re.findall(r"\{([^{}]*)\}", arr)])
    return cols


def test_tracker_positions_reproduce_trackers_own_centre_of_mass_velocity(diabolo):
    """Tracker's data table (the Data Tool tab saved in the project: the centre of mass of the two
    11 g point masses, t, v_x, v_y by its central difference) rebuilt from the marked pixels: the
    same times and the same velocities to 1e-9 m/s (a 0.1 % scale or 0.1 deg axis error is 1e-3)."""
    text = TRK.read_text(encoding="utf-8", errors="replace")
    assert re.findall(r'name="mass" type="double">([^<]+)', text)[:2] == ["0.011", "0.011"]
    cols = _datatool_columns(text)
    assert diabolo.labels == ("masa A", "masa B") and diabolo.xy_m is not None
    both = np.isfinite(diabolo.xy_m).all(axis=(1, 2))
    cm = diabolo.xy_m[both].mean(axis=1)
    frames = diabolo.frame[both]
    t_rows = cols["t"]
    # Tracker's rows are the frames with a centre of mass; its t is our t_s of those frames.
    assert t_rows.size == frames.size
    assert np.abs(t_rows - diabolo.t_s[both]).max() < 1e-12
    assert np.allclose(diabolo.t_s, diabolo.frame * DT_S, atol=1e-15, rtol=0)
    at = {f: k for k, f in enumerate(frames)}
    checked = 0
    for k, f in enumerate(frames):
        if f - 1 in at and f + 1 in at:
            v = (cm[at[f + 1]] - cm[at[f - 1]]) / (2 * DT_S)
            assert abs(v[0] - cols["v_{x}"][k]) < 1e-9 and abs(v[1] - cols["v_{y}"][k]) < 1e-9
            checked += 1
        else:
            assert np.isnan(cols["v_{x}"][k])
    assert checked == 168
    # the scale and rotation matter: a 0.1 % scale error is far outside the tolerance
    k = next(k for k, f in enumerate(frames) if f - 1 in at and f + 1 in at)
    f = frames[k]
    v_bad = (cm[at[f + 1]] - cm[at[f - 1]]) * 1.001 / (2 * DT_S)
    assert abs(v_bad[0] - cols["v_{x}"][k]) > 1e-4


def test_tracker_theta_is_the_turn_of_the_marked_points(diabolo):
    """theta of a two-point body = the turn of the line A->B since the rest frame, counter-clockwise
    as the camera sees it, the same from the image pixels (y flipped) as from Tracker's world."""
    rows = plane_tracks(diabolo, {"d": ("masa A", "masa B")}, rest=(0.0, 0.0))
    ok = rows["status"].to_numpy() == "ok"
    assert ok.sum() == 172 and (rows["status"] == "lost").sum() == 1
    px = diabolo.xy_px * [1.0, -1.0]
    d = px[:, 1] - px[:, 0]
    ang = np.arctan2(d[:, 1], d[:, 0])
    want = np.angle(np.exp(1j * (ang - ang[0])))
    got = rows["theta_rad"].to_numpy()
    assert np.nanmax(np.abs(got[ok] - want[ok])) < 1e-12
    assert abs(got[0]) < 1e-12 and np.nanmax(np.abs(got)) > 3.0  # it spins
    # the centroid in metres is the mean of Tracker's world positions of A and B
    m = diabolo.xy_m.mean(axis=1)
    assert np.nanmax(np.abs(rows["x_m"].to_numpy()[ok] - m[ok, 0])) < 1e-15


def test_plane_tracks_recover_a_known_turn_and_rest():
    """A three-point block turned by a known theta(t) and moved: theta to 1e-12 rad from its last
    frames at rest (auto), an offset rest window gives the offset, a lost point is 'lost'."""
    rng = np.random.default_rng(3)
    n = 200
    t = np.arange(n) / 100.0
    theta = 0.05 * np.exp(-t) * np.sin(8 * t)
    theta[-20:] = 0.0
    shape = np.array([[0.0, 0.0], [0.1, 0.0], [0.05, 0.2]])
    c, s = np.cos(theta), np.sin(theta)
    rot = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)  # (n, 2, 2)
    xy = np.einsum("nij,pj->npi", rot, shape) + rng.normal(0, 0.01, (n, 1, 2))
    xy[50, 2] = np.nan
    pts = PlanePoints(t, np.arange(n), ("a", "b", "c"), None, xy, "synthetic")
    rows = plane_tracks(pts, parse_plane_bodies([], pts.labels), rest="auto")
    got = rows["theta_rad"].to_numpy()
    assert rows["status"].iloc[50] == "lost" and np.isnan(got[50])
    keep = np.arange(n) != 50
    assert np.abs(got[keep] - theta[keep]).max() < 1e-12
    first = plane_tracks(pts, {"b": ("a", "b", "c")}, rest=(0.0, 0.0))["theta_rad"].to_numpy()
    assert np.abs(first[keep] - (theta[keep] - theta[0])).max() < 1e-12
    assert np.isnan(rows["x_px"]).all() and abs(rows["x_m"].iloc[0] - xy[0].mean(axis=0)[0]) < 1e-15


def _with(text: str, old: str, new: str, tmp_path: Path) -> Path:
    assert old in text
    p = tmp_path / "edited.trk"
    p.write_text(text.replace(old, new, 1), encoding="utf-8")
    return p


def test_tracker_units_calibration_and_bad_files(tmp_path, diabolo):
    text = TRK.read_text(encoding="utf-8", errors="replace")
    cm = read_trk(_with(text, '"length_unit" type="string">m<', '"length_unit" type="string">cm<', tmp_path))
    assert np.nanmax(np.abs(cm.xy_m - diabolo.xy_m * 0.01)) < 1e-15
    assert any("from cm to m" in n for n in cm.notes)
    assert any("reference frame 'cm A' is not applied" in n for n in diabolo.notes)
    raw = _with(text, "409.8056734369308", "1.0", tmp_path)
    raw = _with(raw.read_text(), "409.8056734369308", "1.0", tmp_path)
    with collecting() as found:
        pts = read_trk(raw)
    assert pts.xy_m is None and [d.code for d in found] == ["W-TRACK-NOSCALE"]
    assert np.array_equal(pts.xy_px, diabolo.xy_px, equal_nan=True)
    with pytest.raises(InputError, match="the project says 'm', --units says 'cm'"):
        read_trk(TRK, units="cm")
    with pytest.raises(InputError, match=r"edited.trk, line \d+: not valid XML"):
        read_trk(_with(text, "</object>", "</objec>", tmp_path))
    with pytest.raises(InputError, match="delta_t.*set the clip's frame rate"):
        read_trk(_with(text, '"delta_t" type="double">12.5<', '"delta_t" type="double">0<', tmp_path))


def test_trz_member_choice(tmp_path):
    import zipfile

    trz = tmp_path / "two.trz"
    with zipfile.ZipFile(trz, "w") as z:
        z.write(TRK, "a/first.trk")
        z.write(TRK, "a/second.trk")
    with pytest.raises(InputError, match="2 .trk files inside.*--trk NAME"):
        read_trk(trz)
    assert read_trk(trz, member="second.trk").source.endswith("a/second.trk")


def test_cli_import_tracker_writes_tracks_read_by_fit(tmp_path, run_cli):
    out = tmp_path / "tracks.csv"
    rc, stdout, err = run_cli("import", TRK, "-o", out, "--body", "diabolo=masa A,masa B", "--rest", "0,0.001")
    assert rc == 0, err
    assert "diabolo: points ['masa A', 'masa B'], 172/173 frames" in stdout
    tr = read_tracks(out).rows("diabolo")
    t, th = tr.theta()
    assert np.isfinite(th).sum() == 172 and abs(th[0]) < 1e-9
    assert abs(t[-1] - 173 * DT_S) < 1e-12
    rc, stdout, err = run_cli("import", TRK, "-o", tmp_path / "x.csv", "--body", "a=masa A", "--body", "c=nope")
    assert rc == 2 and "--body c: point(s) ['nope'] not in the file" in err and err.count("\n") == 1
    rc, stdout, err = run_cli("import", TRK, "-o", tmp_path / "x.csv", "--body", "a=masa A")
    assert rc == 0 and "a is one point: its position only" in stdout
    one = read_tracks(tmp_path / "x.csv").rows("a")
    assert np.isnan(one.column("theta_rad")).all() and np.isfinite(one.column("x_m")).sum() == 172
    junk = tmp_path / "junk.csv"
    junk.write_text("a,b\n1,2\n")
    rc, _, err = run_cli("import", junk)
    assert rc == 2 and "cannot tell which tool wrote it" in err


def _camera(f, cx, cy, R, C):
    """11 DLT coefficients of a pinhole camera (focal f px, centre cx, cy, rotation R, centre C)."""
    K = np.array([[f, 0, cx], [0, f, cy], [0, 0, 1.0]])
    P = K @ np.hstack([R, -R @ C[:, None]])
    P = P / P[2, 3]
    return np.r_[P[0], P[1], P[2, :3]]


def _rig():
    from scipy.spatial.transform import Rotation

    r1 = Rotation.from_euler("xyz", [0.1, -0.3, 0.02]).as_matrix()
    r2 = Rotation.from_euler("xyz", [-0.05, 0.35, -0.01]).as_matrix()
    return np.stack(
        [
            _camera(1800, 960, 540, r1, np.array([1.0, 0.2, -3.0])),
            _camera(1700, 950, 530, r2, np.array([-1.2, 0.1, -2.8])),
        ],
        axis=1,
    )


def _xypts(tmp_path, xyz, L, hide=None):
    n, p, _ = xyz.shape
    cols = {}
    for i in range(p):
        for j in range(L.shape[1]):
            uv = dlt_project(L[:, j], xyz[:, i])
            if hide is not None and (i, j) == hide[:2]:
                uv[hide[2]] = np.nan
            cols[f"pt{i + 1}_cam{j + 1}_X"] = uv[:, 0]
            cols[f"pt{i + 1}_cam{j + 1}_Y"] = uv[:, 1]
    f = tmp_path / "trial_xypts.csv"
    pd.DataFrame(cols).to_csv(f, index=False, na_rep="NaN", float_format="%.10f")
    c = tmp_path / "cal_DLTcoefs.csv"
    np.savetxt(c, L, delimiter=",", fmt="%.15g")
    return f, c


def test_dltdv_reconstruction_from_two_cameras(tmp_path, run_cli):
    """Points projected by two DLT cameras come back in 3D to 1e-9 of the calibration unit (the
    text's 1e-10 px), in metres from cm; a point one camera missed is NaN there, never guessed."""
    rng = np.random.default_rng(7)
    L = _rig()
    xyz_cm = rng.uniform(-20, 20, (30, 3, 3)) + [0, 0, 100]
    f, c = _xypts(tmp_path, xyz_cm, L, hide=(1, 0, [4]))
    series, info = read_dltdv(f, coefs=c, fps=500.0, units="cm")
    assert series.labels == ("pt1", "pt2", "pt3") and info["cameras"] == 2
    err = np.abs(series.xyz_m - xyz_cm * 0.01)
    assert np.isnan(series.xyz_m[4, 1]).all() and np.isfinite(series.xyz_m[5, 1]).all()
    assert np.nanmax(err) < 1e-9 and info["median_rms_px"] < 1e-8
    assert abs(series.t_s[-1] - 29 / 500.0) < 1e-15
    with pytest.raises(InputError, match="no unit; give --units"):
        read_dltdv(f, coefs=c, fps=500.0)
    with pytest.raises(InputError, match="no time; give the cameras' frame rate with --fps"):
        read_dltdv(f, coefs=c, units="cm")
    bad = tmp_path / "bad_xypts.csv"
    lines = f.read_text().splitlines()
    lines[3] = "oops" + lines[3][lines[3].index(",") :]
    bad.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"bad_xypts.csv, line 4, 'pt1_cam1_X': not a number"):
        read_dltdv(bad, coefs=c, fps=500.0, units="cm")
    # DLTdv's own 3D export of the same points (its xyzpts layout), read as is: the same metres
    xyzpts = tmp_path / "trial_xyzpts.csv"
    cols = {f"pt{i + 1}_{a}": xyz_cm[:, i, k] for i in range(3) for k, a in enumerate("XYZ")}
    pd.DataFrame(cols).to_csv(xyzpts, index=False, float_format="%.10f")
    direct, info3 = read_dltdv(xyzpts, fps=500.0, units="cm")
    assert info3["reconstructed"] is False
    assert np.nanmax(np.abs(direct.xyz_m - series.xyz_m)) < 1e-9
    out = tmp_path / "points.csv"
    rc, stdout, errs = run_cli("import", f, "--coefs", c, "--fps", 500, "--units", "cm", "-o", out)
    assert rc == 0, errs
    back = pd.read_csv(out)
    assert (
        len(back) == 30 * 3 - 1
        and abs(back["z_m"].mean() - np.delete(xyz_cm[..., 2].ravel(), 4 * 3 + 1).mean() / 100) < 1e-9
    )


KINOVEA_XML = Path(__file__).parent / "data" / "importers" / "kinovea_box_jump.xml"
#: A Kinovea Gnuplot export in a repository without a licence: read from its mirror when present.
KINOVEA_TXT = ("/work/.mirror/ANaaim+kinovea_to_json/repo", "b0c8cc7562fdadc338617a0cf487e1db586bc20e")


def _sheet_numbers(path: Path) -> dict:
    """Every trajectory's x, y (cm) as the spreadsheet holds them, parsed independently."""
    text = path.read_text(encoding="utf-8")
    out = {}
    for block in text.split(">Label :<")[1:]:
        label = re.search(r'<Data ss:Type="String">([^<]+)</Data>', block).group(1)
        nums = [float(v) for v in re.findall(r'<Data ss:Type="Number">([^<]+)</Data>', block.split(">Track<")[0])]
        out[label] = np.array(nums).reshape(-1, 2)
    return out


def test_kinovea_spreadsheet_numbers_in_metres():
    """Kinovea's spreadsheet (Coords in cm): every exported x, y comes back as m (x 0.01, exact to
    1e-15), times from its h:mm:ss:cc codes; the one time each trajectory has twice is lost and
    warned (W-IMPORT-TIME), never a guessed row."""
    with collecting() as found:
        pts = read_kinovea(KINOVEA_XML)
    assert [d.code for d in found] == ["W-IMPORT-TIME"]
    want = _sheet_numbers(KINOVEA_XML)
    assert pts.labels == tuple(want) and len(pts.labels) == 9 and pts.xy_px is None
    for j, lab in enumerate(pts.labels):
        got = pts.xy_m[:, j]
        seen = np.isfinite(got).all(axis=1)
        assert seen.sum() == len(want[lab]) - 2  # the two rows sharing a time
        exported = {tuple(np.round(r * 0.01, 12)) for r in want[lab]}
        assert {tuple(np.round(r, 12)) for r in got[seen]} <= exported
    assert np.allclose(pts.t_s[:6], [0, 0.04, 0.08, 0.12, 0.16, 0.21], atol=1e-12, rtol=0)
    with collecting():
        snapped = read_kinovea(KINOVEA_XML, fps=24)
    assert np.array_equal(snapped.frame[:8], np.arange(8)) and abs(snapped.t_s[5] - 5 / 24) < 1e-15
    with pytest.raises(InputError, match=r"is 1\d\.\d ms from any frame at --fps 30"), collecting():
        read_kinovea(KINOVEA_XML, fps=30)
    with pytest.raises(InputError, match="two different times fall on one frame at --fps 12"):
        read_kinovea(KINOVEA_XML, fps=12)
    with pytest.raises(InputError, match="the file says 'cm', --units says 'mm'"):
        read_kinovea(KINOVEA_XML, units="mm")


def test_kinovea_segment_angle_through_the_cli(tmp_path, run_cli):
    """The thigh (hip, knee) as a body: theta is the turn of that segment (closed form from the
    exported coordinates), written to tracks.csv through `rocklab import`."""
    out = tmp_path / "tracks.csv"
    rc, stdout, err = run_cli("import", KINOVEA_XML, "-o", out, "--body", "thigh=Hanche,Genou", "--rest", "first")
    assert rc == 0 and "warning W-IMPORT-TIME" in err
    tr = read_tracks(out).rows("thigh")
    with collecting():
        pts = read_kinovea(KINOVEA_XML)
    d = pts.xy_m[:, 1] - pts.xy_m[:, 0]
    ang = np.arctan2(d[:, 1], d[:, 0])
    _, th = tr.theta()
    ok = np.isfinite(th)
    assert ok.sum() == 27  # 29 times: one shared by two rows, one only the elbow has
    # rest "first": the first 10 frames' mean shape; theta differences are the segment's turns
    assert np.abs(np.diff(th[ok]) - np.diff(ang[ok])).max() < 5e-9  # tracks.csv keeps 9 digits


def test_kinovea_gnuplot_text_needs_its_unit(tmp_path):
    import subprocess

    repo, commit = KINOVEA_TXT
    if not Path(repo).is_dir():
        pytest.skip("the Kinovea text export (ANaaim/kinovea_to_json, no licence) is not mirrored here")
    txt = tmp_path / "pas_camera_01.txt"
    txt.write_bytes(
        subprocess.run(
            ["git", f"--git-dir={repo}", "show", f"{commit}:data_kinovea/pas_camera_01.txt"],
            capture_output=True,
            check=True,
        ).stdout
    )
    with pytest.raises(InputError, match="names no unit; give --units"):
        read_kinovea(txt)
    pts = read_kinovea(txt, units="cm", fps=120)
    assert pts.labels[1:] == ("tarse", "jarret", "hanche", "pointe dos") and pts.t_s.size == 100
    # "77,20 -21,97" (a decimal comma) at t = 0 for the first trajectory
    assert np.allclose(pts.xy_m[0, 0], [0.772, -0.2197], atol=1e-15, rtol=0)
    assert np.array_equal(pts.frame, np.arange(100))


def test_run_reads_a_tracker_project_as_its_track(tmp_path):
    """[sources.track] given a .trk: the same rows `rocklab import` writes with its defaults (every
    point one block, upright in its last frames); a DLTdv file there is refused with the fix."""
    from rocklab.pipelines.experiment._measure import read_track_csv

    tr = read_track_csv(TRK, None)
    t, th = tr.theta()
    with collecting():
        pts = read_trk(TRK)
    want = plane_tracks(pts, {"block_1": pts.labels})
    assert np.array_equal(t, want["t_s"].to_numpy())
    assert np.array_equal(th, want["theta_rad"].to_numpy(), equal_nan=True) and np.isfinite(th).sum() == 172
    dlt = tmp_path / "run_xyzpts.txt"  # a DLTdv table kept under another suffix
    dlt.write_text("pt1_X,pt1_Y,pt1_Z\n1,2,3\n")
    with pytest.raises(InputError, match="convert this dltdv file with rocklab import"):
        read_track_csv(dlt, None)


def test_tracker_trz_times_are_the_films_own_and_the_toss_falls_at_g(tmp_path):
    """Tracker's BallToss project (.trz with its film): the clip's times equal the film's own frame
    times (PyAV's clock) at every marked frame, and the calibrated ball falls with a parabola of
    10.3 m/s^2, g within the 5 % a ball thrown in front of the metre stick gives (perspective),
    residuals of 2 mm (a pixel is 2.5 mm): metres, seconds and y up all right."""
    import zipfile

    from rocklab.tracking import probe_video

    trz = Path(__file__).parent / "data" / "importers" / "BallToss.trz"
    pts = read_trk(trz)
    with zipfile.ZipFile(trz) as z:
        film = tmp_path / "toss.mp4"
        film.write_bytes(z.read("videos/BallToss_new_BallToss.mp4"))
    info = probe_video(film)
    assert pts.labels == ("ball",) and np.array_equal(pts.frame, np.arange(2, 13))
    assert np.abs(pts.t_s - info.frame_times_s[pts.frame]).max() < 1e-12
    y = pts.xy_m[:, 0, 1]
    c = np.polyfit(pts.t_s, y, 2)
    assert 9.81 < -2 * c[0] < 9.81 * 1.06
    assert np.std(y - np.polyval(c, pts.t_s)) < 0.003


def _java_sci(v: float) -> str:
    """Java's DecimalFormat("0.000000E0"), Tracker's full-precision export pattern."""
    if not np.isfinite(v):
        return ""
    mant, exp = f"{v:.6E}".split("E")
    return f"{mant}E{int(exp)}"


def _tracker_export(pts, delim: str, comma: bool) -> str:
    """The text Tracker's ExportDataDialog writes for point masses' t, x, y (#multi:, a names row,
    a header row, a row per frame from the first to the last with data, empty cells where none)."""
    fmt = (lambda v: _java_sci(v).replace(".", ",")) if comma else _java_sci
    lines = ["#multi:"] if len(pts.labels) > 1 else []
    lines.append(delim + "".join(f"{name}{delim}{delim}" for name in pts.labels))
    lines.append("t" + delim + f"x{delim}y{delim}" * len(pts.labels))
    by_frame = {f: i for i, f in enumerate(pts.frame)}
    for f in range(pts.frame.min(), pts.frame.max() + 1):
        t = f * DT_S
        cells = [fmt(t) if comma else repr(round(t, 4))]
        for j in range(len(pts.labels)):
            xy = pts.xy_m[by_frame[f], j] if f in by_frame else (np.nan, np.nan)
            cells += [fmt(xy[0]), fmt(xy[1])]
        lines.append(delim.join(cells))
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("delim, comma", [("\t", False), (";", True)])
def test_tracker_data_table_in_its_export_layout(tmp_path, diabolo, delim, comma, run_cli):
    """Tracker's data export, in the layout its ExportDataDialog writes (no public export was found,
    so the table is written here from the real project's world positions, 7 significant digits,
    a tab or, in a decimal-comma locale, a semicolon): the same positions to the 7 digits, a frame
    without data empty, the unit from --units, theta through `rocklab import` as from the .trk."""
    from rocklab.tracking.imports import read_tracker_table

    f = tmp_path / "diabolo_data.txt"
    f.write_text(_tracker_export(diabolo, delim, comma), encoding="utf-8")
    pts = read_tracker_table(f, units="m")
    assert pts.labels == diabolo.labels and pts.t_s.size == 174  # frames 0..173, frame 3 empty
    same = np.isin(np.arange(174), diabolo.frame)
    assert np.isnan(pts.xy_m[~same]).all()
    rel = np.abs(pts.xy_m[same] - diabolo.xy_m) / np.abs(diabolo.xy_m)
    assert np.nanmax(rel) < 5.1e-7
    assert np.allclose(pts.t_s, np.arange(174) * DT_S, atol=1e-9, rtol=0)
    with pytest.raises(InputError, match="names no length unit; give --units"):
        read_tracker_table(f)
    out = tmp_path / "tracks.csv"
    rc, _, err = run_cli("import", f, "--units", "cm", "--rest", "0,0.001", "-o", out)
    assert rc == 0, err
    _, th = read_tracks(out).rows("block_1").theta()
    want = plane_tracks(diabolo, {"block_1": diabolo.labels}, rest=(0.0, 0.001))["theta_rad"].to_numpy()
    # 7 digits of the positions: a turn error of at most 2 x 5e-7 x |xy| / the points' separation
    sep = np.nanmin(np.linalg.norm(diabolo.xy_m[:, 1] - diabolo.xy_m[:, 0], axis=1))
    bound = 2 * 5e-7 * np.nanmax(np.abs(diabolo.xy_m)) / sep
    assert np.nanmax(np.abs(th[same] - want)) < bound < 2e-4


#: Two real DLTdv7 projects of Project Ushichka (thermal cameras in a cave, 25 Hz, easyWand
#: calibration in m): the repository states no licence, so they are read from its mirror when
#: present (tests/data/importers/README.md).
USHICHKA = ("/work/.mirror/thejasvibr+projectushichka/repo", "fdd234c47107becb05d0fc95ac689a6c66448da1")
USHICHKA_SETS = {
    "acoustic-tracking/2018-08-17/speaker_playbacks/DLTdv7_data_2018-08-17_P03_1000TMC": (1, 51),
    "thermo_lidar_alignment/data/bat_trajs/DLTdv7_data_20180817-P000-15000": (15, 606),
}
USHICHKA_COEFS = "acoustic-tracking/2018-08-17/speaker_playbacks/2018-08-17_wand_dltCoefs_round4.csv"


def _mirror_file(repo_commit, path: str, dest: Path) -> Path:
    import subprocess

    repo, commit = repo_commit
    dest.write_bytes(
        subprocess.run(["git", f"--git-dir={repo}", "show", f"{commit}:{path}"], capture_output=True, check=True).stdout
    )
    return dest


def test_dltdv_reproduces_dltdv7s_own_3d_and_residuals(tmp_path, run_cli):
    """Real DLTdv7 exports (xypts + the easyWand DLTcoefs it used + its own xyzpts and xyzres):
    rocklab's reconstruction gives DLTdv7's 3D points to 1e-6 m (the files keep 6 decimals:
    measured 5.1e-7 m over 657 reconstructions) and its residual to 2e-6 px (measured 1.1e-6 px), with
    exactly DLTdv's NaN pattern. Controls: the plain RMS, two of the three cameras, or another
    calibration of the same rig miss by orders of magnitude more."""
    from rocklab.tracking.imports import dlt_reconstruct, dlt_residual, read_dlt_coefs

    if not Path(USHICHKA[0]).is_dir():
        pytest.skip("the DLTdv7 exports (thejasvibr/projectushichka, no licence) are not mirrored here")
    coefs = _mirror_file(USHICHKA, USHICHKA_COEFS, tmp_path / "wand_dltCoefs.csv")
    L = read_dlt_coefs(coefs)
    assert L.shape == (11, 3)
    other = tmp_path / "other_dltCoefs.csv"  # the same cameras calibrated on 2018-07-28
    _mirror_file(
        USHICHKA, "track-to-trajectory/2018-07-28_001/video_calibration_data/round3_2018-07-28_dltCoefs.csv", other
    )
    for stem, (n_pts, n_recon) in USHICHKA_SETS.items():
        name = stem.rsplit("/", 1)[1]
        files = {
            k: _mirror_file(USHICHKA, f"{stem}{k}.csv", tmp_path / f"{name}{k}.csv")
            for k in ("xypts", "xyzpts", "xyzres")
        }
        series, info = read_dltdv(files["xypts"], coefs=coefs, fps=25.0, units="m")
        theirs = pd.read_csv(files["xyzpts"]).to_numpy(float).reshape(len(series.t_s), n_pts, 3)
        res = pd.read_csv(files["xyzres"]).to_numpy(float)
        assert series.labels == tuple(f"pt{i + 1}" for i in range(n_pts)) and info["cameras"] == 3
        assert np.array_equal(np.isfinite(series.xyz_m), np.isfinite(theirs))
        assert np.isfinite(theirs[..., 0]).sum() == n_recon
        assert np.nanmax(np.abs(series.xyz_m - theirs)) < 1e-6
        assert abs(info["median_dltres_px"] - np.nanmedian(res)) < 2e-6
        uv = pd.read_csv(files["xypts"]).to_numpy(float).reshape(len(series.t_s), n_pts, 3, 2)
        for p in range(n_pts):
            xyz, rms = dlt_reconstruct(L, uv[:, p])
            ours = dlt_residual(L, uv[:, p], xyz)
            assert np.array_equal(np.isfinite(ours), np.isfinite(res[:, p]))
            if np.isfinite(ours).any():
                assert np.nanmax(np.abs(ours - res[:, p])) < 2e-6
                # DLTdv conditions by 2k - 3 degrees of freedom: the plain RMS is not its residual
                assert np.nanmax(np.abs(rms - res[:, p])) > 1e-3
        # controls: drop camera 3, or use the other day's calibration
        two = uv[:, 0].copy()
        two[:, 2] = np.nan
        three_cams = np.isfinite(uv[:, 0]).all(axis=2).sum(axis=1) == 3
        if three_cams.any():
            xyz2, _ = dlt_reconstruct(L, two)
            assert np.nanmax(np.abs(xyz2[three_cams] - theirs[three_cams, 0])) > 1e-3
        wrong, _ = read_dltdv(files["xypts"], coefs=other, fps=25.0, units="m")
        assert np.nanmax(np.abs(wrong.xyz_m - theirs)) > 1e-2
    # through the CLI: points.csv rows are DLTdv7's own numbers, 25 Hz rows
    out = tmp_path / "points.csv"
    rc, _, err = run_cli("import", files["xypts"], "--coefs", coefs, "--fps", 25, "--units", "m", "-o", out)
    assert rc == 0, err
    back = pd.read_csv(out)
    assert len(back) == n_recon
    assert np.abs(np.sort(back["x_m"].to_numpy()) - np.sort(theirs[..., 0][np.isfinite(theirs[..., 0])])).max() < 1e-6


#: The same cameras and calibration filming a thrown object (thejasvibr/tproject, no licence;
#: commit on its `restructured` branch), digitised in DLTdv7 without a 3D export.
TPROJECT = ("/work/.mirror/thejasvibr+tproject/repo", "d489d6cd9b3d5e2fed6393b50f53b1ddcce4d129")


def test_dltdv_thrown_object_falls_at_g(tmp_path):
    """A real DLTdv7 digitisation of an object thrown in the cave (26 frames seen by 2-3 of the
    thermal cameras at 25 Hz), reconstructed by rocklab in m: a parabola fit gives |g| = 10.00
    m/s^2 (9.81 + 2 %), mostly along the calibration's -z. At a wrong frame rate (30 Hz) the same
    fit gives 1.44 g, so the check sees the time base, not only the geometry."""
    if not Path(TPROJECT[0]).is_dir():
        pytest.skip("the DLTdv7 digitisation (thejasvibr/tproject, no licence) is not mirrored here")
    xy = _mirror_file(TPROJECT, "examples/DLTdv7_data_gravityxypts.csv", tmp_path / "gravityxypts.csv")
    coefs = _mirror_file(TPROJECT, "examples/2018-08-17_wand_dltCoefs.csv", tmp_path / "wand_dltCoefs.csv")
    for fps, lo, hi in ((25.0, 9.3, 10.3), (30.0, 13.4, 14.9)):
        series, info = read_dltdv(xy, coefs=coefs, fps=fps, units="m")
        seen = np.isfinite(series.xyz_m[:, 0]).all(axis=1)
        assert seen.sum() == 26 and info["median_dltres_px"] < 2.0
        g = 2 * np.polyfit(series.t_s[seen], series.xyz_m[seen, 0], 2)[0]
        assert lo < np.linalg.norm(g) < hi
        assert -g[2] / np.linalg.norm(g) > 0.97
