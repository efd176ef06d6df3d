"""Outputs never destroy what rocklab did not make; checks happen before the work; errors are one line."""

import json
import os
import shutil

import numpy as np
import pandas as pd
import pytest

from rocklab import Block
from rocklab._outdir import MARKER, check_output_dir, clean_stale
from rocklab.models import simulate
from test_fuzz_corpus import _points_csv


def _experiment(tmp_path, rrd="false"):
    blk = Block(0.045, 0.2025)
    sim = simulate(blk, theta0_rad=0.8 * blk.alpha_rad, duration_s=4.0, restitution="constant", eta=0.9)
    t = np.arange(0, 4.0, 1 / 100)
    th = np.where(t < 0.3, sim.theta_rad[0], np.interp(t - 0.3, sim.t_s, sim.theta_rad))
    th = th + np.random.default_rng(0).normal(0, 3e-4, t.size)
    d = tmp_path / "exp"
    d.mkdir()
    pd.DataFrame({"t_s": t, "theta_rad": th}).to_csv(d / "tracks.csv", index=False)
    (d / "experiment.toml").write_text(
        'name = "safe"\n[block]\nb_m = 0.045\nh_m = 0.2025\n[sources.track]\npath = "tracks.csv"\n'
        f"[output]\nrrd = {rrd}\nfigures = false\n"
    )
    return d / "experiment.toml"


def test_run_refuses_a_users_folder_and_never_deletes_its_files(tmp_path, run_cli):
    cfg = _experiment(tmp_path)
    precious = tmp_path / "precious"
    precious.mkdir()
    (precious / "thesis.txt").write_text("three years of work")
    rc, out, err = run_cli("run", cfg, "--out", precious)
    assert rc == 2 and err.count("\n") == 1 and "thesis.txt" in err and "--force" in err
    assert sorted(p.name for p in precious.iterdir()) == ["thesis.txt"]
    # --force writes beside the user's file; a second forced run replaces only rocklab's own outputs
    for _ in range(2):
        rc, out, err = run_cli("run", cfg, "--out", precious, "--force")
        assert rc == 0, err
        assert (precious / "thesis.txt").read_text() == "three years of work"
        assert json.loads((precious / "report.json").read_text())["status"] == "ok"
    # a user's file that collides with an output name is kept under another name, not overwritten
    (precious / "summary.md").unlink()
    (precious / "summary.md").write_text("my notes")
    marker = json.loads((precious / MARKER).read_text())
    marker["entries"].remove("summary.md")
    (precious / MARKER).write_text(json.dumps(marker))
    rc, out, err = run_cli("run", cfg, "--out", precious, "--force")
    assert rc == 0, err
    kept = [p for p in precious.iterdir() if p.name.startswith("summary.md.user-")]
    assert len(kept) == 1 and kept[0].read_text() == "my notes"


def test_run_replaces_its_own_folder_and_refuses_a_file(tmp_path, run_cli):
    cfg = _experiment(tmp_path)
    out = tmp_path / "res"
    assert run_cli("run", cfg, "--out", out)[0] == 0
    assert run_cli("run", cfg, "--out", out, "--force")[0] == 0  # rocklab's own folder: replaced whole
    assert (out / MARKER).is_file() and (out / "report.json").is_file()
    f = tmp_path / "afile.txt"
    f.write_text("keep me")
    rc, _, err = run_cli("run", cfg, "--out", f)
    assert rc == 2 and "existing file" in err and err.count("\n") == 1
    assert f.read_text() == "keep me"


def test_stale_staging_of_dead_processes_is_cleaned(tmp_path):
    parent = tmp_path
    dead = parent / ".res.tmp-999999999-abc"  # no such pid
    dead.mkdir()
    (dead / "half.csv").write_text("1,2")
    live = parent / f".res.tmp-{os.getpid()}-xyz"  # a run in progress (this process) is left alone
    live.mkdir()
    other = parent / ".unrelated.tmp-999999999-abc"
    other.mkdir()
    removed = clean_stale(parent, "res")
    assert removed == [dead] and live.is_dir() and other.is_dir()


def test_free_space_and_writability_checked_before_work(tmp_path, monkeypatch):
    from collections import namedtuple

    import rocklab._outdir as O

    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(shutil, "disk_usage", lambda p: usage(10**9, 10**9 - 1000, 1000))
    with pytest.raises(O.InputError, match="MB free"):
        check_output_dir(tmp_path / "new", need_bytes=10**6)
    monkeypatch.undo()

    def denied(*a, **k):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(O.tempfile, "mkstemp", denied)
    with pytest.raises(O.InputError, match="not writable"):
        check_output_dir(tmp_path / "new2")


