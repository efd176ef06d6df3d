"""The simulation stage of an experiment: each restitution law's η, its simulation of the
measured run, and the comparison with a synthetic session's truth."""

from __future__ import annotations

import json

import numpy as np

from ...series import TableMotion
from ._stages import FitStage, LawSimulation, TruthComparison

__all__ = ["simulate_laws", "compare_truth"]


def _eta_for_law(law: str, cfg, block, fit: FitStage | None, msgs: list) -> float | None:
    if law == "housner":
        return block.eta_H
    if law == "given":
        return cfg.eta_given
    if law in ("eta_e", "eta_e_first"):
        return None if fit is None else fit.law_eta(law)
    if law in ("axes", "cut_corner", "bumps"):  # thesis App. A: the contact's geometry sets η
        from ...models import make_restitution

        params = {"axes": dict(x1_m=cfg.x1_m, x2_m=cfg.x2_m), "bumps": dict(n=cfg.bumps_n, b2_m=cfg.b2_m)}
        return float(make_restitution(law, block, **params.get(law, dict(b2_m=cfg.b2_m))).eta)
    if law == "modified":
        from ...fitting import KRegression, edge_contact_k, eta_modified

        if cfg.k is not None:
            k = cfg.k
        elif cfg.contact == "edge":
            k = edge_contact_k(cfg.b_m, cfg.l_c_m)
        else:
            pk = KRegression.ceh2018().predict(cfg.h_m / cfg.b_m, cfg.b_m)
            k = pk.k
            if pk.extrapolated:
                msgs.append(f"k = {k:.3f} from Čeh Eq. 19 is extrapolated for this block: {pk.message}")
        return float(eta_modified(block.alpha_rad, k))
    raise AssertionError(law)


def simulate_laws(
    cfg, block, prim, fit: FitStage | None, table: TableMotion | None, msgs: list, theta0_rad=None
) -> dict:
    """Simulate the run with every law of ``cfg.laws``.

    Parameters
    ----------
    cfg : ExperimentConfig
    block : rocklab.Block
    prim : (t_s, theta_rad)
        The primary measurement, shape (n,) each; θ NaN where not usable.
    fit : FitStage or None
        The η_e fit (its release starts a free run).
    table : TableMotion or None
        The measured table: its mirrored acceleration drives the simulation.
    msgs : list
        Notes are appended.
    theta0_rad : float, optional
        The start angle of a forced run (default: θ at the first valid sample).

    Returns
    -------
    dict[str, LawSimulation]
    """
    from ...models import simulate

    t_meas, th_meas = prim
    ok = np.isfinite(th_meas)
    release = None if fit is None else fit.release()
    if table is None and release is not None:  # thread-burn release as fitted
        theta0, t_rel = release
    else:  # forced run or no fit: start at the first valid sample, θ measured there
        theta0, t_rel = float(th_meas[ok][0]) if theta0_rad is None else theta0_rad, float(t_meas[ok][0])
    dur = cfg.duration_s or float(np.nanmax(t_meas) - t_rel)
    base = None
    if table is not None:
        from ._column_run import base_from_table

        # Measured θ is counter-clockwise as the camera sees it, table x to the camera's right;
        # the simulator's θ is clockwise (Čeh Eq. 1-2). φ = -θ obeys the same equation with base
        # -ü, so simulating with the mirrored table acceleration gives θ in the measurement's sense.
        base = base_from_table(table, t_rel, str(cfg.path), sign=-1.0)
    sims = {}
    for law in cfg.laws:
        eta = _eta_for_law(law, cfg, block, fit, msgs)
        if eta is None:
            msgs.append(f"simulation with {law} skipped: no fitted value")
            continue
        if abs(theta0) >= block.alpha_rad:
            msgs.append(f"simulation skipped: θ0 = {theta0:.4f} rad is not below α")
            break
        r = simulate(
            block,
            theta0_rad=theta0,
            duration_s=max(dur, 1e-3),
            dt_s=1e-4,
            restitution="constant",
            eta=eta,
            base=base,
            output_dt_s=1e-3,
        )
        ts = np.asarray(r.t_s) + t_rel
        th_on_meas = np.interp(t_meas, ts, np.asarray(r.theta_rad), left=np.nan, right=np.nan)
        w = ok & (t_meas >= t_rel) & np.isfinite(th_on_meas)
        rms = float(np.sqrt(np.mean((th_meas[w] - th_on_meas[w]) ** 2))) if w.any() else None
        imp = r.impacts.copy()
        imp["t_s"] = imp["t_s"] + t_rel
        sims[law] = LawSimulation(
            law=law,
            eta=eta,
            t_s=ts,
            theta_rad=np.asarray(r.theta_rad),
            energy_J=np.asarray(r.energy_J),
            impacts=imp,
            status=r.status,
            rms_vs_measured_rad=rms,
        )
    return sims


