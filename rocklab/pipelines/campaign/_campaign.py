"""``rocklab campaign``: many experiments in parallel, then the campaign-level fits.

Each experiment runs in its own process (``concurrent.futures``) or on a Dask
distributed cluster (``scheduler=ADDR``); a failing experiment is reported and
the rest continue. Then: η_mat from edge-contact runs (Čeh Eq. 16), k per block
from full-contact runs (Eq. 17–18), the Eq. 19 regression when the campaign
spans enough blocks, ``campaign.csv``, figures and ``campaign.rrd``.
"""

from __future__ import annotations


import json
import traceback
from concurrent.futures import as_completed
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..._errors import InputError
from ..._procs import dask_client, spawn_pool
from ..._io import write_frame_atomic, write_json_atomic, write_text_atomic
from ._groups import campaign_tags, check_group_by, group_lines_md, group_lines_text, group_repeats

__all__ = ["CampaignResult", "run_campaign", "find_experiments"]


#: What a campaign writes in its output folder.
CAMPAIGN_ENTRIES = (
    "experiments",
    "campaign.csv",
    "groups.csv",
    "campaign.json",
    "campaign.rrd",
    "figures",
    "summary.md",
    "report.html",
)


def find_experiments(root) -> list[Path]:
    """Every ``experiment*.toml`` below ``root`` (sorted)."""
    root = Path(root)
    if not root.is_dir():
        raise InputError(f"{root}: campaign folder not found; give a folder holding experiment.toml files")
    found = sorted(p for p in root.rglob("experiment*.toml") if p.is_file())
    if not found:
        raise InputError(f"{root}: no experiment*.toml below this folder; nothing to run")
    return found


def _check_unique_names(configs, root: Path) -> None:
    """Experiment names label a campaign's rows, blocks, links and Rerun entities, so two
    experiments of one name would be merged in its fits and figures: refused before any work.
    A config that cannot be read is left to its own run, which reports it as failed."""
    from ...config import experiment_name

    seen: dict[str, Path] = {}
    for c in configs:
        name = experiment_name(c)
        if name is None:
            continue
        if name in seen:
            raise InputError(
                f"{c.relative_to(root)}: experiment name {name!r} is also used by {seen[name].relative_to(root)}; "
                "names must be unique in a campaign (they label its rows, blocks and figures): "
                'set a different name = "..." in one of them'
            )
        seen[name] = c


def _one(config: str, out: str, force: bool) -> dict:
    """Worker: run one experiment; never raises (the failure is the result)."""
    from ..._errors import InputError as _IE
    from ..experiment import run_experiment

    try:
        report, ran = run_experiment(config, out, force=force)
        return {
            "config": config,
            "out": out,
            "ok": report.get("status") != "failed",
            "ran": ran,
            "report": report,
            "error": None,
        }
    except _IE as e:
        return {"config": config, "out": out, "ok": False, "ran": True, "report": None, "error": str(e)}
    except Exception as e:  # noqa: BLE001 - one broken experiment must not stop the campaign
        tb = traceback.format_exc(limit=3).strip().splitlines()[-1]
        return {
            "config": config,
            "out": out,
            "ok": False,
            "ran": True,
            "report": None,
            "error": f"{type(e).__name__}: {e} ({tb})",
        }


