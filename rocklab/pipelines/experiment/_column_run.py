"""Column experiments in ``rocklab run`` (thesis §4.3): tracked blocks vs the column model.

The blocks' angles come from video (counter-clockwise as the camera sees them);
the column model (clockwise positive, like :func:`rocklab.models.simulate`) is
driven by the table acceleration measured on video or IMU, and the two are
compared block by block and by their opening/closing sequence (which joint
opens when, in which direction).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..._errors import InputError
from ...series import TableMotion

__all__ = ["analyse_column", "base_from_table"]


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


def analyse_column(cfg, track_result, table, truth_path=None):
    """Simulate the column under the measured table motion and compare with the tracked blocks.

    Returns a :class:`rocklab.pipelines.experiment._stages.ColumnStage` (with a truth file, its
    ``theta_truth``, ``sequence_vs_truth`` and ``theta_rms_error_rad`` too).
    """
    from ._stages import ColumnStage

    import pandas as pd

    from ...models import Column, compare_sequences, compare_to_measurement, joint_sequence, simulate_column

    objs = cfg.columns
    t, th = _by_object(track_result.to_frame(), objs)
    ok_t = np.isfinite(th).all(axis=1)
    if not ok_t.any():
        raise InputError(f"{cfg.path}: the column blocks are never tracked together")
    t0 = float(t[ok_t][0])
    col = Column([cfg.block()] * len(objs), cut_m=cfg.column_cut_m)
    base = base_from_table(table, t0, str(cfg.path)) if table is not None else None
    # 1 ms samples: far finer than any camera, and they feed only interpolation to the frame
    # times, plots and Rerun (the events are exact at any spacing); every 0.1 ms step would be 10x the rows
    res = simulate_column(
        col, base, duration_s=float(t[-1] - t0), n_impacts=cfg.column_impacts, dt_s=1e-4, output_dt_s=1e-3
    )
    # measured angles are counter-clockwise, the model's clockwise: sign = -1
    comp = compare_to_measurement(res, t - t0, th, sign=-1.0)
    confs = res.configurations.copy()
    confs["t_s"] = confs["t_s"] + t0
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
    )
    if truth_path is not None:
        tr = pd.read_csv(truth_path)
        tt, tth = _by_object(tr[tr["object"].isin(objs)], objs)
        # which joint opens when, from the tracked angles vs from the rendered truth (thesis Fig. 32)
        mseq = joint_sequence(t - t0, -th)
        tseq = joint_sequence(tt - t0, -tth)
        err = th - np.column_stack([np.interp(t, tt, tth[:, i]) for i in range(len(objs))])
        out = dataclasses.replace(
            out,
            theta_truth=(tt, tth),
            sequence_vs_truth=compare_sequences(tseq, mseq),
            theta_rms_error_rad=np.sqrt(np.nanmean(err**2, axis=0)).tolist(),
        )
    return out
