"""``rocklab track``: per-object θ, x, y (and table motion) from a video.

- ``rocklab track VIDEO [--config track.toml] [-o tracks.csv] [--plot tracks.png]`` writes ``tracks.csv``
  (columns ``frame, t_s, object, x_px, y_px, x_m, y_m, theta_rad, sigma_theta_rad,
  quality, status``; ``x_m, y_m`` empty without a metric scale) and, when the config
  has a table, ``<stem>_table.csv`` (``t_s, x_m, vx_m_s, ax_m_s2``); ``--plot`` draws each
  object's theta (with its 1-sigma band), image position and quality, every frame that is not
  ``ok`` marked by its status.
- ``rocklab track init VIDEO [--object NAME=x,y,w,h ...] [--table x,y,w,h]
  [--marker-size M] [--lens lens.json] [--start-frame N] -o track.toml``: a config from the first
  frame tracked (frame N, written as ``[video] start_frame``; without it frame 0, or the first after
  a lead-in of blank, fading-in or title frames, said in a note) (markers found by
  trying the common dictionaries, or the named regions followed markerless), commented,
  plus ``track_init.png`` with every detection, region and the level line drawn; ``--lens``
  (from ``rocklab calibrate``) is written as ``[video] calibration``.
- ``rocklab track preview VIDEO --config track.toml [-o sheet.png] [--frames 6] [--at T_S]``: a
  contact sheet of frames spread over the first 10 s (the span tracked: a quick check), or of
  consecutive frames around ``T_S``, with each object's pose and θ drawn (a corrected frame's
  pose in white and marked "corrected", a dropped one named).
- ``--corrections FILE`` (track, preview): manual corrections applied after tracking (see
  :mod:`rocklab.tracking._corrections`); ``tracks.csv`` marks the frames ``corrected`` or ``dropped``.
- ``track init`` on a film without markers and without ``--object`` proposes the objects that
  move in the first seconds and the table edge they stand on, draws them over a pixel grid and
  prints each as the option to re-run with.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ...._errors import InputError


def register(sub):
    """Add this module's subcommand(s) to the ``rocklab`` parser ``sub``."""
    p = sub.add_parser(
        "track", help="track blocks and table in a video (ArUco, dots, edges, region)", description=__doc__
    )
    p.add_argument(
        "video",
        help="video file (.mkv/.mp4/...), a folder of numbered PNG/JPEG/TIFF frames (timed by its "
        "timestamps.csv or --fps), a Photron .cih/.mraw or Phantom .cine; or 'init' / 'preview' followed by the video",
    )
    p.add_argument("video2", nargs="?", default=None, metavar="VIDEO", help=argparse.SUPPRESS)
    p.add_argument(
        "--object",
        action="append",
        default=[],
        metavar="NAME=x,y,w,h",
        help="init: an object's region in the first frame (px), followed markerless",
    )
    p.add_argument(
        "--table",
        default=None,
        metavar="x,y,w,h",
        help="init: a markerless table's region (round its top edge: it levels the angles)",
    )
    p.add_argument("--marker-size", type=float, default=None, help="init: printed marker side, m")
    p.add_argument(
        "--lens",
        default=None,
        metavar="LENS_JSON",
        help="init: a lens file from 'rocklab calibrate', written as [video] calibration (points undistorted)",
    )
    p.add_argument("--preview", default=None, help="init: preview PNG (default: <config stem>_init.png)")
    p.add_argument(
        "--start-frame",
        type=int,
        default=None,
        metavar="N",
        help="init: the first frame tracked, written as [video] start_frame (regions are in its pixels; "
        "default: 0, or the first frame after blank, fading-in or title frames)",
    )
    p.add_argument("--frames", type=int, default=6, help="preview: frames on the contact sheet (default 6)")
    p.add_argument("--config", default=None, help="track.toml (default: track.toml next to the video)")
    p.add_argument("-o", "--out", default=None, help="output CSV (default: tracks.csv next to the video)")
    p.add_argument(
        "--fps",
        type=float,
        default=None,
        help="frame rate; required when the film has none (an image folder without timestamps.csv)",
    )
    p.add_argument(
        "--corrections",
        default=None,
        metavar="FILE",
        help="track, preview: manual corrections (CSV or TOML: per object and frame or time range, drop or "
        "set x_m/y_m/theta_rad/theta_deg) applied after tracking; overrides [video] corrections",
    )
    p.add_argument(
        "--at",
        type=float,
        default=None,
        metavar="T_S",
        help="preview: show consecutive frames around this time, s (default: frames spread over the first 10 s)",
    )
    p.add_argument(
        "--plot",
        default=None,
        metavar="PNG",
        help="track: theta, position and quality per object, every failed frame marked",
    )
    p.add_argument("--json", action="store_true", help="print a JSON summary on stdout")
    p.add_argument("--progress", action="store_true", help="progress bar on stderr")
    p.set_defaults(func=run)


