"""Manual corrections: a mistracked stretch set by hand gives the truth back, marked as corrected;
dropped frames are NaN; bad corrections are one line; the preview shows the frames around a time."""

from __future__ import annotations

import json
import math
import re
import shutil

import numpy as np
import pandas as pd
import pytest

from rocklab import InputError
from rocklab.tracking import load_corrections

BAD = range(40, 45)  # frames that show frame 10's picture: the tracker reports frame 10's pose there


@pytest.fixture(scope="module")
def mistrack(tmp_path_factory):
    """A synth film as a PNG folder whose frames 40..44 repeat frame 10 (a stale picture: a mistrack
    the tracker cannot see), its truth, and the uncorrected track."""
    import cv2

    from rocklab.pipelines import main
    from rocklab.tracking import iter_video_frames

    root = tmp_path_factory.mktemp("fix")
    d = root / "s"
    assert main(["synth", "--out", str(d), "--seed", "4", "--size", "480x270", "--duration", "2", "--no-imu"]) == 0
    frames = [img for _, _, img in iter_video_frames(d / "video.mkv", color=True)]
    folder = root / "frames"
    folder.mkdir()
    for i, img in enumerate(frames):
        cv2.imwrite(str(folder / f"f{i:04d}.png"), frames[10] if i in BAD else img)
    truth = pd.read_csv(d / "truth.csv")
    truth = truth[truth.object == "block_1"].set_index("frame")
    assert (
        main(["track", str(folder), "--config", str(d / "track.toml"), "--fps", "50", "-o", str(root / "raw.csv")]) == 0
    )
    return d, folder, truth, pd.read_csv(root / "raw.csv")


def _block(df):
    return df[df.object == "block_1"].set_index("frame")


def test_a_correction_gives_the_truth_back_and_says_so(mistrack, run_cli, tmp_path):
    d, folder, truth, raw = mistrack
    rb = _block(raw)
    bad = list(BAD)
    # the mistrack: frame 10's angle, status ok, far from the truth as the block rocks
    assert (rb.status[bad] == "ok").all()
    assert np.max(np.abs(rb.theta_rad[bad] - truth.theta_rad[bad])) > 5e-3
    fix = tmp_path / "fix.csv"
    rows = ["object,frame,to_frame,t_s,to_t_s,action,theta_deg"]
    for f in bad[:-1]:  # by frame, in degrees
        rows.append(f"block_1,{f},,,,set,{math.degrees(truth.theta_rad[f]):.12g}")
    rows.append(f"block_1,,,{bad[-1] / 50 + 0.004:.3f},,,{math.degrees(truth.theta_rad[bad[-1]]):.12g}")  # by time
    rows.append("block_1,,,1.40,1.46,drop,")  # frames 70..73 by a time range
    fix.write_text("\n".join(rows) + "\n")
    rc, out, err = run_cli(
        "track",
        folder,
        "--config",
        d / "track.toml",
        "--fps",
        50,
        "-o",
        tmp_path / "t.csv",
        "--corrections",
        fix,
        "--json",
    )
    assert rc == 0, err
    s = json.loads(out)
    fb = _block(pd.read_csv(tmp_path / "t.csv"))
    np.testing.assert_allclose(fb.theta_rad[bad], truth.theta_rad[bad], atol=1e-10)
    assert (fb.status[bad] == "corrected").all() and fb.sigma_theta_rad[bad].isna().all()
    dropped = [70, 71, 72, 73]
    assert (fb.status[dropped] == "dropped").all() and fb[["x_m", "theta_rad"]].loc[dropped].isna().all().all()
    # every other frame is the tracker's own
    rest = [f for f in rb.index if f not in bad and f not in dropped]
    np.testing.assert_array_equal(fb.theta_rad[rest].to_numpy(), rb.theta_rad[rest].to_numpy())
    assert (fb.status[rest] == rb.status[rest]).all()
    counts = s["objects"]["block_1"]["status_counts"]
    assert counts["corrected"] == 5 and counts["dropped"] == 4
    assert [c["n_frames"] for c in s["corrections"]] == [1, 1, 1, 1, 1, 4]
    assert s["corrections"][-1]["where"].endswith("fix.csv, line 7") and s["corrections"][-1]["action"] == "drop"
    rc, out, err = run_cli(
        "track", folder, "--config", d / "track.toml", "--fps", 50, "-o", tmp_path / "t2.csv", "--corrections", fix
    )
    assert rc == 0 and "corrections: 6 applied (5 frame(s) corrected, 4 dropped" in out
    # fit restitution takes the corrected samples as measured, not the dropped ones
    rc, out, err = run_cli("fit", "restitution", tmp_path / "t.csv", "--width", 0.1, "--height", 0.2, "--json")
    assert json.loads(out)["n_skipped"] == len(dropped) + int((rb.status != "ok").sum())


