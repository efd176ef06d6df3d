"""The record study as one command: several h/b at once, resumable after a stop (issue 27, item 3)."""

import json
import signal

import numpy as np
import pandas as pd
import pytest

from rocklab.pipelines.spectra import oas_many

KW = ["--levels", 6, "--sizes", 16, "--refine", 3, "--units", "g", "--workers", 1, "--no-progress"]
OAS_KW = dict(levels=6, sizes=16, refine=3)


@pytest.fixture
def records(tmp_path):
    """Three small two-column records (time s, acceleration g): pulses with other periods."""
    folder = tmp_path / "recs"
    folder.mkdir()
    t = np.arange(0.0, 4.0, 0.01)
    for i, (tp, a) in enumerate(((0.3, 0.35), (0.6, 0.25), (1.1, 0.2))):
        acc = a * np.sin(2 * np.pi * t / tp) * np.exp(-t / (2 * tp)) * (t < 3 * tp)
        np.savetxt(folder / f"rec{i}.txt", np.c_[t, acc], fmt="%.6f")
    return folder


def test_several_slenderness_values_are_the_single_runs(records):
    recs = sorted(records.glob("*.txt"))
    study = oas_many(recs, units="g", slenderness=[5, 12], oas_kwargs=OAS_KW, workers=1, progress=False)
    assert len(study) == 6 and study["h_over_b"].tolist() == [5.0, 12.0] * 3
    for hb in (5, 12):
        one = oas_many(recs, units="g", slenderness=hb, oas_kwargs=OAS_KW, workers=1, progress=False)
        got = study[study["h_over_b"] == hb]
        assert got["t_I_s"].tolist() == pytest.approx(one["t_I_s"].tolist(), rel=1e-12)
        assert got["record"].tolist() == [str(r) for r in recs]
    # a more slender block (h/b 12) overturns under smaller pulses: its spectrum differs from h/b 5
    assert not np.allclose(study["f_min"][study["h_over_b"] == 5], study["f_min"][study["h_over_b"] == 12])


def test_a_stopped_study_resumes_where_it_was(run_cli, records, tmp_path, monkeypatch):
    import rocklab.pipelines.spectra._spectra_batch as batch

    out = tmp_path / "study.csv"
    journal = tmp_path / "study.csv.journal.json"
    args = ["oas", records, "--slenderness", "5,12", *KW, "-o", out]
    real, calls = batch.oas_summary_row, []

    def stop_at_the_fourth(*a):
        calls.append(a)
        if len(calls) == 4:
            raise KeyboardInterrupt
        return real(*a)

    monkeypatch.setattr(batch, "oas_summary_row", stop_at_the_fourth)
    rc, _, err = run_cli(*args)  # Ctrl-C: exit 130, no table, the finished rows in the journal
    assert (
        rc == 130
        and not out.exists()
        and "3 finished run(s) kept" in err
        and "--resume" in err
        and len(json.loads(journal.read_text())["rows"]) == 3
    )

    # without --resume the unfinished run's journal is kept and the user is told what to do
    before = journal.read_bytes()
    rc, _, err = run_cli(*args)
    assert rc == 2 and "--resume" in err and err.count("\n") == 1 and journal.read_bytes() == before

    calls.clear()
    rc, out_txt, err = run_cli(*args, "--resume")
    assert rc == 0 and "3 finished run(s)" in err
    assert len(calls) == 3  # only the three runs the stopped study had not finished
    assert not journal.exists()
    resumed = pd.read_csv(out)

    monkeypatch.setattr(batch, "oas_summary_row", real)
    rc, _, _ = run_cli(*args[:-1], tmp_path / "fresh.csv")
    fresh = pd.read_csv(tmp_path / "fresh.csv")
    assert rc == 0 and resumed["t_I_s"].tolist() == pytest.approx(fresh["t_I_s"].tolist(), rel=1e-5)
    assert resumed["h_over_b"].tolist() == [5.0, 12.0] * 3


def test_a_journal_row_is_reused_only_for_the_same_record_and_options(run_cli, records, tmp_path, monkeypatch):
    import rocklab.pipelines.spectra._spectra_batch as batch
    from rocklab.pipelines.spectra._study_journal import file_digest, task_key

    out = tmp_path / "study.csv"
    journal = tmp_path / "study.csv.journal.json"
    args = ["oas", records, *KW, "-o", out]
    recs = sorted(records.glob("*.txt"))
    full = oas_many(recs, units="g", oas_kwargs=OAS_KW, workers=1, progress=False)
    opts = _options_of_the_command(run_cli, args, tmp_path)

    # options differ -> refused, naming what differs, the journal kept
    journal.write_text(
        json.dumps({"kind": "rocklab oas study journal", "options": {**opts, "units": "m/s2"}, "rows": {}})
    )
    rc, _, err = run_cli(*args, "--resume")
    assert rc == 2 and "units" in err and err.count("\n") == 1 and journal.exists()

    # the same options: a journal whose rows carry a marked t_I; the first record then changes
    rows = {}
    for p, r in zip(recs, full.to_dict(orient="records")):
        rows[task_key(file_digest(p), 12.0)] = {**r, "t_I_s": 123.0, "h_over_b": 12.0}
    journal.write_text(json.dumps({"kind": "rocklab oas study journal", "options": opts, "rows": rows}))
    recs[0].write_text(recs[0].read_text() + "4.000000 0.000000\n")
    real, calls = batch.oas_summary_row, []
    monkeypatch.setattr(batch, "oas_summary_row", lambda *a: calls.append(a) or real(*a))
    rc, _, err = run_cli(*args, "--resume")
    tab = pd.read_csv(out)
    assert rc == 0 and "3 finished run(s)" in err and len(calls) == 1 and calls[0][0] == str(recs[0])
    assert tab["t_I_s"].tolist()[1:] == [123.0, 123.0]  # taken from the journal as they were
    assert tab["t_I_s"][0] == pytest.approx(full["t_I_s"][0], rel=0.05)  # run again: not the mark


