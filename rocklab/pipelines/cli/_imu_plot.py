"""``rocklab imu --plot``: what the IMU measured and what was made of it (PNG)."""

from __future__ import annotations

import numpy as np

from .._plotting import pyplot, save_png

__all__ = ["imu_figure"]


def imu_figure(log, res, path, title: str = ""):
    """Write the IMU figure for a block rotation or a table acceleration to ``path`` (PNG).

    Top: theta(t), deg, with the release, the impacts and the final rest (block) or the
    table acceleration, m/s^2, with the rest that gave gravity (table).  Bottom: the
    three gyro axes, deg/s (bias removed for a block), so a spin about another axis or
    a hand-held sensor is visible at a glance.

    Parameters
    ----------
    log : ImuLog
        The log read.
    res : ImuRotation or TableAcceleration
        Its result.
    path : str or Path
        PNG file, written atomically.
    """
    plt = pyplot()
    fig, (ax0, ax1) = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    t = np.asarray(log.t_s, float)
    table = hasattr(res, "turn_rad")
    if table:
        ax0.plot(res.t_s, res.acc_m_s2, lw=0.7, color="C0", label="table acceleration")
        ax0.axvspan(res.rest_s[0], res.rest_s[1], color="0.85", label="rest: gravity measured")
        ax0.set_ylabel("acceleration, m/s$^2$")
        gyro = np.rad2deg(log.gyro_rad_s)
        sub = f"sensor turned {np.rad2deg(res.turn_rad):.3g} deg"
    else:
        ax0.plot(res.t_s, np.rad2deg(res.theta_rad), lw=0.8, color="C0", label=r"$\theta$ (gyro, anchored)")
        if res.ahrs_theta_rad is not None:
            ax0.plot(res.t_s, np.rad2deg(res.ahrs_theta_rad), lw=0.6, color="C1", label=r"$\theta$ AHRS")
        if np.isfinite(res.release_t_s):
            ax0.axvline(res.release_t_s, color="C2", ls="--", lw=1, label=f"release {res.release_t_s:.3f} s")
        if len(res.impact_t_s):
            th_i = np.interp(res.impact_t_s, res.t_s, np.rad2deg(res.theta_rad))
            ax0.plot(res.impact_t_s, th_i, "v", ms=4, color="C3", label=f"{len(res.impact_t_s)} impacts")
        if np.isfinite(res.rest_t_s):
            ax0.axvspan(res.rest_t_s, t[-1], color="0.88", label="final rest")
        ax0.set_ylabel(r"$\theta$, deg")
        gyro = np.rad2deg(log.gyro_rad_s - res.gyro_bias_rad_s)
        ax1.plot(res.t_s, np.rad2deg(res.omega_rad_s), lw=0.6, color="k", label="about the rocking axis")
        a = res.axis
        sub = f"axis ({a[0]:+.2f}, {a[1]:+.2f}, {a[2]:+.2f})"
        if res.rocking is not None and np.isfinite(res.rocking.axis_tilt_rad):
            sub += (
                f", {np.rad2deg(res.rocking.axis_tilt_rad):.3g} deg above horizontal, "
                f"{100 * res.rocking.axis_share:.3g} % of the rotation"
            )
    for k, c in enumerate("xyz"):
        ax1.plot(t, gyro[:, k], lw=0.5, alpha=0.8, color=("tab:red", "tab:green", "tab:blue")[k], label=f"gyro {c}")
    ax1.set_ylabel("rate, deg/s")
    ax1.set_xlabel("t, s (log clock)")
    ax0.legend(loc="upper right", fontsize=8)
    ax1.legend(loc="upper right", fontsize=8, ncol=4)
    ax0.set_title(f"{title} - status {res.status}; {sub}", fontsize=9)
    for ax in (ax0, ax1):
        ax.grid(alpha=0.3)
    return save_png(fig, path)
