"""3D point tracks: readers (CSV, C3D, real files), rigid poses, the rocking decomposition and the audit."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from rocklab import Block
from rocklab._diagnostics import collecting
from rocklab._errors import InputError
from rocklab.synth import synth_points3d
from rocklab.tracking.rigid import (
    PointSeries,
    audit_rocking,
    body_poses,
    kabsch,
    read_c3d,
    read_points,
    read_points_csv,
    reference_shape,
    track_points3d,
    write_c3d,
    write_points_csv,
)
from rocklab.tracking.rigid._rigidity import rigid_groups
from rocklab.tracking import TRACK3D_COLUMNS

C3D = Path(__file__).parent / "data" / "c3d"


def _random_rotation(rng):
    from scipy.spatial.transform import Rotation

    return Rotation.from_rotvec(rng.normal(size=3)).as_matrix()


def _track(session, **kw):
    with collecting() as diags:
        res = track_points3d(session.series, session.bodies, up=kw.pop("up", "z"), **kw)
    return res, diags


def _rms(x):
    x = np.asarray(x, float)
    return float(np.sqrt(np.nanmean(x**2)))


# --- readers -------------------------------------------------------------------------------------


def test_csv_round_trip_and_mm_columns(tmp_path):
    s = synth_points3d(seed=3, table=False)
    p = write_points_csv(s.series, tmp_path / "pts.csv")
    back = read_points_csv(p)
    assert back.labels == s.series.labels
    np.testing.assert_allclose(back.xyz_m, s.series.xyz_m, atol=1e-9)
    np.testing.assert_allclose(back.t_s, s.series.t_s, atol=1e-9)
    # the same numbers in millimetre columns, one point unseen in one sample
    df = s.series.to_frame()
    mm = pd.DataFrame(
        {"t_s": df.t_s, "point": df.point, "x_mm": df.x_m * 1e3, "y_mm": df.y_m * 1e3, "z_mm": df.z_m * 1e3}
    )
    mm.loc[5, ["x_mm", "y_mm", "z_mm"]] = np.nan
    mm.to_csv(tmp_path / "mm.csv", index=False)
    b2 = read_points(tmp_path / "mm.csv")
    assert np.isnan(b2.xyz_m).any(axis=2).sum() == 1
    np.testing.assert_allclose(
        np.nan_to_num(b2.xyz_m), np.nan_to_num(np.where(np.isnan(b2.xyz_m), np.nan, s.series.xyz_m)), atol=1e-9
    )
    assert "from mm to m" in b2.notes[0]


@pytest.mark.parametrize(
    "text, match",
    [
        ("t_s,point,x_m,y_m\n0,A,1,2\n", "no coordinate columns"),
        ("time,point,x_m,y_m,z_m\n0,A,1,2,3\n", r"missing column\(s\) \['t_s'\]"),
        ("t_s,point,x_m,y_m,z_m\n0,A,1,2,3\n0.1,A,abc,2,3\n", r"line 3, 'x_m': not a number"),
        ("t_s,point,x_m,y_m,z_m\n0,A,1,2,3\n0,A,1,2,3\n0.1,A,1,2,3\n", r"line 3: point 'A' appears twice"),
        ("t_s,point,x_m,y_m,z_m\n0,A,1,2,3\n0,B,1,2,3\n", "only one sample time"),
        ("", "empty file"),
    ],
)
def test_csv_errors_name_line_and_fix(tmp_path, text, match):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(InputError, match=match):
        read_points(p)


def test_c3d_round_trip_with_missing_points(tmp_path):
    s = synth_points3d(seed=1, rate_hz=120.0, table=False)
    xyz = s.series.xyz_m.copy()
    xyz[10:14, 2] = np.nan
    series = PointSeries(s.series.t_s, s.series.labels, xyz, "x")
    back = read_c3d(write_c3d(series, tmp_path / "p.c3d"))
    assert back.labels == series.labels
    assert back.rate_hz == pytest.approx(120.0, rel=1e-9)
    np.testing.assert_allclose(back.t_s, series.t_s, atol=1e-9)
    assert np.isnan(back.xyz_m[10:14, 2]).all() and np.isfinite(back.xyz_m[:10]).all()
    # stored as float32 millimetres: 1e-7 relative of ~0.5 m
    np.testing.assert_allclose(back.xyz_m, xyz, atol=2e-7)


def test_real_optotrak_c3d_units_labels_and_missing():
    import ezc3d

    s = read_c3d(C3D / "Optotrak.c3d")
    raw = ezc3d.c3d(str(C3D / "Optotrak.c3d"))["data"]["points"]
    assert len(s.labels) == 54 and s.labels[0] == "Marker_1"
    assert s.rate_hz == pytest.approx(30.0) and s.t_s.size == 29
    # millimetres in the file, metres out
    np.testing.assert_allclose(s.xyz_m[:, 0, :], raw[:3, 0, :].T / 1000.0)
    # Marker_52 and 53 are never seen: every sample NaN, not zeros
    unseen = ~np.isfinite(s.xyz_m).all(axis=2)
    assert unseen[:, 51].all() and unseen[:, 52].all() and not unseen[:, :51].any()


def test_real_qualisys_c3d_time_base_and_missing_point_error():
    s = read_c3d(C3D / "Qualisys.c3d")
    assert s.t_s[0] == pytest.approx(704 / 200.0) and s.rate_hz == pytest.approx(200.0, rel=1e-9)
    assert s.xyz_m.shape == (340, 55, 3)
    with pytest.raises(InputError, match=r"Qualisys.c3d: point\(s\) \['R_XXX'\] not in the file.*fix the --body"):
        s.select(["L_IAS", "R_XXX"])


def test_not_a_c3d_file(tmp_path):
    p = tmp_path / "x.c3d"
    p.write_bytes(b"\x00" * 100)
    with pytest.raises(InputError, match=r"x.c3d: not a readable C3D file"):
        read_points(p)


# --- rigid poses ---------------------------------------------------------------------------------


def test_kabsch_recovers_exact_pose_with_missing_points():
    rng = np.random.default_rng(0)
    ref = rng.normal(size=(7, 3)) * 0.1
    R = np.stack([_random_rotation(rng) for _ in range(50)])
    t = rng.normal(size=(50, 3))
    cur = np.einsum("nij,pj->npi", R, ref) + t[:, None]
    cur[3, [0, 4]] = np.nan  # two points unseen in one sample
    cur[7, :5] = np.nan  # only two left: no pose
    R2, t2, rms = kabsch(ref, cur)
    ok = np.arange(50) != 7
    np.testing.assert_allclose(R2[ok], R[ok], atol=1e-10)
    np.testing.assert_allclose(t2[ok], t[ok], atol=1e-10)
    assert np.nanmax(rms) < 1e-10 and np.isnan(R2[7]).all()
    assert np.allclose(np.linalg.det(R2[ok]), 1.0)


def test_body_poses_reject_a_swapped_marker():
    rng = np.random.default_rng(2)
    ref = rng.normal(size=(6, 3)) * 0.1
    cur = np.repeat(ref[None], 20, axis=0) + rng.normal(0, 5e-5, (20, 6, 3))
    cur[9, 2] += 0.02  # one marker jumps 20 mm in one sample
    p = body_poses(cur, ref)
    assert p.n_rejected == 1
    assert p.rms_m[9] < 2e-4 and np.allclose(p.R[9], np.eye(3), atol=2e-3)


def test_reference_shape_places_a_point_unseen_at_rest():
    rng = np.random.default_rng(4)
    ref = rng.normal(size=(5, 3)) * 0.1
    R = np.stack([_random_rotation(rng) for _ in range(30)])
    cur = np.einsum("nij,pj->npi", R, ref)
    cur[:10] = ref  # at rest for the first ten samples
    cur[:10, 4] = np.nan  # ... where point 5 is hidden
    got = reference_shape(cur, np.arange(10))
    np.testing.assert_allclose(got, ref, atol=1e-9)


def test_real_optotrak_rigid_clusters_hold_their_shape():
    s = read_c3d(C3D / "Optotrak.c3d")
    groups = rigid_groups(s.xyz_m, list(s.labels))
    fours = [g for g in groups if len(g) == 4]
    # the system's 4-marker rigid clusters, consecutive marker numbers
    assert ("Marker_17", "Marker_18", "Marker_19", "Marker_20") in fours and len(fours) >= 6
    for g in fours:
        sub = s.select(g)
        p = body_poses(sub.xyz_m, reference_shape(sub.xyz_m, np.arange(1)))
        moved = np.nanmax(np.ptp(np.nanmean(sub.xyz_m, axis=1), axis=0))
        assert moved > 0.05  # each cluster travels more than 50 mm ...
        assert np.nanmax(p.rms_m) < 1e-3  # ... and keeps its shape within 1 mm


# --- the rocking decomposition on simulated motion capture ---------------------------------------


@pytest.mark.parametrize("up, yaw", [("z", 27.0), ("-y", -140.0), ("x", 95.0)])
def test_track_points3d_accuracy(up, yaw):
    s = synth_points3d(seed=5, up=up, yaw_deg=yaw, noise_m=5e-5)
    res, diags = _track(s, up=up)
    assert not diags
    b = res["block"]
    sign = float(np.sign(b.geometry.e_r @ s.e_r))
    assert abs(b.geometry.e_r @ s.e_r) > 0.9999  # the rocking direction from the data alone
    truth = s.truth
    assert _rms(b.theta_rad - sign * truth.theta_rad) < math.radians(0.02)
    assert _rms(b.twist_rad) < math.radians(0.05)
    assert _rms(b.out_of_plane_rad) < math.radians(0.05)
    assert _rms(b.pivot_slide_m) < 1e-4 and _rms(b.pivot_uplift_m) < 1e-4
    assert b.geometry.base_width_m == pytest.approx(s.block.b_m, abs=1e-3)
    # the reported sigma means something: within a factor 1.5 of the actual error
    err = np.std(b.theta_rad - sign * truth.theta_rad)
    assert 0.67 < np.nanmedian(b.sigma_theta_rad) / err < 1.5
    assert b.audit.verdict == "valid" and b.rest == "last"


def test_track_points3d_rows_have_the_2d_columns():
    s = synth_points3d(seed=6)
    res, _ = _track(s)
    df = res.to_frame()
    assert tuple(df.columns) == TRACK3D_COLUMNS
    assert set(df.object) == {"table", "block"}
    assert (df.status == "ok").all() and df.x_px.isna().all()
    # the table is still: its angle stays within noise and it has no pivot
    tab = df[df.object == "table"]
    assert tab.theta_rad.abs().max() < math.radians(0.1) and tab.pivot_slide_m.isna().all()


@pytest.mark.parametrize(
    "kw, kind, impact, value, rel",
    [
        (dict(slide=(3, 1e-3)), "slide", 3, 1e-3, 0.1),
        (dict(jump=(6, 2e-3)), "jump", 6, 2e-3, 0.1),
        (dict(twist=(9, math.radians(1.0))), "twist", 9, math.radians(1.0), 0.1),
        (dict(double_impact=12), "double_impact", 12, None, None),
    ],
)
def test_audit_finds_each_injected_departure_at_its_impact(kw, kind, impact, value, rel):
    s = synth_points3d(seed=7, **kw)
    res, diags = _track(s)
    a = res["block"].audit
    assert [(f.kind, f.impact) for f in a.flags] == [(kind, impact)]
    if value is not None:
        assert a.flags[0].value == pytest.approx(value, rel=rel)
    assert a.verdict == "suspect" and a.excluded_impacts == (impact,)
    assert [d.code for d in diags] == ["W-AUDIT"]


def test_audit_no_false_alarms_over_20_clean_runs():
    rng = np.random.default_rng(11)
    verdicts = []
    for seed in range(20):
        b = rng.uniform(0.06, 0.25)
        block = Block(b_m=b, h_m=b * rng.uniform(2.5, 6.0))
        s = synth_points3d(
            block=block,
            theta0_rad=rng.uniform(0.3, 0.8) * block.alpha_rad,
            seed=seed,
            yaw_deg=rng.uniform(-180, 180),
            up=("z", "y", "-x")[seed % 3],
            restitution=float(rng.uniform(0.8, 0.95)),
            table=bool(seed % 2),
        )
        res, diags = _track(s, up=("z", "y", "-x")[seed % 3])
        verdicts.append(res["block"].audit.verdict)
        assert not diags, (seed, [d.message for d in diags])
    assert verdicts == ["valid"] * 20


def test_a_jump_of_five_tolerances_is_invalid():
    s = synth_points3d(seed=8, jump=(2, 5e-3))
    res, _ = _track(s)
    assert res["block"].audit.verdict == "invalid"


def test_audit_on_a_plain_theta_series_double_impact_by_short_half_cycle():
    # decaying rocking with one half-cycle cut to 10 % of its neighbours (it rocked back at once)
    t = np.arange(0, 4, 1e-3)
    impacts = np.cumsum([0.5, 0.45, 0.41, 0.04, 0.37, 0.34, 0.31])
    th = np.zeros_like(t)
    edges = np.r_[0.0, impacts, 4.0]
    for j, (a, b) in enumerate(zip(edges[:-1], edges[1:])):
        w = (t >= a) & (t < b)
        th[w] = (-1) ** j * 0.05 * 0.9**j * np.sin(np.pi * (t[w] - a) / (b - a))
    a = audit_rocking(t, th)
    assert np.allclose(a.impacts_t_s, impacts, atol=2e-3)
    # flagged at the impact that began the short half-cycle
    assert [(f.kind, f.detail, f.impact) for f in a.flags] == [("double_impact", "short half-cycle", 3)]


def test_rest_at_start_when_the_block_overturned():
    # a block that ends lying on its side: the reference must be the start, not the end
    s = synth_points3d(seed=9, table=False)
    xyz = s.series.xyz_m.copy()
    from scipy.spatial.transform import Rotation

    n = xyz.shape[0]
    end = np.arange(n) > n - 40
    R = Rotation.from_rotvec(np.outer(np.r_[np.zeros(n - 40), np.linspace(0, 1.4, 40)], s.axis)).as_matrix()
    pivot = xyz[0].mean(axis=0)
    xyz[end] = np.einsum("nij,npj->npi", R[end], xyz[end] - pivot) + pivot
    series = PointSeries(s.series.t_s, s.series.labels, xyz, "fall")
    with collecting():
        res = track_points3d(series, {"block": s.series.labels}, rest="auto")
    # last window is not quiet (still falling) and the first is held tilted -> W-3D-REST, first used
    assert res["block"].rest == "first"


def test_errors_non_rigid_body_and_bad_options():
    s = synth_points3d(seed=10)
    with pytest.raises(InputError, match=r"do not move as one rigid body.*--body block1=B1,.*--body table=T1,T2,T3,T4"):
        track_points3d(s.series, None)
    with pytest.raises(InputError, match="--up 'w'"):
        track_points3d(s.series, s.bodies, up="w")
    with pytest.raises(InputError, match="only a table"):
        track_points3d(s.series, {"table": s.bodies["table"]})


# --- the command ---------------------------------------------------------------------------------


def test_cli_track3d_c3d_then_fit_restitution(tmp_path, run_cli):
    rc, out, err = run_cli("synth", "--points3d", "--out", tmp_path / "s", "--slide", "4,1.2", "--up=-y")
    assert rc == 0, err
    body = ["--body", "block=" + ",".join(f"B{i}" for i in range(1, 11)), "--body", "table=T1,T2,T3,T4"]
    rc, out, err = run_cli(
        "track3d",
        tmp_path / "s" / "points.c3d",
        "-o",
        tmp_path / "t" / "tracks.csv",
        *body,
        "--up=-y",
        "--rrd",
        tmp_path / "t" / "review.rrd",
    )
    assert rc == 0, err
    # the Rerun review: every sample's targets, the pivot, the plots, one text row per impact and flag
    from rocklab.pipelines import read_rrd_summary

    rows = read_rrd_summary(tmp_path / "t" / "review.rrd")
    n = len(pd.read_csv(tmp_path / "s" / "truth.csv"))
    # one row per sample plus the static row of colours and sizes
    assert rows["/3d/block/targets"] == rows["/3d/table/targets"] == n + 1
    assert rows["/plots/block/theta_deg"] == n + 1 and "/3d/block/pivot_path" in rows
    n_impacts = len(json.loads((tmp_path / "t" / "audit.json").read_text())["blocks"]["block"]["impacts_t_s"])
    assert rows["/audit/block"] == n_impacts + 1
    assert "warning W-AUDIT" in err and "impacts 4" in err
    audit = json.loads((tmp_path / "t" / "audit.json").read_text())
    assert audit["verdict"] == "suspect"
    assert [(f["kind"], f["impact"], f["object"]) for f in audit["flags"]] == [("slide", 4, "block")]
    assert audit["flags"][0]["value"] == pytest.approx(1.2e-3, rel=0.1)
    df = pd.read_csv(tmp_path / "t" / "tracks.csv")
    assert list(df.columns) == list(TRACK3D_COLUMNS)
    # the 3D track feeds the restitution fit: Housner's eta for b/h = 1/4 (the simulated law)
    rc, out, err = run_cli(
        "fit",
        "restitution",
        tmp_path / "t" / "tracks.csv",
        "--object",
        "block",
        "--width",
        0.1,
        "--height",
        0.4,
        "--json",
    )
    assert rc == 0, err
    eta_h = 1.0 - 1.5 * math.sin(math.atan(0.25)) ** 2
    assert json.loads(out)["eta_e"] == pytest.approx(eta_h, abs=2e-3)


def test_cli_track3d_bad_input_exits_2(tmp_path, run_cli):
    rc, _, err = run_cli("track3d", C3D / "Qualisys.c3d", "-o", tmp_path / "t.csv", "--body", "pelvis=L_IAS,NOPE,R_IAS")
    assert rc == 2 and "NOPE" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    rc, _, err = run_cli("track3d", tmp_path / "missing.csv", "-o", tmp_path / "t.csv")
    assert rc == 2 and "missing.csv" in err
    rc, _, err = run_cli("track3d", C3D / "Optotrak.c3d", "-o", tmp_path / "t.csv", "--rest", "5,4")
    assert rc == 2 and "--rest" in err


def test_cli_track3d_real_qualisys_pelvis_is_not_planar_rocking(tmp_path, run_cli):
    # a walking subject's pelvis is no block rocking on an edge: the audit must say so, not pass it
    rc, out, err = run_cli(
        "track3d", C3D / "Qualisys.c3d", "-o", tmp_path / "t.csv", "--body", "pelvis=L_IAS,L_IPS,R_IPS,R_IAS"
    )
    assert rc == 0
    audit = json.loads((tmp_path / "audit.json").read_text())
    assert audit["verdict"] == "invalid"
    assert {"twist"} <= {f["kind"] for f in audit["flags"]}


# --- the audit in an experiment run, and on a plane track ----------------------------------------


def _run_on_track3d(session, tmp_path, run_cli, figures: bool):
    """``rocklab run`` of an experiment whose source is the session's track3d output; returns stderr."""
    with collecting():
        res = track_points3d(session.series, session.bodies)
    res.to_frame().to_csv(tmp_path / "tracks.csv", index=False)
    (tmp_path / "experiment.toml").write_text(
        '[block]\nb_m = 0.1\nh_m = 0.4\n[sources.track]\npath = "tracks.csv"\nobject = "block"\n'
        f'[simulate]\nlaws = ["eta_e"]\n[output]\nrrd = false\nfigures = {str(figures).lower()}\n'
    )
    rc, out, err = run_cli("run", tmp_path / "experiment.toml", "--out", tmp_path / "out")
    assert rc == 0, err
    return err


