"""``rocklab imu``: an IMU log to block rotation (or table acceleration).

``rocklab imu PATH [--axis y] [--rate 256] [-o imu.csv] [--json] [--table] [--ahrs] [--plot imu.png]``

PATH is an IMU CSV or a log folder (x-IMU GUI export, x-IMU3 device folder,
Fusion-style CSV).  The output CSV has ``t_s, theta_rad, omega_rad_s,
acc_x_m_s2, acc_y_m_s2, acc_z_m_s2`` (``--table``: ``t_s, acc_m_s2``).
``--json`` prints one object: ``format, sample_rate_hz, n_samples,
dropped_samples, gyro_bias_rad_s, release_t_s, impact_t_s`` and more.
``--plot`` draws theta (or the table acceleration) with the release, the
impacts and the rests, over the three gyro axes.
"""

from __future__ import annotations

import sys

from ....blocks import G
from ...reports import sig


def register(sub):
    """Add this module's subcommand(s) to the ``rocklab`` parser ``sub``."""
    p = sub.add_parser(
        "imu",
        help="IMU log -> block rotation / table acceleration",
        description="Read an IMU log (x-IMU GUI export, x-IMU3 folder, Fusion CSV, a phone's phyphox or "
        "Sensor Logger export: folder or .zip) "
        "and estimate the block rotation about the rocking axis "
        "(or, with --table, the table acceleration).",
    )
    p.add_argument("path", help="IMU CSV, log folder, or a phone export's folder or .zip")
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
    p.add_argument(
        "--plot", default=None, help="PNG: theta (table: acceleration), release, impacts, rests and the gyro axes"
    )
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
    if args.plot:
        from .._imu_plot import imu_figure

        imu_figure(log, res, args.plot, title=str(args.path))
        summary["plot"] = str(args.plot)
    if args.json:
        from .._cli_base import emit_json

        emit_json(summary)
        return 0
    out = sys.stdout
    out.write(
        f"{summary['source']}: {summary['format']}, {summary['n_samples']} samples at "
        f"{sig(summary['sample_rate_hz'], 6)} Hz, {summary['dropped_samples']} dropped\n"
    )
    from ...._diagnostics import collected, worst_status

    diags = collected()
    status = worst_status(res.status, diags)
    if args.table:
        out.write(
            f"table acceleration along sensor {_vec(summary['direction'])}: peak "
            f"{sig(summary['pga_m_s2'])} m/s2, gravity removed in the orientation of the rest "
            f"{summary['rest_s'][0]:.3f}-{summary['rest_s'][1]:.3f} s (sensor tilt "
            f"{sig(math.degrees(summary['tilt_rad']))} deg); the sensor turned by "
            f"{sig(math.degrees(summary['turn_rad']))} deg\n"
        )
    else:
        out.write(_block_text(res, args.release))
    out.write(f"status {status}: {_status_meaning(status, diags)}\n")
    msg = res.message
    for d in diags:  # a warning's text is on stderr with its code: named here, not repeated
        msg = msg.replace(d.message, f"{d.code} (above)")
    if msg:
        out.write(f"  {msg}\n")
    if args.ahrs and not args.table:
        out.write(f"AHRS vs gyro integration: RMS difference {sig(math.degrees(summary['ahrs_rms_diff_rad']))} deg\n")
    for k in ("output", "plot"):
        if k in summary:
            out.write(f"wrote {summary[k]}\n")
    return 0


_STATUS_MEANING = {
    "ok": "rests found before and after, gyro and accelerometer agree, the rocking checks pass, no warning",
    "suspect": "a warning above: the numbers may be wrong; check before using them",
    "no_rest_before": "no rest before the first motion: no release or theta0 measured, the gyro bias estimated "
    "(from the first 0.5 s and the final rest's tilt, or without one from the motion's trend)",
    "no_rest_after": "still moving at the end: the gyro drift is not held by a final rest",
    "no_motion": "nothing moved above the stillness thresholds",
}