@dataclass(frozen=True)
class CampaignResult:
    """Outcome of a campaign.

    Attributes
    ----------
    out_dir : Path
    runs : list[dict]
        Per experiment: config, out, ok, error.
    table : pandas.DataFrame
        One row per experiment (experiment, status ok/suspect/failed, error, warnings (the
        W- codes), block, b_m, h_m, contact, eta_e, eta_e_source (``free``: the free-rocking fit;
        ``half_cycles``: a base-excited run's half cycles under the measured table motion, not
        pooled into η_mat or k), ci_lo, ci_hi, eta_H, eta_M, eta_true, ...);
        a failed experiment's row carries only its name, status and error.
    eta_mat : dict or None
        Edge-contact η_mat fit (:meth:`to_dict` of the fitting result).
    k_table : dict or None
        Full-contact inverse k per block and the regression.
    messages : list[str]
        Notes on the campaign fits (what was not fitted and why).
    groups : pandas.DataFrame or None
        Repeats grouped by their ``[experiment] tags``
        (:func:`rocklab.pipelines.campaign.group_repeats`); None without tags.
    """

    out_dir: Path
    runs: list
    table: object
    eta_mat: dict | None = None
    k_table: dict | None = None
    messages: list = field(default_factory=list)
    groups: object = None

    @property
    def n_ok(self) -> int:
        """Number of experiments that ran without failing."""
        return sum(1 for r in self.runs if r["ok"])

    @property
    def ok_table(self):
        """Rows of :attr:`table` for the experiments that did not fail."""
        return _ok_rows(self.table)

    @property
    def n_suspect(self) -> int:
        """Number of experiments that ran with a suspect status (see their warnings)."""
        return sum(1 for r in self.runs if r["ok"] and (r.get("report") or {}).get("status") == "suspect")

    @property
    def n_failed(self) -> int:
        """Number of experiments that failed (they are listed in ``campaign.csv`` with their error)."""
        return len(self.runs) - self.n_ok

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        return {
            "out_dir": str(self.out_dir),
            "n_experiments": len(self.runs),
            "n_ok": self.n_ok,
            "n_failed": self.n_failed,
            "status": "ok" if self.n_failed == 0 else "partial",
            "failures": [{"config": r["config"], "error": r["error"]} for r in self.runs if not r["ok"]],
            "experiments": self.table.to_dict(orient="records") if self.table is not None else [],
            "eta_mat": self.eta_mat,
            "k_table": self.k_table,
            "groups": self.groups.to_dict(orient="records") if self.groups is not None else [],
            "messages": list(self.messages),
        }

    def summary_md(self, figures: dict | None = None) -> str:
        """The campaign's one-page Markdown report: experiments, campaign fits, figures, failures."""
        from ..reports import sig as g

        n_sus = self.n_suspect
        lines = [
            f"# Campaign {self.out_dir.name}",
            "",
            f"{self.n_ok} of {len(self.runs)} experiments ran"
            + (f", **{n_sus} suspect** (see their warnings)" if n_sus else "")
            + (f", **{self.n_failed} failed**" if self.n_failed else "")
            + ".",
            "",
        ]
        t = self.ok_table
        if t is not None and len(t):
            lines += [
                "| experiment | block | contact | h/b | η_H | η_e | 95 % CI | η_M | truth | status |",
                "|---|---|---|---|---|---|---|---|---|---|",
            ]
            for _, r in t.iterrows():
                name = str(r["experiment"])
                folder = Path(str(r["out"])).name
                ci = f"{g(r.get('ci_lo'))} – {g(r.get('ci_hi'))}" if np.isfinite(r.get("ci_lo", np.nan)) else "–"
                eta_e = g(r["eta_e"]) if np.isfinite(r["eta_e"]) else "–"
                if r.get("eta_e_source") == "half_cycles":
                    eta_e += " (half cycles)"
                lines.append(
                    f"| [{name}](experiments/{folder}/report.html) | {r['block']} | {r['contact']} | "
                    f"{g(r.get('hb'))} | {g(r['eta_H'])} | {eta_e} | {ci} | {g(r.get('eta_M'))} | "
                    f"{g(r.get('eta_true'))} | {r.get('status', '')} |"
                )
            lines.append("")
        if self.eta_mat:
            lines += [
                f"η_mat (edge contact, Čeh Eq. 16) = {g(self.eta_mat.get('eta_mat'))} ± "
                f"{g(self.eta_mat.get('std'))} ({self.eta_mat.get('n')} blocks)",
                "",
            ]
        if self.k_table:
            ks = ", ".join(f"{r['block']}: {g(r['k'])}" for r in self.k_table.get("per_block", []))
            lines += [f"k per full-contact block (Čeh Eq. 18, η_mat = {g(self.k_table.get('eta_mat'))}): {ks}", ""]
            co = self.k_table.get("coefficients")
            if co:
                terms = " ".join(f"{v:+.4g}·{k}" if k != "const" else f"{v:+.4g}" for k, v in co.items())
                lines += [
                    f"k(h/b, b) regression (Čeh Eq. 19 form, b in cm): k = {terms}; "
                    f"R² = {g(self.k_table.get('r2'))}, RMSE = {g(self.k_table.get('rmse'))}",
                    "",
                ]
        lines += group_lines_md(self.groups)
        for r in self.runs:
            if not r["ok"]:
                lines.append(f"- **FAILED** {r['config']}: {r['error']}")
        for m in self.messages:
            lines.append(f"- note: {m}")
        if figures:
            lines += ["", "## Figures", ""] + [f"![{k}](figures/{Path(p).name})" for k, p in figures.items()]
        lines += [
            "",
            "Data: [campaign.csv](campaign.csv), [campaign.json](campaign.json); visual review: `rerun campaign.rrd`",
        ]
        return "\n".join(lines) + "\n"

    def summary_text(self) -> str:
        """The table the CLI prints: per experiment η_H, η_e ± CI, η_M, truth; then the campaign fits."""
        n_sus = self.n_suspect
        sus = f" ({n_sus} suspect: see their warnings)" if n_sus else ""
        lines = [f"campaign: {self.n_ok}/{len(self.runs)} experiments ran{sus}; outputs in {self.out_dir}"]
        t = self.ok_table
        if t is not None and len(t):
            lines.append(
                f"{'experiment':<22}{'block':<7}{'contact':<8}{'eta_H':>8}{'eta_e':>8}"
                f"{'95% CI':>18}{'eta_M':>8}{'truth':>8}"
            )
            for _, r in t.iterrows():
                ci = f"[{r['ci_lo']:.3f}, {r['ci_hi']:.3f}]" if np.isfinite(r.get("ci_lo", np.nan)) else ""
                eta_e = f"{r['eta_e']:>8.3f}" if np.isfinite(r["eta_e"]) else f"{'-':>8}"
                if r.get("eta_e_source") == "half_cycles":
                    ci += " hc"
                lines.append(
                    f"{str(r['experiment'])[:21]:<22}{str(r['block'])[:6]:<7}{r['contact']:<8}"
                    f"{r['eta_H']:>8.3f}{eta_e}{ci:>18}"
                    f"{r.get('eta_M', np.nan):>8.3f}{r.get('eta_true', np.nan):>8.3f}"
                )
            if (t.get("eta_e_source", "") == "half_cycles").any():
                lines.append("hc: η_e from the run's half cycles under the measured table motion (not in η_mat or k)")
            for _, r in t[t.get("column", "") != ""].iterrows() if "column" in t else []:
                c = json.loads(r["column"])
                lines.append(
                    f"{r['experiment']}: column of {len(c['rms_theta_rad'])} blocks, model status "
                    f"{c['status']}, θ RMS measured−model "
                    f"{', '.join(f'{x:.4f}' for x in c['rms_theta_rad'])} rad, opening sequence "
                    f"matched by the model {c['sequence_model_matched']}, same as truth: "
                    f"{c['sequence_same_as_truth']}"
                )
        if self.eta_mat:
            lines.append(
                f"eta_mat (edge contact, Čeh Eq. 16) = {self.eta_mat.get('eta_mat'):.4f} "
                f"± {self.eta_mat.get('std', float('nan')):.4f} ({self.eta_mat.get('n')} blocks)"
            )
        if self.k_table:
            ks = ", ".join(f"{r['block']}: {r['k']:.3f}" for r in self.k_table.get("per_block", []))
            lines.append(f"k per full-contact block (Čeh Eq. 18, eta_mat = {self.k_table.get('eta_mat'):.4f}): {ks}")
            co = self.k_table.get("coefficients")
            if co:
                terms = " ".join(f"{v:+.4f}·{k}" if k != "const" else f"{v:+.4f}" for k, v in co.items())
                lines.append(
                    f"k(h/b, b) regression (Čeh Eq. 19 form, b in cm): k = {terms}; "
                    f"R² = {self.k_table.get('r2', float('nan')):.3f}, "
                    f"RMSE = {self.k_table.get('rmse', float('nan')):.4f} "
                    f"(Čeh: +0.0047·hb2 -0.0258·hb +1.0635 -0.0565·b_cm)"
                )
        lines += group_lines_text(self.groups)
        for r in self.runs:
            if not r["ok"]:
                lines.append(f"FAILED {r['config']}: {r['error']}")
        for m in self.messages:
            lines.append(f"note: {m}")
        if self.n_failed:
            lines.append(
                f"{self.n_failed} of {len(self.runs)} experiments FAILED (listed in campaign.csv "
                "with status 'failed'); exit status 1"
            )
        lines.append(
            f"look: {self.out_dir / 'campaign.csv'}, {self.out_dir / 'figures'}, rerun {self.out_dir / 'campaign.rrd'}"
        )
        return "\n".join(lines)


