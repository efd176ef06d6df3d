"""The base motion: a horizontal ground or table acceleration history on a uniform time grid.

The simulator's input (:func:`rocklab.models.simulate`, the column model, the spectra) and what
the record readers (:mod:`rocklab.models.spectra`), the IMU table model and the video table
motion produce. SI inside: ``t_s`` in s, ``acc_m_s2`` in m/s^2; other acceleration units are
converted once, by :func:`acc_unit_factor`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._errors import InputError
from ..blocks import G

__all__ = ["BaseMotion", "UNITS_TO_M_S2", "acc_unit_factor"]

#: Factors from accepted acceleration units to m/s^2.
UNITS_TO_M_S2 = {
    "g": G,
    "m/s2": 1.0,
    "m/s^2": 1.0,
    "m_s2": 1.0,
    "cm/s2": 0.01,
    "cm/s^2": 0.01,
    "cm_s2": 0.01,
    "gal": 0.01,
    "mm/s2": 0.001,
}


def acc_unit_factor(units: str, source: str = "") -> float:
    """Factor from the acceleration unit ``units`` (a key of :data:`UNITS_TO_M_S2`) to m/s^2.

    ``source`` prefixes the error (a file name and ": ").
    """
    key = str(units).strip().lower().replace(" ", "")
    if key not in UNITS_TO_M_S2:
        raise InputError(
            f"{source}units={units!r}: unknown acceleration unit; use one of {', '.join(sorted(set(UNITS_TO_M_S2)))}"
        )
    return UNITS_TO_M_S2[key]


@dataclass(frozen=True)
class BaseMotion:
    """A horizontal base acceleration history on a uniform time grid.

    Attributes
    ----------
    t_s : ndarray, shape (n,)
        Times, s, uniform spacing ``dt_s``, starting at ``t_s[0]``.
    acc_m_s2 : ndarray, shape (n,)
        Base acceleration, m/s^2 (positive pushes the base towards +x).
    name : str
        Label (file stem or user given).
    source : str
        File it came from, or ``"array"``.
    """

    t_s: np.ndarray
    acc_m_s2: np.ndarray
    name: str = "record"
    source: str = "array"
    meta: dict = field(default_factory=dict, compare=False)

    def __post_init__(self):
        t = np.asarray(self.t_s, dtype=float).ravel()
        a = np.asarray(self.acc_m_s2, dtype=float).ravel()
        src = f"{self.source}: " if self.source != "array" else ""
        if t.size != a.size:
            raise InputError(f"{src}t_s has {t.size} samples but acc_m_s2 has {a.size}; give equal lengths")
        if t.size < 2:
            raise InputError(f"{src}record has {t.size} samples; a base motion needs at least 2")
        bad = ~np.isfinite(t) | ~np.isfinite(a)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise InputError(f"{src}sample {i} is NaN/inf (t={t[i]}, a={a[i]}); clean the record")
        d = np.diff(t)
        if (d <= 0).any():
            i = int(np.flatnonzero(d <= 0)[0])
            raise InputError(
                f"{src}time is not strictly increasing at sample {i + 1} "
                f"(t={t[i]} then {t[i + 1]}); sort or de-duplicate the record"
            )
        dt = float(np.median(d))
        if np.max(np.abs(d - dt)) > 1e-6 * max(dt, 1e-12) + 1e-9:
            i = int(np.argmax(np.abs(d - dt)))
            raise InputError(
                f"{src}non-uniform time step at sample {i + 1} (dt={d[i]:g} s vs median "
                f"{dt:g} s): gap or jitter; resample with BaseMotion.resample() first"
            )
        t.setflags(write=False)
        a.setflags(write=False)
        object.__setattr__(self, "t_s", t)
        object.__setattr__(self, "acc_m_s2", a)

    # -- construction -------------------------------------------------------
    @classmethod
    def from_arrays(cls, t_s, acc, units: str = "m/s2", name: str = "record") -> "BaseMotion":
        """From arrays of times (s) and accelerations in ``units``."""
        f = acc_unit_factor(units)
        return cls(np.asarray(t_s, float), np.asarray(acc, float) * f, name=name)

    @classmethod
    def from_samples(
        cls, acc, dt_s: float, units: str = "m/s2", t0_s: float = 0.0, name: str = "record"
    ) -> "BaseMotion":
        """From equally spaced samples ``acc`` (in ``units``) at step ``dt_s`` (s)."""
        if not (math.isfinite(dt_s) and dt_s > 0):
            raise InputError(f"dt_s={dt_s!r}: time step must be positive (s)")
        acc = np.asarray(acc, float).ravel()
        return cls.from_arrays(t0_s + dt_s * np.arange(acc.size), acc, units=units, name=name)

    # -- derived ------------------------------------------------------------
    @property
    def dt_s(self) -> float:
        """Sample spacing, s."""
        return float(self.t_s[1] - self.t_s[0])

    @property
    def duration_s(self) -> float:
        """t_s[-1] - t_s[0], s."""
        return float(self.t_s[-1] - self.t_s[0])

    @property
    def pga_m_s2(self) -> float:
        """Peak absolute acceleration, m/s^2."""
        return float(np.max(np.abs(self.acc_m_s2)))

    def scaled(self, factor: float) -> "BaseMotion":
        """This record times ``factor``."""
        return BaseMotion(self.t_s, self.acc_m_s2 * float(factor), self.name, self.source, dict(self.meta))

    def scaled_to_pga(self, pga: float, units: str = "g") -> "BaseMotion":
        """This record scaled so that its PGA equals ``pga`` (in ``units``)."""
        target = float(pga) * acc_unit_factor(units)
        if not (math.isfinite(target) and target > 0):
            raise InputError(f"scale-pga={pga!r}: target PGA must be positive")
        if self.pga_m_s2 == 0:
            raise InputError(f"{self.source}: record is all zeros; cannot scale to a PGA")
        return self.scaled(target / self.pga_m_s2)

    def resample(self, dt_s: float, t_end_s: float | None = None) -> "BaseMotion":
        """Linear interpolation onto a uniform grid of step ``dt_s`` (s)."""
        t_end = self.t_s[-1] if t_end_s is None else float(t_end_s)
        t = self.t_s[0] + dt_s * np.arange(int(math.floor((t_end - self.t_s[0]) / dt_s + 1e-9)) + 1)
        return BaseMotion(t, self.at(t), self.name, self.source, dict(self.meta))

    def at(self, t_s) -> np.ndarray:
        """Acceleration (m/s^2) at times ``t_s`` by linear interpolation, 0 outside the record."""
        return np.interp(np.asarray(t_s, float), self.t_s, self.acc_m_s2, left=0.0, right=0.0)

    def to_frame(self):
        """DataFrame with columns ``t_s, acc_m_s2``."""
        import pandas as pd

        return pd.DataFrame({"t_s": self.t_s, "acc_m_s2": self.acc_m_s2})