def test_run_with_a_track3d_source_reports_the_audit(tmp_path, run_cli):
    err = _run_on_track3d(synth_points3d(seed=12, slide=(5, 1.5e-3)), tmp_path, run_cli, figures=False)
    assert "W-AUDIT" in err
    rep = json.loads((tmp_path / "out" / "report.json").read_text())
    assert rep["status"] == "suspect"
    assert rep["audit"]["source"] == "3d" and rep["audit"]["verdict"] == "suspect"
    assert [(f["kind"], f["impact"]) for f in rep["audit"]["flags"]] == [("slide", 5)]
    assert "Assumption audit (3d): **suspect**" in (tmp_path / "out" / "summary.md").read_text()


def test_audit_plane_track_finds_a_slide_in_a_plane_track():
    # the block's centre in the plane (CCW theta, y up) from the simulated truth, with noise
    s = synth_points3d(seed=13, slide=(4, 1e-3))
    tr = s.truth
    th = tr.theta_rad.to_numpy()
    half, hc = s.block.b_m / 2, s.block.h_m / 2
    px = np.where(th >= 0, half, -half)
    x = px + np.cos(th) * (0 - px) + np.sin(th) * hc + tr.slide_m.to_numpy()
    y = -np.sin(th) * (0 - px) + np.cos(th) * hc
    rng = np.random.default_rng(0)
    n = th.size
    from rocklab.tracking.rigid import audit_plane_track, plane_pivot_motion

    sl, up, arms, rms = plane_pivot_motion(tr.t_s, -th, x, y, base_width_m=s.block.b_m)
    # exact data: the arms are the block's half-width and half-height, the slide a 1 mm step
    np.testing.assert_allclose(np.abs(arms[0]), [half, hc], atol=1e-9)
    assert np.nanmax(sl) - np.nanmin(sl) == pytest.approx(1e-3, abs=1e-6) and rms < 1e-9
    a = audit_plane_track(
        tr.t_s,
        -th + rng.normal(0, 1.7e-4, n),
        x + rng.normal(0, 5e-5, n),
        y + rng.normal(0, 5e-5, n),
        1.7e-4,
        base_width_m=s.block.b_m,
    )
    assert [(f.kind, f.impact) for f in a.flags] == [("slide", 4)] and a.source == "2d"


