"""Campaign-level calibration: η_mat from edge-contact tests, inverse k from full-contact tests.

Čeh et al. (2018) §5.3–5.5: η_mat = η_e/η_M (Eq. 16) from edge-contact blocks, where the
impulse position k is known from the strip width (Table 4); then η_RB = η_e,full/η_mat
(Eq. 17) and k, b̄ from inverting Eq. 14 (Eq. 18); finally the regression of Eq. 19.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from .._diagnostics import warn
from .._errors import InputError, where
from ._laws import edge_contact_k, eta_modified, k_from_eta
from ._regression import KRegression, fit_k_regression

__all__ = ["EtaMatResult", "KTableResult", "fit_eta_mat", "k_table", "read_block_table", "ETA_MAT_RULES"]

#: Averaging rules for η_mat over blocks.
ETA_MAT_RULES = ("mean", "median", "lsq")


def read_block_table(src, nan: str = "raise") -> pd.DataFrame:
    """Read and validate a campaign table with columns ``block, b_m, h_m, eta_e``.

    Parameters
    ----------
    src : path or DataFrame
    nan : {"raise", "skip"}
        Rows with missing/NaN values: error naming the line, or dropped.

    Returns
    -------
    DataFrame with columns ``block, b_m, h_m, eta_e, h_over_b, alpha_rad`` (SI).
    """
    path = None
    if isinstance(src, pd.DataFrame):
        df = src.copy()
    else:
        path = Path(src)
        try:
            df = pd.read_csv(path)
        except pd.errors.EmptyDataError:
            raise InputError(f"{where(path)}empty file; give a CSV with columns block,b_m,h_m,eta_e") from None
    missing = [c for c in ("block", "b_m", "h_m", "eta_e") if c not in df.columns]
    if missing:
        raise InputError(
            f"{where(path)}missing column(s) {missing}; the table needs block,b_m,h_m,eta_e (widths/heights in metres)"
        )
    df = df[["block", "b_m", "h_m", "eta_e"]].copy()
    for c in ("b_m", "h_m", "eta_e"):
        df[c] = pd.to_numeric(df[c], errors="coerce")
    bad = df[["b_m", "h_m", "eta_e"]].isna().any(axis=1)
    if bad.any():
        if nan == "raise":
            i = int(np.flatnonzero(bad.to_numpy())[0])
            raise InputError(f"{where(path, i + 2)}missing or non-numeric value; fix the row or use --nan skip")
        df = df[~bad]
    if df.empty:
        raise InputError(f"{where(path)}no usable rows; need at least one block")
    for c, what in (("b_m", "width"), ("h_m", "height")):
        neg = df[c] <= 0
        if neg.any():
            i = int(df.index[neg][0])
            raise InputError(f"{where(path, i + 2 if path else None, c)}block {what} must be > 0 m")
    out = (df["eta_e"] >= 1) | (df["eta_e"] <= 0)
    if out.any():
        i = int(df.index[out][0])
        raise InputError(
            f"{where(path, i + 2 if path else None, 'eta_e')}restitution must be in (0, 1); got {df.loc[i, 'eta_e']}"
        )
    df["block"] = df["block"].astype(str)
    _check_block_rows(df, path)
    dup = df.duplicated(subset=["block", "b_m", "h_m", "eta_e"])
    if dup.any():
        i = int(df.index[dup][0])
        warn(
            "W-FIT-DUPLICATE",
            f"{where(path, i + 2 if path else None)}{int(dup.sum())} repeated row(s) dropped (each block counted once)",
        )
        df = df[~dup].copy()
    df["h_over_b"] = df["h_m"] / df["b_m"]
    df["alpha_rad"] = np.arctan2(df["b_m"], df["h_m"])
    return df.reset_index(drop=True)


@dataclass(frozen=True)
class EtaMatResult:
    """Material restitution η_mat from edge-contact experiments (Čeh Eq. 16).

    Attributes
    ----------
    eta_mat : averaged η_e/η_M (–)
    std : sample standard deviation of the per-block ratios
    n : number of blocks used
    rule : averaging rule: "mean" (arithmetic mean of per-block ratios, Čeh §5.4 "average
        of η_e/η_M over all scales and slendernesses"), "median", or "lsq" (η_mat minimising
        Σ(η_e − η_mat η_M)², = Σ η_e η_M / Σ η_M²)
    contact : "inner" or "midway" (Table 4 k_1 / k_2)
    l_c_m : strip width (m)
    min_hb : blocks with h/b below this were excluded from the average (0: none)
    per_block : DataFrame ``block, b_m, h_m, h_over_b, alpha_rad, k, eta_M, eta_e, ratio, used,
        above_one`` (ratio > 1 is unphysical: flagged)
    status, message
    """

    eta_mat: float
    std: float
    n: int
    rule: str
    contact: str
    l_c_m: float
    min_hb: float
    per_block: pd.DataFrame = field(repr=False)
    status: str = "ok"
    message: str = ""

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        return dict(
            eta_mat=self.eta_mat,
            std=self.std,
            n=self.n,
            rule=self.rule,
            contact=self.contact,
            l_c_m=self.l_c_m,
            min_hb=self.min_hb,
            status=self.status,
            message=self.message,
            per_block=self.per_block.to_dict(orient="records"),
        )

    def report(self) -> str:
        lines = [
            "[[eta_mat (Čeh Eq. 16)]]",
            f"    eta_mat = {self.eta_mat:.5f} +/- {self.std:.5f} (std, {self.rule} of {self.n} blocks)",
            f"    contact = {self.contact}, l_c = {1000 * self.l_c_m:g} mm, min h/b = {self.min_hb:g}",
            f"    ratios > 1 (unphysical): {int(self.per_block['above_one'].sum())}",
        ]
        if self.message:
            lines.append(f"    note: {self.message}")
        return "\n".join(lines)


def _check_block_rows(df: pd.DataFrame, path) -> None:
    """W-FIT-UNITS when a row's size is not a lab block in metres (1 mm - 20 m, h/b 0.5 - 50)."""
    from ..blocks import is_lab_size

    b, h = df["b_m"].to_numpy(float), df["h_m"].to_numpy(float)
    odd = ~is_lab_size(b, h)
    if odd.any():
        i = int(df.index[odd][0])
        warn(
            "W-FIT-UNITS",
            f"{where(path, i + 2 if path else None)}block {df.loc[i, 'block']}: b = "
            f"{b[odd][0]:.4g} m, h = {h[odd][0]:.4g} m (h/b = {h[odd][0] / b[odd][0]:.4g}) is not a "
            f"rocking block in metres ({int(odd.sum())} such row(s)); check units and column order",
        )


