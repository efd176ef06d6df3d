"""``rocklab pulse|oas|design|equivalent``: not implemented yet (overturning issue open)."""

from __future__ import annotations

from .._errors import InputError


def register(sub):
    for c in ("pulse", "oas", "design", "equivalent"):
        p = sub.add_parser(c, help="(not implemented yet)")
        p.set_defaults(func=run)


def run(args) -> int:
    raise InputError(f"'rocklab {args.command}' is not implemented yet; see the open issue")
