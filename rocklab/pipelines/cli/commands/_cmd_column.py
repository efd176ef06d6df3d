"""``rocklab column``: a multi-block column, free or on a base-motion record (thesis §3.2–3.3).

Examples::

    rocklab column --blocks 0.1x0.2,0.1x0.2,0.1x0.2 --cut 0.002 --theta0 0,0,0.05 --duration 3
    rocklab column --blocks 0.1x0.2,0.1x0.2,0.1x0.2 --cut 0.002 --base-motion table.csv --json
    rocklab column --maps-png fig40.png          # overturning maps of 1-, 2-, 3-block columns

Sizes in metres (``WIDTHxHEIGHT`` per block, bottom first), angles in radians
(clockwise positive, as ``rocklab simulate``), times in seconds. ``-o`` writes
the time history CSV (``t_s, theta_<i>_rad, phi_<j>_rad, omega_<j>_rad_s,
energy_J``) atomically, every step or every ``--output-dt`` s.
"""

from __future__ import annotations

import math
import sys

from .._cli_base import add_base_motion_args, base_motion_from_args

_MAX_LINES = 40


def register(sub):
    """Add this module's subcommand(s) to the ``rocklab`` parser ``sub``."""
    p = sub.add_parser(
        "column",
        help="simulate a multi-block column (opening and impact models)",
        description="Simulate a planar column of rigid blocks on a rigid base (SI units).",
    )
    p.add_argument(
        "--blocks",
        default=None,
        help="blocks bottom to top as WIDTHxHEIGHT in m, comma separated (e.g. 0.1x0.2,0.1x0.2)",
    )
    p.add_argument("--cut", default="0", help="cut edge size per joint, m (one value or one per joint)")
    p.add_argument(
        "--density",
        type=float,
        default=2700.0,
        help="block density, kg/m3 (sets the mass ratios; default 2700, granite)",
    )
    p.add_argument("--mu", type=float, default=math.inf, help="friction coefficient (default: no sliding check)")
    p.add_argument("--theta0", default=None, help="initial block angles, rad (comma separated, bottom first)")
    p.add_argument("--omega0", default=None, help="initial block rates, rad/s (comma separated)")
    p.add_argument("--duration", type=float, default=None, help="simulated time, s (default record end + 5 s)")
    p.add_argument("--dt", type=float, default=1e-4, help="time step, s (default 1e-4)")
    p.add_argument(
        "--impacts",
        type=int,
        default=1,
        help="consecutive impacts per closing: 1 Housner, 2 one mid-joint bump (thesis)",
    )
    add_base_motion_args(p)
    p.add_argument(
        "--thesis-form",
        action="store_true",
        help="drop the velocity terms of the App. C reduction (the thesis's M(phi) phi'' = p(phi))",
    )
    p.add_argument("-o", "--output", default=None, help="write the time history CSV here")
    p.add_argument(
        "--output-dt",
        type=float,
        default=None,
        help="spacing of the -o time history, s (a multiple of --dt; default every step); "
        "events and peaks always come from every step",
    )
    p.add_argument(
        "--maps-png",
        default=None,
        help="also compute the thesis Fig. 40 overturning maps (H=12 m, B=1 m, 1-3 blocks) and write them to this PNG",
    )
    p.add_argument(
        "--maps-grid",
        type=int,
        default=10,
        help="maps: grid points per axis over a_p 1-12 m/s2, t_p 0.3-2.4 s (default 10)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON summary object on stdout")
    p.set_defaults(func=run)


def _floats(text, name, n=None):
    from ...._errors import InputError

    try:
        vals = [float(x) for x in str(text).split(",") if x.strip()]
    except ValueError:
        raise InputError(f"--{name} {text!r}: give comma-separated numbers") from None
    if n is not None and len(vals) not in (1, n):
        raise InputError(f"--{name} {text!r}: give one value or one per block ({n})")
    return vals if n is None or len(vals) == n else vals * n


def _blocks(text, density):
    from ...._errors import InputError
    from ....blocks import Block

    out = []
    for i, tok in enumerate(str(text).split(",")):
        parts = tok.strip().lower().split("x")
        if len(parts) != 2:
            raise InputError(f"--blocks item {i + 1} {tok!r}: write WIDTHxHEIGHT in metres, e.g. 0.1x0.2")
        try:
            b, h = float(parts[0]), float(parts[1])
        except ValueError:
            raise InputError(f"--blocks item {i + 1} {tok!r}: width and height must be numbers (m)") from None
        out.append(Block(b, h, density_kg_m3=density, name=f"block_{i}"))
    return tuple(out)


