"""Matplotlib figures for experiment and campaign reports (PNG, written atomically)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._plotting import pyplot, save_png

__all__ = ["experiment_figures", "campaign_figures"]


def experiment_figures(res, out_dir) -> dict[str, Path]:
    """Write the experiment figures; returns {name: path}.

    ``res`` is an :class:`~rocklab.pipelines.ExperimentResult`.
    """
    plt = pyplot()
    out = Path(out_dir)
    figures = {
        "theta": (_theta_figure, True),
        "per_impact_eta": (_per_impact_figure, res.fit is not None and len(res.per_impact_eta) > 0),
        "energy_per_impact": (_energy_figure, bool(res.simulations)),
        "video_vs_imu": (_video_imu_figure, res.video_imu_residual is not None),
        "column": (_column_figure, res.column is not None),
        "table": (_table_figure, res.table is not None),
    }
    return {name: draw(plt, res, out) for name, (draw, wanted) in figures.items() if wanted}


def _theta_figure(plt, res, out: Path) -> Path:
    """θ/α measured and simulated, the ensemble bands, the horizon, the truth and the audit flags."""
    alpha = res.block.alpha_rad
    fig, ax = plt.subplots(figsize=(10, 4))
    for name, (t, th) in res.measured.items():
        ax.plot(t, np.asarray(th) / alpha, lw=1.2, label=f"measured ({name})")
    val = res.validation
    for law, sim in res.simulations.items():
        (line,) = ax.plot(
            sim.t_s, np.asarray(sim.theta_rad) / alpha, lw=0.9, ls="--", label=f"simulated, {law} (η={sim.eta:.3f})"
        )
        band = val.bands.get(law) if val is not None else None
        if band is not None:
            v = val.laws[law]
            ax.fill_between(
                band[0],
                band[1] / alpha,
                band[2] / alpha,
                color=line.get_color(),
                alpha=0.15,
                lw=0,
                label=f"{law}: 5–95 % of {val.n_members} runs, {v.verdict} (coverage {v.band_coverage:.2f})",
            )
    if val is not None:
        ax.axvline(val.horizon_s, color="k", ls=":", lw=1.0, label=f"predictability horizon ({val.reference_law})")
        # overturned members reach ±π/2 (6 α for a stocky block): keep the measurement readable
        peak = max(float(np.nanmax(np.abs(th))) for _, th in res.measured.values()) / alpha
        ax.set_ylim(-max(1.1, 1.3 * peak), max(1.1, 1.3 * peak))
    if res.truth is not None:
        ax.plot(res.truth.t_s, np.asarray(res.truth.theta_rad) / alpha, lw=0.6, color="k", alpha=0.5, label="truth")
    # the assumption audit's flags, where they happened (the impacts a fit should not trust)
    flags = res.audit.flags if res.audit is not None else ()
    for i, f in enumerate(flags):
        ax.axvline(f.t_s, color="crimson", lw=0.8, alpha=0.7, label="audit flag" if i == 0 else None)
        ax.annotate(
            f"{f.kind}",
            (f.t_s, 1.0),
            xycoords=("data", "axes fraction"),
            rotation=90,
            va="top",
            ha="right",
            fontsize=7,
            color="crimson",
        )
    ax.set_xlabel("t (s)")
    ax.set_ylabel("θ/α (-)")
    verdict = res.audit.verdict if res.audit is not None else None
    ax.set_title(f"{res.name}: rotation, measured vs simulated" + (f" (audit: {verdict})" if verdict else ""))
    ax.legend(fontsize=8, ncol=2)
    ax.grid(alpha=0.3)
    return save_png(fig, out / "theta.png")


def _per_impact_figure(plt, res, out: Path) -> Path:
    """Per-impact η with the audit's flagged impacts, η_e and η_H."""
    fig, ax = plt.subplots(figsize=(6, 4))
    k = np.arange(1, len(res.per_impact_eta) + 1)
    ax.plot(k, res.per_impact_eta, "o-", label="per impact (local fits)")
    ex = [e.impact for e in res.fit.excluded_impacts or () if 1 <= e.impact <= len(k)]
    if ex:
        ax.plot(
            ex,
            np.asarray(res.per_impact_eta)[np.asarray(ex) - 1],
            "x",
            color="crimson",
            ms=10,
            mew=2,
            label="flagged by the audit (not to trust)",
        )
    if np.isfinite(res.fit.eta_e):
        ax.axhline(res.fit.eta_e, color="C1", label=f"η_e = {res.fit.eta_e:.4f}")
    ax.axhline(res.block.eta_H, color="k", ls=":", label=f"η_H = {res.block.eta_H:.4f}")
    ax.set_xlabel("impact number")
    ax.set_ylabel("η = ω⁺/ω⁻")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return save_png(fig, out / "per_impact_eta.png")


