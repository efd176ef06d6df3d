"""What one experiment produced: :class:`ExperimentResult` and its typed stage results.

Every stage hands the next one an object (the fit, the simulations, the table motion, the clock
synchronisation, the assumption audit, the comparison with a synthetic truth); numbers become
plain dicts only in :meth:`ExperimentResult.to_dict`, for ``report.json``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ... import __version__
from ...blocks import Block
from ...series import TableMotion
from ...config import ExperimentConfig
from ._review_video import ReviewVideo

if TYPE_CHECKING:
    from ...fitting import EnergyLoss, ForcedRestitutionFit, RestitutionFit
    from ...tracking import SyncResult, TrackResult
    from ...tracking.rigid import AuditResult

__all__ = [
    "ExperimentResult",
    "FitStage",
    "ExcludedImpact",
    "LawSimulation",
    "TruthComparison",
    "ClockSync",
    "ColumnStage",
]


@dataclass(frozen=True)
class ExcludedImpact:
    """An impact of the fit that the assumption audit flagged: its per-impact η is not to trust.

    Attributes
    ----------
    impact : int
        The fit's impact number (1-based).
    t_s : float
        Its time, s.
    eta : float
        Its per-impact η (peaks).
    reasons : tuple of str
        One line per audit flag, SI values.
    """

    impact: int
    t_s: float
    eta: float
    reasons: tuple

    def to_dict(self) -> dict:
        """``impact, t_s, eta, reasons`` (the ``fit.excluded_impacts`` entries of ``report.json``)."""
        return {"impact": self.impact, "t_s": self.t_s, "eta": self.eta, "reasons": list(self.reasons)}


@dataclass(frozen=True)
class FitStage:
    """The experiment's η_e fit: free rocking, or half cycles under the measured table motion.

    Attributes
    ----------
    fit : rocklab.fitting.RestitutionFit or rocklab.fitting.ForcedRestitutionFit
    excluded_impacts : tuple of ExcludedImpact or None
        A free fit's impacts flagged by the audit (None for a forced fit: it has no impacts).
    """

    fit: RestitutionFit | ForcedRestitutionFit
    excluded_impacts: tuple | None = None

    @property
    def forced(self) -> bool:
        """Whether η_e came from half cycles under a moving table."""
        return hasattr(self.fit, "segment_eta")

    @property
    def eta_e(self) -> float:
        return float(self.fit.eta_e)

    @property
    def status(self) -> str:
        return self.fit.status

    @property
    def message(self) -> str:
        return self.fit.message

    @property
    def per_impact_eta(self) -> np.ndarray:
        """η of each impact (free) or of each half cycle's impact (forced), shape (k,)."""
        return np.asarray(self.fit.segment_eta if self.forced else self.fit.per_impact_eta, float)

    def law_eta(self, law: str) -> float | None:
        """The fitted η a law named ``eta_e`` or ``eta_e_first`` simulates with (None when not finite
        or not fitted: a forced fit has no first-impact η)."""
        v = getattr(self.fit, law, None)
        return float(v) if v is not None and np.isfinite(v) else None

    def release(self) -> tuple[float, float] | None:
        """``(theta0_rad, release_t_s)`` of a free fit's thread-burn release (None when not fitted)."""
        if self.forced:
            return None
        th0, t_rel = self.fit.theta0_rad, self.fit.release_t_s
        if th0 is None or t_rel is None or not (np.isfinite(th0) and np.isfinite(t_rel)):
            return None
        return float(th0), float(t_rel)

    def to_dict(self) -> dict:
        """The fit's own dict, with ``excluded_impacts`` for a free fit."""
        d = self.fit.to_dict()
        if self.excluded_impacts is not None:
            d["excluded_impacts"] = [e.to_dict() for e in self.excluded_impacts]
        return d