def test_file_outputs_checked_before_work(tmp_path, run_cli):
    d = tmp_path / "adir"
    d.mkdir()
    rc, out, err = run_cli("simulate", "--width", 0.045, "--height", 0.2, "--theta0", 0.05, "-o", d)
    assert rc == 2 and "is a folder" in err and err.count("\n") == 1 and "Traceback" not in err
    (tmp_path / "f.txt").write_text("x")
    rc, out, err = run_cli(
        "simulate", "--width", 0.045, "--height", 0.2, "--theta0", 0.05, "-o", tmp_path / "f.txt" / "x.csv"
    )
    assert rc == 2 and "is a file, not a folder" in err
    rc, out, err = run_cli(
        "simulate", "--width", 0.045, "--height", 0.2, "--theta0", 0.05, "-o", tmp_path / "new" / "deep" / "x.csv"
    )
    assert rc == 0 and (tmp_path / "new" / "deep" / "x.csv").is_file()


def test_internal_error_is_one_line_exit_3(monkeypatch, run_cli):
    import rocklab.pipelines.cli.commands._cmd_simulate as S

    def boom(args):
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setattr(S, "run", boom)
    rc, out, err = run_cli("simulate", "--width", 0.045, "--height", 0.2)
    assert rc == 3 and err.count("\n") == 1 and "--debug" in err and "ZeroDivisionError" in err
    with pytest.raises(ZeroDivisionError):
        run_cli("--debug", "simulate", "--width", 0.045, "--height", 0.2)


def test_unreachable_scheduler_is_one_line(tmp_path, run_cli, monkeypatch):
    pytest.importorskip("distributed")
    from rocklab import _procs

    # dask retries a refused connection until its timeout (10 s by default): 1 s shows the same message
    monkeypatch.setattr(_procs.dask_client, "__defaults__", (1.0,))
    cfg = _experiment(tmp_path)
    rc, out, err = run_cli(
        "campaign", cfg.parent, "--out", tmp_path / "c", "--scheduler", "tcp://127.0.0.1:9", "--no-progress"
    )
    assert rc == 2 and err.count("\n") == 1 and "no Dask scheduler answered" in err


def test_side_files_keep_a_users_file_and_replace_their_own(tmp_path, run_cli):
    src = _points_csv(tmp_path / "p.csv")
    (tmp_path / "audit.json").write_text("my audit")
    (tmp_path / "tracks.csv").write_text("my tracks")  # the default -o is a side file too
    for k in range(2):
        rc, out, err = run_cli("track3d", src)
        assert rc == 0, err
        kept = sorted(p.name for p in tmp_path.iterdir() if ".user-" in p.name)
        # the first run keeps both of the user's files; the second replaces only rocklab's own
        assert len(kept) == 2, kept
        assert {(tmp_path / n).read_text() for n in kept} == {"my audit", "my tracks"}
        assert json.loads((tmp_path / "audit.json").read_text())["verdict"] in ("valid", "suspect", "invalid")
        assert pd.read_csv(tmp_path / "tracks.csv")["theta_rad"].abs().max() == pytest.approx(0.05, rel=0.2)
        assert err.count("rocklab: kept your") == (2 if k == 0 else 0), err
        assert not (tmp_path / MARKER).exists()  # the user's folder gets the outputs, nothing else
    assert src.read_text().startswith("t_s,point")
    # an explicit -o is the user's choice: replaced, but audit.json beside it is still a side file
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "mine.csv").write_text("replace me")
    (tmp_path / "sub" / "audit.json").write_text("keep me")
    assert run_cli("track3d", src, "-o", tmp_path / "sub" / "mine.csv")[0] == 0
    assert "theta_rad" in (tmp_path / "sub" / "mine.csv").read_text().splitlines()[0]
    assert [p.read_text() for p in (tmp_path / "sub").glob("audit.json.user-*")] == ["keep me"]


def test_user_copies_in_one_second_do_not_collide(tmp_path):
    from rocklab._io import write_text_atomic

    p = tmp_path / "audit.json"
    for k in range(3):
        p.write_text(f"user {k}")  # the user writes it again: not rocklab's any more
        marker = tmp_path / MARKER
        if marker.exists():
            marker.unlink()
        write_text_atomic(p, "rocklab", side=True)
    kept = sorted(q.read_text() for q in tmp_path.glob("audit.json.user-*"))
    assert kept == ["user 0", "user 1", "user 2"] and p.read_text() == "rocklab"


