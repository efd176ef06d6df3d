"""``rocklab run``: one experiment from raw sources to report, figures and ``session.rrd``.

Stages: track video → ingest IMU → sync → compare video vs IMU θ → fit η_e →
simulate with η_H, η_M(k) and η_e (driven by the measured table motion when
there is one) → write outputs.

Outputs are staged in a hidden sibling folder and swapped into place at the
end, so a failure leaves no partial output. A fingerprint of the inputs and
the config is stored in ``report.json``; re-running with the same inputs is a
no-op unless ``force=True``.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import shutil
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ... import __version__
from ._config import ExperimentConfig, load_experiment
from ._measure import _measure_imu, _measure_video, _read_track_csv, _sync, _table_from_imu
from ._report import write_outputs

__all__ = ["ExperimentResult", "run_experiment", "analyse_experiment", "fingerprint"]


@dataclass(frozen=True)
class ExperimentResult:
    """Everything one experiment produced. SI units; θ in rad, t in s.

    Attributes
    ----------
    name : str
    config : ExperimentConfig
    block : rocklab.Block
    measured : dict[str, tuple[ndarray, ndarray]]
        Source name ("video", "imu", "track") → (t_s, theta_rad), on the primary clock.
    primary : str
        The source the fit used.
    sync : dict or None
        ``offset_s, drift, residual_ms`` of the IMU relative to the video.
    video_imu_residual : (t_s, residual_rad) or None
    fit : dict or None
        :meth:`RestitutionFit.to_dict` of the η_e fit.
    per_impact_eta : ndarray
    simulations : dict[str, dict]
        Law → {t_s, theta_rad, energy_J, eta, impacts (DataFrame), status}.
    table : dict or None
        Table motion {t_s, disp_m, vel_m_s, acc_m_s2}.
    truth : dict or None
        Synthetic truth {t_s, theta_rad, eta} when the session has one.
    status : str
        "ok", "failed" or "partial".
    messages : list[str]
        What went wrong or was noticed, one line each.
    """

    name: str
    config: ExperimentConfig
    block: object
    measured: dict
    primary: str
    sync: dict | None
    video_imu_residual: tuple | None
    fit: dict | None
    per_impact_eta: np.ndarray
    simulations: dict
    table: dict | None
    truth: dict | None
    status: str
    messages: list = field(default_factory=list)
    timings_s: dict = field(default_factory=dict)
    frames: object = None  # optional per-frame overlay data from the tracker
    column: dict | None = None  # column experiments: see rocklab.pipelines.experiment._column_run
    video: object = None  # the review film (rocklab.pipelines.experiment._review_video.ReviewVideo)
    diagnostics: tuple = ()  # rocklab._diagnostics.Diagnostic raised while analysing
    audit: dict | None = None  # rocklab.pipelines.experiment._audit_stage.audit_experiment
    validation: object = None  # base-excited runs: rocklab.pipelines._validation.Validation

    def to_dict(self) -> dict:
        """The numbers of ``report.json`` (units in keys)."""
        b = self.block
        d = {
            "name": self.name,
            "status": self.status,
            "messages": list(self.messages),
            "warnings": [d.to_dict() for d in self.diagnostics],
            "block": {k: v for k, v in b.to_dict().items()},
            "contact": {"type": self.config.contact, "l_c_m": self.config.l_c_m, "k": self.config.k},
            "primary_source": self.primary,
            "sources": sorted(self.measured),
            "track_corrections": list(getattr(self.frames, "corrections", ())),
            "sync": self.sync,
            "video_vs_imu_rms_rad": (
                float(np.sqrt(np.nanmean(np.square(self.video_imu_residual[1]))))
                if self.video_imu_residual is not None
                else None
            ),
            "fit": self.fit,
            "audit": self.audit,
            "per_impact_eta": [float(x) for x in self.per_impact_eta],
            "simulations": {
                law: {
                    "eta": float(s["eta"]),
                    "status": s.get("status"),
                    "n_impacts": int(len(s["impacts"])) if s.get("impacts") is not None else 0,
                    "rms_vs_measured_rad": s.get("rms_vs_measured_rad"),
                }
                for law, s in self.simulations.items()
            },
            "table": None
            if self.table is None
            else {
                "peak_disp_m": float(np.nanmax(np.abs(self.table["disp_m"]))) if "disp_m" in self.table else None,
                "peak_acc_m_s2": float(np.nanmax(np.abs(self.table["acc_m_s2"]))),
            },
            "truth": None
            if self.truth is None
            else {"eta": self.truth.get("eta"), "theta_rms_error_rad": self.truth.get("theta_rms_error_rad")},
            "column": None
            if self.column is None
            else {
                k: self.column[k]
                for k in (
                    "objects",
                    "status",
                    "comparison",
                    "cut_m",
                    "impacts_per_closing",
                    "sequence_vs_truth",
                    "theta_rms_error_rad",
                )
                if k in self.column
            },
            "review_video": None
            if self.video is None
            else {
                "kind": self.video.kind,
                "frames": len(self.video.frame_index),
                "bytes": self.video.n_bytes,
                "note": self.video.note,
            },
            "validation": None if self.validation is None else self.validation.to_dict(),
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


def fingerprint(cfg: ExperimentConfig) -> str:
    """SHA-256 over the rocklab version, the config text and every input file's bytes."""
    h = hashlib.sha256(__version__.encode())
    for p in cfg.input_files():
        h.update(str(p.name).encode())
        with open(p, "rb") as f:
            for chunk in iter(lambda: f.read(1 << 20), b""):
                h.update(chunk)
    return h.hexdigest()