@dataclass(frozen=True)
class LawSimulation:
    """One restitution law's simulation of the experiment, on the measurement's clock.

    Attributes
    ----------
    law : str
    eta : float
        The constant η it simulated with.
    t_s, theta_rad, energy_J : ndarray, shape (m,)
        Time (s), rotation in the measurement's sense (rad) and energy (J).
    impacts : pandas.DataFrame
        :attr:`rocklab.models.RockingResult.impacts`, times on the measurement's clock.
    status : str
        The simulation's end state (``rest``, ``overturned``, ...).
    rms_vs_measured_rad : float or None
        RMS of measured − simulated θ from the release on (None without overlap).
    """

    law: str
    eta: float
    t_s: np.ndarray
    theta_rad: np.ndarray
    energy_J: np.ndarray
    impacts: object
    status: str
    rms_vs_measured_rad: float | None

    def impact_times_s(self) -> np.ndarray:
        """The impacts' times, s, shape (k,)."""
        return self.impacts["t_s"].to_numpy(float) if self.impacts is not None else np.empty(0)

    def to_dict(self) -> dict:
        """``eta, status, n_impacts, rms_vs_measured_rad`` (``report.json``'s ``simulations``)."""
        return {
            "eta": float(self.eta),
            "status": self.status,
            "n_impacts": int(len(self.impacts)) if self.impacts is not None else 0,
            "rms_vs_measured_rad": self.rms_vs_measured_rad,
        }


@dataclass(frozen=True)
class TruthComparison:
    """A synthetic session's true motion and how far the measurement is from it.

    Attributes
    ----------
    t_s, theta_rad : ndarray, shape (n,)
        The true rotation of the measured object, s and rad.
    eta : float or None
        The true η (``session.json``), when known.
    theta_rms_error_rad : float or None
        RMS of measured − true θ where both exist.
    table_acc_rms_error_rel : float or None
        RMS of the measured minus the true table acceleration over the true one's RMS, at the
        truth's frames, - (None without a table).
    """

    t_s: np.ndarray
    theta_rad: np.ndarray
    eta: float | None
    theta_rms_error_rad: float | None
    table_acc_rms_error_rel: float | None = None

    def to_dict(self) -> dict:
        return {
            "eta": self.eta,
            "theta_rms_error_rad": self.theta_rms_error_rad,
            "table_acc_rms_error_rel": self.table_acc_rms_error_rel,
        }


@dataclass(frozen=True)
class ClockSync:
    """The IMU clocks put on the reference (video or track) clock.

    Attributes
    ----------
    imu : rocklab.tracking.SyncResult or None
        The block IMU (``t_imu = t_ref + offset + drift t_ref``), from the rocking rates.
    table_imu : rocklab.tracking.SyncResult or None
        The table IMU, from the table accelerations.
    """

    imu: SyncResult | None = None
    table_imu: SyncResult | None = None

    def to_dict(self) -> dict:
        """The block IMU's numbers, with ``table_imu`` nested (``report.json``'s ``sync``)."""
        d = self.imu.to_dict() if self.imu is not None else {}
        if self.table_imu is not None:
            d["table_imu"] = self.table_imu.to_dict()
        return d


