"""Audit of the planar-rocking assumptions behind the single-block equations.

Čeh et al. (2018) Eq. 1-4 and the thesis §3 describe a rigid block rocking in
one plane about a bottom edge that neither slides nor leaves the table, with
one impact per contact. A test that breaks this (the block slid at an impact,
jumped, twisted about the vertical, tilted out of the rocking plane, or hit
twice) gives a wrong restitution coefficient without any other sign. The
audit measures each departure per impact and over the run and compares it
with a stated tolerance.

Measures (each a time series from the 3D or 2D tracker):

- ``slide``: displacement of the active pivot edge along the table, m. A step
  across an impact (median of the half-cycle after minus before) or a spread
  within a half-cycle (95th minus 5th percentile) above the tolerance is flagged;
- ``jump``: uplift of the active pivot edge above its rest height, m (a flight
  phase when it exceeds the tolerance);
- ``twist`` and ``out_of_plane``: rotation about the vertical and about the
  rocking direction, rad, flagged like ``slide``;
- ``double_impact``: the block came down to the table and rose again on the
  same edge (``|theta|`` below the impact finder's hysteresis between two
  excursions on one side: a bounce), or a half-cycle shorter than
  ``double_impact_ratio`` of both its neighbours.

Verdict: ``valid`` without flags; ``invalid`` when any flag exceeds
``invalid_factor`` times its tolerance; ``suspect`` otherwise.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from ._rocking import find_impacts, segment_ids

__all__ = ["AuditTolerances", "AuditFlag", "AuditResult", "audit_rocking", "FLAG_KINDS"]

#: The kinds of flag, in the order the report lists them.
FLAG_KINDS = ("slide", "jump", "twist", "out_of_plane", "double_impact")
#: Samples dropped at each end of a half-cycle before its median and spread (the impact's own samples).
EDGE_SAMPLES = 2


@dataclass(frozen=True)
class AuditTolerances:
    """What departure from planar rocking each check tolerates.

    Attributes
    ----------
    slide_m : float
        Pivot sliding, m (default 0.5 mm: a tenth of a typical 5 mm chamfer-free edge's
        rounding and above 3D optical noise).
    jump_m : float
        Pivot uplift, m (default 1 mm).
    twist_rad, out_of_plane_rad : float
        Rotation about the vertical / the rocking direction, rad (default 0.5 deg).
    double_impact_ratio : float
        A half-cycle shorter than this fraction of both neighbours is a double impact (default 0.3).
    invalid_factor : float
        A flag above this many tolerances makes the test ``invalid`` (default 4).
    """

    slide_m: float = 5e-4
    jump_m: float = 1e-3
    twist_rad: float = math.radians(0.5)
    out_of_plane_rad: float = math.radians(0.5)
    double_impact_ratio: float = 0.3
    invalid_factor: float = 4.0

    def to_dict(self) -> dict:
        """Field name -> value (SI units)."""
        return asdict(self)


@dataclass(frozen=True)
class AuditFlag:
    """One departure from the model's assumptions.

    Attributes
    ----------
    kind : str
        One of :data:`FLAG_KINDS`.
    t_s : float
        When, s (the impact for a step, the worst sample otherwise).
    value : float
        How large: m for slide/jump; rad for twist/out_of_plane and for a bounce (the lower hump's
        height); s for a short half-cycle.
    tolerance : float
        The tolerance it broke, same unit (a bounce: the smallest hump counted; a short half-cycle: the
        shortest believable one).
    impact : int or None
        The impact (1-based) it belongs to: the step's impact, or the impact that began the half-cycle;
        None before the first impact.
    detail : str
        ``"step"`` (across an impact), ``"within"`` (inside one half-cycle), ``"flight"``, ``"bounce"``
        or ``"short half-cycle"``.
    """

    kind: str
    t_s: float
    value: float
    tolerance: float
    impact: int | None
    detail: str

    def to_dict(self) -> dict:
        """The JSON object of ``audit.json``'s ``flags`` list."""
        return {
            "kind": self.kind,
            "t_s": self.t_s,
            "value": self.value,
            "tolerance": self.tolerance,
            "impact": self.impact,
            "detail": self.detail,
        }

    def describe(self) -> str:
        """One line for people, 4 significant digits with units."""
        if self.kind in ("slide", "jump"):
            v, tol, u = self.value * 1e3, self.tolerance * 1e3, "mm"
        elif self.detail == "short half-cycle":
            v, tol, u = self.value * 1e3, self.tolerance * 1e3, "ms half-cycle"
        else:
            v, tol, u = math.degrees(self.value), math.degrees(self.tolerance), "deg"
        at = f"impact {self.impact}" if self.impact else "before the first impact"
        return f"{self.kind} ({self.detail}) at t = {self.t_s:.4g} s, {at}: {v:.4g} {u} (tolerance {tol:.4g} {u})"