def run(args) -> int:
    """Run ``rocklab track`` with parsed ``args``; returns the exit status (0 ok)."""
    import math

    if args.at is not None and args.video != "preview":
        raise InputError("--at T_S: shows the frames around a time in 'rocklab track preview VIDEO --at T_S' only")
    if args.lens is not None and args.video != "init":
        raise InputError("--lens: applies to 'rocklab track init'; a config names its lens in [video] calibration")
    if args.start_frame is not None and args.video != "init":
        raise InputError("--start-frame N: applies to 'rocklab track init'; a config sets [video] start_frame")
    if args.start_frame is not None and args.start_frame < 0:
        raise InputError(f"--start-frame {args.start_frame}: give a frame number >= 0")
    if args.corrections is not None and args.video == "init":
        raise InputError("--corrections: applies to 'rocklab track' and 'track preview', not to 'track init'")
    if args.fps is not None and not (math.isfinite(args.fps) and args.fps > 0):
        raise InputError(f"--fps {args.fps}: must be a positive number of frames per second")
    if args.video in ("init", "preview"):
        return _tools(args)
    if args.video2 is not None:
        raise InputError(
            f"unexpected second argument {args.video2!r}; use 'rocklab track VIDEO', "
            "'rocklab track init VIDEO' or 'rocklab track preview VIDEO'"
        )

    from ...._io import write_frame_atomic
    from ....series import write_tracks
    from ....config import load_track_config
    from ....tracking import track_video
    from .._io_plan import TABLE, track_outputs

    video = Path(args.video)
    if not video.exists() and "%" not in video.name:  # named first: the config's absence would hide it
        raise InputError(f"{video}: video not found (no such file, image folder or numbered pattern); check the path")
    cfg_path = Path(args.config) if args.config else video.parent / "track.toml"
    if not cfg_path.exists():
        raise InputError(f"{cfg_path}: tracking config not found; pass --config track.toml")
    cfg = _with_corrections(load_track_config(cfg_path), args.corrections)
    res = track_video(video, cfg, fps=args.fps, progress=args.progress)
    out = Path(args.out) if args.out else video.parent / "tracks.csv"
    write_tracks(out, res.to_frame(), side=not args.out)
    summary = res.to_dict()
    summary["tracks_csv"] = str(out)
    if args.plot:
        from .._track_plot import track_figure

        track_figure(res, args.plot, title=str(video))
        summary["plot"] = str(args.plot)
    if cfg.table is not None and any(res[cfg.table.id].ok):
        try:
            tm = res.table_motion()
        except InputError as e:
            from ...._diagnostics import warn

            summary["table_motion"] = {"error": str(e)}
            warn("W-TABLE-MOTION", f"{video}: no table motion for {cfg.table.id!r}: {e}")
        else:
            tpath = track_outputs(out)[TABLE]
            write_frame_atomic(tpath, tm.to_frame(), float_format="%.9g", side=True)
            summary["table_motion"] = {**tm.to_dict(), "csv": str(tpath)}
    if args.json:
        from .._cli_base import emit_json

        emit_json(summary)
    else:
        for oid, d in summary["objects"].items():
            angle = (
                f"theta not measured: {d['theta_note']}"
                if d.get("theta_note")
                else f"median sigma_theta {d['median_sigma_theta_rad']:.4g} rad"
            )
            print(f"{oid}: {d['n_ok']}/{res.n_frames} frames ok, {angle}")
        if res.corrections:
            n = {a: sum(c["n_frames"] for c in res.corrections if c["action"] == a) for a in ("set", "drop")}
            print(
                f"corrections: {len(res.corrections)} applied ({n['set']} frame(s) corrected, {n['drop']} dropped; "
                "status corrected/dropped in the CSV)"
            )
        print(f"wrote {out}")
    return 0