@dataclass(frozen=True)
class ColumnStage:
    """A column experiment: the tracked blocks against the column model under the measured table.

    Attributes
    ----------
    objects : tuple of str
        The blocks, bottom to top.
    t_s : ndarray, shape (m,)
    theta_measured_rad : ndarray, shape (m, n)
        Tracked angles, counter-clockwise as the camera sees them.
    sim_t_s : ndarray, shape (k,)
    theta_sim_rad : ndarray, shape (k, n)
        The column model's angles, in the measurement's sense.
    status : str
        The simulation's end state.
    configurations : pandas.DataFrame
        The model's joint configurations, on the measured clock.
    comparison : rocklab.models.ColumnComparison
    cut_m : float
        The joints' cut, m.
    impacts_per_closing : int
    source : str
        What measured the levels: ``video`` or ``imu`` (each level's IMU, on one clock).
    start_t_s : float
        The release (free rocking) or the first sample the levels are measured together, s.
    theta0_rad : tuple of float
        Each level's start angle, counter-clockwise, rad.
    blocks : tuple of dict
        Each level's block (:meth:`rocklab.Block.to_dict`), bottom to top.
    imu_clocks : list of dict or None
        Per level IMU: how its clock was put on the run's (``offset_s``, ``correlation``, ``how``).
    validation : ColumnValidation or None
        The event-sequence verdicts of the model's ensembles
        (:func:`rocklab.pipelines.experiment._column_run.validate_column`).
    theta_truth : (t_s, theta_rad (m', n)) or None
        A synthetic session's true angles.
    sequence_vs_truth : rocklab.models.SequenceComparison or None
        The measured opening/closing sequence against the truth's.
    theta_rms_error_rad : list of float or None
        Per block, RMS of measured − true θ.
    """

    objects: tuple
    t_s: np.ndarray
    theta_measured_rad: np.ndarray
    sim_t_s: np.ndarray
    theta_sim_rad: np.ndarray
    status: str
    configurations: object
    comparison: object
    cut_m: float
    impacts_per_closing: int
    source: str = "video"
    start_t_s: float = 0.0
    theta0_rad: tuple = ()
    blocks: tuple = ()
    imu_clocks: list | None = None
    validation: object = None
    theta_truth: tuple | None = None
    sequence_vs_truth: object = None
    theta_rms_error_rad: list | None = None

    def model_events(self) -> list:
        """The model's openings and impacts: ``t_s`` (measured clock), ``t_from_start_s``, ``joint``,
        ``state`` (after it), ``event``."""
        c = self.configurations
        return [
            {
                "t_s": float(r.t_s),
                "t_from_start_s": float(r.t_s - self.start_t_s),
                "joint": int(r.joint),
                "state": r.state,
                "event": r.event,
            }
            for r in c[c.event != "start"].itertuples()
        ]

    def to_dict(self) -> dict:
        """``report.json``'s ``column``."""
        d = {
            "objects": list(self.objects),
            "status": self.status,
            "source": self.source,
            "start_t_s": float(self.start_t_s),
            "theta0_rad": list(self.theta0_rad),
            "blocks": list(self.blocks),
            "comparison": self.comparison.to_dict(),
            "cut_m": self.cut_m,
            "impacts_per_closing": self.impacts_per_closing,
            "model_events": self.model_events()[:50],
        }
        if self.imu_clocks is not None:
            d["imu_clocks"] = self.imu_clocks
        if self.sequence_vs_truth is not None:
            d["sequence_vs_truth"] = self.sequence_vs_truth.to_dict()
        if self.theta_rms_error_rad is not None:
            d["theta_rms_error_rad"] = list(self.theta_rms_error_rad)
        return d