def run(args) -> int:
    """Run ``rocklab column`` with parsed ``args``; returns the exit status (0 ok)."""
    from ...._errors import InputError
    from ...._io import write_frame_atomic
    from ....models import Column, simulate_column

    if args.blocks is None and args.maps_png is None:
        raise InputError("give --blocks WIDTHxHEIGHT,... (and/or --maps-png FILE)")
    out = {}
    if args.blocks is not None:
        blocks = _blocks(args.blocks, args.density)
        n = len(blocks)
        col = Column(blocks, cut_m=_floats(args.cut, "cut", n), mu=args.mu)
        base = base_motion_from_args(args)
        th0 = _floats(args.theta0, "theta0", n) if args.theta0 else None
        om0 = _floats(args.omega0, "omega0", n) if args.omega0 else None
        if base is None and not (th0 and any(th0)) and not (om0 and any(om0)):
            raise InputError("nothing moves: give --base-motion FILE or a non-zero --theta0/--omega0")
        # without -o nothing reads the time history: keep only the end states
        odt = args.output_dt if args.output else math.inf
        res = simulate_column(
            col,
            base,
            theta0_rad=th0,
            omega0_rad_s=om0,
            duration_s=args.duration,
            dt_s=args.dt,
            n_impacts=args.impacts,
            velocity_terms=not args.thesis_form,
            output_dt_s=odt,
        )
        if args.output:
            write_frame_atomic(args.output, res.to_frame())
        out = res.to_dict()
    if args.maps_png is not None:
        out["maps"] = _maps(args)
    if args.json:
        from .._cli_base import emit_json

        emit_json(out)
        return 0
    if args.blocks is not None:
        _print_summary(res, out)
        if args.output:
            sys.stdout.write(f"wrote {args.output}\n")
    if args.maps_png is not None:
        fr = out["maps"]["overturned_fraction"]
        sys.stdout.write(
            "overturning maps (H=12 m, B=1 m, full-sine pulse): overturned share "
            + ", ".join(f"{k} block{'s' * (k > 1)} {f:.2f}" for k, f in zip((1, 2, 3), fr))
            + f"\nwrote {args.maps_png}\n"
        )
    return 0


def _print_summary(res, d):
    w = sys.stdout.write
    col = res.column
    w(
        f"column of {col.n} block(s), height {col.height_m:g} m, cut {', '.join(f'{c:g}' for c in col.cut_m)} m; "
        f"dt = {res.params['dt_s']:g} s, {res.params['n_impacts']} impact(s) per closing\n"
    )
    t_end = res.t_s[-1] if len(res.t_s) else 0.0
    when = f"at t = {res.t_status_s:.4f} s" if math.isfinite(res.t_status_s) else f"at t = {t_end:.4f} s"
    w(f"status {res.status} {when}, {len(res.impacts)} impacts{': ' + res.message if res.message else ''}\n")
    w("peak |theta| per block, rad: " + ", ".join(f"{x:.5f}" for x in d["max_abs_theta_rad"]) + "\n")
    conf = d["configurations"]
    w(f"configuration changes ({len(conf)}):\n   t_s        joint  state   event\n")
    for c in conf[:_MAX_LINES]:
        w(f"  {c['t_s']:10.5f}  {c['joint']:5d}  {c['state']:<6}  {c['event']}\n")
    if len(conf) > _MAX_LINES:
        w(f"  ... {len(conf) - _MAX_LINES} more (use --json for all)\n")


def _maps(args):
    import numpy as np
    from tqdm import tqdm

    from ....models import column_overturning_maps
    from ...experiment import plot_column_maps

    k = max(int(args.maps_grid), 2)
    # the region where the columns' overturning boundaries differ (thesis Fig. 40)
    ap = np.linspace(1.0, 12.0, k)
    tp = np.linspace(0.3, 2.4, k)
    with tqdm(total=3 * k * k, file=sys.stderr, desc="maps", leave=False) as bar:
        maps = column_overturning_maps(ap_m_s2=ap, tp_s=tp, n_impacts=args.impacts, progress=lambda i: bar.update(1))
    plot_column_maps(maps, args.maps_png)
    return maps.to_dict()
