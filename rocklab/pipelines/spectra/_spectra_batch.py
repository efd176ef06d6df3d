"""OAS and t_I of many records in parallel (local processes or a Dask cluster).

Each record and block slenderness is one task: read the record, compute its pulse parameters
and OAS, return one summary row ``record, t_p_s, t_I_s, t_I_prime_s, beta, f_min, f_min_level,
f_min_R_m, error, h_over_b`` (the thesis's whole study is 44 records x h/b 3, 5, 8, 12). Local
runs use :class:`concurrent.futures.ProcessPoolExecutor`; ``scheduler="tcp://host:port"``
submits the same function to a ``dask.distributed`` cluster. A tqdm progress bar goes to
stderr; with a :class:`~._study_journal.StudyJournal` a stopped study resumes where it was.
"""

from __future__ import annotations

import math
import os
import sys

from ..._procs import dask_client, pool_initializer

__all__ = ["oas_summary_row", "oas_many", "expand_records", "thesis_table4", "table4_row", "h_over_b_values"]

#: Extra columns with ``--band``: the 90 % band of each quantity and the default member's t_I.
BAND_COLUMNS = ["t_I_p05_s", "t_I_p95_s", "t_I_prime_p05_s", "t_I_prime_p95_s", "beta_p05", "beta_p95", "t_I_default_s"]
#: Columns of the record table (``rocklab oas`` with several records), in order: the first nine as
#: scripts have always read them, then the record's name and the thesis's Table 4 values.
TABLE_COLUMNS = [
    "record",
    "t_p_s",
    "t_I_s",
    "t_I_prime_s",
    "beta",
    "f_min",
    "f_min_level",
    "f_min_R_m",
    "error",
    "name",
    "thesis_id",
    "thesis_t_p_s",
    "thesis_t_I_s",
    "thesis_t_I_prime_s",
    "thesis_beta",
]


def thesis_table4():
    """The thesis's Table 4 (44 far-field records, H/B = 12) as a DataFrame (see its PROVENANCE.md)."""
    from importlib.resources import files

    import pandas as pd

    with (files("rocklab") / "data" / "thesis" / "table4_ff.csv").open("r", encoding="utf-8") as f:
        return pd.read_csv(f, dtype={"fema_id": str})


def table4_row(name: str, table=None):
    """The Table 4 row of a record named by its FEMA P695 number (``...120111...``), or None."""
    import re

    table = thesis_table4() if table is None else table
    for m in re.finditer(r"(?<!\d)(12\d{4})(?!\d)", str(name)):
        hit = table[table["fema_id"] == m.group(1)]
        if len(hit):
            return hit.iloc[0]
    return None


