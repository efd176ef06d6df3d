"""``rocklab track --plot``: what the video tracker measured, per object, and where it failed (PNG)."""

from __future__ import annotations

import numpy as np

from .._plotting import pyplot, save_png

__all__ = ["track_figure"]

#: Colour of each non-ok status on the figure's status strip (ok frames are left blank).
STATUS_COLOURS = {
    "lost": "0.35",
    "occluded": "tab:brown",
    "blur": "tab:olive",
    "mismatch": "tab:red",
    "jump": "tab:orange",
    "background": "tab:purple",
    "drift": "tab:pink",
    "twin": "tab:cyan",
    "roundtrip": "teal",
    "misaligned": "tab:green",
    "one_marker": "khaki",
    "low_quality": "tab:gray",
    "outlier": "gold",
    "latch": "lightcoral",
    "interpolated": "tab:cyan",
    "corrected": "tab:blue",
    "dropped": "black",
}


def track_figure(res, path, title: str = ""):
    """Write one column of panels per object of a :class:`~rocklab.tracking.TrackResult` (PNG).

    Rows: theta(t), deg, with its 1-sigma band (or why the angle is not measured); the image
    position x_px, y_px minus their first ok value, px; the quality with a strip showing every
    frame that is not ``ok``, coloured by its status, so that a lost lock, a slide or a run of
    rejected poses is seen at a glance.

    Parameters
    ----------
    res : TrackResult
    path : str or Path
        PNG file, written atomically.
    """
    plt = pyplot()
    n = len(res.tracks)
    fig, axes = plt.subplots(3, n, figsize=(5.5 * n + 1, 7), sharex=True, squeeze=False)
    for j, tr in enumerate(res.tracks):
        ax0, ax1, ax2 = axes[:, j]
        t = np.asarray(tr.t_s, float)
        th, sig = np.rad2deg(tr.theta_rad), np.rad2deg(tr.sigma_theta_rad)
        if tr.theta_note:
            ax0.text(
                0.5,
                0.5,
                f"theta not measured:\n{tr.theta_note}",
                ha="center",
                va="center",
                transform=ax0.transAxes,
                fontsize=8,
                wrap=True,
            )
        else:
            ax0.fill_between(t, th - sig, th + sig, color="C0", alpha=0.25, lw=0, label=r"$\pm1\sigma$")
            ax0.plot(t, th, lw=0.8, color="C0", label=r"$\theta$")
            ax0.legend(loc="upper right", fontsize=7)
        ax0.set_ylabel(r"$\theta$, deg")
        ok = tr.ok
        for arr, lab, c in ((tr.x_px, "x", "C1"), (tr.y_px, "y", "C2")):
            a = np.asarray(arr, float) if arr is not None else np.full(t.size, np.nan)
            first = a[ok][0] if ok.any() and np.isfinite(a[ok][0]) else 0.0
            ax1.plot(t, a - first, lw=0.8, color=c, label=f"{lab}_px - {first:.4g}")
        ax1.set_ylabel("image position, px")
        ax1.legend(loc="upper right", fontsize=7)
        ax2.plot(t, tr.quality, lw=0.7, color="k", label="quality")
        ax2.set_ylim(-0.15, 1.05)
        # every status but ok is marked (one the table does not name, in grey)
        unnamed = sorted(set(tr.status.tolist()) - set(STATUS_COLOURS) - {"ok"})
        for st in [*STATUS_COLOURS, *unnamed]:
            m = tr.status == st
            if m.any():
                ax2.vlines(
                    t[m], -0.14, -0.02, color=STATUS_COLOURS.get(st, "0.6"), lw=1.2, label=f"{st} ({int(m.sum())})"
                )
        ax2.set_ylabel("quality (strip: not ok)")
        ax2.set_xlabel("t, s")
        ax2.legend(loc="lower right", fontsize=7, ncol=2)
        pct = 100.0 * float(np.mean(ok)) if ok.size else 0.0
        ax0.set_title(f"{tr.object} ({tr.kind}): {pct:.4g} % of {ok.size} frames ok", fontsize=9)
        for ax in (ax0, ax1, ax2):
            ax.grid(alpha=0.3)
    level = f"level {np.rad2deg(res.level_rad):.4g} deg from {res.level_source}"
    fig.suptitle(f"{title} - {res.n_frames} frames, {res.fps:.4g} frames/s, {level}", fontsize=9)
    return save_png(fig, path)