def test_oas_parquet_side_file_keeps_a_users_file(tmp_path, run_cli, shared_data):
    recs = sorted((shared_data / "records").glob("*.AT2"))[:2]
    (tmp_path / "tab.parquet").write_text("my parquet")
    rc, out, err = run_cli(
        "oas",
        *recs,
        "-o",
        tmp_path / "tab.csv",
        "--levels",
        6,
        "--sizes",
        6,
        "--refine",
        2,
        "--no-progress",
        "--workers",
        1,
    )
    assert rc == 0, err
    assert [p.read_text() for p in tmp_path.glob("tab.parquet.user-*")] == ["my parquet"]
    assert len(pd.read_parquet(tmp_path / "tab.parquet")) == 2


def test_a_closed_pipe_is_not_an_error(tmp_path):
    """`rocklab ... | head` closing the pipe early: exit 0, nothing on stderr (was exit 2, "Broken pipe")."""
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "PYTHONPATH": str(root)}
    # a command that prints at once (no compiled kernel to wait for): the pipe handling is the CLI's
    argv = [sys.executable, "-m", "rocklab", "fit", "k-predict", "--hb", "4.5", "--b-cm", "9"]
    p = subprocess.Popen([*argv, "--json"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    p.stdout.close()  # the reader is gone before the first byte is written
    with p.stderr:
        err = p.stderr.read().decode()
    assert p.wait(timeout=120) == 0 and err == "", err
    # the same output to a reader that stays reads as one JSON object with the column's status
    done = subprocess.run([*argv, "--json"], capture_output=True, env=env, timeout=120)
    # Čeh Eq. 19 at h/b = 4.5, b = 9 cm
    k_eq19 = 0.0047 * 4.5**2 - 0.0258 * 4.5 + 1.0635 - 0.0565 * 9
    assert done.returncode == 0 and json.loads(done.stdout)["k"] == pytest.approx(k_eq19, abs=1e-12)


@pytest.mark.parametrize("force", [False, True])
def test_run_refuses_an_out_folder_that_holds_its_inputs(tmp_path, run_cli, force):
    """`run S/experiment.toml --out S` on a folder rocklab wrote (a synth session) replaced the session."""
    from rocklab._outdir import claim_dir

    cfg = _experiment(tmp_path)
    session = cfg.parent
    claim_dir(session, ["experiment.toml", "tracks.csv"], command="synth")  # as `rocklab synth` leaves it
    before = {p.name: p.read_bytes() for p in session.iterdir()}
    rc, out, err = run_cli("run", cfg, "--out", session, *(["--force"] if force else []))
    assert rc == 2 and err.count("\n") == 1 and "holds the input" in err, err
    assert {p.name: p.read_bytes() for p in session.iterdir()} == before
    # the user's own folder (no marker entry for the inputs) with --force: outputs beside the inputs
    (session / MARKER).unlink()
    rc, out, err = run_cli("run", cfg, "--out", session, "--force")
    assert rc == 0, err
    assert (session / "tracks.csv").read_bytes() == before["tracks.csv"]
    assert json.loads((session / "report.json").read_text())["status"] == "ok"


def _listing(folder):
    return {p.name: p.read_bytes() for p in folder.iterdir()}


def test_oas_output_in_its_record_folder_is_not_read_back(tmp_path, run_cli):
    """`oas recs/ -o recs/tI.csv` twice: the second run read tI.csv (and tI.parquet) as records;
    the first left a .rocklab-output marker in the user's record folder."""
    import shutil

    from test_fuzz_corpus import _two_records

    recs = tmp_path / "recs"
    recs.mkdir()
    _two_records(recs)
    inputs = _listing(recs)
    # one process: a pool of two would import the package twice per run, and the outputs are the subject here
    argv = ("oas", recs, "-o", recs / "tI.csv", "--levels", 4, "--sizes", 4, "--refine", 1, "--no-progress")
    argv += ("--workers", 1)
    tables = []
    for k in range(2):
        rc, out, err = run_cli(*argv)
        assert rc == 0, err
        assert err.count("not reading") == 2 * k, err  # tI.csv and tI.parquet, from the second run on
        tables.append(pd.read_csv(recs / "tI.csv"))
        # only the outputs asked for are written in the user's folder: no marker, no kept copies
        assert sorted(_listing(recs)) == sorted([*inputs, "tI.csv", "tI.parquet"])
        assert {n: b for n, b in _listing(recs).items() if n in inputs} == inputs
    assert len(tables[1]) == 2 and tables[1]["t_p_s"].tolist() == tables[0]["t_p_s"].tolist()
    assert len(pd.read_parquet(recs / "tI.parquet")) == 2
    # a copy (made by the user, not stamped) is the user's file: it is read, and fails as a record
    shutil.copyfile(recs / "tI.csv", recs / "mine.csv")
    rc, out, err = run_cli(*argv)
    assert rc == 1 and "mine.csv" in err and "2/3 records done" in out, (out, err)
    # a stamped output the user changed afterwards is theirs again: read, so never overwritten
    with open(recs / "tI.csv", "a") as f:
        f.write("# checked\n")
    rc, out, err = run_cli(*argv)
    assert rc == 2 and "would overwrite the input record" in err, err


def test_imu_output_in_its_log_folder_is_not_read_back(tmp_path, run_cli):
    """`imu LOG/ -o LOG/theta.csv` twice: the second run took theta.csv for a second log (or refused)."""
    from test_fuzz_corpus import _imu_folder

    log = _imu_folder(tmp_path)
    (log / "Inertial.csv").rename(log / "mylog.csv")  # found as the folder's single CSV
    inputs = _listing(log)
    for _ in range(2):
        rc, out, err = run_cli("imu", log, "-o", log / "theta.csv")
        assert rc == 0, err
        assert sorted(_listing(log)) == ["mylog.csv", "theta.csv"] and _listing(log)["mylog.csv"] == inputs["mylog.csv"]
        assert pd.read_csv(log / "theta.csv")["t_s"].size > 100


def test_stamps_live_in_the_cache_folder_where_files_hold_no_extended_attributes(tmp_path, monkeypatch):
    """Without user extended attributes (tmpfs on older kernels, some network shares) a side file
    rocklab wrote is still known as its own: replaced by the next run with no .user- copy, and
    nothing written beside it; an edited one is the user's again."""
    from rocklab._io import write_text_atomic
    from rocklab._outdir import rocklab_wrote

    def unsupported(*a, **k):
        raise OSError(95, "Operation not supported")

    monkeypatch.setattr(os, "setxattr", unsupported)
    monkeypatch.setattr(os, "getxattr", unsupported)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    folder = tmp_path / "data"
    folder.mkdir()
    out = folder / "audit.json"
    for k in range(3):
        write_text_atomic(out, f'{{"run": {k}}}', side=True)
        assert rocklab_wrote(out)
        assert sorted(p.name for p in folder.iterdir()) == ["audit.json"]
    out.write_text('{"run": "mine"}')
    assert not rocklab_wrote(out)
    write_text_atomic(out, '{"run": 3}', side=True)
    kept = [p for p in folder.iterdir() if ".user-" in p.name]
    assert [p.read_text() for p in kept] == ['{"run": "mine"}'] and out.read_text() == '{"run": 3}'
    link = folder / "link.json"
    link.symlink_to(out)
    assert not rocklab_wrote(link)


def test_a_killed_writers_staging_file_is_not_the_users(tmp_path):
    """A campaign killed while writing campaign.rrd left ``.campaign.rrd.tmp-<pid>-...``; resuming
    refused the folder as holding "files rocklab did not write". A dead writer's staging is
    rocklab's; a live one's (another rocklab still writing) is not taken."""
    import os
    import subprocess
    import sys

    from rocklab._outdir import foreign_entries

    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    pid = int(dead.stdout)
    (tmp_path / f".campaign.rrd.tmp-{pid}-abc.rrd").write_bytes(b"x")
    (tmp_path / f".report.json.tmp-{os.getpid()}-def").write_bytes(b"x")
    (tmp_path / "notes.txt").write_text("mine")
    assert foreign_entries(tmp_path) == sorted([f".report.json.tmp-{os.getpid()}-def", "notes.txt"])


def test_a_stop_deferred_by_a_compiled_loop_stops_the_next_publication(tmp_path):
    """A SIGTERM that came while numba's loop ran is left to be raised before any output is renamed
    into place: the run that finishes before the signal is sent again publishes nothing (the CLI
    test of this, tests/test_kill.py, lost that race under load: exit 0, output written)."""
    from rocklab._io import write_text_atomic
    from rocklab._outdir import defer_stop, raise_pending_stop

    class Stop(SystemExit):
        pass

    defer_stop(Stop(143))
    with pytest.raises(Stop):
        write_text_atomic(tmp_path / "out.txt", "x")
    assert not (tmp_path / "out.txt").exists() and not list(tmp_path.glob(".*"))
    raise_pending_stop()  # raised once only
    assert write_text_atomic(tmp_path / "out.txt", "x").read_text() == "x"
    defer_stop(Stop(143))
    defer_stop(None)  # forgotten when the stop was raised another way
    assert write_text_atomic(tmp_path / "out2.txt", "y").read_text() == "y"
