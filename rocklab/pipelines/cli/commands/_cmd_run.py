"""``rocklab run EXPERIMENT.toml --out DIR``: one experiment end to end."""

from __future__ import annotations

import sys


def register(sub):
    """Add this module's subcommand(s) to the ``rocklab`` parser ``sub``."""
    p = sub.add_parser("run", help="run one experiment: track, IMU, sync, fit, simulate, report, Rerun")
    p.add_argument("config", help="experiment.toml")
    p.add_argument("--out", required=True, help="output folder (replaced atomically)")
    p.add_argument("--force", action="store_true", help="re-run even if inputs and config are unchanged")
    p.add_argument("--spawn", action="store_true", help="also stream to a newly spawned Rerun viewer")
    p.add_argument("--connect", metavar="ADDR", help="also stream to a Rerun viewer at this gRPC address")
    p.add_argument("--progress", action="store_true", help="progress bars on stderr")
    p.add_argument("--json", action="store_true", help="print report.json's main numbers as one JSON object")
    p.set_defaults(func=run)


def run(args) -> int:
    """Run ``rocklab run`` with parsed ``args``; returns the exit status (0 ok)."""
    from ...._io import dumps_json
    from ...experiment import run_experiment

    report, ran = run_experiment(
        args.config, args.out, force=args.force, spawn=args.spawn, connect=args.connect, progress=args.progress
    )
    if args.json:
        keys = ("name", "status", "fit", "simulations", "sync", "video_vs_imu_rms_rad", "truth", "validation")
        out = {k: report.get(k) for k in keys}
        out["ran"] = ran
        print(dumps_json(out))
    elif not ran:
        print(f"{args.out}: inputs and config unchanged; nothing to do (use --force to re-run)")
    else:
        f = report.get("fit") or {}
        eta = f.get("eta_e")
        eta_s = f"{eta:.4g}" if isinstance(eta, (int, float)) else "not fitted"
        val = report.get("validation")
        if val:  # a shake-table run: η_e from its half cycles and the verdict of every law
            ve = (val.get("eta_e") or {}).get("eta_e")
            if not isinstance(eta, (int, float)) and isinstance(ve, (int, float)) and ve == ve:
                eta_s = f"{ve:.4g} (half cycles)"
            eta_s += "; " + ", ".join(f"{law} {v['verdict']}" for law, v in val["laws"].items())
        print(
            f"{report['name']}: {report['status']}; eta_e = {eta_s}, "
            f"outputs in {args.out} (summary.md, report.json, session.rrd)",
            file=sys.stdout,
        )
    # "partial": the run finished but a part of it failed (the restitution fit): exit 1, as documented
    return 1 if report.get("status") in ("failed", "partial") else 0
