"""OAS and t_I of many records in parallel (local processes or a Dask cluster).

Each record is one task: read it, compute its pulse parameters and OAS, return
one summary row ``record, t_p_s, t_I_s, t_I_prime_s, beta, f_min, f_min_level, f_min_R_m``. Local runs
use :class:`concurrent.futures.ProcessPoolExecutor`; ``scheduler="tcp://host:port"``
submits the same function to a ``dask.distributed`` cluster. A tqdm progress bar
goes to stderr.
"""

from __future__ import annotations

import math
import os
import sys

from ..._procs import dask_client, pool_initializer

__all__ = ["oas_summary_row", "oas_many", "expand_records", "thesis_table4", "table4_row"]

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


def oas_many(
    paths,
    units: str | None = None,
    slenderness: float = 12.0,
    oas_kwargs: dict | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    band: bool = False,
):
    """Summary table (pandas DataFrame, input order) of many records' OAS.

    Parameters
    ----------
    paths : sequence of str or Path
        Record files (any format :func:`rocklab.models.load_base_motion` reads).
    units : str, optional
        Units of the files that state none (``g`` for the FEMA two-column set); a
        file's own units (AT2 units field, CSV column) are kept.
    slenderness : float
        Block h/b.
    oas_kwargs : dict, optional
        Options of :func:`rocklab.models.overturning_spectrum`.
    workers : int, optional
        Local processes (default: CPU count). With 1 everything runs in-process.
    scheduler : str, optional
        Address of a Dask distributed scheduler; local processes are not used then.
    progress : bool
        Show a tqdm bar on stderr.
    """
    import pandas as pd
    from tqdm import tqdm

    paths = [str(p) for p in paths]
    rows = [None] * len(paths)
    if not paths:
        return pd.DataFrame(columns=TABLE_COLUMNS[:9])
    bar = tqdm(total=len(paths), desc="OAS", unit="record", file=sys.stderr, disable=not progress)
    args = (units, slenderness, oas_kwargs, band)
    try:
        if scheduler:
            from dask.distributed import as_completed

            with dask_client(scheduler) as client:
                futs = {client.submit(oas_summary_row, p, *args, pure=False): i for i, p in enumerate(paths)}
                for f in as_completed(futs):
                    rows[futs[f]] = f.result()
                    bar.update()
        elif (workers or os.cpu_count() or 1) <= 1 or len(paths) == 1:
            for i, p in enumerate(paths):
                rows[i] = oas_summary_row(p, *args)
                bar.update()
        else:
            import multiprocessing as mp
            from concurrent.futures import ProcessPoolExecutor, as_completed

            # spawned, not forked: a process that already ran numba's threaded kernels forks
            # children that crash in them (the pool then breaks and the record batch fails)
            with ProcessPoolExecutor(
                max_workers=workers,
                mp_context=mp.get_context("spawn"),
                initializer=pool_initializer,
                initargs=(os.getpid(), _one_numba_thread),
            ) as ex:
                futs = {ex.submit(oas_summary_row, p, *args): i for i, p in enumerate(paths)}
                for f in as_completed(futs):
                    rows[futs[f]] = f.result()
                    bar.update()
    finally:
        bar.close()
    cols = ["record", "t_p_s", "t_I_s", "t_I_prime_s", "beta", "f_min", "f_min_level", "f_min_R_m", "error"]
    return pd.DataFrame(rows, columns=cols + (BAND_COLUMNS if band else []))


def oas_table(
    items,
    units: str | None = None,
    slenderness: float = 12.0,
    oas_kwargs: dict | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    band: bool = False,
):
    """The record table (:data:`TABLE_COLUMNS`) of :func:`expand_records` items.

    Records with an error from the expansion are not run; each row carries the
    thesis's Table 4 values when the record is named by its FEMA P695 number
    (compared only for H/B = 12, the table's slenderness).
    """
    import math

    import pandas as pd

    ok = [(n, p) for n, p, e in items if not e]
    res = oas_many(
        [p for _, p in ok],
        units=units,
        slenderness=slenderness,
        oas_kwargs=oas_kwargs,
        workers=workers,
        scheduler=scheduler,
        progress=progress,
        band=band,
    )
    by_path = {r["record"]: r for r in res.to_dict(orient="records")}
    t4 = thesis_table4()
    rows = []
    columns = TABLE_COLUMNS + (BAND_COLUMNS if band else [])
    for name, path, err in items:
        row = {c: math.nan for c in columns}
        row.update(name=name, record=path, thesis_id="", error=err)
        if not err:
            row.update({k: v for k, v in by_path[path].items() if k in row})
        hit = table4_row(name, t4) if abs(slenderness - 12.0) < 1e-9 else None
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