def expand_records(
    paths, list_file=None, skipped: list | None = None, recursive: bool = False, notes: list | None = None
) -> list:
    """``[(name, path, error)]`` of the records named on the command line.

    A folder stands for every visible record file in it (sorted) except the outputs rocklab
    wrote there (:func:`rocklab._outdir.rocklab_wrote`: a table of an earlier ``oas -o``
    into the folder is not a record; appended to ``skipped`` when given). A file in a folder
    that is plainly not a record (a licence, a README: :func:`rocklab.models.spectra._records.not_a_record`)
    and a subfolder (read with ``recursive``) are left out with one line each in ``notes``,
    never silently. ``list_file`` holds one path per line (relative to the list's folder; ``#``
    starts a comment). A missing file and a second record of the same name get an ``error``
    (one line), so the rest of the batch still runs and the table says what happened to each.
    """
    from pathlib import Path

    from ..._outdir import rocklab_wrote
    from ...models.spectra import not_a_record

    def folder(p: Path) -> list:
        found = []
        for f in sorted(p.iterdir()):
            if f.name.startswith("."):
                continue
            if f.is_dir():
                if recursive:
                    found += folder(f)
                elif notes is not None:
                    notes.append(f"{f}/: a subfolder, not read; add --recursive to read the records in subfolders")
                continue
            if not f.is_file():
                continue
            if rocklab_wrote(f):
                if skipped is not None:
                    skipped.append(f)
                continue
            why = not_a_record(f)
            if why:
                if notes is not None:
                    notes.append(f"{f}: skipped, not a record ({why})")
                continue
            found.append((f, ""))
        return found

    items = []
    for p in paths:
        p = Path(p)
        if p.is_dir():
            items += folder(p)
        else:
            items.append((p, "" if p.is_file() else f"{p}: not found; check the path"))
    if list_file is not None:
        lf = Path(list_file)
        try:
            lines = lf.read_text(encoding="utf-8").splitlines()
        except (OSError, UnicodeDecodeError) as e:
            from ..._errors import InputError

            raise InputError(
                f"--list {lf}: cannot read the list ({type(e).__name__}); give a text file with one "
                "record path per line"
            ) from None
        for i, line in enumerate(lines, start=1):
            entry = line.split("#", 1)[0].strip()
            if not entry:
                continue
            f = Path(entry) if Path(entry).is_absolute() else lf.parent / entry
            items.append((f, "" if f.is_file() else f"{lf}, line {i}: {entry} not found; fix the list"))
    out, seen = [], {}
    for f, err in items:
        name = f.stem
        if not err and name in seen:
            err = f"{f}: same record name as {seen[name]}; rename one (names key the table and the figure)"
        elif not err:
            seen[name] = f
        out.append((name, str(f), err))
    return out


def oas_summary_row(
    path: str, units: str | None = None, slenderness: float = 12.0, oas_kwargs: dict | None = None, band: bool = False
) -> dict:
    """One record's summary row (runs in a worker process). Bad input becomes an ``error`` field.

    With ``band`` the row also holds the 5th/95th percentiles over
    :data:`rocklab.models.BAND_ENSEMBLE` (``t_I_p05_s, t_I_p95_s`` and the same for
    t'_I and beta), and ``t_I_s`` etc. are the ensemble's medians.
    """
    from ..._errors import InputError
    from ...models import load_base_motion, overturning_spectrum, pulse_parameters, t_I_band

    row = dict(
        record=str(path),
        t_p_s=math.nan,
        t_I_s=math.nan,
        t_I_prime_s=math.nan,
        beta=math.nan,
        f_min=math.nan,
        f_min_level=math.nan,
        f_min_R_m=math.nan,
        error="",
    )
    try:
        rec = load_base_motion(path, default_units=units)  # a file's own units are kept
        row["t_p_s"] = pulse_parameters(rec).t_p_s
        if band:
            b = t_I_band(rec, slenderness, **(oas_kwargs or {}))
            d = b.members[0]
            row.update(
                t_I_s=b.t_I_s,
                t_I_prime_s=b.t_I_prime_s,
                beta=b.beta,
                f_min=math.nan,
                f_min_level=d["f_min_level"],
                f_min_R_m=d["f_min_R_m"],
                t_I_p05_s=b.t_I_p05_s,
                t_I_p95_s=b.t_I_p95_s,
                t_I_prime_p05_s=b.t_I_prime_p05_s,
                t_I_prime_p95_s=b.t_I_prime_p95_s,
                beta_p05=b.beta_p05,
                beta_p95=b.beta_p95,
                t_I_default_s=d["t_I_s"],
            )
        else:
            o = overturning_spectrum(rec, slenderness, **(oas_kwargs or {}))
            lv, R = o.f_min_at
            row.update(
                t_I_s=o.t_I_s, t_I_prime_s=o.t_I_prime_s, beta=o.beta, f_min=o.f_min_rad_s, f_min_level=lv, f_min_R_m=R
            )
    except InputError as e:
        row["error"] = str(e)
    return row


def _one_numba_thread():
    # one process per core already: numba's own threads would oversubscribe the CPUs
    import numba

    numba.set_num_threads(1)


