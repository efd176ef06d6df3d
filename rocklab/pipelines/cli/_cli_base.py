"""Command-line options shared by ``rocklab simulate`` and ``rocklab column``: a base-motion record."""

from __future__ import annotations

from ..._errors import InputError

__all__ = ["add_base_motion_args", "base_motion_from_args", "emit_json", "count"]


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


def add_base_motion_args(p) -> None:
    """``--base-motion FILE [--units U] [--scale-pga X]``."""
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


def base_motion_from_args(args):
    """The :class:`BaseMotion` the options name (SI units), or None for free rocking."""
    from ...models import load_base_motion

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