def _ok_rows(table):
    """The rows of a campaign table whose experiment did not fail (renumbered)."""
    if table is None or not len(table):
        return table
    return table[table["status"] != "failed"].reset_index(drop=True)


def _row(run: dict) -> dict:
    rep = run.get("report")
    if not rep:  # a failed experiment is a row too, so campaign.csv shows it with its error
        return {
            "experiment": Path(run["config"]).parent.name,
            "status": "failed",
            "error": str(run.get("error") or "")[:300],
            "config": run["config"],
            "out": run["out"],
        }
    b = rep["block"]
    fit = rep.get("fit") or {}
    source = "free" if fit else ""
    if not fit:
        # a base-excited run's η_e comes from its half cycles under the measured table motion
        fit = (rep.get("validation") or {}).get("eta_e") or {}
        source = "half_cycles" if fit else ""
    ci = fit.get("ci95_eta_e") or [np.nan, np.nan]
    sims = rep.get("simulations") or {}
    truth = rep.get("truth") or {}
    loss = rep.get("energy_loss") or {}
    warn_codes = sorted({w["code"] for w in rep.get("warnings") or []})
    return {
        "experiment": rep["name"],
        "status": rep.get("status"),
        "error": "",
        "warnings": "; ".join(warn_codes),
        "config": run["config"],
        "block": b.get("name") or rep["name"],
        "b_m": b["b_m"],
        "h_m": b["h_m"],
        "hb": b["h_m"] / b["b_m"],
        "contact": rep["contact"]["type"],
        "l_c_m": rep["contact"]["l_c_m"],
        "eta_H": b["eta_H"],
        "eta_e": fit.get("eta_e", np.nan),
        "eta_e_source": source,
        "ci_lo": ci[0] if ci[0] is not None else np.nan,
        "ci_hi": ci[1] if ci[1] is not None else np.nan,
        "eta_e_first": fit.get("eta_e_first", np.nan),
        "eta_M": (sims.get("modified") or {}).get("eta", np.nan),
        "eta_true": truth.get("eta") if truth.get("eta") is not None else np.nan,
        "fit_status": fit.get("status"),
        "energy_loss_mean4": loss.get("mean4", np.nan),
        "eta_equivalent": loss.get("eta_equivalent", np.nan),
        **{f"tag_{k}": v for k, v in (rep.get("tags") or {}).items()},
        "out": run["out"],
        "column": json.dumps(_column_summary(rep["column"])) if rep.get("column") else "",
    }


