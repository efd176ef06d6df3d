"""Outputs of ``rocklab run``: ``series.csv``, ``summary.md``, figures, ``session.rrd`` and
``report.json``, written into a (staging) folder."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..._io import write_frame_atomic, write_json_atomic, write_text_atomic

from ..reports import sig as _g

__all__ = ["series_frame", "write_outputs"]


def series_frame(res):
    """All time series on one table: measured sources and simulations on the primary time base."""
    import pandas as pd

    t, th = res.measured[res.primary]
    cols = {"t_s": t, f"theta_{res.primary}_rad": th}
    for name, (tn, thn) in res.measured.items():
        if name != res.primary:
            cols[f"theta_{name}_rad"] = np.interp(t, tn, thn, left=np.nan, right=np.nan)
    for law, s in res.simulations.items():
        cols[f"theta_sim_{law}_rad"] = np.interp(t, s.t_s, s.theta_rad, left=np.nan, right=np.nan)
    if res.validation is not None:  # the 5–95 % band of each law's ensemble (predicted measurement)
        for law, (tb, lo, hi) in res.validation.bands.items():
            cols[f"theta_sim_{law}_p05_rad"] = np.interp(t, tb, lo, left=np.nan, right=np.nan)
            cols[f"theta_sim_{law}_p95_rad"] = np.interp(t, tb, hi, left=np.nan, right=np.nan)
    if res.truth is not None:
        cols["theta_truth_rad"] = np.interp(t, res.truth.t_s, res.truth.theta_rad, left=np.nan, right=np.nan)
    if res.table is not None:
        for k, v in res.table.columns().items():
            cols[f"table_{k}"] = np.interp(t, res.table.t_s, v, left=np.nan, right=np.nan)
    if res.column is not None:
        c = res.column
        v = c.validation
        band = None if v is None else v.bands[v.reference_law]
        for i, o in enumerate(c.objects):
            cols[f"theta_{o}_{c.source}_rad"] = np.interp(
                t, c.t_s, c.theta_measured_rad[:, i], left=np.nan, right=np.nan
            )
            cols[f"theta_{o}_sim_column_rad"] = np.interp(
                t, c.sim_t_s, c.theta_sim_rad[:, i], left=np.nan, right=np.nan
            )
            if band is not None:  # the reference law's 5–95 % band (predicted measurement)
                for q, b in (("p05", band[1]), ("p95", band[2])):
                    cols[f"theta_{o}_sim_column_{q}_rad"] = np.interp(t, band[0], b[:, i], left=np.nan, right=np.nan)
            if c.theta_truth is not None:
                tt, th = c.theta_truth
                cols[f"theta_{o}_truth_rad"] = np.interp(t, tt, th[:, i], left=np.nan, right=np.nan)
    return pd.DataFrame(cols)


def _fit_lines(fit) -> list:
    """The η_e line of ``summary.md`` (``fit``: a FitStage)."""
    f = fit.fit
    ci = [_g(x) for x in (f.ci95 if fit.forced else f.ci95_eta_e)]
    if fit.forced:  # a shake-table run (see the validation below)
        return [
            f"η_e = {_g(f.eta_e)} (95 % CI {ci[0]} – {ci[1]}) from {f.n_segments} half cycles "
            f"under the measured table motion, residual RMS {_g(f.rms_residual_rad)} rad "
            f"(fit status {f.status})",
            "",
        ]
    return [
        f"η_e = {_g(f.eta_e)} (95 % CI {ci[0]} – {ci[1]}), "
        f"η'_e = {_g(f.eta_e_first)}, θ0 = {_g(f.theta0_rad)} rad, "
        f"release at {_g(f.release_t_s)} s, residual RMS {_g(f.rms_residual_rad)} rad "
        f"(fit status {f.status})",
        "",
    ]


def _audit_lines(audit, fit) -> list:
    """The assumption audit's lines of ``summary.md`` (``audit``: an AuditResult)."""
    a = audit
    lines = [
        f"Assumption audit ({a.source}): **{a.verdict}**, checked {', '.join(a.checked) or 'nothing'}"
        + (f"; impacts not to trust: {', '.join(map(str, a.excluded_impacts))}" if a.excluded_impacts else ""),
        "",
    ]
    lines += [
        f"- {f.kind} ({f.detail}) at {_g(f.t_s)} s, impact {f.impact}: {_g(f.value)} "
        f"(tolerance {_g(f.tolerance)}, SI units)"
        for f in a.flags
    ]
    lines += [""] if a.flags else []
    excluded = (fit.excluded_impacts if fit is not None else None) or ()
    for e in excluded:
        lines.append(
            f"- per-impact η of fit impact {e.impact} at {_g(e.t_s)} s ({_g(e.eta)}) is not "
            f"to be trusted: {'; '.join(e.reasons)}"
        )
    lines += [""] if excluded else []
    return lines


