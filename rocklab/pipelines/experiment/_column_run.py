"""Column experiments in ``rocklab run`` (thesis §4.3): tracked blocks vs the column model.

The blocks' angles come from video (counter-clockwise as the camera sees them);
the column model (clockwise positive, like :func:`rocklab.models.simulate`) is
driven by the table acceleration measured on video or IMU, and the two are
compared block by block and by their opening/closing sequence (which joint
opens when, in which direction).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from ..._errors import InputError
from ...series import TableMotion

__all__ = ["analyse_column", "base_from_table", "validate_column", "ColumnValidation", "COLUMN_ENSEMBLE_SIZE"]


def base_from_table(table: TableMotion, t0_s: float, where: str, *, sign: float = 1.0, dt_s: float = 1e-3):
    """The measured table acceleration as a :class:`BaseMotion` starting at ``t0_s``.

    A near-critical rocking response is sensitive to how frame-rate samples are
    interpolated: linear interpolation of a 50 fps, 0.6 s pulse moved the peak by
    10 %, a cubic spline onto 1 ms by 1 % (measured on a synthetic session), so
    the samples are splined onto ``dt_s``. ``sign = -1`` mirrors the motion.
    """
    from scipy.interpolate import CubicSpline

    from ...series import BaseMotion

    tt = np.asarray(table.t_s, float)
    aa = np.asarray(table.ax_m_s2, float)
    fin = np.isfinite(tt) & np.isfinite(aa)
    if fin.sum() < 4:
        raise InputError(
            f"{where}: the table motion has {int(fin.sum())} valid samples; "
            "cannot drive the simulation (check the table object's tracking)"
        )
    tf = np.arange(tt[fin][0], tt[fin][-1], dt_s)
    af = CubicSpline(tt[fin], aa[fin])(tf)
    return BaseMotion.from_samples(sign * af, dt_s, t0_s=float(tf[0]) - t0_s, units="m/s2", name="table")


def _by_object(df, objects, value="theta_rad"):
    wide = df.pivot_table(index="t_s", columns="object", values=value, dropna=False)
    missing = [o for o in objects if o not in wide.columns]
    if missing:
        raise InputError(f"[column] objects {missing} were never tracked; objects seen: {sorted(wide.columns)}")
    return wide.index.to_numpy(float), wide[list(objects)].to_numpy(float)


def _levels(cfg, track_result):
    """(t_s, theta_rad (m, L) counter-clockwise, release_t_s or None, source, IMU clocks or None)."""
    from ._measure import measure_column_imus

    video = _by_object(track_result.to_frame(), cfg.columns) if track_result is not None else None
    if cfg.column_imus:
        m = measure_column_imus(cfg, video)
        rel = m.release_t_s if np.isfinite(m.release_t_s) else None
        return m.t_s, m.theta_rad, rel, "imu", m.clocks
    t, th = video
    return t, th, None, "video", None


def _free_release(cfg, t, th, rel):
    """(release time s, each level's start angle rad, counter-clockwise) of a free-release column."""
    from ...fitting import detect_release

    ok = np.isfinite(th).all(axis=1)
    head = th[ok][: max(3, min(20, int(ok.sum()) // 3))]
    ref = int(np.argmax(np.abs(np.median(head, axis=0))))
    if rel is None:
        info = detect_release(t[ok], th[ok, ref])
        if not info.found:
            raise InputError(
                f"{cfg.path}: a free-release column (no table motion) but level {ref + 1} shows no release "
                "(no rest at a tilt before it moves); give [sources.table] for a shake-table run"
            )
        rel = float(info.t_s)
    before = ok & (t < rel) & (t >= rel - 0.2)
    if before.sum() < 3:
        raise InputError(f"{cfg.path}: fewer than 3 samples of the column at rest before its release at {rel:.3f} s")
    th0 = np.median(th[before], axis=0)
    if cfg.column_theta0_rad:
        return float(rel), np.asarray(cfg.column_theta0_rad, float)
    # a joint open by less than this at rest is a block standing flat on the one below (a held
    # block is tilted by far more); left open, the model would start with an impact there
    phi = np.diff(np.concatenate([[0.0], th0]))
    phi[np.abs(phi) < JOINT_CLOSED_RAD] = 0.0
    return float(rel), np.cumsum(phi)


def analyse_column(cfg, track_result, table, truth_path=None, msgs=None):
    """Simulate the column (each level's block, start angle, the measured table motion) and compare
    it with the measured blocks: block by block, by the opening/closing sequence, and by the
    event-sequence verdict of its ensemble (:func:`rocklab.fitting.judge_column`).

    Returns a :class:`rocklab.pipelines.experiment._stages.ColumnStage` (with a truth file, its
    ``theta_truth``, ``sequence_vs_truth`` and ``theta_rms_error_rad`` too).
    """
    from ._stages import ColumnStage

    from ...models import Column, compare_to_measurement, simulate_column

    objs = cfg.columns
    t, th, rel, source, clocks = _levels(cfg, track_result)
    ok_t = np.isfinite(th).all(axis=1)
    if not ok_t.any():
        raise InputError(f"{cfg.path}: the column's levels are never measured together")
    col = Column(cfg.column_blocks(), cut_m=cfg.column_cut_m)
    if table is None:  # free release: from each level's measured (or given) start angle
        t0, th0 = _free_release(cfg, t, th, rel)
        base = None
    else:
        t0, th0 = float(t[ok_t][0]), np.zeros(len(objs))
        base = base_from_table(table, t0, str(cfg.path))
    # 1 ms samples: far finer than any camera, and they feed only interpolation to the frame
    # times, plots and Rerun (the events are exact at any spacing); every 0.1 ms step would be 10x the rows
    # measured angles are counter-clockwise, the model's clockwise: sign = -1
    res = simulate_column(
        col,
        base,
        theta0_rad=-th0,
        duration_s=float(t[-1] - t0),
        n_impacts=cfg.column_impacts,
        dt_s=1e-4,
        output_dt_s=1e-3,
    )
    after = t >= t0 - 0.05
    comp = compare_to_measurement(res, t[after] - t0, th[after], sign=-1.0)
    confs = res.configurations.copy()
    confs["t_s"] = confs["t_s"] + t0
    validation = validate_column(cfg, col, t, th, t0, th0, table, source)
    out = ColumnStage(
        objects=tuple(objs),
        t_s=t,
        theta_measured_rad=th,
        sim_t_s=np.asarray(res.t_s) + t0,
        theta_sim_rad=-np.asarray(res.theta_rad),
        status=res.status,
        configurations=confs,
        comparison=comp,
        cut_m=cfg.column_cut_m,
        impacts_per_closing=cfg.column_impacts,
        source=source,
        start_t_s=t0,
        theta0_rad=tuple(float(v) for v in th0),
        blocks=tuple(b.to_dict() for b in col.blocks),
        imu_clocks=clocks,
        validation=validation,
    )
    if truth_path is not None and source == "imu" and track_result is None and msgs is not None:
        # the truth is on the video clock; an IMU-only run is on its released level's log clock
        msgs.append("column vs truth not compared: the run has no film to put the truth's clock on its IMUs'")
    elif truth_path is not None:
        out = _with_truth(out, truth_path, objs, t, th, t0)
    return out


def _with_truth(out, truth_path, objs, t, th, t0):
    """The stage with a synthetic session's true angles and the measured sequence against the truth's."""
    import pandas as pd

    from ...models import compare_sequences, joint_sequence

    tr = pd.read_csv(truth_path)
    tt, tth = _by_object(tr[tr["object"].isin(objs)], objs)
    # which joint opens when, from the measured angles vs from the rendered truth (thesis Fig. 32)
    inside = (t >= tt[0]) & (t <= tt[-1])
    mseq = joint_sequence(t[inside] - t0, -th[inside])
    tseq = joint_sequence(tt - t0, -tth)
    err = th[inside] - np.column_stack([np.interp(t[inside], tt, tth[:, i]) for i in range(len(objs))])
    return dataclasses.replace(
        out,
        theta_truth=(tt, tth),
        sequence_vs_truth=compare_sequences(tseq, mseq),
        theta_rms_error_rad=np.sqrt(np.nanmean(err**2, axis=0)).tolist(),
    )


#: A measured joint opened by less than this at rest starts closed, rad (half the opening threshold
#: the sequences are read with, :data:`rocklab.fitting.EVENT_THRESHOLD_RAD`).
JOINT_CLOSED_RAD = 0.0025
#: The ensembles simulate this long after the release (or the table's first motion), s: a column's predictability horizon comes
#: within its first rockings (0.3 s on the thesis §4.2 release) and its impacts make every
#: simulated second costly (a 2-block, 9 s free release: 0.5 s per run).
COLUMN_ENSEMBLE_SPAN_S = 1.5
#: Members of each column ensemble (a 2-block, 10 s free release: 32 runs take ~2 s on one core).
COLUMN_ENSEMBLE_SIZE = 32
#: Smallest start-angle uncertainty of a level, rad (a tilt read at rest, by accelerometer or camera);
#: also the constant offset of each level's measured angle the ensembles' sequences are read with.
THETA0_MIN_SD_RAD = 2e-3


@dataclass(frozen=True)
class ColumnValidation:
    """The event-sequence verdicts of a column run (``report.json["validation"]``).

    Attributes
    ----------
    horizon_s : float
        Predictability horizon of the reference law (the configured impacts per closing), s.
    reference_law : str
    laws : dict
        ``impacts_<k>`` (k consecutive impacts per joint closing: 1 Housner, 2 one mid-joint bump)
        → :class:`rocklab.fitting.ColumnVerdict`.
    bands : dict
        Law → (p05_rad, p95_rad), each (m, L) on the measured grid, counter-clockwise.
    uncertainty : dict
        The :class:`rocklab.fitting.InputUncertainty` sampled, SI.
    n_members : int
    seconds : float
    acc_scale_source : str
        Where ``uncertainty["acc_scale"]`` comes from (the validation's ``acc_scale_sd``)
        and whether a fused table's own error is drawn; empty without a table.
    """

    horizon_s: float
    reference_law: str
    laws: dict
    bands: dict = field(repr=False)
    uncertainty: dict
    n_members: int
    seconds: float
    acc_scale_source: str = ""

    def to_dict(self) -> dict:
        from ...fitting import HORIZON_FRACTION

        return {
            "kind": "column event sequence",
            "horizon_s": float(self.horizon_s),
            "reference_law": self.reference_law,
            "horizon_fraction_of_alpha": HORIZON_FRACTION,
            "n_members": self.n_members,
            "laws": {k: v.to_dict() for k, v in self.laws.items()},
            "uncertainty": self.uncertainty,
            "acc_scale_source": self.acc_scale_source,
            "ensemble_s": float(self.seconds),
        }


def _rest_noise(th, ok, t, t0):
    """Robust per-sample noise of the measured angles in the rest before ``t0``, rad (NaN: no rest)."""
    w = ok & (t < t0)
    if w.sum() < 5:
        return np.nan
    d = np.diff(th[w], axis=0)
    return float(np.max(1.4826 * np.median(np.abs(d - np.median(d, axis=0)), axis=0) / np.sqrt(2.0)))


def _table_starts(table) -> float:
    """When the table starts moving: its acceleration first leaves its starting level by 5 % of the
    peak, s (its first sample when it never rests)."""
    ta, aa = np.asarray(table.t_s, float), np.asarray(table.ax_m_s2, float)
    fin = np.isfinite(aa)
    ta, aa = ta[fin], aa[fin]
    lev = float(np.median(aa[:10]))
    away = np.flatnonzero(np.abs(aa - lev) > 0.05 * float(np.max(np.abs(aa - lev))))
    return float(ta[away[0]]) if away.size else float(ta[0])


def _column_uncertainty(cfg, t, th, t0, table):
    from .._validation import INPUT_SAFETY, LENGTH_SD_M, MIN_NOISE_RAD, acc_scale_sd, fused_sigma
    from ...fitting import InputUncertainty

    ok = np.isfinite(th).all(axis=1)
    sm = _rest_noise(th, ok, t, t0)
    sm = MIN_NOISE_RAD if not np.isfinite(sm) else max(sm, MIN_NOISE_RAD)
    sa = sb = st = 0.0
    if table is not None:
        aa = np.asarray(table.ax_m_s2, float)
        ta = np.asarray(table.t_s, float)
        rest = aa[np.isfinite(aa) & (ta < _table_starts(table))]
        if rest.size >= 10:
            sa = float(1.4826 * np.median(np.abs(np.diff(rest) - np.median(np.diff(rest)))) / np.sqrt(2.0))
            sb = sa / np.sqrt(rest.size)
        else:
            sa = 0.02 * float(np.nanmax(np.abs(aa)))
        st = 0.25 * float(np.nanmedian(np.diff(ta))) if table.source == "imu" else 0.0
    return InputUncertainty(
        acc_noise_m_s2=INPUT_SAFETY * sa,
        acc_bias_m_s2=INPUT_SAFETY * sb,
        sync_s=st,
        length_m=LENGTH_SD_M,
        theta0_rad=0.0 if table is not None else max(sm, THETA0_MIN_SD_RAD),
        meas_noise_rad=sm,
        # a fused table: the scale its IMU's agreement with the film measured, and its own error (the
        # smoother's σ, with the spectrum measured on synthetic sessions); one source: the 1 % prior
        acc_scale=acc_scale_sd(table)[0] if table is not None else 0.0,
        acc_fused=1.0 if fused_sigma(table) is not None else 0.0,
    )


def _scale_source(table) -> str:
    """Where the sampled scale sd comes from, and whether the fused table's own error is drawn."""
    from .._validation import acc_scale_sd, fused_sigma

    if table is None:
        return ""
    src = acc_scale_sd(table)[1]
    return src + "; the fused table's own error drawn" if fused_sigma(table) is not None else src


def validate_column(cfg, col, t, th, t0, th0, table, source, *, n=COLUMN_ENSEMBLE_SIZE, seed=0):
    """Judge the column model with 1 and 2 impacts per closing by their ensembles' event sequences.

    Parameters
    ----------
    cfg : ExperimentConfig
    col : rocklab.models.Column
    t, th : ndarray, (m,), (m, L)
        Measured grid (s) and angles (counter-clockwise, rad).
    t0 : float
        Release (or the first sample of a shake-table run), s.
    th0 : ndarray, (L,)
        Start angles, counter-clockwise, rad.
    table : rocklab.series.TableMotion or None
    """
    from .._validation import fused_sigma
    from ...fitting import judge_column, simulate_column_ensemble

    unc = _column_uncertainty(cfg, t, th, t0, table)
    # the span counts from the release, or from when the table starts moving
    t_go = t0 if table is None else max(t0, _table_starts(table))
    keep = (t >= t0 - 0.05) & (t <= t_go + COLUMN_ENSEMBLE_SPAN_S) & np.isfinite(th).all(axis=1)
    tg, yg = t[keep], th[keep]
    tab = (None, None) if table is None else (np.asarray(table.t_s, float), np.asarray(table.ax_m_s2, float))
    alphas = np.array([b.alpha_rad for b in col.blocks])
    laws, bands, secs = {}, {}, 0.0
    for k in sorted({1, 2, int(cfg.column_impacts)}):
        ens = simulate_column_ensemble(
            col, tg, theta0_rad=-np.asarray(th0, float), t_start_s=t0, unc=unc, table_t_s=tab[0],
            table_acc_m_s2=tab[1], n_impacts=k, n=n, meas_offset_rad=THETA0_MIN_SD_RAD, seed=seed,
            table_sigma_m_s2=fused_sigma(table),
        )  # fmt: skip
        secs += ens.seconds
        law = f"impacts_{k}"
        laws[law] = judge_column(tg, -yg, ens, alphas, tol_s=cfg.column_event_tol_s, t_start_s=t0)
        lo, hi = ens.band_rad
        bands[law] = (tg, -hi, -lo)  # the counter-clockwise band
    ref = f"impacts_{int(cfg.column_impacts)}"
    src = _scale_source(table)
    return ColumnValidation(laws[ref].horizon_s, ref, laws, bands, unc.to_dict(), n, secs, src)
