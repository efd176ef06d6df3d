"""``rocklab track VIDEO``: per-object θ, x, y (and table motion) from a video.

Writes ``tracks.csv`` (columns ``frame, t_s, object, x_m, y_m, theta_rad,
sigma_theta_rad, quality, status``) and, when the config has a table, a
``<stem>_table.csv`` next to it (``t_s, x_m, vx_m_s, ax_m_s2``).
"""

from __future__ import annotations

from pathlib import Path

from .._errors import InputError


def register(sub):
    """Add this module's subcommand(s) to the ``rocklab`` parser ``sub``."""
    p = sub.add_parser("track", help="track blocks and table in a video (ArUco, dots, edges, region)",
                       description=__doc__)
    p.add_argument("video", help="video file (.mkv/.mp4/...) or image sequence 'dir/%%05d.png'")
    p.add_argument("--config", default=None,
                   help="track.toml (default: track.toml next to the video)")
    p.add_argument("-o", "--out", default=None, help="output CSV (default: tracks.csv next to the video)")
    p.add_argument("--fps", type=float, default=None,
                   help="frame rate; required when the container has none")
    p.add_argument("--json", action="store_true", help="print a JSON summary on stdout")
    p.add_argument("--progress", action="store_true", help="progress bar on stderr")
    p.set_defaults(func=run)


def run(args) -> int:
    """Run ``rocklab track`` with parsed ``args``; returns the exit status (0 ok)."""
    import math

    from .._io import write_frame_atomic
    from ..tracking import load_track_config, track_video

    video = Path(args.video)
    cfg_path = Path(args.config) if args.config else video.parent / "track.toml"
    if not cfg_path.exists():
        raise InputError(f"{cfg_path}: tracking config not found; pass --config track.toml")
    if args.fps is not None and not (math.isfinite(args.fps) and args.fps > 0):
        raise InputError(f"--fps {args.fps}: must be a positive number of frames per second")
    cfg = load_track_config(cfg_path)
    res = track_video(video, cfg, fps=args.fps, progress=args.progress)
    out = Path(args.out) if args.out else video.parent / "tracks.csv"
    write_frame_atomic(out, res.to_frame(), float_format="%.9g")
    summary = res.to_dict()
    summary["tracks_csv"] = str(out)
    if cfg.table is not None and any(res[cfg.table.id].ok):
        try:
            tm = res.table_motion()
        except InputError as e:
            summary["table_motion"] = {"error": str(e)}
        else:
            tpath = out.with_name(out.stem + "_table.csv")
            write_frame_atomic(tpath, tm.to_frame(), float_format="%.9g")
            summary["table_motion"] = {**tm.to_dict(), "csv": str(tpath)}
    if args.json:
        from ._cli_base import emit_json

        emit_json(summary)
    else:
        for oid, d in summary["objects"].items():
            print(f"{oid}: {d['n_ok']}/{res.n_frames} frames ok, "
                  f"median sigma_theta {d['median_sigma_theta_rad']:.2e} rad")
        print(f"wrote {out}")
    return 0