# ---------------------------------------------------------------------------
# measurement stages


def analyse_experiment(
    cfg: ExperimentConfig, progress: bool = False, keep_video: bool | None = None
) -> ExperimentResult:
    """Run every stage of one experiment in memory (no files written).

    ``keep_video``: encode the review film (every frame, AV1) while the frames are decoded for
    tracking (default: when the config writes ``session.rrd``).
    """
    msgs: list[str] = []
    timings: dict[str, float] = {}
    measured: dict = {}
    table = None
    tr = None
    track_rows = None
    film = None
    t0 = time.perf_counter()
    if cfg.video is not None:
        keep = cfg.rrd if keep_video is None else keep_video
        measured["video"], table, tr, film = _measure_video(cfg, progress, keep_film=keep)
        if film is not None and film.kind != "av1":
            msgs.append(f"review video: {film.note}")
        timings["track_s"] = time.perf_counter() - t0
    if cfg.track is not None:
        track_rows = _read_track_csv(cfg.track.path, cfg.track.object)
        measured["track"] = track_rows.theta()  # the samples `rocklab fit restitution` fits
    rot = None
    if cfg.imu is not None:
        t1 = time.perf_counter()
        measured["imu"], rot = _measure_imu(cfg)
        timings["imu_s"] = time.perf_counter() - t1
    table_sync = None
    if cfg.table.source == "imu":
        table, table_sync = _table_from_imu(cfg, table, msgs)
    elif cfg.table.source == "record":
        from ...models import load_base_motion

        bm = load_base_motion(cfg.table.record, units=cfg.table.units, default_units="g")
        table = {"t_s": bm.t_s, "acc_m_s2": bm.acc_m_s2}

    sync = None
    residual = None
    if "imu" in measured and ("video" in measured or "track" in measured) and cfg.sync_method == "xcorr":
        ref = measured.get("video") or measured.get("track")
        s = _sync(ref, rot, cfg.max_offset_s)
        sync = s.to_dict()
        ti, thi = measured["imu"]
        # invert t_imu = t_ref + offset + drift t_ref: the IMU series on the reference clock;
        # sign -1: the IMU's axis points the other way from the camera's θ convention
        thi = s.sign * np.asarray(thi)
        measured["imu"] = ((ti - s.offset_s) / (1.0 + s.drift), thi)
        tv, thv = ref
        thi_on_v = np.interp(tv, measured["imu"][0], thi, left=np.nan, right=np.nan)
        residual = (tv, thv - thi_on_v)

    if table_sync is not None:
        sync = dict(sync or {}, table_imu=table_sync)
    block = cfg.block()
    prim = measured[cfg.primary]
    fit_d = None
    per_imp = np.empty(0)
    sims: dict = {}
    status = "ok"
    column = None

    def result(**kw):
        """The result with what every path shares (read when called: the stages fill them in)."""
        return ExperimentResult(
            name=cfg.name,
            config=cfg,
            block=block,
            measured=measured,
            primary=cfg.primary,
            sync=sync,
            video_imu_residual=residual,
            per_impact_eta=per_imp,
            table=table,
            messages=msgs,
            timings_s=timings,
            frames=tr,
            video=film,
            **kw,
        )

    if cfg.columns:
        from ._column_run import analyse_column

        t3 = time.perf_counter()
        column = analyse_column(cfg, tr, table, cfg.truth)
        timings["column_s"] = time.perf_counter() - t3
        return result(fit=None, simulations={}, truth=None, status=status, column=column)
    from ._audit_stage import audit_experiment

    audit = audit_experiment(cfg, measured, tr, track_rows)
    forced = table is not None and "acc_m_s2" in table
    if cfg.fit_restitution and not forced:
        from ...fitting import fit_restitution

        t2 = time.perf_counter()
        n_lost = int((~np.isfinite(prim[1])).sum())
        if n_lost:  # frames the tracker flagged as lost stay NaN: skip them, never invent them
            msgs.append(f"{n_lost} samples of the {cfg.primary} θ are NaN (lost target) and were skipped by the fit")
        fit = fit_restitution(prim[0], prim[1], block, window=cfg.fit_window, nan="skip")
        timings["fit_s"] = time.perf_counter() - t2
        fit_d = fit.to_dict()
        from ._audit_stage import fit_exclusions

        fit_d["excluded_impacts"] = fit_exclusions(audit, fit.per_impact)  # flagged by the audit: not to trust
        per_imp = np.asarray(fit_d.get("per_impact_eta") or [], float)
        if fit_d.get("status") == "failed":
            status = "partial"
            msgs.append(f"restitution fit failed: {fit_d.get('message')}")
    prep = validation = None
    if forced:  # a free-rocking fit means nothing under a moving table: η_e from half cycles instead
        from .._validation import prepare_forced, validate_forced_run

        t2 = time.perf_counter()
        prep = prepare_forced(cfg, block, prim, table, table_sync, msgs)
        timings["fit_s"] = time.perf_counter() - t2
        if prep is not None and cfg.fit_restitution:
            fit_d = prep.fit.to_dict()
            per_imp = np.asarray(fit_d["segment_eta"], float)  # the impact of each half cycle
            status = "partial" if fit_d["status"] == "failed" else status
    t3 = time.perf_counter()
    # a block resting on the table before the shaking starts flat, not at the tracker's offset
    sims = _simulate_laws(cfg, block, prim, fit_d, table, msgs, None if prep is None else prep.theta0_rad)
    timings["simulate_s"] = time.perf_counter() - t3
    if prep is not None and sims:
        t4 = time.perf_counter()
        validation = validate_forced_run(prep, block, {law: s["eta"] for law, s in sims.items()})
        timings["validation_s"] = time.perf_counter() - t4

    truth = None
    if cfg.truth is not None:
        truth = _truth(cfg, prim, msgs)
    return result(fit=fit_d, simulations=sims, truth=truth, status=status, audit=audit, validation=validation)


