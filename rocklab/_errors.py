"""Errors rocklab raises for bad input.

Every entry point validates its input and raises :class:`InputError` with a
one-line message naming the file/line or parameter, the rule broken and the fix.
The CLI turns it into one line on stderr and exit status 2.
"""

from __future__ import annotations

__all__ = ["InputError", "where", "positive"]


class InputError(ValueError):
    """Bad user input: a one-line, actionable message (what, rule, fix)."""


def where(path=None, line: int | None = None, key: str | None = None) -> str:
    """Format a location prefix ``file:line: `` / ``key: `` for error messages."""
    parts = []
    if path is not None:
        parts.append(str(path))
    if line is not None:
        parts.append(f"line {line}")
    if key is not None:
        parts.append(f"'{key}'")
    return (", ".join(parts) + ": ") if parts else ""


def positive(name: str, value) -> float:
    """``value`` as a float, or :class:`InputError` unless it is a finite number > 0.

    ``name`` is the parameter as the user knows it (with its unit), e.g. ``"b_m (block width)"``.
    """
    import math

    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name}={value!r}: must be a number; give a positive value in SI units") from None
    if not math.isfinite(v) or v <= 0.0:
        raise InputError(f"{name}={value!r}: must be a finite positive number (SI units); fix the value")
    return v