@dataclass(frozen=True)
class AuditResult:
    """Verdict on whether a test kept to planar rocking about a fixed edge.

    Attributes
    ----------
    verdict : str
        ``"valid"``, ``"suspect"`` or ``"invalid"`` (see the module doc).
    flags : tuple of AuditFlag
    impacts_t_s : ndarray, shape (m,)
        Impact times found from ``theta``, s.
    excluded_impacts : tuple of int
        Impacts (1-based) a restitution fit should not trust: those with a flag.
    checked : tuple of str
        The kinds that had data (a 2D track cannot check twist or out-of-plane rotation).
    maxima : dict
        Largest departure over the run per checked kind (SI units).
    tolerances : AuditTolerances
    source : str
        ``"3d"``, ``"2d"`` or ``"imu"``.
    notes : tuple of str
        What could not be checked, or only above a noise floor.
    noise : dict
        Per-sample 1-sigma noise of each checked measure (from its first
        differences), SI units. A flag needs its departure to exceed the
        tolerance by 4 sigma (of the sample, or of the half-cycle median for a step).
    """

    verdict: str
    flags: tuple
    impacts_t_s: np.ndarray
    excluded_impacts: tuple
    checked: tuple
    maxima: dict
    tolerances: AuditTolerances
    source: str = "3d"
    notes: tuple = field(default=())
    noise: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """The ``audit.json`` object: ``verdict``, ``flags`` and the context to read them."""
        return {
            "verdict": self.verdict,
            "flags": [f.to_dict() for f in self.flags],
            "excluded_impacts": list(self.excluded_impacts),
            "checked": list(self.checked),
            "impacts_t_s": [float(x) for x in self.impacts_t_s],
            "maxima": dict(self.maxima),
            "tolerances": self.tolerances.to_dict(),
            "source": self.source,
            "notes": list(self.notes),
            "noise": dict(self.noise),
        }

    def to_frame(self):
        """One row per flag: ``kind, detail, impact, t_s, value, tolerance``."""
        import pandas as pd

        return pd.DataFrame(
            [f.to_dict() for f in self.flags], columns=["kind", "detail", "impact", "t_s", "value", "tolerance"]
        )

    def report(self) -> str:
        """Readable text: the verdict, then one line per flag."""
        lines = [
            f"assumption audit ({self.source}): {self.verdict}; {len(self.impacts_t_s)} impacts, "
            f"checked {', '.join(self.checked) or 'nothing'}"
        ]
        lines += ["  " + f.describe() for f in self.flags]
        if self.excluded_impacts:
            lines.append(f"  impacts a fit should exclude: {', '.join(map(str, self.excluded_impacts))}")
        return "\n".join(lines)


def _noise(values) -> float:
    """Per-sample 1-sigma noise of a series that is constant under the model, from its first differences (MAD)."""
    v = np.asarray(values, float).reshape(len(values), -1)
    tot = 0.0
    for col in v.T:
        d = np.diff(col[np.isfinite(col)])
        if d.size < 3:
            return float("nan")
        tot += (1.4826 * np.median(np.abs(d - np.median(d))) / math.sqrt(2.0)) ** 2
    return math.sqrt(tot)


def _segment_stats(values, seg, n_seg):
    """Per half-cycle (median, spread = twice the 90th percentile deviation, index of the worst sample,
    samples used) of ``values``."""
    med = np.full((n_seg,) + values.shape[1:], np.nan)
    spread = np.full(n_seg, np.nan)
    worst = np.full(n_seg, -1)
    count = np.zeros(n_seg, int)
    for j in range(n_seg):
        idx = np.flatnonzero((seg == j) & np.isfinite(values).reshape(len(values), -1).all(axis=1))
        idx = idx[EDGE_SAMPLES:-EDGE_SAMPLES] if idx.size > 2 * EDGE_SAMPLES + 2 else idx[:0]
        if idx.size == 0:
            continue
        v = values[idx]
        m = np.median(v, axis=0)
        med[j] = m
        dev = np.linalg.norm((v - m).reshape(len(v), -1), axis=1)
        spread[j] = 2.0 * float(np.percentile(dev, 90))
        worst[j] = int(idx[np.argmax(dev)])
        count[j] = idx.size
    return med, spread, worst, count


