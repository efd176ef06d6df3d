"""Pulse parameters of a record and simple acceleration pulses (Ther thesis §5.1.2, §5.3.5).

A record's main pulse is summarised by the peak acceleration ``a_max``, the
largest single-lobe impulse ``I_max`` (the area of the acceleration between two
consecutive zero crossings, thesis Fig. 52) and the duration of the
*replacement sine lobe* with the same peak and area, Eq. 25:
``t_p = I_max / (F a_max)`` with the fullness of a half sine ``F = 2/pi``.

Simple pulses (half sine, full sine, n half sines, rectangular, triangular,
cycloidal) are given as functions of time normalised to a peak of 1; all use
``t_p`` = the duration of one lobe (half cycle), see :func:`pulse_shape`.
Units: s, m/s^2, m/s inside; records in g are converted by the reader.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ..._errors import InputError
from ...series import BaseMotion
from ._records import MIN_SAMPLES

__all__ = [
    "PulseParameters",
    "pulse_parameters",
    "lobe_impulses",
    "pulse_shape",
    "pulse_motion",
    "PULSE_KINDS",
    "F_SINE",
    "pulse_fullness",
]

#: Fullness I/(a_p t_p) of a half-sine lobe, 2/pi (thesis Eq. 16, 25: "F = 0.64").
F_SINE = 2.0 / math.pi

#: Pulse kinds known to :func:`pulse_shape`.
PULSE_KINDS = ("half-sine", "full-sine", "n-half-sines", "rectangular", "triangular", "cycloidal-a", "cycloidal-b")


def check_record(base: BaseMotion) -> BaseMotion:
    if not isinstance(base, BaseMotion):
        raise InputError(
            f"base={type(base).__name__}: expected a BaseMotion; read the record with rocklab.models.load_base_motion"
        )
    # BaseMotion already rejects gaps, non-uniform dt and < 2 samples; an all-zero record has no pulse.
    src = f"{base.source}: " if base.source != "array" else ""
    if base.t_s.size < MIN_SAMPLES:
        raise InputError(
            f"{src}record has {base.t_s.size} samples; pulse and spectrum analysis needs at "
            f"least {MIN_SAMPLES}; check the file was read whole"
        )
    if base.pga_m_s2 == 0.0:
        raise InputError(f"{src}record is all zeros; it has no pulse (check the file or its units)")
    return base


def lobe_impulses(acc, dt_s: float):
    """Signed impulses of every single-signed lobe of a sampled acceleration.

    The record is taken as piecewise linear between samples; a lobe runs from
    one zero crossing (located by linear interpolation) to the next, and its
    impulse is the exact integral of that polyline (trapezoids split at the
    crossings).

    Parameters
    ----------
    acc : array_like, shape (n,)
        Acceleration samples, any unit u (the impulse comes out in u*s).
    dt_s : float
        Sample spacing, s.

    Returns
    -------
    impulse : ndarray, shape (k,)
        Signed area of each lobe, u*s.
    t_start_s, t_end_s : ndarray, shape (k,)
        Lobe boundaries, s from the first sample.
    """
    a = np.asarray(acc, float)
    n = a.size
    a0, a1 = a[:-1], a[1:]
    # Lobe boundaries: a sign change inside an interval (located by linear interpolation) or a
    # sample that is exactly zero (a sampled sine has them at its crossings; a plateau of zeros
    # is a run of them). Testing a0*a1 < 0 alone would merge the lobes on both sides of a zero.
    cross = (a0 * a1) < 0
    zero = a == 0.0
    frac = np.where(cross, a0 / np.where(cross, a0 - a1, 1.0), 0.0)
    full = 0.5 * (a0 + a1) * dt_s
    before = np.where(cross, 0.5 * a0 * frac * dt_s, full)
    after = np.where(cross, 0.5 * a1 * (1 - frac) * dt_s, 0.0)
    # boundaries in order of position: a zero sample i sits at i, a crossing in interval i at i+frac
    zpos = np.flatnonzero(zero).astype(float)
    cpos = np.flatnonzero(cross) + frac[cross]
    bpos = np.sort(np.concatenate((zpos, cpos)))
    # lobe of an interval's first part: boundaries at or before its start (zero samples at i count)
    n_before = np.searchsorted(bpos, np.arange(n - 1), side="right")
    k = bpos.size + 1
    imp = np.zeros(k)
    np.add.at(imp, n_before, before)
    np.add.at(imp, n_before[cross] + 1, after[cross])
    t_start = np.concatenate(([0.0], bpos * dt_s))
    t_end = np.concatenate((bpos * dt_s, [(n - 1) * dt_s]))
    return imp, t_start, t_end


@dataclass(frozen=True)
class PulseParameters:
    """Main-pulse parameters of a record (thesis Eq. 16, 25).

    Attributes
    ----------
    a_max_m_s2 : float
        Peak absolute base acceleration, m/s^2.
    I_max_m_s : float
        Largest absolute single-lobe impulse (area between two zero crossings), m/s.
    t_p_s : float
        Replacement half-sine duration I_max / (F a_max), F = 2/pi, s.
    fullness : float
        Fullness of the I_max lobe itself, I_max / (a_lobe t_lobe) (1 = rectangle, 2/pi = sine).
    lobe_start_s, lobe_end_s : float
        Boundaries of the I_max lobe, s from the record start.
    lobe_peak_m_s2 : float
        Peak absolute acceleration inside the I_max lobe, m/s^2.
    t_amax_s : float
        Time of the peak acceleration, s.
    F : float
        Fullness used for t_p (2/pi).
    name : str
        Record label.
    """

    a_max_m_s2: float
    I_max_m_s: float
    t_p_s: float
    fullness: float
    lobe_start_s: float
    lobe_end_s: float
    lobe_peak_m_s2: float
    t_amax_s: float
    F: float
    name: str = ""

    def to_dict(self) -> dict:
        """Plain dict (SI units in the keys)."""
        return asdict(self)


def pulse_parameters(base: BaseMotion, F: float = F_SINE) -> PulseParameters:
    """a_max, I_max, lobe fullness and the replacement duration t_p of a record.

    Parameters
    ----------
    base : BaseMotion
        The record (SI units; uniform grid is guaranteed by BaseMotion).
    F : float
        Fullness of the replacement pulse; the thesis uses a half sine, 2/pi.

    Returns
    -------
    PulseParameters
    """
    base = check_record(base)
    if not (math.isfinite(F) and 0 < F <= 1):
        raise InputError(f"F={F!r}: fullness must be in (0, 1]; a half sine has 2/pi")
    a = base.acc_m_s2
    imp, ts, te = lobe_impulses(a, base.dt_s)
    j = int(np.argmax(np.abs(imp)))
    i_max = float(abs(imp[j]))
    a_max = base.pga_m_s2
    t0 = base.t_s[0]
    i0 = int(math.floor(ts[j] / base.dt_s + 1e-9))
    i1 = int(math.ceil(te[j] / base.dt_s - 1e-9))
    seg = a[i0 : i1 + 1]
    lobe_peak = float(np.max(np.abs(seg)))
    # zero samples at the lobe's ends (quiet record parts, padding) are not part of its duration
    nz = np.flatnonzero(seg != 0)
    t_lo = max(ts[j], (i0 + nz[0] - 1) * base.dt_s)
    t_hi = min(te[j], (i0 + nz[-1] + 1) * base.dt_s)
    ts[j], te[j] = t_lo, t_hi
    dur = t_hi - t_lo
    if i_max / (F * a_max) < 2.0 * base.dt_s:
        from ..._diagnostics import warn

        warn(
            "W-RECORD-PULSE",
            f"{base.name}: main pulse t_p = {i_max / (F * a_max):.4g} s is shorter than 2 "
            f"samples (dt = {base.dt_s:.4g} s); t_I and spectra from it are unreliable",
        )
    return PulseParameters(
        a_max_m_s2=a_max,
        I_max_m_s=i_max,
        t_p_s=i_max / (F * a_max),
        fullness=i_max / (lobe_peak * dur) if dur > 0 else float("nan"),
        lobe_start_s=float(t0 + ts[j]),
        lobe_end_s=float(t0 + te[j]),
        lobe_peak_m_s2=lobe_peak,
        t_amax_s=float(base.t_s[int(np.argmax(np.abs(a)))]),
        F=float(F),
        name=base.name,
    )


# -- simple pulses -------------------------------------------------------------


def _kind(kind: str) -> str:
    k = str(kind).strip().lower().replace("_", "-")
    k = {
        "half": "half-sine",
        "sine": "full-sine",
        "full": "full-sine",
        "rect": "rectangular",
        "tri": "triangular",
        "cycloidal": "cycloidal-a",
        "n-half": "n-half-sines",
    }.get(k, k)
    if k not in PULSE_KINDS:
        raise InputError(f"pulse kind {kind!r}: unknown; use one of {', '.join(PULSE_KINDS)}")
    return k


def pulse_duration(kind: str, t_p_s: float, n: int = 1) -> float:
    """Total duration (s) of a pulse of lobe duration ``t_p_s``."""
    k = _kind(kind)
    if k == "full-sine" or k.startswith("cycloidal"):
        return 2.0 * t_p_s
    if k == "n-half-sines":
        return n * t_p_s
    return t_p_s


def pulse_fullness(kind: str) -> float:
    """Fullness I/(a_p t_p) of the first lobe of a pulse kind (Eq. 16)."""
    k = _kind(kind)
    return {"rectangular": 1.0, "triangular": 0.5, "cycloidal-b": F_SINE}.get(k, F_SINE)


def pulse_shape(kind: str, t_s, t_p_s: float, n: int = 1) -> np.ndarray:
    """Normalised acceleration (peak 1) of a simple pulse at times ``t_s`` (s).

    Parameters
    ----------
    kind : str
        ``half-sine`` (one lobe), ``full-sine`` (one sine cycle, = Zhang & Makris
        type-A cycloidal pulse ``cycloidal-a``), ``n-half-sines`` (``n``
        alternating lobes), ``rectangular``, ``triangular`` (symmetric, peak at
        mid-lobe), ``cycloidal-b`` (one cosine cycle, Zhang & Makris type B).
    t_s : array_like
        Times from the pulse start, s; the pulse is 0 outside its duration.
    t_p_s : float
        Duration of one lobe (half cycle), s. Cycloidal pulses have period 2 t_p.
    n : int
        Number of lobes for ``n-half-sines``.

    Returns
    -------
    ndarray, shape like ``t_s``
        The sign of the first lobe is positive.
    """
    k = _kind(kind)
    if not (math.isfinite(t_p_s) and t_p_s > 0):
        raise InputError(f"t_p_s={t_p_s!r}: pulse duration must be positive (s)")
    if k == "n-half-sines" and (int(n) != n or n < 1):
        raise InputError(f"n={n!r}: number of half sines must be a positive integer")
    t = np.asarray(t_s, float)
    x = t / t_p_s
    inside = (x >= 0) & (x <= pulse_duration(k, 1.0, int(n)))
    if k in ("half-sine", "full-sine", "n-half-sines", "cycloidal-a"):
        y = np.sin(np.pi * x)
    elif k == "cycloidal-b":
        y = np.cos(np.pi * x)
    elif k == "rectangular":
        y = np.ones_like(x)
    else:  # triangular
        y = 1.0 - np.abs(2.0 * x - 1.0)
    return np.where(inside, y, 0.0)


def pulse_motion(
    kind: str, t_p_s: float, a_p_m_s2: float, n: int = 1, dt_s: float | None = None, pad_s: float = 0.0
) -> BaseMotion:
    """A simple pulse as a :class:`BaseMotion` (peak ``a_p_m_s2``, m/s^2).

    ``dt_s`` defaults to t_p/200; ``pad_s`` seconds of zeros are appended.
    """
    dur = pulse_duration(kind, t_p_s, n)
    dt = t_p_s / 200.0 if dt_s is None else float(dt_s)
    t = np.arange(int(math.ceil((dur + pad_s) / dt)) + 1) * dt
    return BaseMotion(t, a_p_m_s2 * pulse_shape(kind, t, t_p_s, n), name=f"{_kind(kind)} t_p={t_p_s:g}s")
