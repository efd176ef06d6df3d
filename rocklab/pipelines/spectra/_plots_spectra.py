"""Figures for overturning spectra and equivalent mechanisms (matplotlib; pipelines only).

- :func:`plot_oas`: OAS with overturned grid points and the refined boundary, the
  transformed OAS with the vertical (Eq. 20) and inclined (Eq. 28) lines, and the
  OAS over 1/p with the simplified curves Eq. 21, 29, 30 (thesis Fig. 36–37, 47, 55).
- :func:`plot_overturning_curve`: overturning curve and impulse curve of a pulse (Fig. 33–34).
- :func:`plot_wall_error_maps`, :func:`plot_frame_error_maps`: free-period and
  overturning-time error maps of the equivalent block (DeJong & Dimitrakopoulos Fig. 3, 6–8).
"""

from __future__ import annotations

import numpy as np

from .._plotting import pyplot, save_png

__all__ = ["plot_oas", "plot_overturning_curve", "plot_wall_error_maps", "plot_frame_error_maps"]


def _fig(ncols, w=4.2, h=3.6):
    plt = pyplot()
    return plt, *plt.subplots(1, ncols, figsize=(w * ncols, h), constrained_layout=True)


def plot_oas(o, path):
    """Three-panel OAS figure of an :class:`rocklab.models.OASResult`; writes a PNG to ``path``."""
    from ...models import simplified_oas

    plt, fig, ax = _fig(3)
    L, P = np.meshgrid(o.levels, o.p_rad_s, indexing="ij")
    ov = o.overturned
    ax[0].plot(P[ov], L[ov], ".", ms=1.5, color="0.6", label="overturns (grid)")
    ax[0].plot(o.p_min_rad_s, o.levels, "k-", lw=1.2, label="largest unsafe size")
    ax[0].set(xlabel="p [1/s]", ylabel="a_p / a_p,min", title=f"OAS {o.name}", xscale="log")
    from matplotlib.ticker import LogLocator, NullFormatter, ScalarFormatter

    ax[0].xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))  # 1, 2, 5, 10 ...: no crowding
    ax[0].xaxis.set_major_formatter(ScalarFormatter())
    ax[0].xaxis.set_minor_formatter(NullFormatter())
    i = int(np.nanargmin(o.f_rad_s)) if np.isfinite(o.f_rad_s).any() else None
    if i is not None:  # where t_I comes from
        ax[0].plot(o.p_min_rad_s[i], o.levels[i], "o", mfc="none", color="C3", label="sets f_min")
    f = o.f_rad_s
    ax[1].plot(f, o.levels, "k.-", ms=3, label="transformed OAS")
    ax[1].axvline(o.f_min_rad_s, ls="--", color="C3", label=f"f_min: t_I = {o.t_I_s:.3f} s")
    if np.isfinite(o.t_I_prime_s) and np.isfinite(o.beta):
        A = np.linspace(1, o.levels.max(), 50)
        ax[1].plot(
            1 / o.t_I_prime_s + A / o.beta,
            A,
            "--",
            color="C0",
            label=f"t'_I = {o.t_I_prime_s:.3f} s, beta = {o.beta:.2f}",
        )
    ax[1].set(xlabel="f = p a_p/a_p,min [1/s]", ylabel="a_p / a_p,min", title="transformed OAS")
    ax[1].legend(fontsize=7)
    p = np.geomspace(max(o.p_rad_s.min(), 0.05), o.p_rad_s.max(), 300)
    ax[2].plot(1 / o.p_min_rad_s, o.levels, "k-", lw=1.2, label="OAS")
    ax[2].plot(1 / p, simplified_oas(p, o.t_I_s, i_cr=o.i_cr), "--", color="C3", label="Eq. 21")
    if np.isfinite(o.t_I_prime_s) and np.isfinite(o.beta):
        ax[2].plot(
            1 / p, simplified_oas(p, o.t_I_s, o.t_I_prime_s, o.beta, kind="eq29"), ":", color="C0", label="Eq. 29"
        )
        ax[2].plot(
            1 / p,
            simplified_oas(p, o.t_I_s, o.t_I_prime_s, o.beta, o.i_cr, kind="eq30"),
            "-.",
            color="C2",
            label="Eq. 30",
        )
    xmax = 1.5 * np.nanmax(1 / o.p_min_rad_s) if np.isfinite(o.p_min_rad_s).any() else 1 / p.min()
    ax[2].set(
        xlabel="1/p [s]", ylabel="a_p / a_p,min", ylim=(0, o.levels.max() * 1.05), xlim=(0, xmax), title="over 1/p"
    )
    ax[2].legend(fontsize=7)
    ax[0].legend(fontsize=7)
    return save_png(fig, path, dpi=120, tight=False)