def _touches(t, th, seg, hyst):
    """Samples where the block came back down on the edge it rocks on and rose again (a bounce).

    Within one half-cycle ``|theta|`` normally has one hump; two humps, each
    more prominent than ``2 hyst``, with a valley below half the lower one,
    mean the block touched the table in between. Returns the valley samples.
    """
    from scipy.signal import find_peaks

    out = []
    for j in np.unique(seg):
        idx = np.flatnonzero((seg == j) & np.isfinite(th))
        if idx.size < 5:
            continue
        a = np.abs(th[idx])
        peaks, _ = find_peaks(a, prominence=2.0 * hyst)
        for p0, p1 in zip(peaks[:-1], peaks[1:]):
            v = p0 + int(np.argmin(a[p0 : p1 + 1]))
            if a[v] < 0.5 * min(a[p0], a[p1]):
                out.append((int(idx[v]), float(min(a[p0], a[p1]))))
    return out


def audit_rocking(
    t_s,
    theta_rad,
    *,
    slide_m=None,
    uplift_m=None,
    twist_rad=None,
    out_of_plane_rad=None,
    sigma_theta_rad: float | None = None,
    tolerances: AuditTolerances | None = None,
    source: str = "3d",
    noise_floor: dict | None = None,
) -> AuditResult:
    """Check one block's run against the planar-rocking assumptions.

    Parameters
    ----------
    t_s, theta_rad : array_like, shape (n,)
        Time, s, and rocking angle, rad (NaN = not measured).
    slide_m : array_like, shape (n,) or (n, 2), optional
        Active-pivot displacement along the table (along the rocking direction,
        and across it in 3D), m.
    uplift_m : array_like, shape (n,), optional
        Active-pivot height above its rest height, m.
    twist_rad, out_of_plane_rad : array_like, shape (n,), optional
        Rotation about the vertical and about the rocking direction, rad.
    sigma_theta_rad : float, optional
        Typical 1-sigma of ``theta``, rad: the impact finder's hysteresis is
        ``max(5 sigma, 0.05 deg)``.
    tolerances : AuditTolerances, optional
    source : str
        ``"3d"``, ``"2d"`` or ``"imu"`` (reported).
    noise_floor : dict, optional
        Smallest noise to assume per kind (``{"slide": m, "jump": m, ...}``), e.g. the
        misfit of a plane track to rigid rocking; the larger of it and the
        series' own noise is used.

    Returns
    -------
    AuditResult
    """
    tol = tolerances or AuditTolerances()
    t = np.asarray(t_s, float)
    th = np.asarray(theta_rad, float)
    sig = float(sigma_theta_rad) if sigma_theta_rad is not None and np.isfinite(sigma_theta_rad) else 0.0
    audit = _Audit(t, th, max(5.0 * sig, math.radians(0.05)), noise_floor or {})
    if slide_m is not None:
        audit.stepwise("slide", slide_m, tol.slide_m)
    if uplift_m is not None:
        audit.flights(uplift_m, tol.jump_m)
    if twist_rad is not None:
        audit.stepwise("twist", twist_rad, tol.twist_rad)
    if out_of_plane_rad is not None:
        audit.stepwise("out_of_plane", out_of_plane_rad, tol.out_of_plane_rad)
    audit.double_impacts(tol.double_impact_ratio)
    return audit.result(tol, source)


#: A flag needs the departure beyond the tolerance by this many sigma of its noise.
K_SIGMA = 4.0


