"""Ensembles of column simulations and the verdict of a column model on its event sequence.

A column's response is judged by what the thesis compares (§4.2–4.3, Figs. 29 and 32): which
joint opens or closes, in which direction, and when. :func:`simulate_column_ensemble` runs ``n``
column simulations sampling what the run does not know exactly (:class:`InputUncertainty`: each
level's width and height, the start angle of each joint that starts open, and under a moving table its acceleration's
noise, bias, scale and clock, and a fused table's own error, :func:`rocklab.fitting.fused_error_draw`); :func:`judge_column` reads every member's opening/closing sequence
from its block angles exactly as the measured one is read (:func:`rocklab.models.joint_sequence`,
same threshold, same samples) and compares:

- each measured event's probability: the fraction of members with the same joint turning the
  same way within ``±tol_s`` (a ``closed`` state the joint leaves again within ``tol_s``, a pass
  through closed at an impact, is not an event) (matched in order, :func:`rocklab.models.compare_sequences`); an
  event is *matched* when at least half the members have it;
- the predictability horizon: the first time the members' 5–95 % spread of any level's angle
  passes :data:`HORIZON_FRACTION` of that block's α, or, when earlier, the time by which a quarter
  of the members have had an event that fewer than half the others share (a joint that barely opens makes
  the sequences diverge while the angles still agree); events after it are reported, not judged;
- an event inside the horizon is *missed* when fewer than :data:`MISSED_PROBABILITY` (5 %) of
  the members have it: the model hardly ever produces what was measured; the number of events
  inside the horizon is also ranked among the members' (two-sided rank p-value: a model that
  predicts openings the measurement lacks, or lacks some it has, fails here);
- ``score`` = the mean probability of the measured events inside the horizon (1: every member
  reproduces the whole measured sequence); ``inconsistent`` when two or more events inside the
  horizon are missed, the count's p-value is below 0.01 (one missed event alone may be a
  measurement's glitch), or fewer than :data:`COVERAGE_INCONSISTENT` of the measured samples lie
  inside the band (the true model held 0.89–1.0 on synthetic columns, a wrong impact count 0.19–0.65); ``consistent`` when every event inside the horizon is matched, at least
  two are (fewer decide nothing), the count's p-value is at least 0.05 and at least
  :data:`COVERAGE_CONSISTENT` of the measured samples lie inside the band (as for a single block:
  a model whose band misses the measurement has not been shown to agree with it, whatever its
  events); otherwise ``undecided``.
  ``band_coverage`` is the fraction of measured samples (every level) inside the 5–95 % band of
  the predicted measurement (member plus measurement noise); it is reported beside the verdict:
  after the horizon a chaotic column's band is a statement about statistics, not about θ(t).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ._ensemble import DEFAULT_ENSEMBLE_SIZE, HORIZON_FRACTION, InputUncertainty, finite_table, table_draw

__all__ = [
    "ColumnEnsemble",
    "ColumnVerdict",
    "simulate_column_ensemble",
    "judge_column",
    "EVENT_THRESHOLD_RAD",
    "MISSED_PROBABILITY",
    "COVERAGE_INCONSISTENT",
    "COVERAGE_CONSISTENT",
]

#: A joint counts as open when its relative rotation passes this (rad; closed again below half).
EVENT_THRESHOLD_RAD = 0.005
#: A measured event fewer than this fraction of the members reproduce is missed by the model.
MISSED_PROBABILITY = 0.05
#: A model whose band holds less than this fraction of the measured samples is inconsistent.
COVERAGE_INCONSISTENT = 0.5
#: A model is only called consistent when its band holds at least this fraction of the measured samples.
COVERAGE_CONSISTENT = 0.9
_P_INCONSISTENT, _P_CONSISTENT = 0.01, 0.05
#: Event times on the measured frame grid differ by whole frames only up to rounding (at 50 fps
#: 0.80 - 0.78 = 0.020000000000000018 s); the tolerance allows this much more, s (as
#: :func:`rocklab.models.compare_sequences` does).
_ROUNDING_S = 1e-9


@dataclass(frozen=True)
class ColumnEnsemble:
    """Members of a column ensemble on the measured time grid (clockwise-positive angles).

    Attributes
    ----------
    t_s : ndarray, (m,)
    theta_rad : ndarray, (n, m, L)
        Every member's block angles (held at their last value after the run ends), rad.
    sequences : list of list of (t_s, joint, state)
        Every member's opening/closing sequence read from its predicted measurement.
    overturned : ndarray of bool, (n,)
    band_rad : ndarray, (2, m, L)
        5 % and 95 % of the predicted measurement (member + offset + noise), rad.
    n_impacts : int
        Consecutive impacts per closing of the model (1 Housner, 2 one mid-joint bump).
    seconds : float
        Wall time of the simulations, s.
    """

    t_s: np.ndarray
    theta_rad: np.ndarray = field(repr=False)
    sequences: list = field(repr=False)
    overturned: np.ndarray = field(repr=False)
    band_rad: np.ndarray = field(repr=False)
    n_impacts: int = 1
    seconds: float = 0.0


def _member_base(table_t_s, table_acc_m_s2, unc, rng, t_start_s, table_sigma_m_s2=None):
    """One draw of the measured table acceleration as a BaseMotion on 1 ms (None without a table)."""
    if table_t_s is None:
        return None
    tt, aa, sg = finite_table(table_t_s, table_acc_m_s2, table_sigma_m_s2)
    return table_draw(tt, aa, unc, rng, t_start_s, sigma_m_s2=sg)


def _member_column(column, unc, rng):
    from ..blocks import Block
    from ..models import Column

    blocks = []
    for b in column.blocks:
        bm = b.b_m + unc.length_m * rng.standard_normal()
        hm = b.h_m + unc.length_m * rng.standard_normal()
        blocks.append(Block(bm, hm, depth_m=b.depth_m, mass_kg=b.mass_kg, alpha_I=b.alpha_I, name=b.name))
    return Column(tuple(blocks), cut_m=column.cut_m, mu=column.mu)


def _member_theta0(column, theta0_rad, unc, rng):
    """Start angles with their noise on the joints that start open (a closed joint is a block
    resting flat on the one below: it stays closed), each kept inside 0.99 of its block's α."""
    phi = np.diff(np.concatenate([[0.0], np.asarray(theta0_rad, float)]))
    phi = phi + np.where(phi != 0.0, unc.theta0_rad * rng.standard_normal(column.n), 0.0)
    lim = 0.99 * np.array([b.alpha_rad for b in column.blocks])
    return np.cumsum(np.clip(phi, -lim, lim))


