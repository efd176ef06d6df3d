"""A measured shake table's motion: displacement, velocity and acceleration on one clock.

Made by the video tracker (Savitzky-Golay derivatives of the tracked displacement,
:func:`rocklab.tracking.table_motion`), by the table IMU (acceleration only) or from a record
file (acceleration only); read by the experiment's simulations, its figures, ``series.csv`` and
the Rerun recording. A prescribed table program of a simulated session is another thing
(:class:`rocklab.synth.TableProgram`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["TableMotion"]


@dataclass(frozen=True)
class TableMotion:
    """Horizontal motion of a table, sampled at ``t_s``.

    Attributes
    ----------
    t_s : ndarray, shape (n,)
        Sample times, s.
    x_m : ndarray, shape (n,), or None
        Horizontal displacement, relative to the first valid sample, m (NaN where lost);
        None when the source measures acceleration only (an IMU, a record).
    vx_m_s : ndarray, shape (n,), or None
        Velocity, m/s (NaN near gaps); None as ``x_m``.
    ax_m_s2 : ndarray, shape (n,)
        Acceleration, m/s^2 (NaN near gaps).
    window : int
        Savitzky-Golay window that differentiated ``x_m`` (samples, odd); 0 when the
        acceleration was measured, not differentiated.
    polyorder : int
        Its polynomial order (0 as ``window``).
    noise_m : float
        Estimated white-noise level of ``x_m``, which chose the window, m (NaN when none).
    object : str
        The tracked table's id.
    source : str
        Where the motion comes from: ``"video"``, ``"imu"``, ``"record"`` or ``"fused"`` (the
        table IMU's acceleration and the video's displacement, :func:`rocklab.tracking.fuse_table_motion`).
    sigma_ax_m_s2 : ndarray, shape (n,), or None
        Standard deviation of each acceleration sample, m/s^2 (the fusion's smoother); None when
        the source does not give one.
    acc_noise_m_s2 : float
        White-noise level of the acceleration as measured, before any smoothing, m/s^2 (a fused
        table's IMU); NaN when unknown.
    acc_scale_sd : float
        Relative standard deviation of the acceleration's scale as measured (a fused table: from
        its two sources' agreement, :func:`rocklab.tracking.table_scale_agreement`); NaN when
        nothing measured it.
    """

    t_s: np.ndarray
    x_m: np.ndarray | None
    vx_m_s: np.ndarray | None
    ax_m_s2: np.ndarray
    window: int = 0
    polyorder: int = 0
    noise_m: float = math.nan
    object: str = "table"
    source: str = "video"
    sigma_ax_m_s2: np.ndarray | None = None
    acc_noise_m_s2: float = math.nan
    acc_scale_sd: float = math.nan

    @classmethod
    def from_acceleration(cls, t_s, acc_m_s2, source: str, object: str = "table") -> "TableMotion":
        """A table whose acceleration alone is known (an IMU, a record): ``x_m``, ``vx_m_s`` None."""
        return cls(np.asarray(t_s, float), None, None, np.asarray(acc_m_s2, float), object=object, source=source)

    @property
    def window_s(self) -> float:
        """The Savitzky-Golay window, s (NaN when there is none)."""
        if not self.window or len(self.t_s) < 2:
            return math.nan
        return self.window * float(np.median(np.diff(self.t_s)))

    def columns(self) -> dict:
        """The measured series by their report names: ``disp_m``, ``vel_m_s``, ``acc_m_s2``,
        ``sigma_acc_m_s2`` (the ones this source has), each an ndarray on ``t_s``."""
        out = {
            "disp_m": self.x_m,
            "vel_m_s": self.vx_m_s,
            "acc_m_s2": self.ax_m_s2,
            "sigma_acc_m_s2": self.sigma_ax_m_s2,
        }
        return {k: np.asarray(v, float) for k, v in out.items() if v is not None}

    def to_frame(self):
        """The result as a pandas DataFrame (SI units in the column names)."""
        import pandas as pd

        cols = {
            "t_s": self.t_s, "x_m": self.x_m, "vx_m_s": self.vx_m_s, "ax_m_s2": self.ax_m_s2,
            "sigma_ax_m_s2": self.sigma_ax_m_s2,
        }  # fmt: skip
        return pd.DataFrame({k: v for k, v in cols.items() if v is not None})

    def to_base_motion(self, name: str | None = None):
        """As a :class:`rocklab.series.BaseMotion` from t = 0 (gaps filled with 0 m/s²), to drive
        the simulator."""
        from ._base_motion import BaseMotion

        a = np.where(np.isfinite(self.ax_m_s2), self.ax_m_s2, 0.0)
        return BaseMotion.from_arrays(self.t_s - self.t_s[0], a, "m/s2", name=name or f"{self.object} ({self.source})")

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        return {
            "object": self.object,
            "source": self.source,
            "window": self.window,
            "window_s": self.window_s,
            "polyorder": self.polyorder,
            "noise_m": self.noise_m,
            "max_abs_ax_m_s2": float(np.nanmax(np.abs(self.ax_m_s2))) if np.any(np.isfinite(self.ax_m_s2)) else np.nan,
        }
