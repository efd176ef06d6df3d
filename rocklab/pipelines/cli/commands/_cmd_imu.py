"""``rocklab imu``: an IMU log to block rotation (or table acceleration).

``rocklab imu PATH [--axis y] [--rate 256] [-o imu.csv] [--json] [--table] [--ahrs]``

PATH is an IMU CSV or a log folder (x-IMU GUI export, x-IMU3 device folder,
Fusion-style CSV).  The output CSV has ``t_s, theta_rad, omega_rad_s,
acc_x_m_s2, acc_y_m_s2, acc_z_m_s2`` (``--table``: ``t_s, acc_m_s2``).
``--json`` prints one object: ``format, sample_rate_hz, n_samples,
dropped_samples, gyro_bias_rad_s, release_t_s, impact_t_s`` and more.
"""

from __future__ import annotations

import sys


def register(sub):
    """Add this module's subcommand(s) to the ``rocklab`` parser ``sub``."""
    p = sub.add_parser(
        "imu",
        help="IMU log -> block rotation / table acceleration",
        description="Read an IMU log (x-IMU GUI export, x-IMU3 folder, Fusion CSV) "
        "and estimate the block rotation about the rocking axis "
        "(or, with --table, the table acceleration).",
    )
    p.add_argument("path", help="IMU CSV or log folder")
    p.add_argument(
        "--axis",
        default=None,
        help="rocking axis (block) / shaking axis (table) in the sensor frame: "
        "x, y, z with optional sign, e.g. -y; default: found from the data",
    )
    p.add_argument(
        "--rate",
        type=float,
        default=None,
        help="sample rate, Hz (needed when the log has no rate register/time column)",
    )
    p.add_argument("-o", "--out", default=None, help="write the time series to this CSV")
    p.add_argument("--json", action="store_true", help="print one JSON summary on stdout")
    p.add_argument(
        "--table", action="store_true", help="table IMU: base acceleration along the shaking axis, gravity removed"
    )
    p.add_argument(
        "--release",
        default="auto",
        choices=("auto", "thread", "none"),
        help="thread: thread-burn release (rest tilted, then rocking); none: a block on a "
        "shake table that starts upright; auto (default): decide from the data",
    )
    p.add_argument("--ahrs", action="store_true", help="also run imufusion's AHRS and report its difference (slower)")
    p.set_defaults(func=run)


def run(args) -> int:
    """Run ``rocklab imu`` with parsed ``args``; returns the exit status (0 ok)."""
    import math

    from ...._io import write_frame_atomic
    from ....tracking import block_rotation, read_imu, table_acceleration

    log = read_imu(args.path, rate_hz=args.rate)
    if args.table:
        res = table_acceleration(log, args.axis)
        summary = {**log.to_dict(), **res.to_dict()}
    else:
        res = block_rotation(log, args.axis, ahrs=args.ahrs, release=args.release)
        summary = {**log.to_dict(), **res.to_dict()}
    if args.out:
        write_frame_atomic(args.out, res.to_frame())
        summary["output"] = str(args.out)
    if args.json:
        from .._cli_base import emit_json

        emit_json(summary)
        return 0
    out = sys.stdout
    out.write(
        f"{summary['source']}: {summary['format']}, {summary['n_samples']} samples at "
        f"{summary['sample_rate_hz']:g} Hz, {summary['dropped_samples']} dropped\n"
    )
    if args.table:
        out.write(
            f"table acceleration: peak {summary['pga_m_s2']:.3f} m/s2, sensor tilt "
            f"{math.degrees(summary['tilt_rad']):.2f} deg\n"
        )
    else:
        b = [f"{math.degrees(v):.3f}" for v in summary["gyro_bias_rad_s"]]
        out.write(
            f"gyro bias [{', '.join(b)}] deg/s; release {summary['release_t_s']:.4f} s; "
            f"{len(summary['impact_t_s'])} impacts; status {summary['status']}\n"
        )
        if args.ahrs:
            out.write(
                f"AHRS vs gyro integration: RMS difference {math.degrees(summary['ahrs_rms_diff_rad']):.3f} deg\n"
            )
    if args.out:
        out.write(f"wrote {args.out}\n")
    return 0