def fit_eta_mat(
    edge_table, l_c_m: float = 0.0015, contact: str = "inner", rule: str = "mean", min_hb: float = 0.0
) -> EtaMatResult:
    """η_mat = η_e/η_M averaged over edge-contact experiments (Čeh Eq. 16).

    Parameters
    ----------
    edge_table : path or DataFrame with ``block, b_m, h_m, eta_e``
    l_c_m : float
        Width of the base strips, m (Čeh: 1.5 mm).
    contact : {"inner", "midway"}
        Impulse at the strip's inner edge (k = 1 − 2 l_c/b) or midway (k = 1 − l_c/b).
    rule : {"mean", "median", "lsq"}
        Averaging rule, see :class:`EtaMatResult`.
    min_hb : float
        Use only blocks with h/b ≥ min_hb (Čeh: ratio near-constant for h/b > 3).
    """
    if rule not in ETA_MAT_RULES:
        raise InputError(f"rule={rule!r}: averaging rule must be one of {ETA_MAT_RULES}")
    df = read_block_table(edge_table)
    df["k"] = edge_contact_k(df["b_m"].to_numpy(), l_c_m, contact)
    df["eta_M"] = eta_modified(df["alpha_rad"].to_numpy(), df["k"].to_numpy())
    df["ratio"] = df["eta_e"] / df["eta_M"]
    df["used"] = df["h_over_b"] >= float(min_hb)
    df["above_one"] = df["ratio"] > 1.0
    u = df[df["used"]]
    if u.empty:
        raise InputError(f"min_hb={min_hb}: no block has h/b >= min_hb; lower it")
    r = u["ratio"].to_numpy()
    if rule == "mean":
        eta = float(np.mean(r))
    elif rule == "median":
        eta = float(np.median(r))
    else:
        em = u["eta_M"].to_numpy()
        eta = float(np.sum(u["eta_e"].to_numpy() * em) / np.sum(em * em))
    std = float(np.std(r, ddof=1)) if len(r) > 1 else float("nan")
    msg = ""
    if u["above_one"].any():
        msg = (
            f"{int(u['above_one'].sum())} block(s) have eta_e/eta_M > 1 (contact further inside than "
            "assumed); consider contact='inner'"
        )
    status = "ok"
    if not (0.0 < eta <= 1.05):  # a material restitution outside (0, 1] is not a result
        status = "failed"
        msg = (
            f"eta_mat = {eta:.4g} is outside (0, 1]: the table's sizes or eta_e values are not what the "
            "edge-contact model expects (units? full-contact runs?)"
        )
    return EtaMatResult(
        eta_mat=eta,
        std=std,
        n=int(len(r)),
        rule=rule,
        contact=contact,
        l_c_m=float(l_c_m),
        min_hb=float(min_hb),
        per_block=df,
        status=status,
        message=msg,
    )