def _options_of_the_command(run_cli, args, tmp_path):
    """The options ``rocklab oas`` records in its journal, read from a run stopped at its first row."""
    import rocklab.pipelines.spectra._spectra_batch as batch

    probe = tmp_path / "probe.csv"
    real = batch.oas_summary_row
    n = []

    def stop(*a):
        n.append(1)
        if len(n) == 2:
            raise KeyboardInterrupt
        return real(*a)

    batch.oas_summary_row = stop
    try:
        assert run_cli(*args[:-1], probe)[0] == 130
    finally:
        batch.oas_summary_row = real
    return json.loads((tmp_path / "probe.csv.journal.json").read_text())["options"]


def test_bad_study_options(run_cli, records, tmp_path):
    rc, _, err = run_cli("oas", records, "--slenderness", "5,0", *KW)
    assert rc == 2 and "h/b must be a number > 0" in err and err.count("\n") == 1
    rc, _, err = run_cli("oas", records, "--slenderness", "5,5", *KW)
    assert rc == 2 and "given twice" in err
    rc, _, err = run_cli("oas", records, "--resume", *KW)
    assert rc == 2 and "-o" in err
    rc, _, err = run_cli("oas", "--pulse", "sine,0.3,0.5", "--slenderness", "5,12")
    assert rc == 2 and "record study" in err


@pytest.mark.parametrize("sig, rc_want", [(signal.SIGINT, 130)])  # SIGTERM takes the same path (143)
def test_a_study_on_local_processes_stops_at_once(tmp_path, sig, rc_want):
    """Ctrl-C (SIGINT to the whole process group, as a terminal sends it) or SIGTERM to the
    command stops a study running on 2 local processes within seconds: exit 130 / 143, the
    finished rows left in the journal with the line that says to --resume, no worker left
    running. Before, leaving the pool waited for every submitted run (minutes on 176 runs)."""
    import os
    import subprocess
    import sys
    import time

    psutil = pytest.importorskip("psutil")
    folder = tmp_path / "recs"
    folder.mkdir()
    t = np.arange(0.0, 20.0, 0.01)
    for i in range(12):
        acc = 0.3 * np.sin(2 * np.pi * t / (0.4 + 0.1 * i)) * np.exp(-0.2 * t)
        np.savetxt(folder / f"r{i:02d}.txt", np.c_[t, acc], fmt="%.6f")
    out = tmp_path / "study.csv"
    journal = tmp_path / "study.csv.journal.json"
    # the command as a terminal's foreground job runs it: a job started in the background (make test
    # under `&`, nohup) inherits SIGINT ignored, and Python then keeps ignoring it, as it should
    start = "import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
    cli = [sys.executable, "-c", start + "from rocklab.pipelines import main; sys.exit(main())"]
    argv = ["oas", str(folder), "--slenderness", "3,5,8,12", "--band", "--units", "g", "--workers", "2"]
    proc = subprocess.Popen(
        cli + argv + ["-o", str(out), "--no-progress"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,
    )
    t_end = time.time() + 300
    while time.time() < t_end and proc.poll() is None and not journal.exists():
        time.sleep(0.05)  # until the first run has finished
    assert proc.poll() is None, "the study finished before it could be stopped: make it longer"
    workers = psutil.Process(proc.pid).children(recursive=True)
    assert workers
    t0 = time.time()
    if sig == signal.SIGINT:
        os.killpg(proc.pid, sig)
    else:
        proc.send_signal(sig)
    rc = proc.wait(timeout=60)
    stopped_s = time.time() - t0
    with proc.stderr:
        err = proc.stderr.read().decode()
    assert rc == rc_want, err
    assert stopped_s < 15, stopped_s  # measured 0.3-1 s; before: minutes
    assert "--resume" in err and not out.exists()
    assert 1 <= len(json.loads(journal.read_text())["rows"]) < 48
    time.sleep(0.5)
    assert not [w for w in workers if w.is_running() and w.status() != psutil.STATUS_ZOMBIE]