def _column_summary(col: dict) -> dict:
    seq = col["comparison"]["sequence"]
    st = col.get("sequence_vs_truth") or {}
    return {
        "status": col["status"],
        "rms_theta_rad": col["comparison"]["rms_theta_rad"],
        "sequence_model_matched": f"{seq['n_matched']}/{seq['n_measured']}",
        "sequence_same_as_truth": st.get("same_sequence"),
    }


def _campaign_fits(table, msgs):
    from ... import fitting as F

    eta_mat = k_tab = None
    # Čeh's η_mat and k are defined on free rocking; a base-excited run's half-cycle η_e is shown, not pooled
    free = table[np.isfinite(table["eta_e"]) & (table.get("eta_e_source", "free") == "free")]
    edge = free[free["contact"] == "edge"]
    full = free[free["contact"] == "full"]
    if len(edge):
        etab = edge.rename(columns={"experiment": "run"})[["block", "b_m", "h_m", "eta_e", "l_c_m"]]
        r = F.fit_eta_mat(etab, l_c_m=float(edge["l_c_m"].iloc[0]))
        eta_mat = r.to_dict()
    else:
        msgs.append("no edge-contact experiments: η_mat not fitted (0.989 of Čeh et al. used for k)")
    if len(full):
        em = eta_mat["eta_mat"] if eta_mat else 0.989
        ftab = full[["block", "b_m", "h_m", "eta_e"]]
        try:
            k_tab = F.k_table(ftab, eta_mat=em).to_dict()
        except InputError as e:  # too few blocks for the Eq. 19 regression: k per block only
            msgs.append(f"Eq. 19 regression not fitted: {e}")
            k_tab = F.k_table(ftab, eta_mat=em, form=None).to_dict()
    return eta_mat, k_tab


