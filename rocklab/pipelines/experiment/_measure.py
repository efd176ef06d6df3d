"""The measurement stages of an experiment: a tracked CSV, a film, IMU logs, the table, the clocks.

Each returns ``(t_s, theta_rad)`` on its own clock (and what else the stage measured);
:func:`rocklab.pipelines.experiment.analyse_experiment` puts them on the primary clock.
"""

from __future__ import annotations

from dataclasses import dataclass
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
    """Table motion from the table IMU, fused with the video's when the video tracked the table.

    A 50 fps camera cannot measure a record's table acceleration (content above 25 Hz is lost;
    on a synthetic El Centro run the 50 Hz samples turned a surviving block into an overturning
    one), and a table IMU's is noisy (5 mg) and offset by any tilt. With a video table, gravity's
    leak through the table's tilt is taken out by the IMU's gyro (``level=True``), the IMU's clock
    is found by cross-correlating its acceleration with the video's (t_imu = t_video + offset +
    drift t_video) and the two are fused (:func:`rocklab.tracking.fuse_table_motion`: the film's
    displacement below a few hertz, the IMU's acceleration above, each sample's σ).

    Returns
    -------
    table : TableMotion
        ``source="fused"`` on the video's clock and sense; ``"imu"`` on the IMU's clock without a
        video table.
    sync : rocklab.tracking.SyncResult or None
        The table IMU's clock (None without a video table).
    fusion : rocklab.tracking.TableFusion or None
        The fusion's noises, the IMU's offset and the sources' agreement (None without a video table).
    """
    from ...tracking import read_imu, table_acceleration

    log = read_imu(cfg.table.imu)
    # with a film to pin its drift, the gyro takes gravity's leak through a pitching table out
    ta = table_acceleration(log, axis=None, level=video_table is not None)
    t, a = np.asarray(ta.t_s, float), np.asarray(ta.acc_m_s2, float)
    if video_table is None:
        msgs.append("table IMU used on its own clock: no tracked table on video to sync it with")
        return TableMotion.from_acceleration(t, a, source="imu", object=cfg.table.object), None, None
    return fuse_with_video(t, a, video_table, cfg.max_offset_s, label=f"{cfg.path}: table")


def fuse_with_video(t_imu_s, acc_m_s2, video_table: TableMotion, max_offset_s: float, label: str = "table"):
    """Sync a table IMU's acceleration to the video's table (``t_imu = t_video + offset + drift
    t_video``, the video's sense of x) and fuse the two: ``(TableMotion, SyncResult, TableFusion)``."""
    from ...tracking import fuse_table_motion, sync_offset

    s = sync_offset(t_imu_s, acc_m_s2, video_table.t_s, video_table.ax_m_s2, max_offset_s=max_offset_s)
    t_v = (np.asarray(t_imu_s, float) - s.offset_s) / (1.0 + s.drift)
    fusion = fuse_table_motion(video_table, t_v, s.sign * np.asarray(acc_m_s2, float), label=label)
    return fusion.motion, s, fusion


def sync_clocks(ref, rot, max_offset_s):
    """Clock model t_imu = t_ref + offset + drift * t_ref from the rocking rates."""
    from ...tracking import sync_imu_to_track

    return sync_imu_to_track(rot, ref[0], ref[1], max_offset_s=max_offset_s)


#: A level IMU whose impact spikes correlate less than this with the reference level's is flagged.
COLUMN_SYNC_MIN_CORRELATION = 0.4


@dataclass(frozen=True)
class ColumnImus:
    """A column's levels measured by their IMUs, on one clock.

    Attributes
    ----------
    t_s : ndarray, (m,)
        The reference clock's samples (the video's clock with a film, else the released level's IMU).
    theta_rad : ndarray, (m, L)
        Each level's angle, counter-clockwise positive (the camera's sense), rad; NaN outside its log.
    release_t_s : float
        The release seen by the level that starts farthest from upright (NaN: none, a forced run), s.
    theta_start_rad : ndarray, (L,)
        Each level's angle in its rest before the motion, rad.
    clocks : list of dict
        Per level: ``offset_s`` (its log's time minus the reference's), ``drift``, ``correlation``,
        ``how`` (``video``, ``reference`` or ``impacts of level N``).
    """

    t_s: np.ndarray
    theta_rad: np.ndarray
    release_t_s: float
    theta_start_rad: np.ndarray
    clocks: list