def simulate_column_ensemble(
    column,
    t_out_s,
    *,
    theta0_rad,
    t_start_s: float,
    unc: InputUncertainty,
    table_t_s=None,
    table_acc_m_s2=None,
    n_impacts: int = 1,
    n: int = DEFAULT_ENSEMBLE_SIZE,
    dt_s: float = 1e-4,
    threshold_rad: float = EVENT_THRESHOLD_RAD,
    meas_offset_rad: float = 0.0,
    seed: int = 0,
    table_sigma_m_s2=None,
) -> ColumnEnsemble:
    """Simulate ``n`` members of a column run, sampling :class:`InputUncertainty`.

    Parameters
    ----------
    column : rocklab.models.Column
        The nominal column (each level's measured block, the cut).
    t_out_s : array_like, (m,)
        Times at which the angles are wanted (the measured samples), s.
    theta0_rad : array_like, (L,)
        Start angle of each level, clockwise positive (the simulator's sense), rad; ω = 0.
    t_start_s : float
        Start (release) time on the measurement's clock, s.
    unc : InputUncertainty
        ``length_m`` (each width and height), ``theta0_rad`` (each level's start angle),
        ``meas_noise_rad`` (band), and with a table its ``acc_*`` and ``sync_s``.
    table_t_s, table_acc_m_s2 : array_like, (k,), optional
        The measured table acceleration (s, m/s², positive to the right) on the measurement's
        clock; None: free rocking.
    n_impacts : int
        The model's consecutive impacts per closing.
    n : int
        Members.
    dt_s : float
        Simulator step, s.
    threshold_rad : float
        The joint-opening threshold the sequences are read with (as the measured one).
    meas_offset_rad : float
        Standard deviation of a constant offset of each level's measured angle, rad (an IMU's tilt
        anchored at rest, a camera's level): a joint that barely opens crosses the threshold or not
        depending on it, so the members' sequences are read from the predicted measurement (member
        plus one offset per level plus ``unc.meas_noise_rad`` white noise), as the measured one is.
    seed : int
        Same seed, same members.
    table_sigma_m_s2 : array_like, (k,), optional
        A fused table's per-sample σ (m/s²): its own error is drawn at ``unc.acc_fused`` times it
        (:func:`rocklab.fitting.fused_error_draw`).

    Returns
    -------
    ColumnEnsemble
    """
    from ..models import joint_sequence, simulate_column

    rng = np.random.default_rng(seed)
    t_out = np.asarray(t_out_s, float)
    L = column.n
    out = np.empty((n, t_out.size, L))
    over = np.zeros(n, bool)
    span = float(t_out[-1] - t_start_s)
    t0 = time.perf_counter()
    for i in range(n):
        base = _member_base(table_t_s, table_acc_m_s2, unc, rng, t_start_s, table_sigma_m_s2)
        col = _member_column(column, unc, rng)
        th0 = _member_theta0(col, theta0_rad, unc, rng)
        r = simulate_column(
            col, base, theta0_rad=th0, duration_s=max(span, 1e-3), dt_s=dt_s, n_impacts=n_impacts, output_dt_s=1e-3
        )
        th = np.asarray(r.theta_rad)
        for k in range(L):
            out[i, :, k] = np.interp(t_out - t_start_s, r.t_s, th[:, k], left=th0[k], right=th[-1, k])
        over[i] = r.status == "overturned"
    secs = time.perf_counter() - t0
    noisy = out + unc.meas_noise_rad * rng.standard_normal(out.shape)
    noisy += meas_offset_rad * rng.standard_normal((n, 1, L))
    seqs = [joint_sequence(t_out, noisy[i], threshold_rad) for i in range(n)]
    band = np.percentile(noisy, [5.0, 95.0], axis=0)
    return ColumnEnsemble(t_out, out, seqs, over, band, int(n_impacts), secs)