def compare_truth(cfg, prim, table=None) -> TruthComparison:
    """The session's truth for the measured object (``cfg.truth``, ``session.json`` beside it)
    and the RMS of the primary measurement ``prim`` against it (and of the measured ``table``'s
    acceleration against the truth's ``table`` rows, when both exist)."""
    import pandas as pd

    df = pd.read_csv(cfg.truth)
    table_err = _table_error(df, table)
    obj = cfg.video.object if cfg.video else (cfg.track.object if cfg.track else None)
    if obj is not None and "object" in df.columns:
        df = df[df["object"] == obj]
    t, th = df["t_s"].to_numpy(float), df["theta_rad"].to_numpy(float)
    meas = np.interp(t, prim[0], prim[1], left=np.nan, right=np.nan)
    err = meas - th
    sess = cfg.truth.parent / "session.json"
    eta = None
    if sess.is_file():
        meta = json.loads(sess.read_text())
        eta = meta.get("eta")
        for blk in meta.get("blocks", []):  # rocklab synth sessions
            if blk.get("id") == obj:
                eta = blk.get("eta_true", eta)
    rms = float(np.sqrt(np.nanmean(err**2))) if np.isfinite(err).any() else None
    return TruthComparison(t_s=t, theta_rad=th, eta=eta, theta_rms_error_rad=rms, table_acc_rms_error_rel=table_err)


def _table_error(df, table) -> float | None:
    """RMS of the measured table acceleration minus the truth's, over the truth's RMS, where both
    exist (the truth's frames), -; None without a table in either, or for a table not on the film's
    clock (an IMU alone, a record). The measurement is read at the frames by a cubic spline, as
    :func:`base_from_table` resamples it for the simulations (linear interpolation of a 256 Hz
    record adds 0.7 % of El Centro's RMS)."""
    from scipy.interpolate import CubicSpline

    if table is None or table.source not in ("fused", "video") or "object" not in df.columns:
        return None
    if "ax_m_s2" not in df.columns:
        return None
    tb = df[df["object"] == table.object]
    ta, aa = np.asarray(table.t_s, float), np.asarray(table.ax_m_s2, float)
    fin = np.isfinite(aa)
    if tb.empty or fin.sum() < 4:
        return None
    t, a_true = tb["t_s"].to_numpy(float), tb["ax_m_s2"].to_numpy(float)
    # only between two measured samples: a spline across a gap would invent the table there
    inside = np.interp(t, ta, fin.astype(float), left=0.0, right=0.0) == 1.0
    a = np.where(inside, CubicSpline(ta[fin], aa[fin])(np.clip(t, ta[fin][0], ta[fin][-1])), np.nan)
    ok = np.isfinite(a) & np.isfinite(a_true)
    den = float(np.sqrt(np.mean(a_true[ok] ** 2))) if ok.any() else 0.0
    return float(np.sqrt(np.mean((a[ok] - a_true[ok]) ** 2)) / den) if den > 0 else None
