"""``rocklab run``: one experiment from raw sources to report, figures and ``session.rrd``.

Stages: track video → ingest IMU → sync → compare video vs IMU θ → fit η_e →
simulate with η_H, η_M(k) and η_e (driven by the measured table motion when
there is one; :mod:`._simulate_stage`) → write outputs (:mod:`._report`). The result and its
typed stage results are in :mod:`._result`.

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
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ... import __version__
from ...series import TableMotion
from ...config import ExperimentConfig
from ._config import load_experiment
from ._measure import measure_imu, measure_video, read_track_csv, sync_clocks, table_from_imu
from ._report import write_outputs
from ._stages import ClockSync, ExperimentResult, FitStage
from ._simulate_stage import compare_truth, simulate_laws

__all__ = ["ExperimentResult", "run_experiment", "analyse_experiment", "fingerprint"]


def fingerprint(cfg: ExperimentConfig) -> str:
    """SHA-256 over the rocklab version, the config text and every input file's bytes."""
    h = hashlib.sha256(__version__.encode())
    for p in cfg.input_files():
        h.update(str(p.name).encode())
        with open(p, "rb") as f:
            for chunk in iter(lambda: f.read(1 << 20), b""):
                h.update(chunk)
    return h.hexdigest()


@dataclass(frozen=True)
class _Measured:
    """What the measurement stages give the analysis (every series on the primary clock)."""

    measured: dict
    table: TableMotion | None
    tracked: object  # rocklab.tracking.TrackResult of the video, or None
    film: object  # the review film, or None
    track_rows: object  # rocklab.series.Tracks of [sources.track], or None
    sync: ClockSync | None
    residual: tuple | None
    table_sync: object  # rocklab.tracking.SyncResult of the table IMU, or None
    table_fusion: object = None  # rocklab.tracking.TableFusion (table IMU and film), or None


def _measure(cfg: ExperimentConfig, progress: bool, keep_video: bool | None, msgs: list, timings: dict) -> _Measured:
    """Track the film, read the track and the IMU logs, find the table motion, sync the clocks."""
    measured: dict = {}
    table = tr = track_rows = film = None
    t0 = time.perf_counter()
    if cfg.video is not None:
        keep = cfg.rrd if keep_video is None else keep_video
        measured["video"], table, tr, film = measure_video(cfg, progress, keep_film=keep)
        if film is not None and film.kind != "av1":
            msgs.append(f"review video: {film.note}")
        timings["track_s"] = time.perf_counter() - t0
    if cfg.track is not None:
        track_rows = read_track_csv(cfg.track.path, cfg.track.object)
        measured["track"] = track_rows.theta()  # the samples `rocklab fit restitution` fits
    rot = None
    if cfg.imu is not None:
        t1 = time.perf_counter()
        measured["imu"], rot = measure_imu(cfg)
        timings["imu_s"] = time.perf_counter() - t1
    table_sync = fusion = None
    if cfg.table.source == "imu":
        table, table_sync, fusion = table_from_imu(cfg, table, msgs)
    elif cfg.table.source == "record":
        from ...models import load_base_motion

        bm = load_base_motion(cfg.table.record, units=cfg.table.units, default_units="g")
        table = TableMotion.from_acceleration(bm.t_s, bm.acc_m_s2, source="record", object=cfg.table.object)

    imu_sync = residual = None
    if "imu" in measured and ("video" in measured or "track" in measured) and cfg.sync_method == "xcorr":
        ref = measured.get("video") or measured.get("track")
        imu_sync = s = sync_clocks(ref, rot, cfg.max_offset_s)
        ti, thi = measured["imu"]
        # invert t_imu = t_ref + offset + drift t_ref: the IMU series on the reference clock;
        # sign -1: the IMU's axis points the other way from the camera's θ convention
        thi = s.sign * np.asarray(thi)
        measured["imu"] = ((ti - s.offset_s) / (1.0 + s.drift), thi)
        tv, thv = ref
        thi_on_v = np.interp(tv, measured["imu"][0], thi, left=np.nan, right=np.nan)
        residual = (tv, thv - thi_on_v)
    sync = ClockSync(imu_sync, table_sync) if imu_sync is not None or table_sync is not None else None
    return _Measured(measured, table, tr, film, track_rows, sync, residual, table_sync, fusion)


def _fit_free(cfg, block, prim, audit, msgs: list, timings: dict) -> FitStage:
    """η_e of a free-rocking run (thread-burn release), with the impacts the audit flagged."""
    from ...fitting import fit_restitution
    from ._audit_stage import fit_exclusions

    t2 = time.perf_counter()
    n_lost = int((~np.isfinite(prim[1])).sum())
    if n_lost:  # frames the tracker flagged as lost stay NaN: skip them, never invent them
        msgs.append(f"{n_lost} samples of the {cfg.primary} θ are NaN (lost target) and were skipped by the fit")
    fit = fit_restitution(prim[0], prim[1], block, window=cfg.fit_window, nan="skip")
    timings["fit_s"] = time.perf_counter() - t2
    # flagged by the audit: not to trust
    return FitStage(fit, excluded_impacts=fit_exclusions(audit, fit.per_impact))


