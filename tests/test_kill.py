"""``kill -9`` at random moments of ``run``, ``campaign`` and ``oas``: never a half-written result,
no orphaned worker, and the next run finishes (a campaign resumes, skipping finished experiments)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pandas as pd
import pytest

from rocklab import Block
from rocklab._outdir import MARKER
from rocklab.models import simulate

psutil = pytest.importorskip("psutil")
pytestmark = pytest.mark.slow

CLI = [sys.executable, "-c", "import sys; from rocklab.pipelines import main; sys.exit(main())"]
EXP_FILES = ("report.json", "summary.md", "series.csv", "session.rrd", MARKER)


def _experiment(root, name, seed):
    blk = Block(0.045, 0.2025)
    sim = simulate(blk, theta0_rad=0.8 * blk.alpha_rad, duration_s=5.0, restitution="constant", eta=0.9)
    t = np.arange(0, 5.0, 1 / 100)
    th = np.where(t < 0.5, sim.theta_rad[0], np.interp(t - 0.5, sim.t_s, sim.theta_rad))
    th = th + np.random.default_rng(seed).normal(0, 3e-4, t.size)
    d = root / name
    d.mkdir(parents=True)
    pd.DataFrame({"t_s": t, "theta_rad": th}).to_csv(d / "tracks.csv", index=False)
    (d / "experiment.toml").write_text(
        f'name = "{name}"\n[block]\nb_m = 0.045\nh_m = 0.2025\n[sources.track]\npath = "tracks.csv"\n'
        "[output]\nrrd = true\nfigures = true\n"
    )
    return d / "experiment.toml"


def _start(args):
    return subprocess.Popen(CLI + [str(a) for a in args], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def _finish(args):
    p = subprocess.run(CLI + [str(a) for a in args], capture_output=True, text=True, timeout=600)
    return p.returncode, p.stdout, p.stderr


def _complete_experiment(out) -> bool:
    """A finished output holds every file and a readable report; anything else is half-written."""
    if not out.exists():
        return False
    names = {p.name for p in out.iterdir()}
    assert set(EXP_FILES) <= names, f"partial output in {out}: {sorted(names)}"
    json.loads((out / "report.json").read_text())
    return True


def _kill_at(args, delay_s, after=None):
    """Start the command, wait ``delay_s`` (after ``after()`` turns true, if given), kill -9 it."""
    proc = _start(args)
    if after is not None:
        t_end = time.time() + 600  # a cold numba cache makes the first experiments slow
        while not after() and proc.poll() is None and time.time() < t_end:
            time.sleep(0.05)
    time.sleep(delay_s)
    kids = []
    try:
        kids = psutil.Process(proc.pid).children(recursive=True)
    except psutil.NoSuchProcess:
        pass
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    return kids


def _gone(kids, within_s=10.0):
    t_end = time.time() + within_s
    alive = list(kids)
    while alive and time.time() < t_end:
        alive = [k for k in alive if k.is_running() and k.status() != psutil.STATUS_ZOMBIE]
        time.sleep(0.1)
    return [k.pid for k in alive]


def test_kill_run_at_random_moments(tmp_path):
    cfg = _experiment(tmp_path, "e", 0)
    out = tmp_path / "out"
    t0 = time.perf_counter()
    rc, _, err = _finish(["run", cfg, "--out", out])
    full_s = time.perf_counter() - t0
    assert rc == 0, err and _complete_experiment(out)
    first = json.loads((out / "report.json").read_text())["fit"]["eta_e"]
    rng = np.random.default_rng(7)
    for delay in rng.uniform(0.1, full_s, 5):
        _kill_at(["run", cfg, "--out", out, "--force"], delay)
        assert _complete_experiment(out)  # the previous result, whole, or the new one, whole
        assert json.loads((out / "report.json").read_text())["fit"]["eta_e"] == pytest.approx(first, abs=1e-9)
    rc, _, err = _finish(["run", cfg, "--out", out, "--force"])
    assert rc == 0, err and _complete_experiment(out)
    assert not list(tmp_path.glob(".out.*")), "staging folders of killed runs were not cleaned up"


def test_kill_campaign_no_orphans_and_resume(tmp_path):
    root = tmp_path / "c"
    for i in range(4):
        _experiment(root, f"e{i}", i)
    out = tmp_path / "out"
    rng = np.random.default_rng(11)

    def one_done():
        return any((out / "experiments").glob("e*/report.json"))

    for k, delay in enumerate(rng.uniform(0.0, 3.0, 3)):
        # the first kill lands once an experiment has finished (so the re-run can show it resumes)
        kids = _kill_at(
            ["campaign", root, "--out", out, "--workers", 2, "--no-progress"], delay, after=one_done if k == 0 else None
        )
        assert _gone(kids) == [], "worker processes outlived the killed campaign"
        for d in (out / "experiments").glob("*") if (out / "experiments").exists() else []:
            if not d.name.startswith("."):
                assert _complete_experiment(d)
    exp_dir = out / "experiments"
    done_before = {
        d.name: (d / "report.json").stat().st_mtime_ns for d in (exp_dir.glob("e*") if exp_dir.exists() else [])
    }
    rc, stdout, err = _finish(["campaign", root, "--out", out, "--workers", 2, "--no-progress", "--json"])
    assert rc == 0, err
    res = json.loads(stdout)
    assert res["n_ok"] == 4 and res["n_failed"] == 0
    for d in (out / "experiments").iterdir():
        if not d.name.startswith("."):
            assert _complete_experiment(d)
    assert (out / "campaign.csv").is_file()
    # resumed: experiments that finished before a kill were not run again (fingerprint unchanged)
    assert done_before, "no experiment finished before the kills; lengthen the delays"
    for name, mtime in done_before.items():
        assert (exp_dir / name / "report.json").stat().st_mtime_ns == mtime, name


def test_kill_oas_leaves_no_partial_csv(tmp_path):
    t = np.arange(0, 10, 0.01)
    rec = tmp_path / "r.csv"
    pd.DataFrame({"t_s": t, "acc_g": 0.3 * np.sin(2 * np.pi * t) * np.exp(-0.3 * t)}).to_csv(rec, index=False)
    out = tmp_path / "oas.csv"
    rng = np.random.default_rng(3)
    for delay in rng.uniform(0.5, 3.0, 3):
        _kill_at(["oas", rec, "--levels", 20, "--sizes", 30, "-o", out], delay)
        if out.exists():
            pd.read_csv(out)  # whole CSV or none
    rc, _, err = _finish(["oas", rec, "--levels", 20, "--sizes", 30, "-o", out])
    assert rc == 0, err
    assert len(pd.read_csv(out)) > 0
    assert not list(tmp_path.glob(".oas.csv.*")), "temp files of killed writers were not cleaned up"


def test_sigterm_stops_cleanly(tmp_path):
    """SIGTERM (what a scheduler or `timeout` sends) exits 143 and removes the staged output."""
    cfg = _experiment(tmp_path, "e", 1)
    out = tmp_path / "out"
    proc = subprocess.Popen(
        CLI + ["run", str(cfg), "--out", str(out)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
    )
    t_end = time.time() + 60
    while time.time() < t_end and not list(tmp_path.glob(".out.tmp-*")) and proc.poll() is None:
        time.sleep(0.02)  # wait until the run is staging its outputs
    proc.send_signal(signal.SIGTERM)
    rc = proc.wait(timeout=60)
    with proc.stderr:
        err = proc.stderr.read().decode()
    if rc == 0:  # finished before the signal landed: the output is whole
        assert _complete_experiment(out)
    else:  # one line, and no native library's complaint from the interpreter's teardown
        assert rc == 143 and not out.exists(), (rc, err)
        assert err.strip().splitlines() == ["rocklab run: terminated (SIGTERM); staged outputs removed"], err
    assert not list(tmp_path.glob(".out.tmp-*"))


def _catches_sigterm(pid: int) -> bool:
    """Whether process ``pid`` has a SIGTERM handler installed (Linux: SigCgt of /proc/PID/status)."""
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("SigCgt:"):
                    return bool(int(line.split()[1], 16) & (1 << (signal.SIGTERM - 1)))
    except OSError:
        return True  # not Linux, or the process is gone: the CPU time alone decides
    return True


def test_sigterm_during_a_compiled_loop_is_one_line_and_143(tmp_path):
    """SIGTERM while numba's compiled loop runs: Python runs the handler when numba boxes the
    results, inside numba's own callback, and the exception raised there crashed the interpreter
    (exit 139, 10 of 10 tries on a 25 s `simulate`). The run now ends after the loop: one line, 143."""
    t = np.arange(0, 1500, 0.005)
    rec = tmp_path / "sine.csv"
    pd.DataFrame({"t_s": t, "acc_m_s2": 0.21 * 9.81 * np.sin(4 * np.pi * t)}).to_csv(
        rec, index=False, float_format="%.9g"
    )
    out = tmp_path / "sim.csv"
    argv = ["simulate", "--width", 0.2, "--height", 1.0, "--base-motion", rec, "--duration", 1500, "--dt", 2e-6]
    for blocked in (False, True):
        # a child inherits its parent's blocked signals: the CLI unblocks SIGTERM (a test process had
        # blocked it, and the killed run went on to publish its output, exit 0)
        mask = signal.pthread_sigmask(signal.SIG_BLOCK if blocked else signal.SIG_UNBLOCK, {signal.SIGTERM})
        try:
            proc = subprocess.Popen(
                CLI + [str(a) for a in argv] + ["--output-dt", "0.01", "-o", str(out)],
                stdout=subprocess.DEVNULL,
                stderr=subprocess.PIPE,
            )
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        ps = psutil.Process(proc.pid)
        # past the imports (about 1 CPU-s) and the handler's installation (a loaded machine's
        # imports took longer and the signal killed the run before it, exit -15): inside numba
        # (compiling, or the ~5 CPU-s loop)
        while proc.poll() is None and (sum(ps.cpu_times()[:2]) < 2.5 or not _catches_sigterm(proc.pid)):
            time.sleep(0.05)
        assert proc.poll() is None, "the run ended before the signal: make it longer"
        proc.send_signal(signal.SIGTERM)
        rc = proc.wait(timeout=600)
        with proc.stderr:
            err = proc.stderr.read().decode()
        assert rc == 143, (rc, err)
        assert err.strip().splitlines() == ["rocklab simulate: terminated (SIGTERM); staged outputs removed"], err
        assert not out.exists() and not list(tmp_path.glob(".sim.csv.*"))
