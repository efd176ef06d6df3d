"""``rocklab track init`` and ``rocklab track preview``: a config from the first frame, and a
contact sheet to check the set-up before a long run."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from ..._errors import InputError
from ...series import USABLE_STATUSES

__all__ = ["track_init", "track_preview", "draw_init_preview", "contact_sheet"]

_COLOURS = [(0, 200, 255), (255, 120, 0), (0, 220, 0), (220, 0, 220), (0, 0, 255), (255, 255, 0)]


def _per_frame(info) -> int:
    """Images a frame of the film yields: 2 when it is deinterlaced into fields, else 1."""
    return 2 if info.field_order is not None else 1


def _first_frame(video: Path, start_frame=None, fps=None):
    """(info, grey, BGR, start frame, note, the film's own rate or None) of the first frame tracked:
    ``start_frame`` when given, else the first frame after a lead-in of blank, fading-in or
    cut-away frames (a note says so). ``info.fps`` is the film's own rate, else ``fps``; a film
    with neither is refused."""
    from ...tracking.video import iter_video_frames, lead_in, probe_video

    if not video.exists():
        raise InputError(f"{video}: video not found; check the path")
    info = probe_video(video)
    own_fps = info.fps
    if not info.fps:
        # a rate guessed here would scale every time, velocity and frequency of the run
        if not fps:
            raise InputError(
                f"{video}: the film has no frame rate (an image folder has one only from its timestamps.csv); "
                "give the rate it was filmed at: --fps N"
            )
        info = dataclasses.replace(info, fps=float(fps))
    per = _per_frame(info)
    n = per * (info.n_frames or 0)
    if start_frame is not None and n and not 0 <= start_frame < n:
        raise InputError(f"--start-frame {start_frame}: {video} holds frames 0-{n - 1}; give one of them")
    note = ""
    if start_frame is None:
        n_lead = max(int(round(LEAD_IN_S * per * info.fps)), 3)
        grays = [
            g for _, g in iter_video_frames(video, 0, n_lead, pixel_aspect=info.pixel_aspect, fields=info.field_order)
        ]
        start_frame, what = lead_in(grays, per * info.fps)
        if start_frame:
            note = (
                (f"frames 0-{start_frame - 1} are" if start_frame > 1 else "frame 0 is")
                + f" a lead-in ({_LEAD_IN[what]}): tracking starts at frame "
                f"{start_frame} ([video] start_frame; regions in its pixels); give --start-frame N to choose"
            )
    for _, gray, img in iter_video_frames(
        video, start_frame, start_frame + 1, color=True, pixel_aspect=info.pixel_aspect, fields=info.field_order
    ):
        return info, gray, img, start_frame, note, own_fps
    raise InputError(f"{video}: frame {start_frame} could not be decoded; check the file (or --start-frame)")


#: The first seconds of a film searched for a lead-in before its scene.
LEAD_IN_S = 2.0
_LEAD_IN = {
    "blank": "blank frames, one grey level",
    "fade-in": "the picture fading in",
    "cut": "a title card or another shot, then a cut",
}


#: ``track init`` without markers compares frames over the first seconds (then, when nothing moves
#: there, over a longer stretch), this many frames spread over each.
PROPOSE_WINDOWS_S = (3.0, 12.0)
PROPOSE_SAMPLES = 30


def _samples(video, info, window_s, start=0):
    """Grey frames spread over the ``window_s`` seconds after frame ``start`` (decoded in one pass)."""
    from ...tracking.video import iter_video_frames

    per = _per_frame(info)
    n = per * (info.n_frames or 0)
    stop = start + int(round(window_s * per * info.fps))
    stop = min(stop, n) if n else stop
    step = max(1, (stop - start - 1) // PROPOSE_SAMPLES)
    return [
        g
        for i, g in iter_video_frames(video, start + 1, stop, pixel_aspect=info.pixel_aspect, fields=info.field_order)
        if (i - start) % step == 0
    ]


#: Frames compared over the film's last seconds for whether the first block rests there.
REST_SAMPLES = 12


def _end_frames(video, info, start=0):
    """Grey frames spread over the film's last :data:`~rocklab.tracking.video.REST_WINDOW_S`
    seconds (after frame ``start``), at most :data:`REST_SAMPLES`; empty when the film's length is
    unknown."""
    from ...tracking.video import REST_WINDOW_S, iter_video_frames

    per = _per_frame(info)
    n = per * (info.n_frames or 0)
    first = max(n - int(round(REST_WINDOW_S * per * info.fps)), start)
    if n - first < 2:
        return []
    step = max(1, (n - first - 1) // (REST_SAMPLES - 1))
    out, last = [], None
    for i, g in iter_video_frames(video, first, n, pixel_aspect=info.pixel_aspect, fields=info.field_order):
        if (i - first) % step == 0:
            out.append(g)
        last = g
    # the film's last frame is always one: a rest is judged against the film's end
    if last is not None and (not out or out[-1] is not last):
        out.append(last)
    return out


def _propose(video, info, gray, start=0):
    """Objects proposed from what moves after frame ``start``; (Proposals, window s)."""
    from ...tracking.video import propose_objects

    per = _per_frame(info)
    duration = max((per * (info.n_frames or 0) - start) / (per * info.fps), 0.0)
    for window in PROPOSE_WINDOWS_S:
        props = propose_objects(gray, _samples(video, info, window, start))
        if props.blocks or duration <= window or props.camera_moves:
            break
    return props, min(window, duration) if duration else window


def track_init(
    video,
    out,
    *,
    objects=(),
    table=None,
    marker_size_m=None,
    preview=None,
    side=(False, False),
    fps=None,
    lens=None,
    start_frame=None,
):
    """Write a commented ``track.toml`` for ``video`` (and a preview PNG); returns (config, notes).

    Without markers and without ``objects``, the objects that move in the first seconds and the
    table they stand on are proposed (:mod:`rocklab.tracking.video._propose`), written as
    markerless objects and drawn on the preview with a pixel grid.

    Parameters
    ----------
    objects : sequence of str
        ``NAME=x,y,w,h`` regions (px, first frame), followed markerless.
    table : str or None
        ``x,y,w,h`` of a markerless table (round its top edge: it levels the angles).
    fps : float or None
        Frame rate written to the config (``--fps``: an image folder or a film without one).
    marker_size_m : float or None
        Printed marker side, m, when markers are used.
    preview : path or None
        PNG with every detection, region and the level line drawn on the first frame.
    lens : path or None
        A lens file (``rocklab calibrate``) written as ``[video] calibration`` (relative to the
        config's folder); refused when calibrated at another picture size than the film's.
    start_frame : int or None
        The first frame tracked (``[video] start_frame``; regions are in its pixels). Not given:
        frame 0, or the first frame after a lead-in (blank frames, a fade-in, a title card cut
        away from: :func:`~rocklab.tracking.video.lead_in`), with a note.

    Returns
    -------
    (TrackConfig, list of str, tuple)
        The config, its notes, and the proposed objects as options (``--object NAME=x,y,w,h``,
        ``--table x,y,w,h``; empty when nothing was proposed).

    Raises
    ------
    InputError
        Bad regions; no marker and nothing moving (the preview, a pixel grid on the first
        frame, is written first so the regions can be read off it).
    """
    from ..._io import write_text_atomic
    from ...tracking.video import find_markers, parse_region, rests_at_end, suggest_config
    from .._plotting import save_bgr_png

    video, out = Path(video), Path(out)
    info, gray, img, start, lead_note, own_fps = _first_frame(video, start_frame, fps)
    regions = {}
    for spec in objects:
        name, sep, box = str(spec).partition("=")
        if not sep or not name or "," in name:
            raise InputError(f"--object {spec!r}: give NAME=x,y,w,h (px, first frame)")
        if name in regions:
            raise InputError(f"--object {name}: given twice; names must be unique")
        regions[name] = parse_region(box, f"--object {name}")
    troi = parse_region(table, "--table") if table is not None else None
    if marker_size_m is not None and not (math.isfinite(marker_size_m) and marker_size_m > 0):
        raise InputError(f"--marker-size {marker_size_m}: give the printed marker side in metres (> 0)")
    found, proposed, pnotes, line = None, (), [], None
    turning: set = set()
    if not regions and troi is None:
        found = find_markers(gray)
        if found is None:
            regions, troi, line, proposed, pnotes, turning = _from_motion(
                video, info, gray, img, start, lead_note, preview, side
            )
    lens_rel = None
    if lens is not None:
        import os

        from ...tracking.video import load_calibration

        load_calibration(lens, (info.width_px, info.height_px))
        lens_rel = Path(os.path.relpath(Path(lens).resolve(), out.resolve().parent)).as_posix()
    cfg, notes, found = suggest_config(
        gray,
        regions=regions or None,
        table_roi=troi,
        fps=fps or None,
        marker_size_m=marker_size_m,
        found=found,
        level_line_px=line,
        start_frame=start,
        rest_check=lambda box: rests_at_end(gray, box, _end_frames(video, info, start)),
    )
    if turning:
        # the whole disc's registration does not follow a small mark's turn (PhysTrack's turning
        # disc: theta within 2 deg while it made 9.6 turns, every frame ok): a position only
        objs = tuple(dataclasses.replace(o, kind="point") if o.id in turning else o for o in cfg.objects)
        cfg = dataclasses.replace(cfg, objects=objs)
    notes = ([lead_note] if lead_note else []) + pnotes + notes
    if regions and not proposed:
        notes += _camera_note(video, info, gray, start)
    if lens_rel is not None:
        cfg = dataclasses.replace(cfg, video=dataclasses.replace(cfg.video, calibration=lens_rel))
        notes.append(f"lens {lens_rel}: detected points are undistorted with it before any geometry")
    if not own_fps:
        notes.append(f"the film has no frame rate of its own: fps = {fps:g} written from --fps")
    head = [
        f"track.toml written by 'rocklab track init' from {video.name} ({info.width_px}x{info.height_px}, "
        f"{info.n_frames} frames, {own_fps or 'unknown'} fps)" + (f", from frame {start}" if start else ""),
        "Schema: docs/track-toml.md",
        *notes,
    ]
    write_text_atomic(out, cfg.to_toml(header=head), side=side[0])
    if preview is not None:
        save_bgr_png(Path(preview), draw_init_preview(img, cfg, found, grid=found is None), side=side[1])
    return cfg, notes, proposed


def _camera_note(video, info, gray, start) -> list:
    """Regions given by hand on a film whose camera moves: W-VIDEO-CAMERA, and a note in the config."""
    from ..._diagnostics import warn
    from ...tracking.video import CAMERA_SHARE, camera_motion

    share, shift = camera_motion([gray, *_samples(video, info, PROPOSE_WINDOWS_S[0], start)])
    if share < CAMERA_SHARE:
        return []
    what = (
        f"the camera moves (the whole picture shifts, by a median {shift:.3g} px, between {100 * share:.0f} % "
        f"of the frames compared over {PROPOSE_WINDOWS_S[0]:g} s): positions in the picture include the "
        "camera's motion; film from a fixed camera (a tripod)"
    )
    warn("W-VIDEO-CAMERA", f"{video}: {what}")
    return [what]


def _from_motion(video, info, gray, img, start, lead_note, preview, side):
    """Objects proposed from what moves after frame ``start`` (film without markers or regions):
    (regions, table region, level line, proposals as options, notes, names of the discs turning
    on a pin); an InputError, after the
    pixel grid is written to ``preview``, when nothing trackable moves."""
    from .._plotting import save_bgr_png

    from ...tracking.video import MIN_TEXTURE_STD, texture_std

    line = None
    props, window = _propose(video, info, gray, start)
    # a proposal the tracker could not register (a flat patch) is dropped here, not refused later
    # under an --object name the user never gave
    flat = [b for b in props.blocks if texture_std(gray, b) < MIN_TEXTURE_STD]
    if flat:
        props = dataclasses.replace(props, blocks=tuple(b for b in props.blocks if b not in flat))
    if not props.blocks:
        if preview is not None:
            save_bgr_png(Path(preview), draw_grid(img), side=side[1])
        what = "nothing moves" if not props.still else _still_text(props.still) + ", and nothing else moves"
        if flat:
            what = f"what moves holds no texture to track ({', '.join(_box_text(b) for b in flat)})"
        fix = ""
        if props.camera_moves:  # every pixel changes: "nothing moves" would be false
            what = (
                f"the camera moves (the whole picture shifts, by a median {props.camera[1]:.3g} px, between "
                f"{100 * props.camera[0]:.0f} % of the frames compared)"
            )
            fix = (
                "positions in the picture are then not positions in the scene: film from a fixed camera (a tripod), or "
            )
        raise InputError(
            f"{video}: no ArUco/AprilTag marker in frame {start} and {what} in the "
            f"{window:.3g} s from it{' (' + lead_note + ')' if lead_note else ''}; {fix}give the objects as "
            "--object NAME=x,y,w,h (and --table x,y,w,h)"
            + (f", read off the pixel grid in {preview}" if preview is not None else "")
            + ", or --start-frame N where the motion starts"
        )
    regions = {f"block_{k}": b for k, b in enumerate(props.blocks, start=1)}
    troi = props.table if props.table_moves else None
    if props.table_edge is not None and not props.table_moves:
        line = tuple(tuple(round(float(v), 1) for v in p) for p in props.table_edge.ends_px)
    proposed = tuple(f"--object {n}={_box_text(b)}" for n, b in regions.items())
    if troi is not None:
        proposed += (f"--table {_box_text(troi)}",)
    pnotes = _proposal_notes(props, window, gray.size)
    pnotes += [
        f"a moving region at {_box_text(b)} not proposed: it holds no texture to track "
        f"(grey std {texture_std(gray, b):.3g} < {MIN_TEXTURE_STD:g})"
        for b in flat
    ]
    turning = {n for n, b in regions.items() if b in props.turning}
    return regions, troi, line, proposed, pnotes, turning


def _box_text(b) -> str:
    return ",".join(f"{v:.0f}" for v in b)


#: A proposal larger than this share of the frame is likely several things merged.
LARGE_PROPOSAL = 0.1


def _still_text(still) -> str:
    return "; ".join(
        f"something moves at {_box_text(b)}, but that box is mostly still things (its content stays in place in "
        f"{100 * share:.0f} % of the frames compared, correlation {cc:.2f}): a tracker would follow them, so it is "
        "not proposed"
        for b, share, cc in still
    )


def _proposal_notes(props, window_s, frame_px) -> list:
    notes = [
        f"PROPOSED, check before tracking: no marker found, so the objects are what moves in the first "
        f"{window_s:.3g} s ({props.n_moving} of {props.n_samples} frames compared with the first moved); "
        "see the preview, and re-run with --object NAME=x,y,w,h (and --table x,y,w,h) to correct them"
    ]
    if props.still:
        notes.append(_still_text(props.still) + "; draw the moving thing's own box with --object")
    for k, (x, y, w, h) in enumerate(props.blocks, start=1):
        if w * h > LARGE_PROPOSAL * frame_px:
            notes.append(
                f"PROPOSED block_{k} covers {100 * w * h / frame_px:.0f} % of the frame: likely several things that "
                "move together (a hand, its shadow); draw the object's own box with --object block_"
                f"{k}=x,y,w,h (a large region also tracks slowly)"
            )
    for k, b in enumerate(props.blocks, start=1):
        if b in props.turning:
            notes.append(
                f"PROPOSED block_{k} is a disc turning on a pin: only its mark moves, its outline stays; it is "
                'written as kind = "point" (its position only: the whole disc\'s registration does not follow a '
                f"small mark's turn); for its angle draw a box round the mark with --object block_{k}=x,y,w,h "
                "(the mark turns with the disc)"
            )
    if props.table_edge is not None:
        e = props.table_edge
        what = (
            'it moves: the table is an object, its top edge levels the angles (level = "table"); its '
            "velocity and acceleration need a metric scale: set reference.m_per_px (W-TABLE-MOTION otherwise)"
            if props.table_moves
            else 'it stays still: level = "line" through it (a shake table: add --table x,y,w,h)'
        )
        notes.append(
            f"PROPOSED table: a straight edge below the first block over columns {e.u_span_px[0]:.0f}-"
            f"{e.u_span_px[1]:.0f} px at {math.degrees(e.angle_rad):+.2f} deg; {what}"
        )
    else:
        notes.append("no table edge found below the moving objects")
    return notes


def draw_grid(img, step_px: int | None = None):
    """``img`` (BGR or grey) with a pixel grid, lines every ``step_px`` (default 50 px, 100 px on
    frames wider than 1000 px) labelled with their pixel coordinate, to read regions off."""
    import cv2

    out = img.copy() if img.ndim == 3 else cv2.cvtColor(img, cv2.COLOR_GRAY2BGR)
    H, W = out.shape[:2]
    step = int(step_px or (100 if W > 1000 else 50))
    scale = max(0.35, W / 1800)
    for k, n in ((0, W), (1, H)):
        for p in range(step, n, step):
            a, b = ((p, 0), (p, H - 1)) if k == 0 else ((0, p), (W - 1, p))
            cv2.line(out, a, b, (255, 255, 255), 1, cv2.LINE_4)
            at = (p + 2, int(14 * scale / 0.35)) if k == 0 else (2, p - 3)
            for col, th in (((0, 0, 0), 3), ((255, 255, 255), 1)):  # white on a dark halo: readable anywhere
                cv2.putText(out, str(p), at, cv2.FONT_HERSHEY_SIMPLEX, scale, col, th, cv2.LINE_AA)
    return out


def draw_init_preview(img, cfg, found, grid: bool = False):
    """The first frame (BGR) with markers (id, outline), regions and the level line drawn (over a
    pixel grid with ``grid``)."""
    import cv2

    out = draw_grid(img) if grid else img.copy() if img.ndim == 3 else cv2.cvtColor(img, cv2.COLOR_GRAY2BGR)
    owner = {m: (k, o) for k, o in enumerate(cfg.objects) for m in o.markers}
    if found is not None:
        for mid, c in zip(found.ids, found.corners_px):
            k, o = owner.get(mid, (len(_COLOURS) - 1, None))
            col = _COLOURS[k % len(_COLOURS)]
            cv2.polylines(out, [np.round(c).astype(np.int32)], True, col, 2)
            cv2.putText(
                out,
                f"{mid} {o.id if o else '?'}",
                tuple(int(x) for x in c[0] - (0, 6)),
                cv2.FONT_HERSHEY_SIMPLEX,
                0.5,
                col,
                1,
                cv2.LINE_AA,
            )
        tab = cfg.table
        if tab is not None and len(tab.markers) >= 2:  # the level line through the table's markers
            cs = found.centres_px[[found.ids.index(m) for m in tab.markers]]
            a, b = cs[np.argmin(cs[:, 0])], cs[np.argmax(cs[:, 0])]
            cv2.line(out, tuple(int(x) for x in a), tuple(int(x) for x in b), (0, 255, 255), 1, cv2.LINE_AA)
    line = cfg.reference.level_line_px if cfg.reference.level == "line" else None
    if line is not None:
        a, b = (tuple(int(round(v)) for v in p) for p in line)
        cv2.line(out, a, b, (0, 255, 255), 1, cv2.LINE_AA)
        cv2.putText(out, "level line", (a[0], a[1] + 16), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (0, 255, 255), 1, cv2.LINE_AA)
    for k, o in enumerate(cfg.objects):
        if o.roi is not None:
            x, y, w, h = (int(round(v)) for v in o.roi)
            col = _COLOURS[k % len(_COLOURS)]
            s = max(1.0, out.shape[1] / 960)  # readable on a 1080p frame too
            cv2.rectangle(out, (x, y), (x + w, y + h), col, int(round(2 * s)))
            cv2.putText(
                out, o.id, (x, max(y - int(6 * s), 10)), cv2.FONT_HERSHEY_SIMPLEX, 0.5 * s, col, int(s), cv2.LINE_AA
            )
            if o.kind == "table" and not o.markers:
                _draw_top_edge(out, img, cfg, o)
    return out


def _draw_top_edge(out, img, cfg, table) -> None:
    """Draw on ``out`` a markerless table's top edge in ``img`` (the undrawn frame) as the level will
    use it: the line over the span followed, and its angle (or a note that the region holds no edge)."""
    import cv2

    from ...tracking.video import make_plane_map
    from ...tracking.video.targets import table_top_edge

    gray = img if img.ndim == 2 else cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
    x, y = (int(round(v)) for v in table.roi[:2])
    try:
        edge = table_top_edge(gray, table.roi, make_plane_map(cfg, gray.shape[1], gray.shape[0], gray))
    except InputError:  # a board or table-marker plane that this frame cannot give: the pixels' own
        from ...tracking.video import PlaneMap

        edge = table_top_edge(gray, table.roi, PlaneMap(gray.shape[1], gray.shape[0]))
    if edge is None:
        cv2.putText(out, "no top edge: cannot level", (x, y + 16), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (0, 0, 255), 1)
        return
    a, b = (tuple(int(round(v)) for v in p) for p in edge.ends_px)
    cv2.line(out, a, b, (0, 255, 255), 1, cv2.LINE_AA)
    text = f"level {math.degrees(edge.angle_rad):+.3f} +- {math.degrees(edge.sigma_rad):.3f} deg"
    cv2.putText(out, text, (a[0], a[1] + 16), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (0, 255, 255), 1, cv2.LINE_AA)


#: ``track preview`` tracks at most this much of the film (s from its start frame): a quick check.
PREVIEW_SPAN_S = 10.0


def track_preview(
    video,
    config,
    out,
    *,
    n_frames: int = 6,
    progress: bool = False,
    side: bool = False,
    fps=None,
    at_s=None,
    corrections=None,
):
    """Track the first :data:`PREVIEW_SPAN_S` seconds of ``video`` (all of a shorter film) and write
    a contact sheet of ``n_frames`` frames spread over them (PNG); returns (result, frames drawn).

    With ``at_s`` the film is tracked from its start frame to just past ``at_s`` (s) and the sheet
    shows the ``n_frames`` consecutive frames around it. ``fps`` is ``--fps``; ``corrections`` a
    corrections file applied after tracking (in place of the config's).
    """
    from dataclasses import replace

    from ...config import load_track_config
    from ...tracking import track_video

    video = Path(video)
    if not 1 <= int(n_frames) <= 48:
        raise InputError(f"--frames {n_frames}: give 1 to 48 frames for the sheet")
    if at_s is not None and not (math.isfinite(at_s) and at_s >= 0):
        raise InputError(f"--at {at_s}: give a time in the film, s (>= 0)")
    from ...tracking.video import iter_video_frames, probe_video

    vinfo = probe_video(video)  # the sheet shows the frames (fields) as tracked: square pixels
    cfg = load_track_config(config)
    fixes = corrections or cfg.video.corrections
    if fixes is not None:  # applied to the span tracked here: those outside it are not an error
        from ...tracking import load_corrections

        fixes = load_corrections(fixes)
        cfg = replace(cfg, video=replace(cfg.video, corrections=None))
    # frames (fields) in the span: the container's rate, or the config's when it has none
    if not (fps or vinfo.fps or cfg.video.fps):
        from ...tracking.video import no_rate_error

        raise no_rate_error(video, cfg)
    rate = (fps or vinfo.fps or cfg.video.fps) * (2 if vinfo.field_order is not None else 1)
    if at_s is not None:
        n_all = vinfo.n_frames * (2 if vinfo.field_order is not None else 1)
        if vinfo.frame_times_s is not None and not fps and len(vinfo.frame_times_s):
            end_s = float(vinfo.frame_times_s[-1])
        else:
            end_s = (n_all - 1) / rate
        if at_s > end_s + 0.5 / rate:
            raise InputError(f"--at {at_s:g}: past the end of the film ({end_s:.4g} s); give a time in it")
        stop = cfg.video.start_frame + int(round(at_s * rate)) + int(n_frames) + 2
    else:
        stop = cfg.video.start_frame + max(int(round(PREVIEW_SPAN_S * rate)), 1)
    if cfg.video.stop_frame is None or stop < cfg.video.stop_frame:
        cfg = replace(cfg, video=replace(cfg.video, stop_frame=stop))
    res = track_video(video, cfg, fps=fps, progress=progress)
    if fixes:
        from ...tracking import apply_corrections

        res = apply_corrections(res, fixes, partial=True)
    frames = np.asarray(res.tracks[0].frame)
    if at_s is not None:
        k = int(np.argmin(np.abs(np.asarray(res.tracks[0].t_s, float) - at_s)))
        lo = min(max(k - (int(n_frames) - 1) // 2, 0), max(frames.size - int(n_frames), 0))
        pick = frames[lo : lo + int(n_frames)]
    else:
        pick = frames[np.unique(np.round(np.linspace(0, frames.size - 1, int(n_frames))).astype(int))]
    tiles = []
    for f in pick:  # decode only the frames shown (a long film is not kept in memory)
        for i, _, img in iter_video_frames(
            video, int(f), int(f) + 1, prefetch=0, color=True, pixel_aspect=vinfo.pixel_aspect, fields=vinfo.field_order
        ):
            tiles.append(_draw_pose(img, res, i))
    from .._plotting import save_bgr_png

    save_bgr_png(Path(out), contact_sheet(tiles), side=side)
    return res, [int(f) for f in pick]


def _draw_pose(img, res, frame):
    import cv2

    out = img.copy() if img.ndim == 3 else cv2.cvtColor(img, cv2.COLOR_GRAY2BGR)
    t0 = res.tracks[0]
    cv2.putText(
        out,
        f"frame {frame}  t = {float(t0.t_s[np.flatnonzero(t0.frame == frame)[0]]):.3f} s",
        (8, 22),
        cv2.FONT_HERSHEY_SIMPLEX,
        0.6,
        (255, 255, 255),
        2,
        cv2.LINE_AA,
    )
    for k, t in enumerate(res.tracks):
        col = _COLOURS[k % len(_COLOURS)]
        i = int(np.flatnonzero(t.frame == frame)[0])
        fixed = t.status[i] == "corrected"
        if fixed:  # a hand-set pose: white, and said so
            col = (255, 255, 255)
        if fixed and t.x_px is not None and not np.isfinite(t.x_px[i]):
            th_deg = math.degrees(t.theta_rad[i]) if np.isfinite(t.theta_rad[i]) else math.nan
            cv2.putText(
                out,
                f"{t.object}: corrected, theta {th_deg:.4g} deg",
                (8, 46 + 20 * k),
                cv2.FONT_HERSHEY_SIMPLEX,
                0.55,
                col,
                2,
                cv2.LINE_AA,
            )
            continue
        if t.status[i] not in USABLE_STATUSES or t.x_px is None or not np.isfinite(t.x_px[i]):
            cv2.putText(
                out, f"{t.object}: {t.status[i]}", (8, 46 + 20 * k), cv2.FONT_HERSHEY_SIMPLEX, 0.55, col, 2, cv2.LINE_AA
            )
            continue
        u, v, th = float(t.x_px[i]), float(t.y_px[i]), float(t.theta_rad[i] + res.level_rad)
        L = 0.06 * max(out.shape[:2])
        if math.isfinite(th):  # no axes where the angle is not measured (kind "point", a disk)
            for ang, ln in ((th, L), (th + math.pi / 2, 0.6 * L)):  # object x and y axes (image v down)
                p1 = (int(u + ln * math.cos(ang)), int(v - ln * math.sin(ang)))
                cv2.line(out, (int(u), int(v)), p1, col, 2, cv2.LINE_AA)
        cv2.circle(out, (int(u), int(v)), 4, col, -1)
        angle = f"theta {math.degrees(t.theta_rad[i]):.4g} deg" if math.isfinite(th) else "position only"
        angle += " (corrected)" if fixed else ""
        cv2.putText(out, f"{t.object}: {angle}", (8, 46 + 20 * k), cv2.FONT_HERSHEY_SIMPLEX, 0.55, col, 2, cv2.LINE_AA)
    return out


def contact_sheet(tiles, width_px: int = 1800):
    """Tiles (BGR, same size) in a grid of up to 3 columns, scaled to ``width_px`` wide."""
    import cv2

    if not tiles:
        raise InputError("no tracked frame to show; check the video and the config")
    cols = min(3, len(tiles))
    rows = -(-len(tiles) // cols)
    h, w = tiles[0].shape[:2]
    s = min(1.0, width_px / (cols * w))
    th, tw = max(int(h * s), 1), max(int(w * s), 1)
    sheet = np.zeros((rows * th, cols * tw, 3), np.uint8)
    for k, t in enumerate(tiles):
        r, c = divmod(k, cols)
        sheet[r * th : (r + 1) * th, c * tw : (c + 1) * tw] = cv2.resize(t, (tw, th), interpolation=cv2.INTER_AREA)
    return sheet
