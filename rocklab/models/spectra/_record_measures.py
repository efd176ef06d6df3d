"""Ground-motion measures of a record, by eqsig: PGA/PGV/PGD, Arias intensity, significant duration,
the velocity-pulse period, and the pseudo-acceleration response spectrum.

The near-field study of the thesis sorts records by their velocity pulse; these are the standard
measures a lab reports beside t_p and t_I. eqsig (MIT, numpy and scipy only) does the signal work;
rocklab chooses the baseline correction and the units and states them.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ..._errors import InputError
from ...series import BaseMotion

__all__ = ["RecordMeasures", "record_measures", "response_spectrum"]

#: Degree of the polynomial removed from the acceleration before integrating (a linear baseline:
#: a constant offset or a slow drift of the sensor would otherwise grow into metres of displacement).
BASELINE_POLY = 1


@dataclass(frozen=True)
class RecordMeasures:
    """Ground-motion measures of one record (SI).

    Attributes
    ----------
    name : str
    pga_m_s2 : float
        Peak |acceleration|, m/s^2.
    pgv_m_s, pgd_m : float
        Peak |velocity| and |displacement| after removing a degree-``baseline_poly`` polynomial
        from the acceleration, m/s and m.
    arias_m_s : float
        Arias intensity pi/(2 g) * integral of a^2 dt, m/s.
    d5_95_s : float
        Significant duration, 5-95 % of the Arias intensity (Trifunac & Brady 1975), s.
    t_v_s : float
        Velocity-pulse period: the period of the largest 15 %-damped pseudo-velocity response over
        0.1-10 s (as eqsig's ``calc_max_velocity_period``, which stops at 2 s), s; NaN when the
        largest response is at either end of that range (the pulse is outside it).
    baseline_poly : int
    """

    name: str
    pga_m_s2: float
    pgv_m_s: float
    pgd_m: float
    arias_m_s: float
    d5_95_s: float
    t_v_s: float
    baseline_poly: int = BASELINE_POLY

    def to_dict(self) -> dict:
        return asdict(self)


def _asig(base: BaseMotion, poly: int):
    import eqsig

    if not isinstance(base, BaseMotion):
        raise InputError(f"base={type(base).__name__}: expected a BaseMotion; read the record with load_base_motion")
    sig = eqsig.AccSignal(np.asarray(base.acc_m_s2, float).copy(), float(base.dt_s))
    if poly >= 0:
        sig.remove_poly(poly_fit=poly)
    return sig


def record_measures(base: BaseMotion, baseline_poly: int = BASELINE_POLY) -> RecordMeasures:
    """PGA, PGV, PGD, Arias intensity, D5-95 and the velocity-pulse period of ``base``.

    Parameters
    ----------
    base : BaseMotion
        The record, m/s^2.
    baseline_poly : int
        Degree of the polynomial removed from the acceleration before integrating (-1: none).
    """
    from eqsig import im

    sig = _asig(base, baseline_poly)
    arias = float(np.asarray(im.calc_arias_intensity(sig))[-1])
    d = im.calc_sig_dur_vals(sig.values, sig.dt, start=0.05, end=0.95)
    return RecordMeasures(
        name=base.name,
        pga_m_s2=float(np.max(np.abs(base.acc_m_s2))),
        pgv_m_s=float(np.max(np.abs(sig.velocity))),
        pgd_m=float(np.max(np.abs(sig.displacement))),
        arias_m_s=arias,
        d5_95_s=float(d),
        t_v_s=_velocity_pulse_period(base),
        baseline_poly=int(baseline_poly),
    )


#: Periods searched for the velocity pulse, s.
TV_PERIODS_S = np.logspace(-1, 1, 161)


def _velocity_pulse_period(base: BaseMotion) -> float:
    T = TV_PERIODS_S
    sv = response_spectrum(base, T, damping=0.15) * T / (2 * np.pi)
    k = int(np.argmax(sv))
    return float("nan") if k in (0, T.size - 1) else float(T[k])


def response_spectrum(base: BaseMotion, periods_s, damping: float = 0.05):
    """Pseudo-acceleration response spectrum of ``base`` (eqsig's SDOF integration).

    Parameters
    ----------
    base : BaseMotion
    periods_s : array_like, shape (n,)
        Oscillator periods, s (> 0).
    damping : float
        Damping ratio (0.05 = 5 %).

    Returns
    -------
    ndarray, shape (n,)
        Pseudo-spectral acceleration, m/s^2.
    """
    T = np.asarray(periods_s, float).ravel()
    if T.size == 0 or not np.all(T > 0):
        raise InputError("periods_s: give one or more oscillator periods > 0 s")
    if not 0.0 <= float(damping) < 1.0:
        raise InputError(f"damping={damping!r}: a damping ratio in [0, 1), e.g. 0.05")
    sig = _asig(base, -1)
    sig.generate_response_spectrum(response_times=T, xi=float(damping))
    return np.asarray(sig.s_a, float)