def run_campaign(
    root,
    out_dir,
    *,
    workers: int = 2,
    scheduler: str | None = None,
    force: bool = False,
    progress: bool = True,
    group_by=(),
) -> CampaignResult:
    """Run every experiment under ``root`` into ``out_dir/experiments/<name>/`` and fit the campaign.

    Parameters
    ----------
    root : path
        Folder searched recursively for ``experiment*.toml``.
    out_dir : path
        Output folder (``campaign.csv``, ``groups.csv``, ``campaign.json``, figures, ``summary.md``).
    workers : int
        Local processes.
    scheduler : str or None
        A Dask distributed scheduler's address: run the experiments there.
    force : bool
        Re-run unchanged experiments too.
    progress : bool
        Show a progress bar.
    group_by : sequence of str
        Groupings of repeats, each tag names joined by commas (``"config"``, ``"config,tape"``);
        empty: one grouping per tag name the experiments carry. A name no experiment carries is
        refused before any work.
    """
    import pandas as pd
    from tqdm import tqdm

    from ..._outdir import check_output_dir, claim_dir

    root = Path(root).resolve()
    configs = find_experiments(root)
    _check_unique_names(configs, root)
    groupings = check_group_by(group_by, campaign_tags(configs), root)
    out_dir = check_output_dir(out_dir, force=force, need_bytes=len(configs) * 30 * 1024 * 1024)
    claim_dir(out_dir, CAMPAIGN_ENTRIES, command="campaign")
    jobs = []
    for c in configs:
        rel = c.parent.relative_to(root) if c.parent != root else Path(c.stem)
        jobs.append((str(c), str(out_dir / "experiments" / "__".join(rel.parts or (c.stem,))), force))
    runs = []
    bar = tqdm(total=len(jobs), desc="campaign", unit="exp", disable=not progress)
    if scheduler:
        client = dask_client(scheduler)
        from dask.distributed import as_completed as das_completed

        with client:
            futs = [client.submit(_one, *j, pure=False) for j in jobs]
            for f in das_completed(futs):
                runs.append(f.result())
                bar.update(1)
    elif workers <= 1 or len(jobs) == 1:
        for j in jobs:
            runs.append(_one(*j))
            bar.update(1)
    else:
        with spawn_pool(workers) as ex:
            futs = [ex.submit(_one, *j) for j in jobs]
            for f in as_completed(futs):
                runs.append(f.result())
                bar.update(1)
    bar.close()
    runs.sort(key=lambda r: r["config"])
    table = pd.DataFrame([_row(x) for x in runs])
    msgs: list[str] = []
    eta_mat = k_tab = None
    good = _ok_rows(table)
    if len(good):
        try:
            eta_mat, k_tab = _campaign_fits(good, msgs)
        except InputError as e:
            msgs.append(f"campaign fits not done: {e}")
    groups = group_repeats(table, groupings) if groupings and len(good) else None
    res = CampaignResult(
        out_dir=out_dir, runs=runs, table=table, eta_mat=eta_mat, k_table=k_tab, messages=msgs, groups=groups
    )
    _write_campaign(res)
    return res


def _write_campaign(res: CampaignResult) -> None:
    from ..experiment import campaign_figures
    from ..reports import write_html_report

    out = res.out_dir
    out.mkdir(parents=True, exist_ok=True)
    if res.table is not None and len(res.table):
        write_frame_atomic(out / "campaign.csv", res.table)
        if res.groups is not None and len(res.groups):
            write_frame_atomic(out / "groups.csv", res.groups)
        reg = None
        from ...fitting import KRegression

        reg = KRegression.ceh2018()
        if res.k_table and res.k_table.get("coefficients"):
            reg = KRegression.from_coefficients(res.k_table["coefficients"])
        figs = campaign_figures(res.ok_table, out / "figures", regression=reg) if len(res.ok_table) else {}
        from ._campaign_rrd import campaign_rrd

        campaign_rrd(res, out / "campaign.rrd")
    else:
        figs = {}
    write_json_atomic(out / "campaign.json", json.loads(json.dumps(res.to_dict(), default=str)))
    md = res.summary_md(figs if isinstance(figs, dict) else {})
    write_text_atomic(out / "summary.md", md)
    write_html_report(md, out / "report.html", out, title=f"rocklab campaign: {out.name}")