def h_over_b_values(slenderness) -> list[float]:
    """The block slendernesses of a study: one h/b or a sequence of them, each > 0, no repeats.

    Raises
    ------
    InputError
        An h/b that is not a positive number, or one given twice.
    """
    from ..._errors import InputError

    vals = [slenderness] if isinstance(slenderness, (int, float)) else list(slenderness)
    out: list[float] = []
    for v in vals:
        try:
            f = float(v)
        except (TypeError, ValueError):
            f = math.nan
        if not (f > 0 and math.isfinite(f)):
            raise InputError(f"--slenderness {v!r}: each h/b must be a number > 0 (e.g. 12 or 3,5,8,12)")
        if f in out:
            raise InputError(f"--slenderness: h/b {f:g} is given twice; give each value once")
        out.append(f)
    if not out:
        raise InputError("--slenderness: give at least one h/b (e.g. 12 or 3,5,8,12)")
    return out


def _run_tasks(args_list, workers, scheduler, on_done) -> None:
    """Run :func:`oas_summary_row` on each argument tuple (in-process, local processes or Dask),
    calling ``on_done(index, row)`` as each finishes (any order)."""
    if not args_list:
        return
    if scheduler:
        from dask.distributed import as_completed

        with dask_client(scheduler) as client:
            futs = {client.submit(oas_summary_row, *a, pure=False): i for i, a in enumerate(args_list)}
            for f in as_completed(futs):
                on_done(futs[f], f.result())
    elif (workers or os.cpu_count() or 1) <= 1 or len(args_list) == 1:
        for i, a in enumerate(args_list):
            on_done(i, oas_summary_row(*a))
    else:
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor, as_completed

        # spawned, not forked: a process that already ran numba's threaded kernels forks
        # children that crash in them (the pool then breaks and the record batch fails)
        ex = ProcessPoolExecutor(
            max_workers=workers,
            mp_context=mp.get_context("spawn"),
            initializer=pool_initializer,
            initargs=(os.getpid(), _one_numba_thread),
        )
        try:
            futs = {ex.submit(oas_summary_row, *a): i for i, a in enumerate(args_list)}
            for f in as_completed(futs):
                on_done(futs[f], f.result())
        except BaseException:
            _stop_pool(ex)
            raise
        ex.shutdown(wait=True)


def _stop_pool(ex) -> None:
    """Stop a process pool now: queued runs cancelled, running ones ended.

    Leaving the pool's ``with`` block on Ctrl-C or SIGTERM waits for every submitted run (a
    176-run study went on for minutes after the signal, its progress bar frozen); the finished
    rows are already in the study's journal, so the running ones are simply ended.
    """
    procs = list((getattr(ex, "_processes", None) or {}).values())
    ex.shutdown(wait=False, cancel_futures=True)
    for proc in procs:
        if proc.is_alive():
            proc.terminate()
    for proc in procs:
        proc.join(timeout=5)


