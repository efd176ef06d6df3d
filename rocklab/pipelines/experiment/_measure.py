"""The measurement stages of an experiment: a tracked CSV, a film, IMU logs, the table, the clocks.

Each returns ``(t_s, theta_rad)`` on its own clock (and what else the stage measured);
:func:`rocklab.pipelines.experiment.analyse_experiment` puts them on the primary clock.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..._errors import InputError
from ...series import TableMotion, Tracks, read_tracks
from ...config import ExperimentConfig
from ._review_video import ReviewFilm

__all__: list[str] = []


def read_track_csv(path: Path, obj: str | None):
    """The rows of ``obj`` in a tracked CSV (:class:`rocklab.series.Tracks`), checked.

    A Tracker project (``.trk``, ``.trz``) or a Kinovea spreadsheet is imported on the way: every
    point it marks is one block, ``block_1``, upright in its last frames (``rocklab import``
    groups points into several blocks and takes the other choices).
    """
    if Path(path).suffix.lower() in (".csv", ".parquet"):
        return read_tracks(path).rows(obj, fix="[sources.track] object")
    from ...tracking.imports import PLANE_TOOLS, detect_tool, parse_plane_bodies, plane_tracks, read_plane_points

    tool = detect_tool(path)
    if tool not in PLANE_TOOLS:
        raise InputError(
            f"{path}: [sources.track] takes a tracks.csv, a Tracker project or a Kinovea spreadsheet; "
            f"convert this {tool} file with rocklab import"
        )
    if Path(path).suffix.lower() not in (".trk", ".trz", ".xml"):  # text exports name no unit
        raise InputError(
            f"{path}: a {tool} text export names no length unit; convert it with rocklab import FILE "
            "--units cm -o tracks.csv and give that as [sources.track] path"
        )
    pts = read_plane_points(path, tool)
    rows = plane_tracks(pts, parse_plane_bodies([], pts.labels, pts.source))
    return Tracks.from_frame(rows, path).rows(obj, fix="[sources.track] object")


def _probe_fps(path, given: float | None) -> float:
    """Frame rate for the review film's container, Hz (the timeline uses the tracker's own)."""
    if given:
        return float(given)
    from ...tracking import probe_video

    # the container's own rate (PyAV's packet clock: OpenCV cannot open every film PyAV reads, AV1);
    # a film with none is refused by the tracker, which needs one too
    fps = probe_video(path).fps
    return float(fps) if fps else 50.0


def measure_video(cfg: ExperimentConfig, progress: bool, keep_film: bool):
    from ...config import load_track_config
    from ...tracking import track_video

    tcfg = load_track_config(cfg.video.track_config) if cfg.video.track_config else None
    if tcfg is not None and cfg.video.corrections is not None:  # the experiment's hand fixes win
        from dataclasses import replace

        tcfg = replace(tcfg, video=replace(tcfg.video, corrections=str(cfg.video.corrections)))
    film = ReviewFilm(_probe_fps(cfg.video.path, cfg.video.fps), cfg.video_decimation) if keep_film else None
    tr = track_video(cfg.video.path, tcfg, fps=cfg.video.fps, progress=progress, on_frame=film)
    df = tr.to_frame()
    if cfg.video.object not in set(df["object"]):
        raise InputError(
            f"{cfg.path}: [sources.video] object {cfg.video.object!r} was never tracked in "
            f"{cfg.video.path.name}; objects seen: {sorted(set(df['object']))}"
        )
    table = None
    if cfg.table.source in ("video", "imu") and tcfg is not None and tcfg.table is not None:
        table = tr.table_motion(cfg.table.object)
    review = film.finish() if film is not None else None
    # the samples tracks.csv would give `rocklab fit restitution`: usable statuses only
    return Tracks.from_frame(df).rows(cfg.video.object).theta(), table, tr, review


def measure_imu(cfg: ExperimentConfig):
    from ...tracking import block_rotation, read_imu

    log = read_imu(cfg.imu.path, rate_hz=cfg.imu.rate_hz)
    axis = None if cfg.imu.axis == "auto" else cfg.imu.axis
    rot = block_rotation(log, axis=axis)
    return (np.asarray(rot.t_s, float), np.asarray(rot.theta_rad, float)), rot


def table_from_imu(cfg: ExperimentConfig, video_table: TableMotion | None, msgs: list):
    """Table acceleration from the table IMU, on the video clock when the video tracked the table.

    A 50 fps camera cannot measure a record's table acceleration (content above 25 Hz is lost;
    on a synthetic El Centro run the 50 Hz samples turned a surviving block into an overturning
    one), so the IMU (~256 Hz) drives the simulation; its clock is found by cross-correlating its
    acceleration with the video's (t_imu = t_video + offset + drift t_video).

    Returns
    -------
    table : TableMotion
        The IMU's acceleration; with a video table, on its clock and sense, with the video's
        displacement and velocity interpolated onto the IMU's times.
    sync : rocklab.tracking.SyncResult or None
        The table IMU's clock (None without a video table).
    """
    from ...tracking import read_imu, sync_offset, table_acceleration

    log = read_imu(cfg.table.imu)
    ta = table_acceleration(log, axis=None)
    t, a = np.asarray(ta.t_s, float), np.asarray(ta.acc_m_s2, float)
    if video_table is None:
        msgs.append("table IMU used on its own clock: no tracked table on video to sync it with")
        return TableMotion.from_acceleration(t, a, source="imu", object=cfg.table.object), None
    s = sync_offset(t, a, video_table.t_s, video_table.ax_m_s2, max_offset_s=cfg.max_offset_s)
    # the video's sense of x is the reference: a_video = sign * a_imu
    t_v = (t - s.offset_s) / (1.0 + s.drift)

    def on_imu_times(y):  # displacement and velocity stay the video's
        return np.interp(t_v, video_table.t_s, y, left=np.nan, right=np.nan)

    table = TableMotion(
        t_v, on_imu_times(video_table.x_m), on_imu_times(video_table.vx_m_s), s.sign * a,
        object=video_table.object, source="imu",
    )  # fmt: skip
    return table, s


def sync_clocks(ref, rot, max_offset_s):
    """Clock model t_imu = t_ref + offset + drift * t_ref from the rocking rates."""
    from ...tracking import sync_imu_to_track

    return sync_imu_to_track(rot, ref[0], ref[1], max_offset_s=max_offset_s)
