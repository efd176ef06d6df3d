"""Figures of multi-block columns (matplotlib lives in pipelines only)."""

from __future__ import annotations

from .._plotting import pyplot, save_png

__all__ = ["plot_column_maps", "plot_column_response"]


def plot_column_maps(maps, path=None, title: str | None = None):
    """The overturning maps of thesis Fig. 40: one panel per column, overturning cells marked.

    Parameters
    ----------
    maps : rocklab.models.ColumnMaps
    path : str or Path, optional
        Write a PNG here (atomically); the figure is returned either way.
    """
    import numpy as np

    plt = pyplot()

    k = len(maps.n_blocks)
    fig, axes = plt.subplots(1, k, figsize=(3.6 * k, 3.4), sharey=True, squeeze=False)
    T, A = np.meshgrid(maps.tp_s, maps.ap_m_s2)
    for ax, n, over, frac in zip(axes[0], maps.n_blocks, maps.overturned, maps.overturned_fraction):
        ax.scatter(T[~over], A[~over], s=14, facecolors="none", edgecolors="0.6", label="safe")
        ax.scatter(T[over], A[over], s=14, color="tab:blue", label="overturns")
        ax.set_title(f"{n} block{'s' if n > 1 else ''} ({100 * frac:.0f} % overturn)", fontsize=10)
        ax.set_xlabel("$t_p$ [s]")
        ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel("$a_p$ [m/s$^2$]")
    axes[0, -1].legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, frameon=False)
    fig.suptitle(
        title
        or f"Column overturning, H = {maps.H_m:g} m, B = {maps.B_m:g} m, full-sine pulse "
        f"({maps.params.get('n_impacts', 1)} impact(s) per closing)",
        fontsize=10,
    )
    fig.tight_layout()
    if path is not None:
        save_png(fig, path, dpi=120, tight=False)
    else:
        plt.close(fig)
    return fig


def plot_column_response(result, path=None):
    """Block angles and joint states of a :class:`rocklab.models.ColumnResult` against time."""
    plt = pyplot()

    fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 5), sharex=True, gridspec_kw={"height_ratios": [3, 1]})
    for i in range(result.column.n):
        a1.plot(result.t_s, result.theta_rad[:, i], lw=1, label=f"block {i}")
    a1.set_ylabel("θ [rad] (clockwise +)")
    a1.legend(fontsize=8)
    conf = result.configurations
    code = {"closed": 0, "cw": 1, "ccw": -1}
    for j in range(result.column.n):
        c = conf[conf.joint == j]
        a2.step(c.t_s, [j + 0.3 * code[s] for s in c.state], where="post", lw=1)
    a2.set_ylabel("joint (±cw/ccw)")
    a2.set_xlabel("t [s]")
    fig.tight_layout()
    if path is not None:
        save_png(fig, path, dpi=120, tight=False)
    else:
        plt.close(fig)
    return fig
