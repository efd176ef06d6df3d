"""True motions for synthetic sessions: the shake table and the blocks on it.

Sign conventions (SI throughout):

* World frame = the tracker's (``_config.py``): rocking plane, ``x`` right,
  ``y`` up as seen by the camera; the table top is ``y = 0``.
* ``phi`` (written as ``theta_rad`` in ``truth.csv``) is the block's
  counter-clockwise angle as seen by the camera, the tracker's convention.
  :func:`rocklab.models.simulate`'s ``theta`` is positive when the block tips
  towards ``+x`` (clockwise here) under a base acceleration along ``+x``, so
  ``phi = -theta_sim`` with the table's world-frame acceleration as the
  simulator's base motion.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._errors import InputError

__all__ = ["TableProgram", "sine_pulse_table", "record_table", "still_table", "BlockMotion"]

_SINE_PEAK = 0.6495190525534192  # max |(sin x - sin 2x / 2) / 2| on [0, 2 pi]


@dataclass(frozen=True)
class TableProgram:
    """A prescribed horizontal table displacement ``u(t)`` (m) with consistent ``v``, ``a``: the
    motion a simulated session drives the table with (a measured one is
    :class:`rocklab.series.TableMotion`).

    Attributes
    ----------
    kind : {"none", "sine", "record"}
    start_s : float
        Time the motion starts (the table is at rest before), s.
    info : dict
        Parameters for ``session.json`` (period, amplitude, record, scale...).
    """

    kind: str
    start_s: float
    info: dict
    _spline: object = None
    _period_s: float = 0.0
    _amp_m: float = 0.0

    def _eval(self, t, d: int):
        t = np.asarray(t, float)
        if self.kind == "none":
            return np.zeros_like(t)
        tau = t - self.start_s
        if self.kind == "sine":
            # u = A' sin(w tau) sin^2(w tau / 2): one cycle whose displacement, velocity and
            # acceleration all start and end at 0 (a table cannot jump in velocity).
            w = 2 * math.pi / self._period_s
            x = w * np.clip(tau, 0.0, self._period_s)
            A = self._amp_m / _SINE_PEAK
            f = [
                (np.sin(x) - np.sin(2 * x) / 2) / 2,
                w * (np.cos(x) - np.cos(2 * x)) / 2,
                w * w * (-np.sin(x) + 2 * np.sin(2 * x)) / 2,
            ][d]
            out = A * f
            if d > 0:
                out = np.where((tau < 0) | (tau > self._period_s), 0.0, out)
            return out
        sp = self._spline
        tt = np.clip(tau, sp.x[0], sp.x[-1])
        out = sp(tt, d)
        if d > 0:
            out = np.where((tau < sp.x[0]) | (tau > sp.x[-1]), 0.0, out)
        return out

    def u(self, t):
        """Displacement, m."""
        return self._eval(t, 0)

    def v(self, t):
        """Velocity, m/s."""
        return self._eval(t, 1)

    def a(self, t):
        """Acceleration, m/s^2."""
        return self._eval(t, 2)

    @property
    def end_s(self) -> float:
        if self.kind == "none":
            return self.start_s
        if self.kind == "sine":
            return self.start_s + self._period_s
        return self.start_s + float(self._spline.x[-1])

    def base_motion(self, t_end_s: float, dt_s: float = 5e-4):
        """The table acceleration as a :class:`~rocklab.series.BaseMotion` from t = 0 (None when still).

        For records the knots are the record's own samples: the cubic spline's
        second derivative is linear between knots, exactly what the simulator's
        linear interpolation of the base record reproduces.
        """
        from ..series import BaseMotion

        if self.kind == "none":
            return None
        if self.kind == "record":
            sp = self._spline
            dt = float(sp.x[1] - sp.x[0])
            n0 = int(round(self.start_s / dt))
            if abs(n0 * dt - self.start_s) > 1e-9:
                raise AssertionError("record start must sit on the record grid")
            t = dt * np.arange(int(math.ceil(t_end_s / dt)) + 1)
            return BaseMotion(t, self.a(t), name=self.info.get("record", "record"), source="synth")
        t = dt_s * np.arange(int(math.ceil(t_end_s / dt_s)) + 1)
        return BaseMotion(t, self.a(t), name="sine-pulse", source="synth")


def still_table() -> TableProgram:
    return TableProgram("none", 0.0, {"kind": "none"})


def sine_pulse_table(start_s: float, period_s: float = 0.6, amplitude_m: float = 0.045) -> TableProgram:
    """One smooth sine cycle (thesis §4.3, Fig. 31: period 0.6 s, amplitude 45 mm).

    ``u(t) = A' sin(w t) sin^2(w t / 2)`` on one period, scaled so that
    ``max |u| = amplitude_m``; velocity and acceleration are zero at both ends
    (peak acceleration ~2.1 ``amplitude w^2``: 10.4 m/s^2 for the default).
    """
    for name, v in (("table period_s", period_s), ("table amplitude_m", amplitude_m)):
        if not (math.isfinite(v) and v > 0):
            raise InputError(f"{name}={v!r}: must be positive")
    w = 2 * math.pi / period_s
    return TableProgram(
        "sine",
        float(start_s),
        {
            "kind": "sine",
            "start_s": float(start_s),
            "period_s": float(period_s),
            "amplitude_m": float(amplitude_m),
            "formula": "u = A/0.6495 * (sin x - sin 2x / 2) / 2, x = 2 pi (t - start_s) / period_s, 0 <= x <= 2 pi",
            "peak_acc_m_s2": float(amplitude_m / _SINE_PEAK * w * w * 1.3679075505129872),
        },
        None,
        float(period_s),
        float(amplitude_m),
    )


def record_table(
    base, start_s: float, length_s: float, stroke_m: float, target_pga_m_s2: float, name: str = "record"
) -> TableProgram:
    """A ground-motion record made playable by a table of limited stroke.

    As shake-table labs do: the record (a :class:`~rocklab.series.BaseMotion`)
    is cut to ``length_s``, scaled to ``target_pga_m_s2``, high-pass filtered
    (4th-order Butterworth, zero phase) with the lowest corner frequency that
    keeps the doubly integrated displacement within ``stroke_m``, and tapered
    (1 s half-cosines) so the table starts and ends at rest. The table then
    follows the cubic spline through the displacement samples; ``v`` and ``a``
    are its derivatives (``a`` is what the blocks feel, consistent with ``u``).
    """
    from scipy.interpolate import CubicSpline
    from scipy.signal import butter, sosfiltfilt

    dt = base.dt_s
    if not (stroke_m > 0 and target_pga_m_s2 > 0):
        raise InputError(f"record table: stroke_m={stroke_m!r} and target PGA must be positive")
    n = int(min(len(base.acc_m_s2), round(length_s / dt) + 1))
    if n < 50:
        raise InputError(f"record {name}: only {n} samples in {length_s} s; give a longer duration")
    a = np.asarray(base.acc_m_s2[:n], float)
    a = a * (target_pga_m_s2 / max(np.max(np.abs(a)), 1e-12))
    t = dt * np.arange(n)
    taper = np.ones(n)
    k = min(n // 4, int(round(1.0 / dt)))
    ramp = 0.5 - 0.5 * np.cos(np.pi * np.arange(k) / k)
    taper[:k], taper[n - k :] = ramp, ramp[::-1]
    fc, u = None, None
    for fc in (0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.7, 1.0, 1.4, 2.0, 2.8, 4.0):
        sos = butter(4, fc, btype="highpass", fs=1.0 / dt, output="sos")
        af = sosfiltfilt(sos, a * taper)
        v = np.concatenate(([0.0], np.cumsum(0.5 * (af[1:] + af[:-1]) * dt)))
        u = np.concatenate(([0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * dt)))
        u = (u - np.polyval(np.polyfit(t, u, 1), t)) * taper
        if np.max(np.abs(u)) <= stroke_m:
            break
    scale = min(1.0, stroke_m / np.max(np.abs(u)))
    u = u * scale
    sp = CubicSpline(t, u, bc_type="clamped")
    info = {
        "kind": "record",
        "record": name,
        "start_s": float(start_s),
        "length_s": float(t[-1]),
        "dt_s": dt,
        "stroke_m": float(stroke_m),
        "highpass_hz": float(fc),
        "target_pga_m_s2": float(target_pga_m_s2),
        "pga_m_s2": float(np.max(np.abs(sp(t, 2)))),
        "max_abs_u_m": float(np.max(np.abs(u))),
        "processing": "cut, scaled to target PGA, 4th-order zero-phase Butterworth high-pass "
        "at highpass_hz, 1 s cosine tapers, double integration, linear detrend; "
        "table = clamped cubic spline through u",
    }
    start = round(start_s / dt) * dt
    return TableProgram("record", float(start), info, sp)


@dataclass(frozen=True)
class BlockMotion:
    """One block's rocking on the table: true pose at any time.

    Attributes
    ----------
    id : str
    b_m, h_m : float
    x0_m : float
        World x of the block's bottom centre at rest with the table at u = 0, m.
    t_s, phi_rad : ndarray
        Fine time grid (s) and counter-clockwise angle (rad, ``-theta_sim``).
    release_s : float or None
        Thread-burn release time (free rocking), s.
    """

    id: str
    b_m: float
    h_m: float
    x0_m: float
    t_s: np.ndarray
    phi_rad: np.ndarray
    table: TableProgram
    release_s: float | None = None

    def phi(self, t):
        return np.interp(np.asarray(t, float), self.t_s, self.phi_rad)

    def pose(self, t):
        """Body origin (bottom centre of the face) ``(ox, oy)`` m and ``phi`` rad at ``t``.

        The block pivots on its left bottom corner when ``phi > 0``, on the
        right one when ``phi < 0`` (no sliding, no bouncing).
        """
        t = np.asarray(t, float)
        phi = self.phi(t)
        sg = np.where(phi >= 0, 1.0, -1.0)
        half = self.b_m / 2
        ox = self.x0_m + self.table.u(t) - sg * half * (1 - np.cos(phi))
        oy = half * np.abs(np.sin(phi))
        return ox, oy, phi

    def centre(self, t):
        """Centre of the front face, world ``(x, y)`` m."""
        ox, oy, phi = self.pose(t)
        r = self.h_m / 2
        return ox - r * np.sin(phi), oy + r * np.cos(phi)
