"""Errors rocklab raises for bad input.

Every entry point validates its input and raises :class:`InputError` with a
one-line message naming the file/line or parameter, the rule broken and the fix.
The CLI turns it into one line on stderr and exit status 2.
"""

from __future__ import annotations

__all__ = ["InputError", "where"]


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