def _table_lines(res) -> list:
    """The table motion the simulations were driven by, and for a fused one its two sources."""
    if res.table is None:
        return []
    f = res.table_fusion
    if f is None:
        return [f"Table motion: from the {res.table.source}", ""]
    return [
        f"Table motion: fused from the table IMU (noise {_g(f.sigma_a_m_s2)} m/s²) and the film "
        f"(noise {_g(1000 * f.sigma_x_m)} mm): median σ of the acceleration "
        f"{_g(float(np.nanmedian(f.motion.sigma_ax_m_s2)))} m/s², the IMU's offset up to "
        f"{_g(float(np.max(np.abs(f.imu_bias_m_s2))))} m/s², the film's normalised innovations "
        f"{_g(f.video_nis)} (1 when the two agree)"
        + (
            f"; the film's scale over the IMU's {_g(1 + f.scale.ratio_minus_one)} ± {_g(f.scale.se)}, so the "
            f"acceleration's scale is known to {_g(100 * f.scale.sd)} %"
            if f.scale is not None and f.scale.status == "ok"
            else ""
        ),
        "",
    ]


def _summary_md(res, figs: dict, rrd: bool) -> str:
    lines = [
        f"# {res.name}",
        "",
        f"Status: **{res.status}**",
        "",
        *([f"Tags: {', '.join(f'{k} = {v}' for k, v in res.config.tags)}", ""] if res.config.tags else []),
        f"Block: b = {_g(res.block.b_m)} m, h = {_g(res.block.h_m)} m, α = {_g(res.block.alpha_rad)} rad, "
        f"p = {_g(res.block.p_rad_s)} rad/s, η_H = {_g(res.block.eta_H)}; contact: {res.config.contact}",
        "",
    ]
    if res.fit is not None:
        lines += _fit_lines(res.fit)
    if res.energy_loss is not None:
        e = res.energy_loss
        lines += [
            f"Energy loss per rocking (thesis Eq. 12, exact rise of the centre of mass): mean of the first "
            f"four {_g(e.mean4)}, the constant η that loses as much {_g(e.eta_equivalent)}",
            "",
        ]
    if res.audit is not None:
        lines += _audit_lines(res.audit, res.fit)
    if res.sync is not None:
        imu = res.sync.imu
        lines += [
            f"IMU sync: offset {_g(1000 * (imu.offset_s if imu is not None else float('nan')))} ms, "
            f"drift {_g(None if imu is None else imu.drift)}, "
            f"residual {_g(None if imu is None else imu.residual_ms)} ms",
            "",
        ]
    lines += _table_lines(res)
    lines += ["| simulation | η | RMS vs measured (rad) | impacts |", "|---|---|---|---|"]
    for law, s in res.simulations.items():
        rms = s.rms_vs_measured_rad
        lines.append(f"| {law} | {_g(s.eta)} | {'–' if rms is None else _g(rms)} | {len(s.impacts)} |")
    lines.append("")
    if res.validation is not None:
        from .._validation import summary_lines

        lines += summary_lines(res.validation, res.block.alpha_rad)
    if res.truth is not None:
        lines += [
            f"Synthetic truth: η = {_g(res.truth.eta)}, measured θ RMS error {_g(res.truth.theta_rms_error_rad)} rad"
            + (
                ""
                if res.truth.table_acc_rms_error_rel is None
                else f", table acceleration RMS error {100 * res.truth.table_acc_rms_error_rel:.3g} % of its RMS"
            ),
            "",
        ]
    if res.column is not None:
        c = res.column
        cmp_ = c.comparison
        lines += [
            f"Column of {len(c.objects)} blocks (cut {1000 * c.cut_m:.1f} mm, "
            f"{c.impacts_per_closing} impact(s) per closing): simulation status {c.status}",
            "",
            "| block | RMS measured − simulated (rad) | peak measured (rad) | peak simulated (rad) |",
            "|---|---|---|---|",
        ]
        for o, r, pm, ps in zip(c.objects, cmp_.rms_theta_rad, cmp_.peak_measured_rad, cmp_.peak_simulated_rad):
            lines.append(f"| {o} | {_g(r)} | {_g(pm)} | {_g(ps)} |")
        sq = cmp_.sequence
        lines += [
            "",
            f"Opening/closing sequence, measured vs simulated: {sq.n_matched} of "
            f"{sq.n_measured} measured / {sq.n_simulated} simulated events matched "
            f"(median timing error {_g(sq.timing_error_s)} s)",
        ]
        lines += _column_validation_lines(c)
        if c.sequence_vs_truth is not None:
            st = c.sequence_vs_truth
            lines += [
                f"Measured sequence vs truth: same sequence = {st.same_sequence} ({st.n_matched}/{st.n_measured} events)"
            ]
        lines.append("")
    for d in res.diagnostics:
        lines.append(f"- **warning {d.code}**: {d.message}")
    for m in res.messages:
        lines.append(f"- note: {m}")
    lines += ["", "## Figures", ""] + [f"![{k}](figures/{p.name})" for k, p in figs.items()]
    lines += ["", "Data: [report.json](report.json), [series.csv](series.csv)"]
    if rrd:
        lines += ["", "Visual review: `rerun session.rrd`"]
    return "\n".join(lines) + "\n"