@dataclass(frozen=True)
class ColumnVerdict:
    """A column model judged on its event sequence by its ensemble (see the module doc).

    Attributes
    ----------
    verdict : str
        "consistent", "inconsistent" or "undecided".
    score : float
        Mean probability of the measured events inside the horizon (0–1; 1 when there are none).
    band_coverage : float
        Fraction of measured samples (every level) inside the 5–95 % band.
    horizon_s : float
        Predictability horizon on the measurement's clock (angles' spread or the members' event
        sequences diverging, the earlier), s.
    events : list of dict
        Per measured event: ``t_s, joint, state, probability`` (members with it within ±``tol_s``),
        ``matched`` (probability ≥ 0.5), ``inside_horizon``.
    tests : dict
        Test name → p-value (``n_events_inside``: the measured count's rank among the members').
    n_events_inside : int
        Measured events inside the horizon.
    n_matched_inside : int
    members_events_inside : dict
        ``p05, p50, p95`` of the members' event counts inside the horizon.
    overturning_probability : float
    tol_s : float
    n_impacts : int
    """

    verdict: str
    score: float
    band_coverage: float
    horizon_s: float
    events: list
    tests: dict
    n_events_inside: int
    n_matched_inside: int
    members_events_inside: dict
    overturning_probability: float
    tol_s: float
    n_impacts: int

    @property
    def all_matched_inside(self) -> bool:
        """Every measured event inside the horizon is matched."""
        return self.n_matched_inside == self.n_events_inside

    def to_dict(self) -> dict:
        return {
            "verdict": self.verdict,
            "score": float(self.score),
            "band_coverage": float(self.band_coverage),
            "horizon_s": float(self.horizon_s),
            "n_events_inside": int(self.n_events_inside),
            "n_matched_inside": int(self.n_matched_inside),
            "members_events_inside": self.members_events_inside,
            "events": self.events,
            "tests": {k: float(v) for k, v in self.tests.items()},
            "overturning_probability": float(self.overturning_probability),
            "tol_s": float(self.tol_s),
            "impacts_per_closing": int(self.n_impacts),
        }


def _rank_p(x, sample):
    """Two-sided rank p-value of x among the sample (ties split; +1 smoothing)."""
    s = np.asarray(sample, float)
    below = np.sum(s < x) + 0.5 * np.sum(s == x)
    above = s.size - below
    return float(min(1.0, 2.0 * min(below + 1, above + 1) / (s.size + 1)))


def _through_closed(seq, tol_s: float) -> list:
    """The sequence without the ``closed`` states a joint passes through at an impact (reopened
    within ``tol_s``): whether a sample falls inside the closed band during a sign change of a fast
    joint is a matter of the sampling's phase, not of the motion."""
    out = []
    for i, (t, j, st) in enumerate(seq):
        if st == "closed":
            nxt = next((e for e in seq[i + 1 :] if e[1] == j), None)
            if nxt is not None and nxt[0] - t <= tol_s:
                continue
        out.append((t, j, st))
    return out


