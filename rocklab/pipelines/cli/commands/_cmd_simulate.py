"""``rocklab simulate``: one rocking block, free or on a base-motion record.

Examples::

    rocklab simulate --width 0.045 --height 0.2025 --theta0 0.05 --duration 10 --json
    rocklab simulate --width 0.3 --height 1.5 --base-motion rec.AT2 --units g --scale-pga 0.3 -o out.csv

Sizes in metres, angles in radians, times in seconds. ``-o`` writes the time
history (``t_s, theta_rad, omega_rad_s, energy_J``) atomically.
"""

from __future__ import annotations

import sys

from .._cli_base import add_base_motion_args, base_motion_from_args


def register(sub):
    """Add this module's subcommand(s) to the ``rocklab`` parser ``sub``."""
    p = sub.add_parser(
        "simulate",
        help="simulate a rocking block (free rocking or base motion)",
        description="Simulate one rigid block rocking on a rigid base (SI units).",
    )
    p.add_argument("--width", type=float, required=True, help="block width b, m")
    p.add_argument("--height", type=float, required=True, help="block height h, m")
    p.add_argument(
        "--alpha-I",
        dest="alpha_I",
        type=float,
        default=4.0 / 3.0,
        help="corner inertia coefficient I_O/(m R^2) (default 4/3, uniform block)",
    )
    p.add_argument("--theta0", type=float, default=0.0, help="initial rotation, rad (|theta0| < alpha)")
    p.add_argument("--omega0", type=float, default=0.0, help="initial angular velocity, rad/s")
    p.add_argument("--duration", type=float, default=10.0, help="simulated time, s (default 10)")
    p.add_argument("--dt", type=float, default=1e-4, help="time step, s (default 1e-4)")
    p.add_argument("--output-dt", type=float, default=None, help="output spacing, s (multiple of --dt)")
    p.add_argument(
        "--restitution",
        default="housner",
        choices=["housner", "modified", "constant", "bumps", "cut_corner"],
        help="impact law (default housner)",
    )
    p.add_argument("--k", type=float, default=None, help="modified law: impulse position / half-width")
    p.add_argument("--eta", type=float, default=None, help="constant law: omega+/omega-")
    p.add_argument("--bumps", type=int, default=None, help="bumps law: number of bumps (n+1 impacts)")
    p.add_argument("--b2", type=float, default=None, help="cut_corner/bumps: half-distance of contact lines, m")
    add_base_motion_args(p)
    p.add_argument(
        "--method",
        default="newmark",
        help="integrator from rocklab.models.rocking.METHODS: newmark (numba, fast; default), taylor "
        "(high order, exact impacts) or event (scipy solve_ivp with impact events, the reference)",
    )
    p.add_argument(
        "--no-stop-at-rest",
        dest="stop_at_rest",
        action="store_false",
        help="keep integrating after the block has come to rest",
    )
    p.add_argument("-o", "--output", default=None, help="write the time history CSV here")
    p.add_argument("--json", action="store_true", help="print one JSON summary object on stdout")
    p.set_defaults(func=run)


def run(args) -> int:
    """Run ``rocklab simulate`` with parsed ``args``; returns the exit status (0 ok)."""
    from ...._errors import InputError
    from ...._io import write_frame_atomic
    from ....blocks import Block
    from ....models import simulate

    block = Block(args.width, args.height, alpha_I=args.alpha_I)
    law = {}
    if args.restitution == "modified":
        law["k"] = 1.0 if args.k is None else args.k
    elif args.restitution == "constant":
        if args.eta is None:
            raise InputError("--restitution constant needs --eta <value in [-1, 1]>")
        law["eta"] = args.eta
    elif args.restitution in ("bumps", "cut_corner"):
        if args.restitution == "bumps":
            law["n"] = 1 if args.bumps is None else args.bumps
        if args.b2 is not None:
            law["b2_m"] = args.b2
    base = base_motion_from_args(args)
    res = simulate(
        block,
        theta0_rad=args.theta0,
        omega0_rad_s=args.omega0,
        duration_s=args.duration,
        dt_s=args.dt,
        restitution=args.restitution,
        base=base,
        method=args.method,
        stop_at_rest=args.stop_at_rest,
        output_dt_s=args.output_dt,
        **law,
    )
    if args.output:
        write_frame_atomic(args.output, res.to_frame())
    d = res.to_dict()
    if args.json:
        from .._cli_base import emit_json

        emit_json(d)
    else:
        over = "" if d["overturn_t_s"] is None else f", passed alpha at t = {d['overturn_t_s']:.4f} s"
        sys.stdout.write(
            f"block {block.b_m:g} x {block.h_m:g} m: alpha = {block.alpha_rad:.5f} rad, "
            f"p = {block.p_rad_s:.4f} rad/s, eta_H = {block.eta_H:.4f}\n"
            f"law {res.restitution.name} (eta = {res.restitution.eta:.4f}), method {res.method}, "
            f"dt = {res.dt_s:g} s\n"
            f"status {res.status} at t = {d['t_end_s']:.4f} s, {res.n_impacts} impacts, "
            f"max |theta|/alpha = {res.max_abs_theta_over_alpha:.4f}{over}\n"
        )
        if args.output:
            sys.stdout.write(f"wrote {args.output}\n")
    return 0