def _impact_signal(rot):
    """The impacts' spikes in a level's accelerometer: ``|‖specific force‖ - g|`` above its running
    median over 9 samples (the rocking's slow part taken out), square-rooted so that the released
    block's large spikes do not outweigh the small ones a level below feels at the same instants."""
    from scipy.ndimage import median_filter

    from ...blocks import G

    y = np.abs(np.linalg.norm(np.asarray(rot.acc_m_s2, float), axis=1) - G)
    return np.asarray(rot.t_s, float), np.sqrt(np.clip(y - median_filter(y, 9, mode="nearest"), 0.0, None))


def measure_column_imus(cfg: ExperimentConfig, video=None) -> ColumnImus:
    """Each ``[column] imu`` log as its level's angle, all on one clock.

    With a film (``video`` = ``(t_s, theta_rad (m, L))`` tracked, counter-clockwise), each IMU is put
    on the video clock by its own block's rocking rates (:func:`sync_clocks`). Without one, the IMU of
    the level that starts farthest from upright (the released one) is the clock, and the others are
    put on it, each through its neighbour nearer that level, by cross-correlating the acceleration
    spikes of the impacts, which every level feels at the same instants (a column's impact changes
    the velocity of every block). On synthetic 2- and 3-level columns this found the logs' offsets
    within 1 ms (correlations 0.51–0.84); the raw accelerations or rate jumps, dominated by the
    released block's large spikes and the rocking's slow part, put a wide bottom level 20–200 ms off.
    A weak correlation is a coded warning (``W-IMU-COLUMN-SYNC``).
    """
    from ..._diagnostics import warn
    from ...tracking import block_rotation, read_imu, sync_offset

    rots = [block_rotation(read_imu(p), axis=cfg.column_imu_axis) for p in cfg.column_imus]
    starts = np.array([float(r.theta0_rad) for r in rots])
    clocks: list = []
    series = []
    if video is not None:
        tv, thv = video
        for i, r in enumerate(rots):
            s = sync_clocks((tv, thv[:, i]), r, cfg.max_offset_s)
            series.append(((np.asarray(r.t_s) - s.offset_s) / (1.0 + s.drift), s.sign * np.asarray(r.theta_rad)))
            clocks.append({"offset_s": s.offset_s, "drift": s.drift, "correlation": s.correlation, "how": "video"})
        t_ref = np.asarray(tv, float)
        ref = int(np.argmax(np.abs(starts)))
        t_rel = (float(rots[ref].release_t_s) - clocks[ref]["offset_s"]) / (1.0 + clocks[ref]["drift"])
    else:
        ref = int(np.argmax(np.abs(starts)))
        shift = {ref: 0.0}  # level -> what to add to its log's times to put them on the reference clock
        clocks = [{"offset_s": 0.0, "drift": 0.0, "correlation": 1.0, "how": "reference"} for _ in rots]
        for i in sorted(range(len(rots)), key=lambda k: abs(k - ref)):
            if i == ref:
                continue
            nb = i + 1 if i < ref else i - 1  # already on the reference clock
            ta, ya = _impact_signal(rots[nb])
            s = sync_offset(ta, ya, *_impact_signal(rots[i]), max_offset_s=cfg.max_offset_s, drift=False)
            # t_neighbour = t_level + offset
            shift[i] = s.offset_s + shift[nb]
            clocks[i] = {
                "offset_s": -shift[i],
                "drift": 0.0,
                "correlation": s.correlation,
                "how": f"impacts of level {nb + 1}",
            }
            if not s.correlation >= COLUMN_SYNC_MIN_CORRELATION:
                warn(
                    "W-IMU-COLUMN-SYNC",
                    f"{cfg.path}: [column] imu {cfg.column_imus[i]} correlates {s.correlation:.2f} with level "
                    f"{nb + 1}'s impacts (< {COLUMN_SYNC_MIN_CORRELATION}); its clock offset is uncertain",
                )
        series = [(np.asarray(r.t_s, float) + shift[i], np.asarray(r.theta_rad, float)) for i, r in enumerate(rots)]
        t_ref = series[ref][0]
        t_rel = float(rots[ref].release_t_s)
    th = np.column_stack([np.interp(t_ref, tt, yy, left=np.nan, right=np.nan) for tt, yy in series])
    return ColumnImus(t_ref, th, t_rel, starts, clocks)