def _event_horizon(seqs, tol_s: float) -> float:
    """The 25th percentile over members of the time of their first event that fewer than half the
    other members share (same joint and state within ±``tol_s``), s; inf when most never diverge."""
    n = len(seqs)
    keyed: list[dict] = [{} for _ in seqs]
    for d, seq in zip(keyed, seqs):
        for t, j, st in seq:
            d.setdefault((j, st), []).append(t)
    keyed = [{k: np.asarray(v) for k, v in d.items()} for d in keyed]
    first = []
    for i, seq in enumerate(seqs):
        div = np.inf
        for t, j, st in seq:
            share = sum(
                1 for k, d in enumerate(keyed) if k != i and (j, st) in d and np.min(np.abs(d[(j, st)] - t)) <= tol_s
            )
            if share < 0.5 * (n - 1):
                div = t
                break
        first.append(div)
    # "lower": one member's own time (inf when a quarter never diverge), no inf - inf interpolation
    return float(np.percentile(np.asarray(first), 25.0, method="lower")) if first else np.inf


def judge_column(
    t_s,
    theta_rad,
    ens: ColumnEnsemble,
    alpha_rad,
    *,
    tol_s: float,
    t_start_s: float,
    threshold_rad: float = EVENT_THRESHOLD_RAD,
) -> ColumnVerdict:
    """Judge a column model's ensemble against the measured block angles (see the module doc).

    Parameters
    ----------
    t_s : array_like, (m,)
        The ensemble's grid, s.
    theta_rad : array_like, (m, L)
        Measured block angles, clockwise positive (the simulator's sense), rad; NaN rows skipped.
    ens : ColumnEnsemble
    alpha_rad : array_like, (L,)
        Each block's slenderness angle, rad.
    tol_s : float
        ±Δt within which a member's event matches a measured one, s (up to float rounding: one
        frame matches events one frame apart on the measured grid).
    t_start_s : float
        The release (or the start of the shaking), s: events at the first sample are the start
        state, not a prediction.
    threshold_rad : float
        The joint-opening threshold of both sequences.
    """
    from ..models import compare_sequences, joint_sequence

    t = np.asarray(t_s, float)
    y = np.asarray(theta_rad, float)
    ok = np.isfinite(y)
    lo, hi = ens.band_rad
    coverage = float(np.mean(((y >= lo) & (y <= hi))[ok]))
    p05, p95 = np.percentile(ens.theta_rad, [5.0, 95.0], axis=0)
    wide = np.flatnonzero(np.any(p95 - p05 > HORIZON_FRACTION * np.asarray(alpha_rad, float), axis=1))
    horizon = float(t[wide[0]]) if wide.size else float(t[-1])
    t_first = float(t[np.flatnonzero(ok.all(axis=1))[0]])
    tol = tol_s + _ROUNDING_S
    meas = _through_closed([e for e in joint_sequence(t, y, threshold_rad) if e[0] > t_first], tol)
    members = [_through_closed([e for e in q if e[0] > t_first], tol) for q in ens.sequences]
    horizon = min(horizon, _event_horizon(members, tol))
    n = len(ens.sequences)
    hits = np.zeros(len(meas), int)
    counts = []
    for seq in members:
        counts.append(sum(e[0] < horizon for e in seq))
        matched = {(p[0], p[2]) for p in compare_sequences(meas, seq, tol_s=tol_s).pairs}
        hits += np.array([(e[0], e[1]) in matched for e in meas], int)
    events = []
    for e, h in zip(meas, hits):
        events.append(
            {
                "t_s": float(e[0]),
                "t_from_start_s": float(e[0] - t_start_s),
                "joint": int(e[1]),
                "state": e[2],
                "probability": float(h / n),
                "matched": bool(h >= 0.5 * n),
                "inside_horizon": bool(e[0] < horizon),
            }
        )
    inside = [ev for ev in events if ev["inside_horizon"]]
    n_in, n_match = len(inside), sum(ev["matched"] for ev in inside)
    n_missed = sum(ev["probability"] < MISSED_PROBABILITY for ev in inside)
    tests = {"n_events_inside": _rank_p(n_in, counts)}
    score = float(np.mean([ev["probability"] for ev in inside])) if inside else 1.0
    if n_missed >= 2 or tests["n_events_inside"] < _P_INCONSISTENT or coverage < COVERAGE_INCONSISTENT:
        verdict = "inconsistent"
    elif (
        n_in >= 2 and n_match == n_in and tests["n_events_inside"] >= _P_CONSISTENT and coverage >= COVERAGE_CONSISTENT
    ):
        verdict = "consistent"
    else:
        verdict = "undecided"
    q = np.percentile(counts, [5, 50, 95])
    mem = {"p05": float(q[0]), "p50": float(q[1]), "p95": float(q[2])}
    p_over = float(np.mean(ens.overturned))
    return ColumnVerdict(
        verdict, score, coverage, horizon, events, tests, n_in, n_match, mem, p_over, float(tol_s), ens.n_impacts
    )