def _column_validation_lines(c) -> list:
    """The event-sequence verdicts of a column run (``summary.md``)."""
    v = c.validation
    if v is None:
        return []
    lines = [
        "",
        f"Event-sequence validation ({v.n_members} simulations per model, measured by {c.source}; "
        f"start {_g(c.start_t_s)} s, start angles {', '.join(_g(x) for x in c.theta0_rad)} rad): "
        f"predictability horizon ({v.reference_law}) {_g(v.horizon_s)} s",
        "",
        "| model | verdict | score | events inside the horizon matched | band coverage |",
        "|---|---|---|---|---|",
    ]
    for law, lv in v.laws.items():
        lines.append(
            f"| {law} | **{lv.verdict}** | {_g(lv.score)} | {lv.n_matched_inside} of {lv.n_events_inside} "
            f"(±{_g(lv.tol_s)} s) | {_g(lv.band_coverage)} |"
        )
    if v.acc_scale_source:
        lines += [
            "",
            f"Table acceleration scale sampled: {_g(100 * v.uncertainty['acc_scale'])} % ({v.acc_scale_source})",
        ]
    ev = c.model_events()[:3]
    if ev:
        lines += [
            "",
            "First model events after the start: "
            + ", ".join(f"{_g(e['t_from_start_s'])} s joint {e['joint']} {e['event']} ({e['state']})" for e in ev),
        ]
    return lines


def write_outputs(res, out_dir: Path, fp: str, *, spawn=False, connect=None, progress=False) -> dict:
    """Write report.json, series.csv, figures, summary.md, report.html and session.rrd into ``out_dir``."""
    from ..reports import write_html_report
    from ._figures import experiment_figures
    from ._log_experiment import log_experiment

    out_dir.mkdir(parents=True, exist_ok=True)
    figs = experiment_figures(res, out_dir / "figures") if res.config.figures else {}
    write_frame_atomic(out_dir / "series.csv", series_frame(res))
    rrd_rows = None
    if res.config.rrd or spawn or connect:
        rrd_path = out_dir / "session.rrd" if res.config.rrd else None
        rrd_rows = log_experiment(res, rrd_path, spawn=spawn, connect=connect, progress=progress)
    report = res.to_dict()
    report["fingerprint"] = fp
    report["outputs"] = {
        "figures": {k: f"figures/{p.name}" for k, p in figs.items()},
        "series": "series.csv",
        "rrd": "session.rrd" if res.config.rrd else None,
        "rrd_rows": rrd_rows,
    }
    md = _summary_md(res, figs, bool(res.config.rrd))
    write_text_atomic(out_dir / "summary.md", md)
    write_html_report(md, out_dir / "report.html", out_dir, title=f"rocklab: {res.name}")
    write_json_atomic(out_dir / "report.json", report)
    return report
