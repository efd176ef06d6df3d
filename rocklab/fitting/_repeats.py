"""Repeated runs of one block: fit many records, mean ± std, outliers flagged (thesis: 40 runs per case)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._eta_fit import RestitutionFit, fit_restitution

__all__ = ["RepeatSummary", "summarize_repeats", "fit_many", "campaign_table"]


@dataclass(frozen=True)
class RepeatSummary:
    """Statistics of η_e over repeated runs.

    Attributes
    ----------
    mean, std : float
        Mean and sample standard deviation of η_e over the runs kept (not failed, not
        outliers).
    median : float
    n, n_used : int
        Runs given and runs kept.
    values : tuple of float
        η_e of every run (NaN for failed ones), in input order.
    outliers : tuple of int
        Indices of runs whose robust z-score |η − median| / (1.4826 MAD) exceeds ``z_max``.
    failed : tuple of int
        Indices of failed fits.
    suspicious : tuple of int
        Indices of fits flagged suspicious (kept unless also outliers).
    z_max : float
    status, message
    """

    mean: float
    std: float
    median: float
    n: int
    n_used: int
    values: tuple
    outliers: tuple
    failed: tuple
    suspicious: tuple
    z_max: float
    status: str = "ok"
    message: str = ""

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        return dict(
            mean=self.mean,
            std=self.std,
            median=self.median,
            n=self.n,
            n_used=self.n_used,
            values=[float(v) for v in self.values],
            outliers=list(self.outliers),
            failed=list(self.failed),
            suspicious=list(self.suspicious),
            z_max=self.z_max,
            status=self.status,
            message=self.message,
        )

    def report(self) -> str:
        lines = [
            "[[Repeats]]",
            f"    eta_e = {self.mean:.5f} +/- {self.std:.5f} (mean +/- std of {self.n_used} of {self.n} runs)",
            f"    median = {self.median:.5f}",
        ]
        if self.outliers:
            lines.append(
                f"    outliers (robust z > {self.z_max:g}): runs {list(self.outliers)} = "
                + ", ".join(f"{self.values[i]:.4f}" for i in self.outliers)
            )
        if self.failed:
            lines.append(f"    failed fits: runs {list(self.failed)}")
        if self.suspicious:
            lines.append(f"    suspicious (slip/jump symptoms): runs {list(self.suspicious)}")
        if self.message:
            lines.append(f"    note: {self.message}")
        return "\n".join(lines)


def summarize_repeats(fits, z_max: float = 3.5) -> RepeatSummary:
    """Mean ± std of η_e over repeated runs, with robust outlier rejection.

    Parameters
    ----------
    fits : sequence of RestitutionFit or of floats (η_e values)
    z_max : float
        Robust z-score (median/MAD) above which a run is an outlier (Iglewicz–Hoaglin 3.5).
    """
    vals: list[float] = []
    failed: list[int] = []
    susp: list[int] = []
    for i, f in enumerate(fits):
        if isinstance(f, RestitutionFit):
            vals.append(f.eta_e if f.ok else np.nan)
            if not f.ok:
                failed.append(i)
            elif f.suspicious:
                susp.append(i)
        else:
            x = float(f)
            vals.append(x)
            if not np.isfinite(x):
                failed.append(i)
    v = np.asarray(vals, float)
    good = np.isfinite(v)
    nan = float("nan")
    if good.sum() == 0:
        return RepeatSummary(
            nan,
            nan,
            nan,
            len(v),
            0,
            tuple(v),
            (),
            tuple(failed),
            tuple(susp),
            z_max,
            status="failed",
            message="no successful fit among the runs",
        )
    med = float(np.median(v[good]))
    mad = float(np.median(np.abs(v[good] - med)))
    scale = 1.4826 * mad
    if scale > 0:
        z = np.where(good, np.abs(v - med) / scale, 0.0)
        out = np.flatnonzero(good & (z > z_max))
    else:
        out = np.zeros(0, int)
    keep = good.copy()
    keep[out] = False
    kv = v[keep]
    std = float(np.std(kv, ddof=1)) if kv.size > 1 else nan
    msg = "" if kv.size > 1 else "a single usable run: no spread"
    return RepeatSummary(
        mean=float(np.mean(kv)),
        std=std,
        median=med,
        n=int(v.size),
        n_used=int(kv.size),
        values=tuple(float(x) for x in v),
        outliers=tuple(int(i) for i in out),
        failed=tuple(failed),
        suspicious=tuple(susp),
        z_max=float(z_max),
        message=msg,
    )


def fit_many(runs, block=None, progress: bool = False, **kwargs) -> list:
    """Fit η_e to many records.

    Parameters
    ----------
    runs : iterable of (t_s, theta_rad) or (t_s, theta_rad, block)
    block : Block, optional
        Used for runs given without their own block.
    progress : bool
        Show a tqdm bar on stderr.
    **kwargs
        Passed to :func:`fit_restitution`.

    Returns
    -------
    list of RestitutionFit (failed fits included, in order)
    """
    runs = list(runs)
    it = runs
    if progress:
        from tqdm import tqdm

        it = tqdm(runs, desc="fit eta_e", unit="run")
    out = []
    for r in it:
        t, y, *rest = r
        b = rest[0] if rest else block
        out.append(fit_restitution(t, y, b, **kwargs))
    return out


def campaign_table(results, z_max: float = 3.5):
    """Per-block η_e table from many fitted runs, ready for :func:`fit_eta_mat` / :func:`k_table`.

    Parameters
    ----------
    results : iterable of (Block, RestitutionFit)
        Runs of a campaign; runs of the same block are grouped by ``block.name`` (or by
        its width and height when unnamed) and averaged with :func:`summarize_repeats`
        (failed fits and outliers dropped).
    z_max : float
        Outlier threshold (robust z-score).

    Returns
    -------
    DataFrame ``block, b_m, h_m, eta_e, eta_e_std, n_runs, n_used, n_outliers`` (SI).
    """
    import pandas as pd

    groups: dict = {}
    for blk, fit in results:
        key = blk.name or f"b{blk.b_m:g}_h{blk.h_m:g}"
        groups.setdefault(key, (blk, []))[1].append(fit)
    rows = []
    for key, (blk, fits) in groups.items():
        s = summarize_repeats(fits, z_max=z_max)
        rows.append(
            dict(
                block=key,
                b_m=blk.b_m,
                h_m=blk.h_m,
                eta_e=s.mean,
                eta_e_std=s.std,
                n_runs=s.n,
                n_used=s.n_used,
                n_outliers=len(s.outliers),
            )
        )
    return pd.DataFrame(rows, columns=["block", "b_m", "h_m", "eta_e", "eta_e_std", "n_runs", "n_used", "n_outliers"])