class _Audit:
    """One run's audit as it is built: the half-cycles between impacts, and the checks made, their flags,
    largest departures, noise and notes so far."""

    def __init__(self, t, th, hyst, floor):
        self.t, self.th, self.hyst, self.floor = t, th, hyst, floor
        self.impacts = find_impacts(t, th, hyst)
        self.seg = segment_ids(t, self.impacts)
        self.n_seg = self.impacts.size + 1
        self.flags: list[AuditFlag] = []
        self.checked: list[str] = []
        self.maxima: dict = {}
        self.noise: dict = {}
        self.notes: list[str] = []

    def resolvable(self, kind, sigma, limit, margin):
        """Record the noise of ``kind`` and note when it hides departures at the tolerance ``limit``."""
        self.noise[kind] = sigma
        if np.isfinite(sigma) and margin > limit:
            self.notes.append(
                f"{kind}: measurement noise {sigma:.3g} (SI) per sample; departures below "
                f"{limit + margin:.3g} cannot be told from noise"
            )

    @staticmethod
    def impact_of(j):
        return int(j) if j >= 1 else None

    def stepwise(self, kind, values, limit):
        """Flag steps of ``values`` (n,) or (n, k) across impacts and spreads within half-cycles above ``limit``."""
        values = np.asarray(values, float)
        if values.ndim == 1:
            values = values[:, None]
        if not np.isfinite(values).any():
            return
        self.checked.append(kind)
        med, spread, worst, count = _segment_stats(values, self.seg, self.n_seg)
        ok = np.isfinite(med).all(axis=1)
        sigma = np.nanmax([_noise(values), self.floor.get(kind, np.nan), 0.0])
        sg = sigma if np.isfinite(sigma) else 0.0
        self.resolvable(kind, sigma, limit, K_SIGMA * sg)
        dev = np.linalg.norm(values - np.nanmedian(values, axis=0), axis=1)
        self.maxima[kind] = float(np.nanmax(dev)) if np.isfinite(dev).any() else float("nan")
        prev = None
        for j in range(self.n_seg):
            if not ok[j]:
                continue
            if prev is not None:
                step = float(np.linalg.norm(med[j] - med[prev]))
                s_step = 1.25 * sg * math.sqrt(1.0 / count[j] + 1.0 / count[prev])
                if step > limit + K_SIGMA * s_step:
                    self.flags.append(
                        AuditFlag(kind, float(self.impacts[j - 1]), step, limit, self.impact_of(j), "step")
                    )
            if spread[j] > limit + K_SIGMA * sg:
                self.flags.append(
                    AuditFlag(kind, float(self.t[worst[j]]), float(spread[j]), limit, self.impact_of(j), "within")
                )
            prev = j

    def flights(self, uplift_m, limit):
        """Flag each flight phase of the pivot's uplift (n,) above ``limit`` m, at its highest sample."""
        up = np.asarray(uplift_m, float)
        if not np.isfinite(up).any():
            return
        self.checked.append("jump")
        self.maxima["jump"] = float(np.nanmax(up))
        s_up = float(np.nanmax([_noise(up), self.floor.get("jump", np.nan), 0.0]))
        self.resolvable("jump", s_up, limit, K_SIGMA * (s_up if np.isfinite(s_up) else 0.0))
        above = np.isfinite(up) & (up > limit + K_SIGMA * (s_up if np.isfinite(s_up) else 0.0))
        # one flag per flight phase (a run of samples above the tolerance), at its highest sample
        edges = np.flatnonzero(np.diff(np.r_[0, above.astype(int), 0]))
        for a, b in zip(edges[::2], edges[1::2]):
            k = a + int(np.argmax(up[a:b]))
            self.flags.append(
                AuditFlag("jump", float(self.t[k]), float(up[k]), limit, self.impact_of(self.seg[k]), "flight")
            )

    def double_impacts(self, ratio):
        """Flag bounces, and half-cycles shorter than ``ratio`` times both their neighbours."""
        self.checked.append("double_impact")
        t, seg, impacts = self.t, self.seg, self.impacts
        for k, h in _touches(t, self.th, seg, self.hyst):
            # the block came down to the table and went back up on the same edge: the next impact was doubled
            self.flags.append(
                AuditFlag("double_impact", float(t[k]), float(h), 2.0 * self.hyst, int(seg[k]) + 1, "bounce")
            )
        if impacts.size >= 3:
            dur = np.diff(impacts)  # half-cycle j (impact j -> j+1) lasts dur[j-1]
            for i in range(1, dur.size - 1):
                shortest = ratio * min(dur[i - 1], dur[i + 1])
                if dur[i] < shortest:
                    self.flags.append(
                        AuditFlag(
                            "double_impact",
                            float(impacts[i]),
                            float(dur[i]),
                            float(shortest),
                            i + 1,
                            "short half-cycle",
                        )
                    )

    def result(self, tol, source) -> AuditResult:
        """The verdict over the flags, and the impacts a fit should exclude."""
        flags = sorted(self.flags, key=lambda f: (f.t_s, FLAG_KINDS.index(f.kind)))
        if not flags:
            verdict = "valid"
        elif any(f.kind != "double_impact" and f.value > tol.invalid_factor * f.tolerance for f in flags):
            verdict = "invalid"
        else:
            verdict = "suspect"
        excluded = tuple(sorted({f.impact for f in flags if f.impact is not None}))
        return AuditResult(
            verdict,
            tuple(flags),
            self.impacts,
            excluded,
            tuple(self.checked),
            self.maxima,
            tol,
            source,
            tuple(self.notes),
            self.noise,
        )