def plot_overturning_curve(c, path):
    """Overturning curve (a_p/a_p,min vs p t_p) with the grid map, and the impulse curve."""
    plt, fig, ax = _fig(2)
    X, L = np.meshgrid(c.ptp, c.levels)
    ax[0].plot(X[c.overturned], L[c.overturned], ".", ms=2, color="0.6")
    ax[0].plot(c.ptp, c.a_min_ratio, "k-")
    ax[0].set(xlabel="p t_p", ylabel="a_p / a_p,min", title=f"overturning curve: {c.kind}")
    ax[1].plot(c.ptp, c.impulse_ratio, "k-")
    ax[1].axhline(c.i_cr, ls="--", color="C3", label=f"i_cr = {c.i_cr:.4f}")
    ax[1].set(xlabel="p t_p", ylabel="p I / a_p,min", title="overturning impulse curve")
    ax[1].legend(fontsize=7)
    return save_png(fig, path, dpi=120, tight=False)


def _error_maps(mechs, ys, ylabel, path, ratios, accs, title):
    from ...models import equivalence_errors

    errs = [equivalence_errors(m, ratios, accs) for m in mechs]
    T = np.array([e["period_ratio"] for e in errs])
    t1 = np.array([e["t_ratio_kappa1"] for e in errs])
    t2 = np.array([e["t_ratio_kappa2"] for e in errs])
    plt, fig, ax = _fig(3)
    for k, (Z, x, lab) in enumerate(
        ((T, ratios, "phi/phi_cr"), (t1, accs, "u_g/(g lambda)  [kappa1]"), (t2, accs, "u_g/(g lambda)  [kappa2]"))
    ):
        cs = ax[k].contourf(x, ys, Z, levels=15, cmap="viridis")
        fig.colorbar(cs, ax=ax[k])
        ax[k].set(xlabel=lab, ylabel=ylabel)
    ax[0].set_title(f"{title}: T_r,blockeq / T_r")
    ax[1].set_title("t_over,blockeq / t_over")
    ax[2].set_title("t_over,blockeq / t_over")
    save_png(fig, path, dpi=120, tight=False)
    return dict(
        y=np.asarray(ys),
        ratios=np.asarray(ratios),
        accs=np.asarray(accs),
        period_ratio=T,
        t_ratio_kappa1=t1,
        t_ratio_kappa2=t2,
    )


def plot_wall_error_maps(path, alphas=None, ratios=None, accs=None, R_m=1.0):
    """Rocking wall: T_eq24/T_wall over (phi/phi_cr, alpha) and t_eq25/t_wall over (u/(g lambda),
    alpha) for kappa1 and kappa2 (DeJong & Dimitrakopoulos Fig. 3). Returns the arrays."""
    from ...models import wall_mechanism

    alphas = np.linspace(0.05, 0.4, 8) if alphas is None else np.asarray(alphas)
    ratios = np.linspace(0.05, 0.95, 10) if ratios is None else np.asarray(ratios)
    accs = np.linspace(1.1, 4.0, 8) if accs is None else np.asarray(accs)
    return _error_maps([wall_mechanism(R_m, a) for a in alphas], alphas, "alpha [rad]", path, ratios, accs, "wall")


