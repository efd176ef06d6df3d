"""``rocklab imu``: not implemented yet (its issue is open)."""

from __future__ import annotations

from .._errors import InputError


def register(sub):
    p = sub.add_parser("imu", help="(not implemented yet)")
    p.set_defaults(func=run)


def run(args) -> int:
    raise InputError("'rocklab imu' is not implemented yet; see the open issue")