@dataclass(frozen=True)
class ExperimentResult:
    """Everything one experiment produced. SI units; θ in rad, t in s.

    Attributes
    ----------
    name : str
    config : ExperimentConfig
    block : rocklab.Block
    measured : dict[str, tuple[ndarray, ndarray]]
        Source name ("video", "imu", "track") → (t_s, theta_rad), on the primary clock; θ NaN
        where a sample is not usable (:meth:`rocklab.series.Tracks.usable`).
    primary : str
        The source the fit used.
    sync : ClockSync or None
    video_imu_residual : (t_s, residual_rad) or None
    fit : FitStage or None
    per_impact_eta : ndarray
    simulations : dict[str, LawSimulation]
        Law → its simulation.
    table : rocklab.series.TableMotion or None
        The table motion the simulations are driven by (``table.source``: ``fused``, ``imu``,
        ``video`` or ``record``).
    truth : TruthComparison or None
        When the session has a synthetic truth.
    status : str
        "ok", "failed" or "partial" (then "suspect" when a warning says so).
    messages : list[str]
        What went wrong or was noticed, one line each.
    timings_s : dict[str, float]
        Seconds each stage took.
    frames : rocklab.tracking.TrackResult or None
        The video tracker's result (per-frame overlays).
    column : ColumnStage or None
        Column experiments (:func:`rocklab.pipelines.experiment._column_run.analyse_column`).
    video : ReviewVideo or None
        The review film (:mod:`rocklab.pipelines.experiment._review_video`).
    diagnostics : tuple of rocklab._diagnostics.Diagnostic
        Warnings raised while analysing.
    audit : rocklab.tracking.rigid.AuditResult or None
        The assumption audit of the primary source.
    validation : rocklab.pipelines._validation.Validation or None
        Base-excited runs: the laws judged by their ensembles.
    energy_loss : rocklab.fitting.EnergyLoss or None
        Free rocking: the energy lost per rocking from the peaks of θ (thesis Eq. 12), the mean
        of the first four and the constant η that loses as much.
    table_fusion : rocklab.tracking.TableFusion or None
        The table IMU fused with the film's table (their noises, the IMU's offset, agreement).
    """

    name: str
    config: ExperimentConfig
    block: Block
    measured: dict
    primary: str
    sync: ClockSync | None
    video_imu_residual: tuple | None
    fit: FitStage | None
    per_impact_eta: np.ndarray
    simulations: dict
    table: TableMotion | None
    truth: TruthComparison | None
    status: str
    messages: list = field(default_factory=list)
    timings_s: dict = field(default_factory=dict)
    frames: TrackResult | None = None
    column: ColumnStage | None = None
    video: ReviewVideo | None = None
    diagnostics: tuple = ()
    audit: AuditResult | None = None
    validation: object = None
    energy_loss: EnergyLoss | None = None
    table_fusion: object = None

    def to_dict(self) -> dict:
        """The numbers of ``report.json`` (units in keys)."""
        return {
            "name": self.name,
            "tags": self.config.tag_dict,
            "status": self.status,
            "messages": list(self.messages),
            "warnings": [d.to_dict() for d in self.diagnostics],
            "block": dict(self.block.to_dict()),
            "contact": {"type": self.config.contact, "l_c_m": self.config.l_c_m, "k": self.config.k},
            "primary_source": self.primary,
            "sources": sorted(self.measured),
            "track_corrections": list(getattr(self.frames, "corrections", ())),
            "sync": None if self.sync is None else self.sync.to_dict(),
            "video_vs_imu_rms_rad": (
                float(np.sqrt(np.nanmean(np.square(self.video_imu_residual[1]))))
                if self.video_imu_residual is not None
                else None
            ),
            "fit": None if self.fit is None else self.fit.to_dict(),
            "audit": None if self.audit is None else self.audit.to_dict(),
            "per_impact_eta": [float(x) for x in self.per_impact_eta],
            "simulations": {law: s.to_dict() for law, s in self.simulations.items()},
            "table_source": None if self.table is None else self.table.source,
            "table": None if self.table is None else _table_peaks(self.table, self.table_fusion),
            "truth": None if self.truth is None else self.truth.to_dict(),
            "column": None if self.column is None else self.column.to_dict(),
            "review_video": None
            if self.video is None
            else {
                "kind": self.video.kind,
                "frames": len(self.video.frame_index),
                "bytes": self.video.n_bytes,
                "note": self.video.note,
            },
            "validation": self.validation.to_dict()
            if self.validation is not None
            else (None if self.column is None or self.column.validation is None else self.column.validation.to_dict()),
            "energy_loss": None if self.energy_loss is None else _energy_loss_dict(self.energy_loss),
            "timings_s": self.timings_s,
            "units": {
                "t": "s",
                "theta": "rad",
                "omega": "rad/s",
                "length": "m",
                "energy": "J",
                "acceleration": "m/s^2",
            },
            "versions": _versions(),
        }


def _table_peaks(table: TableMotion, fusion=None) -> dict:
    d = {
        "source": table.source,
        "peak_disp_m": None if table.x_m is None else float(np.nanmax(np.abs(table.x_m))),
        "peak_acc_m_s2": float(np.nanmax(np.abs(table.ax_m_s2))),
    }
    if fusion is not None:
        d["fusion"] = fusion.to_dict()
    return d


def _versions() -> dict:
    import importlib.metadata as md

    out = {"rocklab": __version__}
    for pkg in ("numpy", "scipy", "pandas", "numba", "opencv-python-headless", "rerun-sdk", "imufusion", "av"):
        try:
            out[pkg] = md.version(pkg)
        except md.PackageNotFoundError:
            out[pkg] = None
    return out


def _energy_loss_dict(e) -> dict:
    """Eq. 12's numbers for report.json (the peaks table stays in memory)."""
    d = e.to_dict()
    d.pop("peaks", None)
    return {
        "mean4": d["mean4"],
        "eta_equivalent": d["eta_equivalent"],
        "start": d["start"],
        "exact_rise": d["exact"],
        "loss_per_rocking": d["loss"],
        "equation": "Ther thesis Eq. 12",
    }