def _tools(args) -> int:
    from .._track_tools import PREVIEW_SPAN_S, track_init, track_preview

    if args.video2 is None:
        raise InputError(f"rocklab track {args.video}: give the video, e.g. 'rocklab track {args.video} film.mp4'")
    video = Path(args.video2)
    if args.video == "init":
        out = Path(args.out) if args.out else video.parent / "track.toml"
        if out.suffix.lower() != ".toml":
            raise InputError(f"-o {out}: the config is a .toml file; give e.g. -o track.toml")
        preview = Path(args.preview) if args.preview else out.with_name(out.stem + "_init.png")
        cfg, notes, proposed = track_init(
            video,
            out,
            objects=args.object,
            table=args.table,
            marker_size_m=args.marker_size,
            preview=preview,
            side=(not args.out, not args.preview),
            fps=args.fps,
            lens=args.lens,
            start_frame=args.start_frame,
        )
        if args.json:
            from .._cli_base import emit_json

            emit_json(
                {
                    "config": str(out),
                    "preview": str(preview),
                    "objects": [o.id for o in cfg.objects],
                    "style": cfg.targets.style,
                    "level": cfg.reference.level,
                    "start_frame": cfg.video.start_frame,
                    "proposed": list(proposed),
                    "notes": notes,
                }
            )
        else:
            for n in notes:
                print(f"note: {n}")
            for p in proposed:
                print(f"proposed: {p}")
            start = f" --start-frame {cfg.video.start_frame}" if cfg.video.start_frame else ""
            if proposed:
                print(f"to correct them: rocklab track init {video}{start} {' '.join(proposed)} -o {out}")
            print(
                f"wrote {out} ({', '.join(o.id for o in cfg.objects)}) and {preview}; check the preview, then "
                f"'rocklab track {video} --config {out}'"
            )
        return 0
    if not video.exists() and "%" not in video.name:  # named first: the config's absence would hide it
        raise InputError(f"{video}: video not found (no such file, image folder or numbered pattern); check the path")
    cfg_path = Path(args.config) if args.config else video.parent / "track.toml"
    if not cfg_path.exists():
        raise InputError(f"{cfg_path}: tracking config not found; pass --config track.toml")
    out = Path(args.out) if args.out else video.parent / "track_preview.png"
    res, frames = track_preview(
        video,
        cfg_path,
        out,
        n_frames=args.frames,
        progress=args.progress,
        side=not args.out,
        fps=args.fps,
        at_s=args.at,
        corrections=args.corrections,
    )
    span = f"around t = {args.at:g} s" if args.at is not None else f"of the first {PREVIEW_SPAN_S:g} s"
    print(f"wrote {out}: frames {', '.join(map(str, frames))} ({span}, tracked for the check)")
    return 0


def _with_corrections(cfg, path):
    """The config with ``--corrections`` in place of its ``[video] corrections``."""
    if path is None:
        return cfg
    from dataclasses import replace

    return replace(cfg, video=replace(cfg.video, corrections=str(path)))
