"""Errors rocklab raises for bad input.

Every entry point validates its input and raises :class:`InputError` with a
one-line message naming the file/line or parameter, the rule broken and the fix.
The CLI turns it into one line on stderr and exit status 2.
"""

from __future__ import annotations

__all__ = ["InputError", "where", "positive", "check_memory", "check_time", "available_memory_bytes"]

#: Longest computation a single command starts without being asked to split it, s.
MAX_RUN_S = 3600.0


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


def available_memory_bytes() -> int:
    """Memory this machine can still give, bytes (physical pages available; 8 GiB if unknown)."""
    import os

    try:
        return int(os.sysconf("SC_AVPHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return 8 * 1024**3


def check_memory(nbytes: float, what: str, fix: str) -> None:
    """:class:`InputError` when ``what`` would need more than half of the available memory.

    ``nbytes`` is an estimate made before allocating; ``fix`` says which option to reduce.
    """
    avail = available_memory_bytes()
    if nbytes > 0.5 * avail:
        raise InputError(
            f"{what} would need about {nbytes / 1024**3:.4g} GiB of memory ({avail / 1024**3:.4g} GiB available); {fix}"
        )


def check_time(seconds: float, what: str, fix: str) -> None:
    """:class:`InputError` when ``what`` would run longer than :data:`MAX_RUN_S` (an estimate made before starting).

    ``seconds`` is a lower-bound estimate from the loop's measured speed; ``fix`` says which option to change.
    """
    if not seconds <= MAX_RUN_S:
        shown = f"{seconds / 3600:.3g} hours" if seconds < 1e7 * 3600 else "forever"
        raise InputError(f"{what} would take about {shown} (at most {MAX_RUN_S / 3600:g} h is started); {fix}")