@dataclass(frozen=True)
class KTableResult:
    """Inverse analysis of full-contact experiments (Čeh Eq. 17–18) and the k regression.

    Attributes
    ----------
    eta_mat : material restitution used (–)
    per_block : DataFrame ``block, b_m, h_m, h_over_b, alpha_rad, eta_e, eta_RB, k, b_bar_m,
        feasible`` (feasible: 0 < k ≤ 1; Čeh attributes k > 1 to extra tape dissipation)
    regression : KRegression fitted to the per-block k (all blocks with finite k, feasible or
        not, as in the paper — or only feasible ones if asked)
    n_infeasible : count of k > 1 or undefined
    """

    eta_mat: float
    per_block: pd.DataFrame = field(repr=False)
    regression: KRegression | None
    n_infeasible: int
    status: str = "ok"
    message: str = ""

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        reg = self.regression
        pb = self.per_block[["block", "b_m", "h_m", "h_over_b", "eta_e", "eta_RB", "k", "b_bar_m", "feasible"]]
        d = dict(
            eta_mat=self.eta_mat,
            per_block=pb.to_dict(orient="records"),
            n_infeasible=self.n_infeasible,
            status=self.status,
            message=self.message,
        )
        if reg is not None:
            d.update(
                coefficients=dict(reg.coefficients),
                form=reg.form,
                r2=reg.r2,
                rmse=reg.rmse,
                residuals=[float(x) for x in reg.residuals],
                loso=reg.loso.to_dict(orient="records"),
                hb_range=list(reg.hb_range),
                b_cm_range=list(reg.b_cm_range),
            )
        return d

    def report(self) -> str:
        lines = [f"[[Inverse k (Čeh Eq. 17-18), eta_mat = {self.eta_mat:.5f}]]"]
        for r in self.per_block.itertuples():
            flag = "" if r.feasible else "   <- infeasible (k > 1)"
            lines.append(
                f"    {r.block:6s} h/b={r.h_over_b:5.2f} eta_e={r.eta_e:.3f} eta_RB={r.eta_RB:.4f} "
                f"k={r.k:.4f} b_bar={1000 * r.b_bar_m:.2f} mm{flag}"
            )
        if self.regression is not None:
            lines.append(self.regression.report())
        if self.message:
            lines.append(f"note: {self.message}")
        return "\n".join(lines)


def k_table(
    full_table, eta_mat: float, form: str | None = "ceh19", feasible_only: bool = False, nan: str = "raise"
) -> KTableResult:
    """k and b̄ per full-contact block (Čeh Eq. 17–18) and the regression k(h/b, b).

    Parameters
    ----------
    full_table : path or DataFrame with ``block, b_m, h_m, eta_e`` (η_e,full)
    eta_mat : float
        Material restitution from :func:`fit_eta_mat` (Čeh: 0.989).
    form : str or None
        Regression form (see :data:`~rocklab.fitting.REGRESSION_FORMS`); None skips it.
    feasible_only : bool
        Fit the regression only to blocks with k ≤ 1 (the paper used all 27).
    """
    eta_mat = float(eta_mat)
    if not (np.isfinite(eta_mat) and 0 < eta_mat <= 1):
        raise InputError(f"eta_mat={eta_mat}: material restitution must be in (0, 1]")
    df = read_block_table(full_table, nan=nan)
    df["eta_RB"] = df["eta_e"] / eta_mat
    df["k"] = k_from_eta(df["alpha_rad"].to_numpy(), df["eta_RB"].to_numpy())
    df["b_bar_m"] = 0.5 * df["b_m"] * df["k"]
    df["feasible"] = np.isfinite(df["k"]) & (df["k"] <= 1.0) & (df["k"] > 0)
    n_bad = int((~df["feasible"]).sum())
    msg = ""
    if n_bad:
        msg = (
            f"{n_bad} block(s) give k > 1 or eta_RB >= 1 (impulse outside the base): "
            + ", ".join(df.loc[~df["feasible"], "block"])
            + "; Čeh attributes this to tape dissipation"
        )
    reg = None
    if form is not None:
        sel = df[df["feasible"]] if feasible_only else df[np.isfinite(df["k"])]
        reg = fit_k_regression(sel["h_over_b"], sel["b_m"], sel["k"], form=form)
    return KTableResult(eta_mat=eta_mat, per_block=df, regression=reg, n_infeasible=n_bad, message=msg)