def _status_meaning(status: str, diags) -> str:
    """What ``status`` means; a suspect one names the warnings that made it so."""
    text = _STATUS_MEANING.get(status, "")
    codes = sorted({d.code for d in diags if d.severity == "suspect"})
    if status == "suspect" and codes:
        text = text.replace("a warning above", f"a warning above ({', '.join(codes)})", 1)
    return text


def _vec(v) -> str:
    """A unit vector as ``(+0.2012, -0.3614, 0)`` (4 significant digits, signed, never -0)."""
    return "(" + ", ".join(("+" if float(sig(x)) > 0 else "") + sig(x) for x in v) + ")"


def _axis_text(res) -> str:
    """The rocking axis and the rocking checks' measured values with their bounds."""
    import math

    import numpy as np

    a = res.axis
    k = int(np.argmax(np.abs(a)))
    name = ("+" if a[k] > 0 else "-") + "xyz"[k]
    line = f"rocking axis ~{name} {_vec(a)} in the sensor frame"
    rk = res.rocking
    if rk is not None and math.isfinite(rk.axis_tilt_rad):
        bound = rk.bounds()
        line += (
            f", {sig(math.degrees(rk.axis_tilt_rad))} deg above the horizontal at rest "
            f"(a rocking edge: < {sig(math.degrees(bound['axis_tilt_max_rad']))} deg), "
            f"{sig(100 * rk.axis_share)} % of the rotation about it (> {sig(100 * bound['axis_share_min'])} %)"
        )
        if math.isfinite(rk.lateral_acc_m_s2):
            line += (
                f", {sig(rk.lateral_acc_m_s2 / G)} g RMS along it while turning "
                f"(< {sig(bound['lateral_acc_max_m_s2'] / G)} g)"
            )
    return line


def _block_text(res, release: str = "auto") -> str:
    """The text report of a block's rotation: axis, bias, kind of run and release, theta, impacts.

    ``release`` is the ``--release`` option: a kind of run the user named is said to be so, not
    measured. A log that is not a rocking block (``W-IMU-NOT-ROCKING``) has its release, theta and
    impacts marked as meaningless where they are printed.
    """
    import math

    import numpy as np

    line = _axis_text(res)
    bogus = " (meaningless: not a rocking block)" if res.rocking is not None and res.rocking.reasons else ""
    b = ", ".join(sig(math.degrees(v)) for v in res.gyro_bias_rad_s)
    # the drift is anchored by the final rest; without one none is estimated (not a drift of 0)
    drift = (
        f"{sig(math.degrees(res.drift_rad_s))} deg/s"
        if math.isfinite(res.rest_t_s)
        else "not estimated (no final rest)"
    )
    line += f"\ngyro bias [{b}] deg/s, residual drift {drift}\n"
    th = np.rad2deg(res.theta_rad)
    if res.run_kind == "forced":
        why = "as --release none says" if release == "none" else "the table moved the block from rest upright"
        line += f"forced run, no release ({why}): upright = the rest at the start"
    elif res.status == "no_rest_before":
        line += "in motion from the log's start: no release and no theta0 measured"
    elif math.isfinite(res.release_t_s):
        said = " (--release thread)" if release == "thread" else ""
        line += f"release{said} at {res.release_t_s:.4f} s from theta0 {sig(math.degrees(res.theta0_rad))} deg"
    else:
        line += "no release found"
    line += f"; theta from {sig(th.min())} to {sig(th.max())} deg{bogus}"
    line += f"; final rest from {res.rest_t_s:.3f} s\n" if math.isfinite(res.rest_t_s) else "; no final rest\n"
    imp = res.impact_t_s
    if len(imp) == 0:
        return line + "no impacts (theta never crosses 0 with an acceleration spike or a rate step)\n"
    at = "at " + ", ".join(f"{x:.4f}" for x in imp) if len(imp) <= 6 else f"first {imp[0]:.4f}, last {imp[-1]:.4f}"
    return line + f"{len(imp)} impacts (theta crosses 0 with a spike or a rate step), {at} s{bogus}\n"