def _energy_figure(plt, res, out: Path) -> Path:
    """Kinetic-energy loss per impact of each simulated law."""
    fig, ax = plt.subplots(figsize=(8, 4))
    for law, sim in res.simulations.items():
        imp = sim.impacts
        if imp is not None and len(imp):
            e_ratio = (np.asarray(imp["omega_after_rad_s"]) / np.asarray(imp["omega_before_rad_s"])) ** 2
            ax.plot(np.arange(1, len(e_ratio) + 1), 1 - e_ratio, "o-", ms=3, label=law)
    ax.set_xlabel("impact number")
    ax.set_ylabel("kinetic-energy loss per impact (-)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return save_png(fig, out / "energy_per_impact.png")


def _video_imu_figure(plt, res, out: Path) -> Path:
    """θ video − θ IMU."""
    t, r = res.video_imu_residual
    fig, ax = plt.subplots(figsize=(10, 3))
    ax.plot(t, np.degrees(r), lw=0.8)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("θ video − θ IMU (°)")
    ax.set_title(f"video vs IMU, RMS {np.degrees(np.sqrt(np.nanmean(np.asarray(r) ** 2))):.3f}°")
    ax.grid(alpha=0.3)
    return save_png(fig, out / "video_vs_imu.png")


def _column_figure(plt, res, out: Path) -> Path:
    """Each block of a column run: measured, model, truth."""
    c = res.column
    n = len(c.objects)
    fig, axs = plt.subplots(n, 1, figsize=(10, 2.2 * n + 1), sharex=True, squeeze=False)
    for i, (ax, o) in enumerate(zip(axs[:, 0], c.objects)):
        ax.plot(c.t_s, c.theta_measured_rad[:, i], lw=1.2, label="measured (video)")
        ax.plot(c.sim_t_s, c.theta_sim_rad[:, i], lw=0.9, ls="--", label="column model")
        if c.theta_truth is not None:
            tt, th = c.theta_truth
            ax.plot(tt, th[:, i], lw=0.6, color="k", alpha=0.5, label="truth")
        ax.set_ylabel(f"θ {o} (rad)")
        ax.grid(alpha=0.3)
    axs[0, 0].legend(fontsize=8)
    axs[0, 0].set_title(f"{res.name}: column, measured vs simulated (status {c.status})")
    axs[-1, 0].set_xlabel("t (s)")
    return save_png(fig, out / "column.png")


def _table_figure(plt, res, out: Path) -> Path:
    """The table's displacement, velocity and acceleration (with its ±2σ band when fused)."""
    fig, axs = plt.subplots(3, 1, figsize=(10, 6), sharex=True)
    tt = res.table.t_s
    cols = res.table.columns()
    for ax, key, lab in zip(
        axs, ("disp_m", "vel_m_s", "acc_m_s2"), ("displacement (m)", "velocity (m/s)", "acceleration (m/s²)")
    ):
        if key in cols:
            ax.plot(tt, cols[key], lw=0.9)
        if key == "acc_m_s2" and "sigma_acc_m_s2" in cols:  # a fused table: each sample's ±2σ
            a, s2 = cols[key], 2 * cols["sigma_acc_m_s2"]
            ax.fill_between(tt, a - s2, a + s2, alpha=0.3, lw=0, label="±2σ")
            ax.legend(loc="upper right")
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
    axs[-1].set_xlabel("t (s)")
    axs[0].set_title(f"table motion ({res.table.source})")
    return save_png(fig, out / "table.png")


def campaign_figures(table, out_dir, regression=None) -> dict[str, Path]:
    """η vs h/b per scale with η_H and η_M curves (Čeh Fig. 13, 16–19), and the k surface.

    ``table`` is the campaign DataFrame (columns block, b_m, h_m, contact, eta_e,
    ci_lo, ci_hi, eta_H, eta_M, ...).
    """
    from ...blocks import Block

    plt = pyplot()
    out = Path(out_dir)
    figs: dict[str, Path] = {}
    if table is None or not len(table):
        return figs
    fig, ax = plt.subplots(figsize=(7, 5))
    hb_grid = np.linspace(0.8, 10, 200)
    # Čeh's figures are of free rocking: a shake-table run's half-cycle η_e is not drawn here
    free = table.get("eta_e_source", "free") == "free"
    fitted = table[np.isfinite(table["eta_e"]) & free]
    for i, (b_m, grp) in enumerate(fitted.groupby("b_m")):
        eta_h = [Block(b_m, hb * b_m).eta_H for hb in hb_grid]
        ax.plot(hb_grid, eta_h, color=f"C{i}", ls=":", lw=1)
        for contact, mk in (("full", "o"), ("edge", "s")):
            g = grp[grp["contact"] == contact]
            if not len(g):
                continue
            hb = g["h_m"] / g["b_m"]
            yerr = None
            if {"ci_lo", "ci_hi"} <= set(g.columns):
                yerr = np.vstack([g["eta_e"] - g["ci_lo"], g["ci_hi"] - g["eta_e"]]).clip(min=0)
            ax.errorbar(
                hb,
                g["eta_e"],
                yerr=yerr,
                fmt=mk,
                color=f"C{i}",
                ms=5,
                capsize=2,
                label=f"b = {100 * b_m:.1f} cm, {contact} contact",
            )
        if regression is not None:
            try:
                eta_m = [regression.predict(hb, b_m).eta_M for hb in hb_grid]
                ax.plot(hb_grid, eta_m, color=f"C{i}", lw=1, label=f"η_M (Eq. 19 k), b = {100 * b_m:.1f} cm")
            except Exception:  # a regression without predict() support: skip the curve
                pass
    ax.set_xlabel("h/b (-)")
    ax.set_ylabel("η (-)")
    ax.set_title("restitution vs slenderness (dotted: η_H)")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    figs["eta_vs_hb"] = save_png(fig, out / "eta_vs_hb.png")

    if regression is not None and hasattr(regression, "predict"):
        try:
            hb = np.linspace(1.5, 10, 40)
            bb = np.linspace(0.02, 0.08, 30)
            H, Bm = np.meshgrid(hb, bb)
            K = np.vectorize(lambda x, y: regression.predict(x, y).k)(H, Bm)
            fig, ax = plt.subplots(figsize=(6, 4.5))
            cs = ax.contourf(H, 100 * Bm, K, levels=15, cmap="viridis")
            fig.colorbar(cs, ax=ax, label="k (-)")
            ax.set_xlabel("h/b (-)")
            ax.set_ylabel("b (cm)")
            ax.set_title("k(h/b, b) regression (Čeh Eq. 19 form)")
            figs["k_surface"] = save_png(fig, out / "k_surface.png")
        except Exception:  # noqa: BLE001 - the surface is optional decoration
            pass
    return figs