def test_run_names_the_fit_impacts_the_audit_flagged(tmp_path, run_cli):
    s = synth_points3d(seed=14, jump=(4, 3e-3))
    _run_on_track3d(s, tmp_path, run_cli, figures=True)
    assert (tmp_path / "out" / "figures" / "theta.png").stat().st_size > 10_000
    rep = json.loads((tmp_path / "out" / "report.json").read_text())
    ex = rep["fit"]["excluded_impacts"]
    # the fit's impact at the simulated 4th impact's time, with the jump as the reason
    assert len(ex) == 1 and ex[0]["t_s"] == pytest.approx(s.impacts_t_s[3], abs=0.01)
    assert ex[0]["reasons"][0].startswith("jump (flight)")
    assert "is not to be trusted: jump" in (tmp_path / "out" / "summary.md").read_text()


@pytest.mark.parametrize("seed,static,n_block", [(5, "T1", 4), (11, "T3", 6), (12, "T4", 10)])
def test_a_static_point_in_the_block_is_named_not_audited_as_sliding(seed, static, n_block):
    # one table marker listed with the block's bends the block's pose by a few tenths of a
    # millimetre, below the rigid-body residual test: the audit reported it as slide and jump
    s = synth_points3d(seed=seed, noise_m=5e-5)
    block = s.bodies["block"][:n_block] + (static,)
    table = tuple(p for p in s.bodies["table"] if p != static)
    with pytest.raises(InputError, match=rf"body 'block': point\(s\) {static} \(.* mm\) do not keep.*--body block="):
        track_points3d(s.series, {"block": block, "table": table})
    # the same bodies without the stray point track, with a valid audit
    res = track_points3d(s.series, {"block": block[:-1], "table": table})
    assert res["block"].audit.verdict == "valid"


def test_a_point_in_two_bodies_is_refused():
    s = synth_points3d(seed=5)
    with pytest.raises(InputError, match=r"point 'B2' is listed in body 'block' and in body 'table'"):
        track_points3d(s.series, {"block": s.bodies["block"], "table": s.bodies["table"] + ("B2",)})
