"""``rocklab track3d``: blocks' rocking from 3D points (optical-system exports), with the assumption audit.

``rocklab track3d POINTS -o tracks.csv [--body NAME=P1,P2,... ...] [--up z] [--rest auto]``

POINTS is a long CSV (``t_s, point, x_m, y_m, z_m``; ``_mm``/``_cm`` suffixes are
converted) or a ``.c3d`` file. Without ``--body`` every point belongs to one block.
A body named ``table`` (or ``base``) is tracked too and the blocks are measured
relative to it. The rig's axes may be yawed and offset: ``--up`` only names the
vertical; the rocking direction, the pivot edges and the table height come from
the motion.

Writes ``tracks.csv`` (the 2D tracker's columns plus ``out_of_plane_rad,
twist_rad, pivot_slide_m, pivot_uplift_m``) and ``audit.json`` next to it:
``{"verdict": "valid"|"suspect"|"invalid", "flags": [{"kind", "t_s", "value",
"tolerance", "impact", "detail", "object"}, ...], ...}``.
"""

from __future__ import annotations

import math
from pathlib import Path

from ...._errors import InputError


def register(sub):
    """Add ``track3d`` to the ``rocklab`` parser ``sub``."""
    p = sub.add_parser(
        "track3d",
        help="rocking angle, twist, pivot sliding/uplift and the assumption audit from 3D points (CSV or C3D)",
        description=__doc__,
    )
    p.add_argument("points", help="3D points: .c3d, or CSV with t_s, point, x_m, y_m, z_m (long format)")
    p.add_argument(
        "-o",
        "--out",
        default=None,
        help="output tracks.csv (default: tracks.csv next to POINTS); audit.json is written next to it",
    )
    p.add_argument(
        "--body",
        action="append",
        default=[],
        metavar="NAME=P1,P2,...",
        help="a rigid body and its point labels (repeat; 'table' or 'base' names the table); "
        "default: all points are one block",
    )
    p.add_argument("--up", default="z", help="the rig's vertical axis: x, y or z, optionally signed (default z)")
    p.add_argument(
        "--rest",
        default="auto",
        metavar="auto|first|last|T0,T1",
        help="samples where the block stands upright at rest (default auto: the end, or the start if it overturned)",
    )
    p.add_argument("--slide-tol", type=float, default=0.5, metavar="MM", help="pivot sliding tolerance, mm (0.5)")
    p.add_argument("--jump-tol", type=float, default=1.0, metavar="MM", help="pivot uplift tolerance, mm (1.0)")
    p.add_argument(
        "--twist-tol",
        type=float,
        default=0.5,
        metavar="DEG",
        help="twist and out-of-plane rotation tolerance, deg (0.5)",
    )
    p.add_argument(
        "--rrd",
        default=None,
        metavar="FILE",
        help="also write a Rerun review: the targets in 3D, the pivot path, the plots, the audit's flags",
    )
    p.add_argument("--json", action="store_true", help="print a JSON summary on stdout")
    p.set_defaults(func=run)


def rest_spec(spec: str):
    s = str(spec).strip().lower()
    if s in ("auto", "first", "last"):
        return s
    try:
        t0, t1 = (float(v) for v in s.split(","))
    except ValueError:
        raise InputError(f"--rest {spec!r}: give auto, first, last or T0,T1 in seconds (e.g. 4.5,5.0)") from None
    if not (math.isfinite(t0) and math.isfinite(t1) and t1 > t0):
        raise InputError(f"--rest {spec!r}: T1 must be a time after T0, in seconds")
    return (t0, t1)


def write_track3d_outputs(out: Path, series, res, rrd=None, out_side: bool = False) -> dict:
    """Write ``tracks.csv`` at ``out``, ``audit.json`` beside it and the Rerun review at ``rrd`` (if given);
    returns the summary (:meth:`Track3DResult.to_dict` with the paths and the verdict).

    ``audit.json`` (and ``out`` when ``out_side``: a default name) never replaces a user's file
    (kept as ``NAME.user-<time>``)."""
    from ...._io import write_json_atomic
    from ....series import write_tracks
    from .._io_plan import AUDIT, track3d_outputs

    write_tracks(out, res.to_frame(), side=out_side)
    audit = res.audit_dict()
    audit_path = track3d_outputs(out)[AUDIT]
    write_json_atomic(audit_path, audit, side=True)
    summary = res.to_dict()
    summary.update(tracks_csv=str(out), audit_json=str(audit_path), verdict=audit["verdict"])
    if rrd:
        from ...experiment import write_track3d_rrd

        write_track3d_rrd(rrd, series, res)
        summary["rrd"] = str(rrd)
    return summary


def run(args) -> int:
    """Run ``rocklab track3d`` with parsed ``args``; returns the exit status (0 ok)."""
    from ...._errors import positive
    from ....tracking.rigid import AuditTolerances, parse_bodies, read_points, track_points3d

    src = Path(args.points)
    tol = AuditTolerances(
        slide_m=positive("--slide-tol (mm)", args.slide_tol) * 1e-3,
        jump_m=positive("--jump-tol (mm)", args.jump_tol) * 1e-3,
        twist_rad=math.radians(positive("--twist-tol (deg)", args.twist_tol)),
        out_of_plane_rad=math.radians(args.twist_tol),
    )
    rest = rest_spec(args.rest)
    out = Path(args.out) if args.out else src.parent / "tracks.csv"
    series = read_points(src)
    bodies = parse_bodies(args.body, series.labels, series.source)
    res = track_points3d(series, bodies, up=args.up, rest=rest, tolerances=tol)
    summary = write_track3d_outputs(out, series, res, args.rrd, out_side=not args.out)
    if args.json:
        from .._cli_base import emit_json

        emit_json(summary)
        return 0
    for n in res.notes:
        print(f"note: {n}")
    for b in res.bodies:
        d = b.to_dict()
        line = (
            f"{b.name}: {d['samples_ok']}/{d['samples']} samples, rest = {b.rest}, "
            f"max |theta| {math.degrees(d['max_abs_theta_rad']):.4g} deg, "
            f"median sigma_theta {math.degrees(d['median_sigma_theta_rad']):.4g} deg"
        )
        if not b.is_table:
            line += f", base width {b.geometry.base_width_m * 1e3:.4g} mm"
        print(line)
        if b.audit is not None:
            print(b.audit.report())
    print(f"wrote {out} and {summary['audit_json']} (verdict {summary['verdict']})")
    return 0
