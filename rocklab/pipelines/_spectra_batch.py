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

from .._procs import dask_client, pool_initializer

__all__ = ["oas_summary_row", "oas_many"]


def oas_summary_row(path: str, units: str | None = None, slenderness: float = 12.0,
                    oas_kwargs: dict | None = None) -> dict:
    """One record's summary row (runs in a worker process). Bad input becomes an ``error`` field."""
    from .._errors import InputError
    from ..models import load_base_motion, overturning_spectrum, pulse_parameters

    row = dict(record=str(path), t_p_s=math.nan, t_I_s=math.nan, t_I_prime_s=math.nan, beta=math.nan,
               f_min=math.nan, f_min_level=math.nan, f_min_R_m=math.nan, error="")
    try:
        rec = load_base_motion(path, units=units)
        row["t_p_s"] = pulse_parameters(rec).t_p_s
        o = overturning_spectrum(rec, slenderness, **(oas_kwargs or {}))
        lv, R = o.f_min_at
        row.update(t_I_s=o.t_I_s, t_I_prime_s=o.t_I_prime_s, beta=o.beta, f_min=o.f_min_rad_s,
                   f_min_level=lv, f_min_R_m=R)
    except InputError as e:
        row["error"] = str(e)
    return row


def _one_numba_thread():
    # one process per core already: numba's own threads would oversubscribe the CPUs
    import numba

    numba.set_num_threads(1)


def oas_many(paths, units: str | None = None, slenderness: float = 12.0, oas_kwargs: dict | None = None,
             workers: int | None = None, scheduler: str | None = None, progress: bool = True):
    """Summary table (pandas DataFrame, input order) of many records' OAS.

    Parameters
    ----------
    paths : sequence of str or Path
        Record files (any format :func:`rocklab.models.load_base_motion` reads).
    units : str, optional
        Units of headerless files (``g`` for the FEMA two-column set).
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
    bar = tqdm(total=len(paths), desc="OAS", unit="record", file=sys.stderr, disable=not progress)
    args = (units, slenderness, oas_kwargs)
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
            from concurrent.futures import ProcessPoolExecutor, as_completed

            with ProcessPoolExecutor(max_workers=workers, initializer=pool_initializer,
                                     initargs=(os.getpid(), _one_numba_thread)) as ex:
                futs = {ex.submit(oas_summary_row, p, *args): i for i, p in enumerate(paths)}
                for f in as_completed(futs):
                    rows[futs[f]] = f.result()
                    bar.update()
    finally:
        bar.close()
    return pd.DataFrame(rows, columns=["record", "t_p_s", "t_I_s", "t_I_prime_s", "beta", "f_min", "f_min_level",
                                       "f_min_R_m", "error"])
