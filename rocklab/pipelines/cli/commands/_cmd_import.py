"""``rocklab import``: another tool's tracking into rocklab's files.

``rocklab import FILE [--tool auto|tracker|kinovea|dltdv] [-o OUT] [--body NAME=P1,P2 ...]``

- Tracker (``.trk``, or a ``.trz`` with ``--trk NAME`` when it holds several): the point-mass
  tracks become ``tracks.csv`` (the film tracker's columns): each body's angle from two or more
  points marked on it, counter-clockwise from its rest shape (``--rest``), its centroid in px
  and, when the project is calibrated, in m. Without ``--body`` every point is one block.
- Kinovea (*Export to spreadsheet* ``.xml``, or the Gnuplot ``.txt`` with ``--units``):
  the trajectories, in the calibration's unit (y up), become ``tracks.csv`` the same way.
- DLTdv (``*xypts.csv`` with ``--coefs *DLTcoefs.csv``, or ``*xyzpts.csv``): 3D points,
  reconstructed from two or more cameras with the DLT coefficients, written as the long
  ``points.csv`` (``t_s, point, x_m, y_m, z_m``) that ``rocklab track3d`` reads; ``--fps``
  gives the time base and ``--units`` the unit of the calibration frame.

The tool is told from the file (``--tool auto``). ``tracks.csv`` then feeds ``rocklab fit
restitution`` and ``[sources.track]`` of ``rocklab run`` like a film's.
"""

from __future__ import annotations

from pathlib import Path

from ...._errors import InputError

#: Tools ``--tool`` accepts (``auto``: from the file's name and content).
TOOLS = ("auto", "tracker", "kinovea", "dltdv")


def register(sub):
    """Add ``import`` to the ``rocklab`` parser ``sub``."""
    p = sub.add_parser(
        "import",
        help="another tool's tracking (Tracker .trk/.trz or data table, Kinovea .xml/.txt, DLTdv xypts/xyzpts) into tracks.csv "
        "or points.csv",
        description=__doc__,
    )
    p.add_argument(
        "file",
        help="the tool's file: .trk, .trz or Tracker's data table, Kinovea's .xml or .txt, *xypts.csv or *xyzpts.csv",
    )
    p.add_argument("--tool", choices=TOOLS, default="auto", help="the tool that wrote FILE (default: auto)")
    p.add_argument(
        "-o",
        "--out",
        default=None,
        help="output: tracks.csv for a plane tool, points.csv for DLTdv (default: that name next to FILE)",
    )
    p.add_argument("--trk", default=None, metavar="NAME", help="the .trk inside a .trz that holds several")
    p.add_argument(
        "--body",
        action="append",
        default=[],
        metavar="NAME=P1,P2,...",
        help="a rigid body and the names of its points (repeat; two or more for its angle, one point is a "
        "position only); default: every point is one block, block_1",
    )
    p.add_argument(
        "--rest",
        default="auto",
        metavar="auto|first|last|T0,T1",
        help="frames where each body stands upright (theta = 0): auto/last the last 10 frames with all its "
        "points (free rocking ends upright), first the first 10, or the frames between T0 and T1 s",
    )
    p.add_argument(
        "--units",
        default=None,
        metavar="UNIT",
        help="length unit of the tool's calibration when the file names none (Tracker's data table, Kinovea .txt, "
        "DLTdv): m, cm, mm "
        "(Tracker also in, ft)",
    )
    p.add_argument("--coefs", default=None, metavar="CSV", help="DLTdv: the DLT coefficients (*DLTcoefs.csv)")
    p.add_argument(
        "--fps",
        type=float,
        default=None,
        help="DLTdv: the cameras' frame rate, Hz (t_s = row / fps); Kinovea: snap the exported times to frames",
    )
    p.add_argument("--json", action="store_true", help="print a JSON summary on stdout")
    p.set_defaults(func=run)


def _run_plane(args, src: Path, out: Path, tool: str) -> dict:
    from ....series import write_tracks
    from ....tracking.imports import parse_plane_bodies, plane_tracks, read_plane_points
    from ._cmd_track3d import rest_spec

    pts = read_plane_points(src, tool, member=args.trk, units=args.units, fps=args.fps)
    bodies = parse_plane_bodies(args.body, pts.labels, pts.source)
    rows = plane_tracks(pts, bodies, rest=rest_spec(args.rest))
    write_tracks(out, rows, side=not args.out)
    per = {b: int((rows[rows["object"] == b]["status"] == "ok").sum()) for b in bodies}
    return {
        "tool": tool,
        "source": pts.source,
        "points": list(pts.labels),
        "bodies": {b: list(v) for b, v in bodies.items()},
        "frames": int(pts.t_s.size),
        "frames_ok": per,
        "metric": pts.xy_m is not None,
        "notes": list(pts.notes),
        "tracks_csv": str(out),
    }


def _run_dltdv(args, src: Path, out: Path) -> dict:
    from ....tracking.imports import read_dltdv
    from ....tracking.rigid import write_points_csv

    series, info = read_dltdv(src, coefs=args.coefs, fps=args.fps, units=args.units)
    write_points_csv(series, out, side=not args.out)
    return {
        "tool": "dltdv",
        "source": series.source,
        "points": list(series.labels),
        "samples": int(series.t_s.size),
        **info,
        "notes": list(series.notes),
        "points_csv": str(out),
    }


def run(args) -> int:
    """Run ``rocklab import`` with parsed ``args``; returns the exit status (0 ok)."""
    src = Path(args.file)
    if not src.is_file():
        raise InputError(f"{src}: not found; give the tool's file")
    from ....tracking.imports import detect_tool
    from .._io_plan import import_output

    tool = detect_tool(src) if args.tool == "auto" else args.tool
    out = Path(args.out) if args.out else import_output(src, tool)
    summary = _run_dltdv(args, src, out) if tool == "dltdv" else _run_plane(args, src, out, tool)
    if args.json:
        from .._cli_base import emit_json

        emit_json(summary)
        return 0
    for n in summary["notes"]:
        print(f"note: {n}")
    if tool != "dltdv":
        for b, pts in summary["bodies"].items():
            print(f"{b}: points {pts}, {summary['frames_ok'][b]}/{summary['frames']} frames with every point")
        for b, pts in summary["bodies"].items():
            if len(pts) == 1:
                print(f"note: {b} is one point: its position only (theta_rad empty); an angle needs two points")
        print(f"wrote {out}" + ("" if summary["metric"] else " (x_m, y_m empty: no calibration)"))
    else:
        print(f"{len(summary['points'])} points, {summary['samples']} samples; wrote {out}")
        print(f"next: rocklab track3d {out} --body block=P1,P2,P3 --up z")
    return 0
