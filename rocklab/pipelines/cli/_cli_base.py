"""Command-line options shared by the commands that take a base motion: a record file or a pulse."""

from __future__ import annotations

from ..._errors import InputError

__all__ = ["add_base_motion_args", "base_motion_from_args", "pulse_from_spec", "PULSE_HELP", "emit_json", "count"]


def count(minimum: int):
    """An argparse ``type``: an integer >= ``minimum`` (a usage error, exit 2, otherwise)."""
    import argparse

    def parse(text):
        try:
            v = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
        if v < minimum:
            raise argparse.ArgumentTypeError(f"{v}: must be >= {minimum}")
        return v

    parse.__name__ = "count"
    return parse


#: Help text of ``--pulse`` (one place for every command that takes it).
PULSE_HELP = (
    "a simple pulse instead of a record, KIND,PEAK,T_P[,N]: KIND half-sine, sine (one full sine), "
    "n-half-sines, rectangular, triangular, cycloidal-a, cycloidal-b; PEAK with its unit (0.3g or "
    "2.94m/s2); T_P the duration of one lobe (half a cycle), s; N lobes of n-half-sines"
)


def add_base_motion_args(p) -> None:
    """``--base-motion FILE [--units U] [--scale-pga X]`` or ``--pulse KIND,PEAK,T_P[,N]``."""
    p.add_argument(
        "--base-motion", default=None, help="base acceleration record (.AT2, CSV t_s,acc_m_s2, 2-column text)"
    )
    p.add_argument(
        "--units",
        default=None,
        help="units of a record that states none: g, m/s2, cm/s2 (2-column text needs it); "
        "a file's own units win, a conflict is an error",
    )
    p.add_argument("--scale-pga", type=float, default=None, help="scale the record to this PGA (in --units, default g)")
    p.add_argument("--pulse", default=None, metavar="KIND,PEAK,T_P[,N]", help=PULSE_HELP)


def pulse_from_spec(spec: str, option: str = "--pulse"):
    """The :class:`~rocklab.series.BaseMotion` of ``KIND,PEAK,T_P[,N]`` (peak ``0.3g`` or ``2.94m/s2``).

    The pulse is sampled at t_p/200 and followed by one t_p of zeros (the commands integrate on
    past the record as free rocking).
    """
    from ...blocks import G
    from ...models import pulse_motion

    parts = [x.strip() for x in str(spec).split(",")]
    fix = f"give {option} KIND,PEAK,T_P[,N], e.g. {option} half-sine,0.3g,0.5"
    if len(parts) not in (3, 4):
        raise InputError(f"{option} {spec!r}: {len(parts)} fields; {fix}")
    kind, peak, tp = parts[:3]
    low = peak.lower().replace(" ", "")
    for unit, factor in (("m/s2", 1.0), ("m/s^2", 1.0), ("g", G)):
        if low.endswith(unit):
            num = low[: -len(unit)]
            break
    else:
        raise InputError(f"{option} {spec!r}: peak {peak!r} has no unit; write it as 0.3g or 2.94m/s2")
    try:
        a = float(num) * factor
        t_p = float(tp)
        n = int(parts[3]) if len(parts) == 4 else 1
    except ValueError:
        raise InputError(f"{option} {spec!r}: PEAK and T_P must be numbers, N a whole number; {fix}") from None
    if not (a > 0 and t_p > 0 and n >= 1) or not (a < float("inf") and t_p < float("inf")):
        raise InputError(f"{option} {spec!r}: peak and t_p must be finite and > 0, N >= 1; {fix}")
    base = pulse_motion(kind, t_p, a, n=n, pad_s=t_p)
    return base


def base_motion_from_args(args):
    """The :class:`BaseMotion` the options name (SI units), or None for free rocking."""
    from ...models import load_base_motion

    pulse = getattr(args, "pulse", None)
    if pulse is not None:
        if args.base_motion is not None or args.scale_pga is not None or args.units is not None:
            raise InputError("--pulse replaces --base-motion/--units/--scale-pga; give one or the other")
        return pulse_from_spec(pulse)
    if args.base_motion is None:
        if args.scale_pga is not None or args.units is not None:
            raise InputError("--scale-pga/--units need --base-motion FILE")
        return None
    base = load_base_motion(args.base_motion, units=args.units)
    if args.scale_pga is not None:
        base = base.scaled_to_pga(args.scale_pga, args.units or "g")
    return base


def emit_json(obj: dict) -> None:
    """Print ``obj`` as one JSON line on stdout, with the warnings raised so far.

    Adds ``warnings`` (the :class:`rocklab._diagnostics.Diagnostic` dicts collected by the
    CLI) and turns a ``status`` of ``"ok"`` into ``"suspect"`` when one of them is.
    """
    import sys

    from ..._diagnostics import collected, worst_status
    from ..._io import dumps_json

    diags = collected()
    out = dict(obj)
    out["warnings"] = [d.to_dict() for d in diags]
    if isinstance(out.get("status"), str):
        out["status"] = worst_status(out["status"], diags)
    sys.stdout.write(dumps_json(out) + "\n")
