"""Opening/closing sequences of a column: from block angles, and their comparison.

For the shake-table validation (thesis §4.3): which joint opens, in which
direction, and when — measured (tracked block angles) against simulated. Apply
:func:`joint_sequence` with the SAME threshold to both the measured and the
simulated block angles, then :func:`compare_sequences`.

Signs: block angles clockwise positive (the convention of
:func:`rocklab.models.simulate_column`); pass ``sign=-1`` for counter-clockwise data.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._errors import InputError

__all__ = ["joint_sequence", "compare_sequences", "SequenceComparison", "compare_to_measurement", "ColumnComparison"]

#: Event times read on a frame grid (``i / fps``) differ by whole frames only up to rounding: at 50 fps
#: 0.80 - 0.78 = 0.020000000000000018 s. A match allows this much over the tolerance, s, so that a
#: tolerance of one frame matches events one frame apart whatever their place on the grid.
_ROUNDING_S = 1e-9


def joint_sequence(
    t_s, theta_rad, threshold_rad: float = 0.005, *, base_theta_rad=None, sign: float = 1.0, min_duration_s: float = 0.0
) -> list[tuple[float, int, str]]:
    """Configuration changes ``(t_s, joint, state)`` from absolute block angles.

    Parameters
    ----------
    t_s : array (m,)
        Sample times, s (NaN rows of ``theta_rad`` are skipped).
    theta_rad : array (m, n)
        Absolute block angles, bottom block first, rad.
    threshold_rad : float
        A joint is open when its relative rotation ``|θ_j - θ_{j-1}|`` exceeds
        this (rad) and closes again below half of it (hysteresis against noise).
    base_theta_rad : array (m,), optional
        Angle of the base (e.g. the tracked table), subtracted from block 0.
    sign : float
        -1 for counter-clockwise-positive angles.
    min_duration_s : float
        Ignore states that last shorter than this, s (debounce).

    Returns
    -------
    list of (t_s, joint, state)
        ``state`` in ``closed | cw | ccw``; the time is the first sample in the
        new state. Joints are numbered from the base (joint 0 under block 0).
    """
    t = np.asarray(t_s, float).ravel()
    th = np.asarray(theta_rad, float)
    if th.ndim == 1:
        th = th[:, None]
    if th.ndim != 2 or th.shape[0] != t.size:
        raise InputError(f"theta_rad has shape {th.shape} for {t.size} times; give (n_samples, n_blocks)")
    if not threshold_rad > 0:
        raise InputError(f"threshold_rad={threshold_rad!r}: must be positive (rad)")
    th = sign * th
    if base_theta_rad is not None:
        th = th - sign * np.asarray(base_theta_rad, float).reshape(-1, 1)
    phi = np.diff(np.concatenate([np.zeros((th.shape[0], 1)), th], axis=1), axis=1)
    out = []
    for j in range(phi.shape[1]):
        state = "closed"
        cand = None  # (t, state) waiting for its minimum duration
        for k in range(t.size):
            x = phi[k, j]
            if not np.isfinite(x):
                continue
            if state == "closed":
                new = "cw" if x > threshold_rad else ("ccw" if x < -threshold_rad else "closed")
            elif state == "cw":
                new = "cw" if x > threshold_rad / 2 else ("ccw" if x < -threshold_rad else "closed")
            else:
                new = "ccw" if x < -threshold_rad / 2 else ("cw" if x > threshold_rad else "closed")
            if cand is not None and new != cand[1]:
                cand = None if new == state else (t[k], new)
            elif cand is None and new != state:
                cand = (t[k], new)
            if cand is not None and t[k] - cand[0] >= min_duration_s:
                out.append((float(cand[0]), j, cand[1]))
                state = cand[1]
                cand = None
    out.sort(key=lambda e: (e[0], e[1]))
    return out


@dataclass(frozen=True)
class SequenceComparison:
    """Agreement of two opening/closing sequences.

    Attributes
    ----------
    n_measured, n_simulated, n_matched : int
        Events in each sequence, and events matched in order (same joint and
        state, times within ``tol_s``; longest common subsequence).
    pairs : list of (t_measured_s, t_simulated_s, joint, state)
    timing_error_s : float
        Median |t_measured - t_simulated| of the matched events, s (nan if none).
    same_sequence : bool
        Every event of both sequences matched.
    tol_s : float
    """

    n_measured: int
    n_simulated: int
    n_matched: int
    pairs: list
    timing_error_s: float
    same_sequence: bool
    tol_s: float

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        return {
            "n_measured": self.n_measured,
            "n_simulated": self.n_simulated,
            "n_matched": self.n_matched,
            "timing_error_s": self.timing_error_s,
            "same_sequence": self.same_sequence,
            "tol_s": self.tol_s,
            "pairs": [list(p) for p in self.pairs],
        }


def compare_sequences(measured, simulated, tol_s: float = 0.05, t_max_s: float | None = None) -> SequenceComparison:
    """Match two sequences of ``(t_s, joint, state)`` in order (LCS with a time tolerance).

    Parameters
    ----------
    measured, simulated : list of (t_s, joint, state)
        E.g. from :func:`joint_sequence`.
    tol_s : float
        Largest time difference of matched events, s (up to float rounding: events one frame
        apart on a frame grid match a tolerance of one frame).
    t_max_s : float, optional
        Compare only events before this time, s.
    """
    if not tol_s > 0:
        raise InputError(f"tol_s={tol_s!r}: time tolerance must be positive (s)")
    lim = tol_s + _ROUNDING_S
    a = [e for e in measured if t_max_s is None or e[0] <= t_max_s]
    b = [e for e in simulated if t_max_s is None or e[0] <= t_max_s]
    na, nb = len(a), len(b)
    L = np.zeros((na + 1, nb + 1), int)
    for i in range(na - 1, -1, -1):
        for k in range(nb - 1, -1, -1):
            ok = a[i][1] == b[k][1] and a[i][2] == b[k][2] and abs(a[i][0] - b[k][0]) <= lim
            L[i, k] = L[i + 1, k + 1] + 1 if ok else max(L[i + 1, k], L[i, k + 1])
    pairs = []
    i = k = 0
    while i < na and k < nb:
        ok = a[i][1] == b[k][1] and a[i][2] == b[k][2] and abs(a[i][0] - b[k][0]) <= lim
        if ok and L[i, k] == L[i + 1, k + 1] + 1:
            pairs.append((float(a[i][0]), float(b[k][0]), int(a[i][1]), str(a[i][2])))
            i += 1
            k += 1
        elif L[i + 1, k] >= L[i, k + 1]:
            i += 1
        else:
            k += 1
    err = float(np.median([abs(p[0] - p[1]) for p in pairs])) if pairs else float("nan")
    return SequenceComparison(na, nb, len(pairs), pairs, err, len(pairs) == na == nb, float(tol_s))


@dataclass(frozen=True)
class ColumnComparison:
    """A simulated column response against measured block angles.

    Attributes
    ----------
    sequence : SequenceComparison
        Opening/closing sequences matched in order (both read with the same threshold).
    measured_sequence, simulated_sequence : list of (t_s, joint, state)
    rms_theta_rad : ndarray (n,)
        RMS of measured minus simulated block angle at the measured times, rad.
    peak_measured_rad, peak_simulated_rad : ndarray (n,)
        Peak |block angle| over the compared time span, rad.
    """

    sequence: SequenceComparison
    measured_sequence: list
    simulated_sequence: list
    rms_theta_rad: np.ndarray
    peak_measured_rad: np.ndarray
    peak_simulated_rad: np.ndarray

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        return {
            "sequence": self.sequence.to_dict(),
            "measured_sequence": [list(e) for e in self.measured_sequence],
            "simulated_sequence": [list(e) for e in self.simulated_sequence],
            "rms_theta_rad": self.rms_theta_rad.tolist(),
            "peak_measured_rad": self.peak_measured_rad.tolist(),
            "peak_simulated_rad": self.peak_simulated_rad.tolist(),
        }


def compare_to_measurement(
    result,
    t_s,
    theta_rad,
    *,
    threshold_rad: float = 0.005,
    tol_s: float = 0.05,
    sign: float = 1.0,
    base_theta_rad=None,
    min_duration_s: float = 0.0,
) -> ColumnComparison:
    """Compare a :class:`ColumnResult` with tracked block angles (thesis §4.3, Fig. 32).

    Parameters
    ----------
    result : ColumnResult
        Simulation driven by the measured base acceleration, on the measured time axis.
    t_s : array (m,)
        Measured sample times, s (same origin as the simulation).
    theta_rad : array (m, n)
        Measured absolute block angles, bottom first, rad (NaN where tracking failed).
    threshold_rad, min_duration_s, sign, base_theta_rad
        As :func:`joint_sequence` (applied to both histories; ``sign``/``base``
        only to the measurement).
    tol_s : float
        Time tolerance of matched events, s.
    """
    t = np.asarray(t_s, float).ravel()
    th = sign * np.asarray(theta_rad, float).reshape(t.size, -1)
    if base_theta_rad is not None:
        th = th - sign * np.asarray(base_theta_rad, float).reshape(-1, 1)
    n = result.column.n
    if th.shape[1] != n:
        raise InputError(f"theta_rad has {th.shape[1]} columns for a column of {n} blocks")
    inside = (t >= result.t_s[0]) & (t <= result.t_s[-1])
    sim = np.column_stack([np.interp(t[inside], result.t_s, result.theta_rad[:, i]) for i in range(n)])
    meas = th[inside]
    diff = meas - sim
    ok = np.isfinite(diff)
    rms = np.sqrt(np.array([np.mean(diff[ok[:, i], i] ** 2) if ok[:, i].any() else np.nan for i in range(n)]))
    mseq = joint_sequence(t[inside], meas, threshold_rad, min_duration_s=min_duration_s)
    sseq = result.joint_sequence(threshold_rad, min_duration_s=min_duration_s)
    t_max = float(t[inside][-1]) if inside.any() else None
    comp = compare_sequences(mseq, sseq, tol_s=tol_s, t_max_s=t_max)
    peak_m = np.array([np.max(np.abs(meas[ok[:, i], i])) if ok[:, i].any() else np.nan for i in range(n)])
    return ColumnComparison(
        comp, mseq, [e for e in sseq if t_max is None or e[0] <= t_max], rms, peak_m, np.max(np.abs(sim), axis=0)
    )