def oas_many(
    paths,
    units: str | None = None,
    slenderness=12.0,
    oas_kwargs: dict | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    band: bool = False,
    journal=None,
):
    """Summary table (pandas DataFrame) of many records' OAS, a row per record and h/b.

    Parameters
    ----------
    paths : sequence of str or Path
        Record files (any format :func:`rocklab.models.load_base_motion` reads).
    units : str, optional
        Units of the files that state none (``g`` for the FEMA two-column set); a
        file's own units (AT2 units field, CSV column) are kept.
    slenderness : float or sequence of float
        Block h/b, or several (the thesis's study: 3, 5, 8, 12); rows are record-major in the
        order given, column ``h_over_b``.
    oas_kwargs : dict, optional
        Options of :func:`rocklab.models.overturning_spectrum`.
    workers : int, optional
        Local processes (default: CPU count). With 1 everything runs in-process.
    scheduler : str, optional
        Address of a Dask distributed scheduler; local processes are not used then.
    progress : bool
        Show a tqdm bar on stderr (one step per record and h/b).
    journal : StudyJournal, optional
        Rows finished by an earlier run of the same study are taken from it and not run again;
        each row finished here is added to it as it comes (see :mod:`._study_journal`).
    """
    import pandas as pd
    from tqdm import tqdm

    from ._study_journal import file_digest, task_key

    hbs = h_over_b_values(slenderness)
    cols = ["record", "t_p_s", "t_I_s", "t_I_prime_s", "beta", "f_min", "f_min_level", "f_min_R_m", "error"]
    cols += (BAND_COLUMNS if band else []) + ["h_over_b"]
    tasks = [(str(p), hb) for p in paths for hb in hbs]
    if not tasks:
        return pd.DataFrame(columns=cols)
    keys: list = [None] * len(tasks)
    if journal is not None:
        digests = {}
        for p in {p for p, _ in tasks}:
            try:
                digests[p] = file_digest(p)
            except OSError:  # the run reports it as the row's error; nothing to reuse
                digests[p] = None
        keys = [task_key(digests[p], hb) if digests[p] else None for p, hb in tasks]
    rows: list = [journal.get(k) if (journal is not None and k) else None for k in keys]
    todo = [i for i, r in enumerate(rows) if r is None]
    bar = tqdm(
        total=len(tasks), initial=len(tasks) - len(todo), desc="OAS", unit="run", file=sys.stderr, disable=not progress
    )

    def done(j: int, row: dict) -> None:
        i = todo[j]
        row["h_over_b"] = tasks[i][1]
        rows[i] = row
        if journal is not None and keys[i] and not row["error"]:  # an error is cheap to meet again
            journal.add(keys[i], row)
        bar.update()

    try:
        _run_tasks([(tasks[i][0], units, tasks[i][1], oas_kwargs, band) for i in todo], workers, scheduler, done)
    finally:
        bar.close()
    for r, (p, _) in zip(rows, tasks):
        r["record"] = p  # a resumed row names the record as this run does
    return pd.DataFrame(rows, columns=cols)


def oas_table(
    items,
    units: str | None = None,
    slenderness=12.0,
    oas_kwargs: dict | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    band: bool = False,
    journal=None,
):
    """The record table (:data:`TABLE_COLUMNS`, then ``h_over_b``) of :func:`expand_records` items.

    A row per record and h/b (``slenderness``: one value or several), record-major. Records with
    an error from the expansion are not run; each row carries the thesis's Table 4 values when
    the record is named by its FEMA P695 number and h/b is 12 (the table's slenderness).
    ``journal``: see :func:`oas_many`.
    """
    import math

    import pandas as pd

    hbs = h_over_b_values(slenderness)
    ok = [(n, p) for n, p, e in items if not e]
    res = oas_many(
        [p for _, p in ok],
        units=units,
        slenderness=hbs,
        oas_kwargs=oas_kwargs,
        workers=workers,
        scheduler=scheduler,
        progress=progress,
        band=band,
        journal=journal,
    )
    by_task = {(r["record"], r["h_over_b"]): r for r in res.to_dict(orient="records")}
    t4 = thesis_table4()
    rows = []
    columns = TABLE_COLUMNS + (BAND_COLUMNS if band else []) + ["h_over_b"]
    for name, path, err in items:
        for hb in hbs:
            row = {c: math.nan for c in columns}
            row.update(name=name, record=path, thesis_id="", error=err, h_over_b=hb)
            if not err:
                row.update({k: v for k, v in by_task[(path, hb)].items() if k in row})
            hit = table4_row(name, t4) if abs(hb - 12.0) < 1e-9 else None
            if hit is not None:
                row.update(
                    thesis_id=hit["ff_id"],
                    thesis_t_p_s=float(hit["t_p_s"]),
                    thesis_t_I_s=float(hit["t_I_s"]),
                    thesis_t_I_prime_s=float(hit["t_I_prime_s"]),
                    thesis_beta=float(hit["beta"]),
                )
            rows.append(row)
    return pd.DataFrame(rows, columns=columns)
