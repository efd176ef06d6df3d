"""``rocklab demo``: render a small synthetic campaign and run it end to end."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

from .._cli_base import count


def viewer_command() -> str:
    """How to call Rerun's viewer from here: ``rerun`` when it is on the PATH, else the one
    installed beside this Python (``.venv/bin/rerun`` after ``make demo``, relative when it can be)."""
    if shutil.which("rerun"):
        return "rerun"
    exe = Path(sys.executable).parent / "rerun"
    if not exe.is_file():
        return "rerun"
    try:
        return str(exe.relative_to(Path.cwd()))
    except ValueError:
        return str(exe)


def register(sub):
    """Add this module's subcommand(s) to the ``rocklab`` parser ``sub``."""
    p = sub.add_parser(
        "demo",
        help="render a small synthetic campaign (Čeh blocks, ArUco video, x-IMU logs, "
        "an El Centro shake-table run) and run it end to end",
    )
    p.add_argument("--out", default="demo_out", help="output folder (default: demo_out)")
    p.add_argument("--workers", type=count(1), default=2, help="parallel processes (default 2)")
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    p.add_argument(
        "--lossless",
        action="store_true",
        help="track the lossless video.mkv films instead of the camcorder-like H.264 video.mp4 (the default)",
    )
    p.set_defaults(func=run)


def run(args) -> int:
    """Run ``rocklab demo`` with parsed ``args``; returns the exit status (0 ok)."""
    from ...campaign import run_demo

    res, t = run_demo(args.out, workers=args.workers, progress=not args.no_progress, camcorder=not args.lossless)
    print(res.summary_text())
    print(f"(rendered sessions in {t['render_s']:.0f} s, campaign in {t['campaign_s']:.0f} s)")
    rerun = viewer_command()
    print(
        f"look: {args.out}/results/campaign.csv, {args.out}/results/figures/, "
        f"{rerun} {args.out}/results/campaign.rrd, {rerun} {args.out}/results/experiments/<run>/session.rrd"
    )
    return 0 if res.n_ok == len(res.runs) else 1