def test_toml_corrections_read_as_the_csv(tmp_path):
    t = tmp_path / "fix.toml"
    t.write_text(
        '[[corrections]]\nobject = "block_1"\nframe = 40\nto_frame = 44\ntheta_rad = 0.01\n'
        '[[corrections]]\nobject = "table"\nt_s = 1.4\nto_t_s = 1.46\naction = "drop"\n'
    )
    c = tmp_path / "fix.csv"
    c.write_text(
        "# hand fixes\nobject,frame,to_frame,t_s,to_t_s,action,theta_rad\nblock_1,40,44,,,,0.01\n\n"
        "# the table's reflection\ntable,,,1.4,1.46,drop,\n"
    )
    a, b = load_corrections(t), load_corrections(c)
    assert b[1].where.endswith("fix.csv, line 6")  # lines as the file numbers them, comments included
    with pytest.raises(InputError, match=r"fix.csv, line 6: object 'table' is not tracked \(objects: block_1\)"):
        load_corrections(c, objects=["block_1"])
    assert [x.to_dict() | {"where": ""} for x in a] == [x.to_dict() | {"where": ""} for x in b]
    assert a[0].frames == (40, 44) and a[0].theta_rad == 0.01 and a[1].times_s == (1.4, 1.46)


@pytest.mark.parametrize(
    "text, words",
    [
        ("object,frame,theta\nblock_1,3,0.1\n", ["'theta' has no unit", "theta_rad or theta_deg"]),
        ("object,frame,theta_rad\nblok_1,3,0.1\n", ["line 2", "object 'blok_1' is not tracked", "block_1"]),
        ("object,frame,theta_rad\nblock_1,5000,0.1\n", ["line 2", "frames 5000..5000 are outside the film"]),
        ("object,t_s,theta_rad\nblock_1,99.5,0.1\n", ["t_s = 99.5 s is outside the film"]),
        ("object,frame,action\nblock_1,3,set\n", ["set without a value"]),
        ("object,frame,action,x_m\nblock_1,3,drop,0.1\n", ["drop with values"]),
        ("object,frame,t_s,theta_rad\nblock_1,3,0.1,0.1\n", ["either frame", "not both"]),
        ("object,frame,to_frame,theta_rad\nblock_1,9,3,0.1\n", ["ends before it starts"]),
    ],
)
def test_bad_corrections_are_one_line_naming_the_file(mistrack, run_cli, tmp_path, text, words):
    d, folder, _, _ = mistrack
    fix = tmp_path / "fix.csv"
    fix.write_text(text)
    rc, _, err = run_cli(
        "track", folder, "--config", d / "track.toml", "--fps", 50, "-o", tmp_path / "t.csv", "--corrections", fix
    )
    assert rc == 2 and len(err.strip().splitlines()) == 1, err
    assert str(fix) in err and all(w in err for w in words), err
    assert not (tmp_path / "t.csv").exists()


def test_preview_at_a_time_shows_the_frames_around_it_with_the_correction(mistrack, run_cli, tmp_path):
    d, folder, truth, _ = mistrack
    fix = tmp_path / "fix.toml"
    fix.write_text('[[corrections]]\nobject = "block_1"\nframe = 41\ntheta_deg = 1.0\n')
    sheet = tmp_path / "sheet.png"
    rc, out, err = run_cli(
        "track",
        "preview",
        folder,
        "--config",
        d / "track.toml",
        "--fps",
        50,
        "--at",
        0.84,
        "--frames",
        5,
        "--corrections",
        fix,
        "-o",
        sheet,
    )
    assert rc == 0, err
    shown = [int(v) for v in re.search(r"frames ([\d, ]+) \(", out).group(1).split(", ")]
    assert shown == [40, 41, 42, 43, 44] and "around t = 0.84 s" in out  # frame 42 in the middle
    assert sheet.stat().st_size > 20_000
    rc, _, err = run_cli(
        "track", "preview", folder, "--config", d / "track.toml", "--fps", 50, "--at", 9.0, "-o", sheet
    )
    assert rc == 2 and "past the end of the film" in err
    rc, _, err = run_cli(
        "track", folder, "--config", d / "track.toml", "--fps", 50, "--at", 0.5, "-o", tmp_path / "x.csv"
    )
    assert rc == 2 and "--at T_S: shows the frames around a time in 'rocklab track preview" in err


def test_run_applies_the_experiment_corrections_and_reports_them(mistrack, run_cli, tmp_path):
    d, folder, truth, _ = mistrack
    s = tmp_path / "s"
    shutil.copytree(d, s)
    (s / "fix.csv").write_text("object,frame,to_frame,action\nblock_1,40,44,drop\n")
    toml = (s / "experiment.toml").read_text()
    toml = re.sub(r"(\[sources\.video\]\n)", r'\1corrections = "fix.csv"\n', toml)
    (s / "experiment.toml").write_text(toml + "\n[output]\nrrd = false\nfigures = false\n")
    rc, out, err = run_cli("run", s / "experiment.toml", "--out", tmp_path / "out")
    assert rc in (0, 1), err
    rep = json.loads((tmp_path / "out" / "report.json").read_text())
    assert rep["track_corrections"] == [
        {"object": "block_1", "action": "drop", "where": f"{s / 'fix.csv'}, line 2", "frames": [40, 44], "n_frames": 5}
    ]
    (s / "fix.csv").write_text("object,frame,theta\nblock_1,40,0.1\n")
    rc, _, err = run_cli("run", s / "experiment.toml", "--out", tmp_path / "out2")
    assert rc == 2 and "'theta' has no unit" in err


def test_a_missing_corrections_file_is_named(tmp_path):
    with pytest.raises(InputError, match="corrections file not found"):
        load_corrections(tmp_path / "nope.csv")