def analyse_experiment(
    cfg: ExperimentConfig, progress: bool = False, keep_video: bool | None = None
) -> ExperimentResult:
    """Run every stage of one experiment in memory (no files written).

    ``keep_video``: encode the review film (every frame, AV1) while the frames are decoded for
    tracking (default: when the config writes ``session.rrd``).
    """
    msgs: list[str] = []
    timings: dict[str, float] = {}
    m = _measure(cfg, progress, keep_video, msgs, timings)
    block = cfg.block()
    status = "ok"
    shared = dict(
        name=cfg.name,
        config=cfg,
        block=block,
        measured=m.measured,
        primary=cfg.primary,
        sync=m.sync,
        video_imu_residual=m.residual,
        table=m.table,
        table_fusion=m.table_fusion,
        messages=msgs,
        timings_s=timings,
        frames=m.tracked,
        video=m.film,
    )
    if cfg.columns:
        from ._column_run import analyse_column

        t3 = time.perf_counter()
        column = analyse_column(cfg, m.tracked, m.table, cfg.truth, msgs)
        timings["column_s"] = time.perf_counter() - t3
        if cfg.primary not in m.measured:  # levels measured by their IMUs alone: the bottom level's clock
            shared["measured"] = {cfg.primary: (column.t_s, column.theta_measured_rad[:, 0]), **m.measured}
        return ExperimentResult(
            **shared, fit=None, per_impact_eta=np.empty(0), simulations={}, truth=None, status=status, column=column
        )
    prim = m.measured[cfg.primary]
    from ._audit_stage import audit_experiment

    audit = audit_experiment(cfg, m.measured, m.tracked, m.track_rows)
    fit = None
    forced = m.table is not None
    energy_loss = None
    if cfg.fit_restitution and not forced:
        fit = _fit_free(cfg, block, prim, audit, msgs, timings)
        if fit.status == "failed":
            status = "partial"
            msgs.append(f"restitution fit failed: {fit.message}")
        energy_loss = _energy_loss(block, prim, msgs)
    prep = validation = None
    if forced:  # a free-rocking fit means nothing under a moving table: η_e from half cycles instead
        from .._validation import prepare_forced, validate_forced_run

        t2 = time.perf_counter()
        prep = prepare_forced(cfg, block, prim, m.table, m.table_sync, msgs)
        timings["fit_s"] = time.perf_counter() - t2
        if prep is not None and cfg.fit_restitution:
            fit = FitStage(prep.fit)  # per impact: the impact of each half cycle
            status = "partial" if fit.status == "failed" else status
    t3 = time.perf_counter()
    # a block resting on the table before the shaking starts flat, not at the tracker's offset
    sims = simulate_laws(cfg, block, prim, fit, m.table, msgs, None if prep is None else prep.theta0_rad)
    timings["simulate_s"] = time.perf_counter() - t3
    if prep is not None and sims:
        t4 = time.perf_counter()
        validation = validate_forced_run(prep, block, {law: s.eta for law, s in sims.items()})
        timings["validation_s"] = time.perf_counter() - t4
    truth = compare_truth(cfg, prim, m.table) if cfg.truth is not None else None
    return ExperimentResult(
        **shared,
        fit=fit,
        per_impact_eta=np.empty(0) if fit is None else fit.per_impact_eta,
        simulations=sims,
        truth=truth,
        status=status,
        audit=audit,
        validation=validation,
        energy_loss=energy_loss,
    )


def _energy_loss(block, prim, msgs: list):
    """Ther's Eq. 12 on the free rocking: the mean energy loss of the first four rockings after
    release, from the peaks of θ (None, with a note, when the record has fewer than five peaks)."""
    from ..._errors import InputError
    from ...fitting import energy_loss_from_peaks

    ok = np.isfinite(prim[1])
    try:
        return energy_loss_from_peaks(prim[0][ok], prim[1][ok], block)
    except InputError as e:
        msgs.append(f"energy loss (thesis Eq. 12) not computed: {e}")
        return None


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

    Parameters
    ----------
    config_path : path
        The experiment's ``experiment.toml``.
    out_dir : path
        Output folder (``report.json``, ``summary.md``, ``series.csv``, ``figures/``,
        ``session.rrd``); an existing rocklab output is replaced only when its inputs changed.
    force : bool
        Run even when the inputs and config are unchanged.
    spawn, connect : bool, str
        Also stream the review to a new Rerun viewer, or to one at this address.
    progress : bool
        Progress bars on stderr.

    Returns
    -------
    report : dict
        The content of ``report.json``.
    ran : bool
        False when the inputs and config were unchanged and nothing was done.

    Examples
    --------
    A rendered free-rocking session (the truth is η = 0.75), tracked, fitted and simulated:

    >>> import pathlib, tempfile
    >>> from rocklab.synth import synth_session
    >>> from rocklab.pipelines import run_experiment
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> s = synth_session(d / "s", seed=1, size=(480, 270), duration_s=3.0, mp4=False, imu=False)
    >>> report, ran = run_experiment(d / "s" / "experiment.toml", d / "out")
    >>> report["status"], round(report["fit"]["eta_e"], 3), ran
    ('ok', 0.75, True)
    >>> run_experiment(d / "s" / "experiment.toml", d / "out")[1]  # unchanged inputs: nothing to do
    False
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
