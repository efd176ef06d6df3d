"""Rerun logging of experiments and campaigns.

Entity paths form a hierarchy::

    experiment/video                       the film: an AV1 video asset + a frame reference per
                                           frame (JPEG stills only as the fallback)
    experiment/video/targets               tracked target points (per frame)
    experiment/video/outline               block outline (per frame)
    experiment/video/sim_<law>             the simulated block's outline (per frame, per law)
    experiment/<block>/theta/measured_video    θ from video, rad
    experiment/<block>/theta/measured_imu      θ from IMU (synced), rad
    experiment/<block>/theta/sim_<law>         simulations, rad
    experiment/<block>/theta/truth             synthetic truth, rad
    experiment/<block>/theta/impacts_<law>     each simulation's impacts: markers at θ = 0
    experiment/<block>/theta_deg/...           the same θ series in degrees
    experiment/<block>/residual/video_minus_imu, .../measured_minus_sim_eta_e
    experiment/<block>/energy/sim_<law>    energy, J
    experiment/<block>/impacts             the η_e simulation's impacts, one text line each
    experiment/table/displacement_m, velocity_m_s, acceleration_m_s2
    experiment/geometry                    block and calibration (static)

Long series go in with ``send_columns``; geometry and calibration are
``static``. The blueprint (video + θ plot + residual plot) is built by
:func:`experiment_blueprint`, apart from the data. A viewer opens a recording with its time
cursor at the start of the ``time`` timeline, so a run with a film logs nothing before the film's
first frame (the IMU log's earlier samples stay in ``series.csv``): the film shows on first load.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = [
    "open_recording",
    "close_recording",
    "log_series",
    "log_events",
    "log_impact_markers",
    "log_video_frames",
    "log_video_asset",
    "read_rrd_scalars",
    "experiment_blueprint",
    "campaign_blueprint",
    "read_rrd_summary",
]

TIMELINE = "time"


def open_recording(
    app_id: str, rrd_path=None, spawn: bool = False, connect: str | None = None, recording_id: str | None = None
):
    """A new :class:`rerun.RecordingStream` writing to ``rrd_path`` and/or a viewer.

    Parameters
    ----------
    rrd_path : path, optional
        File to save to (the caller renames it into place afterwards).
    spawn : bool
        Also spawn a local viewer.
    connect : str, optional
        Also stream to a viewer at this gRPC address (``rerun+http://host:9876/proxy``).
    """
    import rerun as rr

    rec = rr.RecordingStream(app_id, recording_id=recording_id)
    sinks = []
    if rrd_path is not None:
        sinks.append(rr.FileSink(str(rrd_path)))
    if spawn:
        # start a local viewer (listening on the default port) and stream to it
        rec.spawn(connect=False)
        sinks.append(rr.GrpcSink())
    if connect:
        sinks.append(rr.GrpcSink(connect))
    if sinks:
        rec.set_sinks(*sinks)
    return rec


#: Longest wait for a Rerun sink to take the logged data, s. A full disk or a gone
#: viewer must fail the run, not hang it.
FLUSH_TIMEOUT_S = 60.0


def close_recording(rec, rrd_path=None) -> None:
    """Flush ``rec`` (bounded by :data:`FLUSH_TIMEOUT_S`) and disconnect it.

    Raises
    ------
    OSError
        The ``.rrd`` file was not written (full disk, folder gone).
    """
    import errno

    rec.flush(timeout_sec=FLUSH_TIMEOUT_S)
    rec.disconnect()
    if rrd_path is not None:
        p = Path(rrd_path)
        if not p.is_file() or p.stat().st_size == 0:
            raise OSError(errno.EIO, "the Rerun recording was not written (disk full or folder removed?)", str(p))


def log_series(
    rec,
    path: str,
    t_s,
    values,
    *,
    color=None,
    width: float | None = None,
    name: str | None = None,
    t_min_s: float | None = None,
) -> int:
    """Send a whole scalar series on the ``time`` timeline (NaNs dropped). Returns rows sent.

    ``color`` (RGB 0-255), ``width`` (points) and ``name`` style the line (static); samples
    before ``t_min_s`` (s) are left out.
    """
    import rerun as rr

    t = np.asarray(t_s, float)
    v = np.asarray(values, float)
    ok = np.isfinite(t) & np.isfinite(v)
    if t_min_s is not None:
        ok &= t >= t_min_s
    if not ok.any():
        return 0
    rec.send_columns(path, indexes=[rr.TimeColumn(TIMELINE, duration=t[ok])], columns=rr.Scalars.columns(scalars=v[ok]))
    if color is not None or name is not None or width is not None:
        rec.log(path, rr.SeriesLines(colors=color, widths=width, names=name), static=True)
    return int(ok.sum())


def log_events(rec, path: str, t_s, texts, values=None) -> None:
    """Log discrete events (impacts, configuration changes) as text at their times,
    and optionally as points on a series."""
    import rerun as rr

    for i, (t, txt) in enumerate(zip(np.asarray(t_s, float), texts)):
        rec.set_time(TIMELINE, duration=float(t))
        rec.log(path, rr.TextLog(str(txt)))
    if values is not None and len(t_s):
        rec.send_columns(
            f"{path}/marker",
            indexes=[rr.TimeColumn(TIMELINE, duration=np.asarray(t_s, float))],
            columns=rr.Scalars.columns(scalars=np.asarray(values, float)),
        )
        rec.log(f"{path}/marker", rr.SeriesPoints(markers="circle", marker_sizes=4.0), static=True)
    rec.reset_time()


def log_impact_markers(rec, path: str, t_s, values, *, color, name: str) -> int:
    """Impacts as markers (no line) on a θ plot: ``values`` (same unit as the plot) at ``t_s`` (s).

    Returns the number of markers sent.
    """
    import rerun as rr

    t = np.asarray(t_s, float)
    v = np.asarray(values, float)
    ok = np.isfinite(t) & np.isfinite(v)
    if not ok.any():
        return 0
    rec.send_columns(path, indexes=[rr.TimeColumn(TIMELINE, duration=t[ok])], columns=rr.Scalars.columns(scalars=v[ok]))
    rec.log(path, rr.SeriesPoints(colors=color, markers="diamond", marker_sizes=5.0, names=name), static=True)
    return int(ok.sum())


def log_video_frames(rec, path: str, frames, *, overlays=None, progress=None) -> int:
    """Log video frames (JPEG stills, the fallback of :func:`log_video_asset`) on the ``time`` and
    ``frame`` timelines.

    Parameters
    ----------
    frames : iterable of (frame_index, t_s, jpeg_bytes)
        The frames to show (already decimated: see ``output.video_decimation``).
    overlays : callable(frame_index) -> dict, optional
        Returns {"points": (k, 2) px, "outlines": list of (m, 2) px polylines, "sim": list of
        (law, (m, 2) px polyline, RGB): each simulation's block}.
    Returns the number of frames logged.
    """
    import rerun as rr

    n = 0
    for idx, t, data in frames:
        rec.set_time(TIMELINE, duration=float(t))
        rec.set_time("frame", sequence=int(idx))
        rec.log(path, rr.EncodedImage(contents=data, media_type="image/jpeg"))
        if overlays is not None:
            _log_overlay(rec, path, overlays(idx) or {})
        n += 1
        if progress is not None:
            progress.update(1)
    rec.reset_time()
    return n


def log_video_asset(
    rec, path: str, mp4: bytes, frame_index, fps: float, *, overlays=None, progress=None, frame_t_s=None
) -> int:
    """Log a film as one Rerun ``AssetVideo`` and a ``VideoFrameReference`` per frame.

    Parameters
    ----------
    mp4 : bytes
        The MP4 (AV1 plays in every Rerun viewer).
    frame_index : sequence of int, shape (n,)
        Source frame index of each of the film's n frames, in order; frame ``i`` is shown at
        ``t = i / fps`` s on the ``time`` timeline and at ``i`` on ``frame``.
    fps : float
        The tracker's frame rate, Hz.
    overlays : callable(frame_index) -> dict, optional
        As in :func:`log_video_frames`.
    frame_t_s : ndarray (n,), optional
        Each frame's time, s (a variable-rate film's own times); default ``frame_index / fps``.

    Returns the number of frames referenced.

    Raises
    ------
    ValueError
        The film's frame count differs from ``frame_index`` (a truncated encode).
    """
    import rerun as rr

    asset = rr.AssetVideo(contents=mp4, media_type="video/mp4")
    rec.log(path, asset, static=True)
    ts_ns = np.asarray(asset.read_frame_timestamps_nanos(), np.int64)
    idx = np.asarray(frame_index, np.int64)
    if len(ts_ns) != len(idx):
        raise ValueError(f"review film has {len(ts_ns)} frames, the tracker decoded {len(idx)}")
    t = idx / float(fps) if frame_t_s is None else np.asarray(frame_t_s, float)
    rec.send_columns(
        path,
        indexes=[rr.TimeColumn(TIMELINE, duration=t), rr.TimeColumn("frame", sequence=idx)],
        columns=rr.VideoFrameReference.columns_nanos(ts_ns),
    )
    if overlays is not None:
        for i, ti in zip(idx, t):
            rec.set_time(TIMELINE, duration=float(ti))
            rec.set_time("frame", sequence=int(i))
            _log_overlay(rec, path, overlays(int(i)) or {})
            if progress is not None:
                progress.update(1)
        rec.reset_time()
    return int(len(idx))


def _log_overlay(rec, path: str, ov: dict) -> None:
    import rerun as rr

    if ov.get("points") is not None and len(ov["points"]):
        rec.log(f"{path}/targets", rr.Points2D(ov["points"], radii=3.0, colors=[0, 255, 0]))
    if ov.get("outlines"):
        rec.log(f"{path}/outline", rr.LineStrips2D(ov["outlines"], colors=[255, 128, 0], radii=-2.0))
    # thin and on top (η_e's topmost): a simulated block that matches the measured one leaves the
    # orange visible around it
    for law, q, colour in ov.get("sim") or ():
        order = 32.0 if law == "eta_e" else 31.0
        rec.log(
            f"{path}/sim_{law}",
            rr.LineStrips2D(
                [q], colors=[colour], radii=-0.75, draw_order=order, labels=[f"sim {law}"], show_labels=False
            ),
        )


def experiment_blueprint(block_paths: list[str], has_video: bool = True, focus=None):
    """Video + θ plots (rad, degrees) + residual plot (and energy, table) for one experiment.

    ``focus``: ``(t_impact_s, t0_s, t1_s)``: the review opens on that window (the impact with
    the largest residual): the plots zoomed on it, the time panel's loop selection on it (play
    loops over it at quarter speed).
    """
    import rerun.blueprint as rrb
    import rerun.encodings as enc

    ranges = None
    if focus is not None:
        _, t0, t1 = focus
        ranges = [
            rrb.VisibleTimeRange(
                TIMELINE,
                start=rrb.TimeRangeBoundary.absolute(seconds=max(t0, 0.0)),
                end=rrb.TimeRangeBoundary.absolute(seconds=t1),
            )
        ]
    plots = []
    for bp in block_paths:
        short = bp.split("/")[-1]
        plots.append(
            rrb.Tabs(
                rrb.TimeSeriesView(origin=f"{bp}/theta_deg", name=f"θ {short} (°)", time_ranges=ranges),
                rrb.TimeSeriesView(origin=f"{bp}/theta", name=f"θ {short} (rad)", time_ranges=ranges),
                rrb.TimeSeriesView(origin=f"{bp}/theta_deg", name=f"θ {short} (°), whole run"),
            )
        )
    res = [rrb.TimeSeriesView(origin=f"{bp}/residual", name="residual (rad)", time_ranges=ranges) for bp in block_paths]
    extra = [rrb.TimeSeriesView(origin=f"{bp}/energy", name="energy (J)") for bp in block_paths]
    extra.append(rrb.TimeSeriesView(origin="experiment/table", name="table"))
    left = [rrb.Spatial2DView(origin="experiment/video", name="video")] if has_video else []
    left.append(rrb.TextLogView(origin="experiment", name="events"))
    # always on the ``time`` timeline (the film's ``frame`` timeline would hide every plot)
    panel = rrb.TimePanel(timeline=TIMELINE, play_state="paused")
    if focus is not None:
        _, t0, t1 = focus
        panel = rrb.TimePanel(
            timeline=TIMELINE,
            play_state="paused",
            loop_mode="selection",
            playback_speed=0.25,
            time_selection=enc.AbsoluteTimeRange(int(max(t0, 0.0) * 1e9), int(t1 * 1e9)),
        )
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(*left, row_shares=[3, 1] if has_video else None),
            rrb.Vertical(rrb.Vertical(*plots), rrb.Vertical(*res), rrb.Tabs(*extra), row_shares=[3, 2, 2]),
            column_shares=[1, 1],
        ),
        panel,
        collapse_panels=True,
    )


#: The campaign recording's x axis: h/b × 1000 on a sequence timeline (a viewer's plots take their
#: x from a timeline, and sequence timelines hold integers).
HB_TIMELINE = "h_over_b_x1000"


def campaign_blueprint(hb_x1000: tuple[int, int] | None = None):
    """η vs h/b as a scatter plot (one marker series per experiment, η_H and the truth as
    references), the campaign's summary (one text document) and the experiments' log.

    ``hb_x1000``: (smallest, largest) h/b × 1000 of the experiments; the plot's x axis shows all
    of them (a viewer otherwise shows a window around its time cursor).
    """
    import rerun.blueprint as rrb

    axis = None
    if hb_x1000 is not None:
        lo, hi = hb_x1000
        pad = max(500, (hi - lo) // 6)
        axis = rrb.TimeAxis(
            view_range=rrb.TimeRange(
                start=rrb.TimeRangeBoundary.absolute(seq=lo - pad), end=rrb.TimeRangeBoundary.absolute(seq=hi + pad)
            )
        )
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.TimeSeriesView(
                origin="campaign",
                contents=["+ campaign/eta_vs_hb/**", "+ campaign/reference/**"],
                name="η vs h/b (x axis: h/b × 1000); click a marker for its experiment",
                axis_x=axis,
                plot_legend=rrb.PlotLegend(corner="RightBottom"),
            ),
            rrb.Vertical(
                rrb.TextDocumentView(origin="campaign/summary", name="campaign"),
                rrb.TextLogView(origin="campaign/experiments", name="experiments"),
                row_shares=[3, 1],
            ),
            column_shares=[3, 2],
        ),
        rrb.TimePanel(timeline=HB_TIMELINE, play_state="paused"),
    )


def read_rrd_summary(path) -> dict:
    """Entity path → number of rows in a saved ``.rrd`` (rerun's own reader).

    Used by tests and by ``rocklab run`` to check what it wrote.
    """
    import rerun.chunk as rc

    counts: dict[str, int] = {}
    store = rc.RrdReader(str(Path(path))).stream().collect()
    for ch in store.stream():
        counts[str(ch.entity_path)] = counts.get(str(ch.entity_path), 0) + int(ch.num_rows)
    return counts


def read_rrd_scalars(path, entity: str) -> tuple[np.ndarray, np.ndarray]:
    """(t_s, values) of a scalar series in a saved ``.rrd`` (sorted by time)."""
    import rerun.chunk as rc

    ts, vs = [], []
    store = rc.RrdReader(str(Path(path))).stream().collect()
    ent = entity if entity.startswith("/") else "/" + entity
    for ch in store.stream():
        if str(ch.entity_path) != ent or ch.is_static:
            continue
        rb = ch.to_record_batch()
        names = rb.schema.names
        tcol = next(n for n in names if n == TIMELINE or n.endswith(f":{TIMELINE}") or n == "time")
        vcol = next(n for n in names if "Scalars:scalars" in n)
        t = rb.column(names.index(tcol)).to_numpy(zero_copy_only=False)
        t = t.astype("timedelta64[ns]").astype(np.int64) / 1e9 if t.dtype.kind in "mM" else t.astype(float)
        v = rb.column(names.index(vcol)).to_pylist()
        ts.append(np.asarray(t, float))
        vs.append(np.asarray([x[0] if isinstance(x, list) else x for x in v], float))
    if not ts:
        return np.empty(0), np.empty(0)
    t, v = np.concatenate(ts), np.concatenate(vs)
    o = np.argsort(t, kind="stable")
    return t[o], v[o]