def _eta_for_law(law, cfg, block, fit_d, msgs):
    if law == "housner":
        return block.eta_H
    if law == "given":
        return cfg.eta_given
    if law in ("eta_e", "eta_e_first"):
        key = "eta_e" if law == "eta_e" else "eta_e_first"
        v = (fit_d or {}).get(key)
        return float(v) if v is not None and np.isfinite(v) else None
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


def _simulate_laws(cfg, block, prim, fit_d, table, msgs, theta0_rad=None) -> dict:
    from ...models import simulate

    t_meas, th_meas = prim
    ok = np.isfinite(th_meas)
    fit_ok = fit_d and all(
        np.isfinite(fit_d.get(k) if fit_d.get(k) is not None else np.nan) for k in ("theta0_rad", "release_t_s")
    )
    if table is None and fit_ok:  # thread-burn release as fitted
        theta0, t_rel = float(fit_d["theta0_rad"]), float(fit_d["release_t_s"])
    else:  # forced run or no fit: start at the first valid sample, θ measured there
        theta0, t_rel = float(th_meas[ok][0]) if theta0_rad is None else theta0_rad, float(t_meas[ok][0])
    dur = cfg.duration_s or float(np.nanmax(t_meas) - t_rel)
    base = None
    if table is not None and "acc_m_s2" in table:
        from ._column_run import base_from_table

        # Measured θ is counter-clockwise as the camera sees it, table x to the camera's right;
        # the simulator's θ is clockwise (Čeh Eq. 1-2). φ = -θ obeys the same equation with base
        # -ü, so simulating with the mirrored table acceleration gives θ in the measurement's sense.
        base = base_from_table(table, t_rel, str(cfg.path), sign=-1.0)
    sims = {}
    for law in cfg.laws:
        eta = _eta_for_law(law, cfg, block, fit_d, msgs)
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
        sims[law] = {
            "t_s": ts,
            "theta_rad": np.asarray(r.theta_rad),
            "energy_J": np.asarray(r.energy_J),
            "eta": eta,
            "impacts": imp,
            "status": r.status,
            "rms_vs_measured_rad": rms,
        }
    return sims


