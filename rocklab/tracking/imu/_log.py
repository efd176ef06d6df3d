"""The ImuLog record: one IMU's inertial samples in SI units."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._errors import InputError

__all__ = ["ImuLog"]


@dataclass(frozen=True)
class ImuLog:
    """One IMU's inertial samples in SI units.

    Attributes
    ----------
    t_s : ndarray, shape (n,)
        Sample times, s, strictly increasing (device clock, or index / rate).
    gyro_rad_s : ndarray, shape (n, 3)
        Angular rate in the sensor frame, rad/s.
    acc_m_s2 : ndarray, shape (n, 3)
        Specific force (accelerometer reading) in the sensor frame, m/s^2;
        +G along the upward axis at rest.
    rate_hz : float
        Nominal sample rate, Hz.
    dropped_samples : int
        Samples missing from the log (estimated from timestamp or packet gaps).
    saturated : ndarray of bool, shape (n,)
        Main accelerometer at full scale on some axis (value replaced from the
        high-g accelerometer where one was available).
    source : str
        File the samples were read from (or ``"simulated"``/``"array"``).
    format : str
        ``"ximu-gui" | "ximu3" | "fusion" | "phyphox" | "sensor-logger" | "mapped" | "simulated" | "array"``.
    packet : ndarray or None, shape (n,)
        x-IMU GUI packet numbers (unwrapped), else None.
    high_g_samples : int
        Number of samples whose acceleration came from the high-g accelerometer.
    """

    t_s: np.ndarray
    gyro_rad_s: np.ndarray
    acc_m_s2: np.ndarray
    rate_hz: float
    dropped_samples: int = 0
    saturated: np.ndarray | None = None
    source: str = "array"
    format: str = "array"
    packet: np.ndarray | None = field(default=None, repr=False)
    high_g_samples: int = 0

    def __post_init__(self):
        n = len(self.t_s)
        if self.gyro_rad_s.shape != (n, 3) or self.acc_m_s2.shape != (n, 3):
            raise InputError(
                f"ImuLog: gyro_rad_s {self.gyro_rad_s.shape} and acc_m_s2 "
                f"{self.acc_m_s2.shape} must both be ({n}, 3); pass (n, 3) arrays"
            )
        if self.saturated is None:
            object.__setattr__(self, "saturated", np.zeros(n, dtype=bool))

    @property
    def n(self) -> int:
        """Number of samples."""
        return len(self.t_s)

    @property
    def duration_s(self) -> float:
        """Time span of the log, s."""
        return float(self.t_s[-1] - self.t_s[0]) if self.n else 0.0

    def to_frame(self):
        """Samples as a DataFrame: ``t_s, gyro_{x,y,z}_rad_s, acc_{x,y,z}_m_s2, saturated``."""
        import pandas as pd

        d = {"t_s": self.t_s}
        for i, ax in enumerate("xyz"):
            d[f"gyro_{ax}_rad_s"] = self.gyro_rad_s[:, i]
        for i, ax in enumerate("xyz"):
            d[f"acc_{ax}_m_s2"] = self.acc_m_s2[:, i]
        d["saturated"] = self.saturated
        return pd.DataFrame(d)

    def to_dict(self) -> dict:
        """Summary (no arrays): format, rate, sample count, drops, saturation, source."""
        return {
            "format": self.format,
            "sample_rate_hz": float(self.rate_hz),
            "n_samples": int(self.n),
            "dropped_samples": int(self.dropped_samples),
            "saturated_samples": int(np.count_nonzero(self.saturated)),
            "high_g_samples": int(self.high_g_samples),
            "duration_s": self.duration_s,
            "source": self.source,
        }

    def slice(self, i0: int, i1: int) -> "ImuLog":
        """Samples ``i0:i1`` as a new log (same rate and metadata)."""
        pk = None if self.packet is None else self.packet[i0:i1]
        return ImuLog(
            self.t_s[i0:i1],
            self.gyro_rad_s[i0:i1],
            self.acc_m_s2[i0:i1],
            self.rate_hz,
            0,
            self.saturated[i0:i1],
            self.source,
            self.format,
            pk,
        )