def plot_frame_error_maps(
    path,
    H1_over_H=None,
    direction="+",
    b_m=0.3,
    H_m=2.0,
    L_m=3.0,
    h_m=0.2,
    masses=(1.0, 1.0, 1.0),
    ratios=None,
    accs=None,
):
    """Asymmetric frame error maps over (phi/phi_cr or u/(g lambda), H1/H) for one rocking
    direction (paper Fig. 6–8). Returns the arrays."""
    from ...models import asymmetric_frame

    hs = np.linspace(1.0, 1.5, 6) if H1_over_H is None else np.asarray(H1_over_H)
    ratios = np.linspace(0.05, 0.95, 10) if ratios is None else np.asarray(ratios)
    accs = np.linspace(1.1, 4.0, 8) if accs is None else np.asarray(accs)
    k = 0 if direction == "+" else 1
    mechs = [asymmetric_frame(b_m, H_m, r * H_m, L_m, h_m, *masses)[k] for r in hs]
    return _error_maps(mechs, hs, "H1/H", path, ratios, accs, f"frame ({direction})")


def plot_tI_vs_tp(table, path, slenderness: float = 12.0):
    """t_I against t_p across records (the thesis's Fig. 53 kind), its regression line and
    correlation when 3 or more records have both, the thesis's Table 4 values overlaid.

    ``table`` is the record table of ``rocklab oas`` (``t_p_s, t_I_s, thesis_t_p_s, thesis_t_I_s, name``).
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 5.2))
    ok = table[np.isfinite(table["t_I_s"].astype(float)) & np.isfinite(table["t_p_s"].astype(float))]
    if "t_I_p05_s" in ok.columns:
        lo = (ok["t_I_s"] - ok["t_I_p05_s"]).clip(lower=0)
        hi = (ok["t_I_p95_s"] - ok["t_I_s"]).clip(lower=0)
        ax.errorbar(
            ok["t_p_s"],
            ok["t_I_s"],
            yerr=[lo, hi],
            fmt="o",
            color="C0",
            ms=4,
            elinewidth=0.8,
            label=f"rocklab, median and 90 % band (H/B = {slenderness:g})",
        )
    else:
        ax.plot(ok["t_p_s"], ok["t_I_s"], "o", color="C0", label=f"rocklab (H/B = {slenderness:g})")
    th = ok[np.isfinite(ok["thesis_t_I_s"].astype(float))]
    if len(th):
        ax.plot(th["thesis_t_p_s"], th["thesis_t_I_s"], "s", mfc="none", color="C3", label="thesis Table 4")
        for _, r in th.iterrows():
            ax.plot([r["t_p_s"], r["thesis_t_p_s"]], [r["t_I_s"], r["thesis_t_I_s"]], color="0.6", lw=0.6)
    for _, r in ok.iterrows():
        ax.annotate(
            str(r["thesis_id"] or r["name"]),
            (r["t_p_s"], r["t_I_s"]),
            fontsize=6,
            xytext=(3, 2),
            textcoords="offset points",
        )
    lim = (
        float(np.nanmax(np.r_[ok["t_p_s"], ok["t_I_s"], th["thesis_t_I_s"] if len(th) else []])) * 1.1
        if len(ok)
        else 1.0
    )
    ax.plot([0, lim], [0, lim], "k:", lw=0.8, label="t_I = t_p")
    if len(ok) >= 3:
        from ...models.spectra import tI_tp_regression

        reg = tI_tp_regression(ok["t_p_s"], ok["t_I_s"])
        ax.plot(
            [0, lim],
            [reg.intercept, reg.intercept + reg.slope * lim],
            "C0--",
            lw=0.9,
            label=f"t_I = {reg.slope:.3f} t_p + {reg.intercept:.3f} s (r = {reg.r:.3f}, n = {reg.n})",
        )
    ax.set_xlim(0, lim)
    ax.set_ylim(0, lim)
    ax.set_xlabel("pulse duration t_p (s)")
    ax.set_ylabel("replacement impulse duration t_I (s)")
    ax.set_title(f"t_I vs t_p over {len(ok)} records")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return save_png(fig, path)