def _truth(cfg, prim, msgs):
    import pandas as pd

    df = pd.read_csv(cfg.truth)
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
    return {
        "t_s": t,
        "theta_rad": th,
        "eta": eta,
        "theta_rms_error_rad": float(np.sqrt(np.nanmean(err**2))) if np.isfinite(err).any() else None,
    }


def run_experiment(
    config_path,
    out_dir,
    *,
    force: bool = False,
    spawn: bool = False,
    connect: str | None = None,
    progress: bool = False,
) -> tuple[dict, bool]:
    """Run one experiment and write its outputs into ``out_dir`` atomically.

    Returns
    -------
    report : dict
        The content of ``report.json``.
    ran : bool
        False when the inputs and config were unchanged and nothing was done.
    """
    from ..._outdir import check_output_dir, publish_dir, stage_dir

    from ..._inputs import check_folder_keeps_inputs

    cfg = load_experiment(config_path)
    out_dir = check_output_dir(out_dir, force=force, need_bytes=_space_needed(cfg))
    check_folder_keeps_inputs(out_dir, [("source", p) for p in cfg.input_files()])
    fp = fingerprint(cfg)
    rep_path = out_dir / "report.json"
    if not force and rep_path.is_file():
        try:
            old = json.loads(rep_path.read_text())
        except (OSError, json.JSONDecodeError):
            old = {}
        if old.get("fingerprint") == fp:
            return old, False
    from ..._diagnostics import collecting, stderr_echo, worst_status

    # in a campaign worker no CLI collector is active: the run prints its own warnings
    with collecting(echo=stderr_echo("run")) as diags:
        res = analyse_experiment(cfg, progress=progress, keep_video=cfg.rrd or spawn or bool(connect))
    if diags:
        res = dataclasses.replace(res, status=worst_status(res.status, diags), diagnostics=tuple(diags))
    stage = stage_dir(out_dir)
    try:
        report = write_outputs(res, stage, fp, spawn=spawn, connect=connect, progress=progress)
        publish_dir(stage, out_dir, command="run")
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise
    return report, True


def _space_needed(cfg: ExperimentConfig) -> int:
    """Bytes an experiment's outputs may take: 20 MB of tables and figures plus, for the Rerun
    recording, at most half the size of the video (the AV1 review film is far smaller)."""
    need = 20 * 1024 * 1024
    if cfg.rrd and cfg.video is not None:
        try:
            need += Path(cfg.video.path).stat().st_size // 2
        except OSError:
            pass
    return need
