"""Acceleration units of base-motion records: an AT2 header's units field, and the rule that a
file's own units win over ``--units`` (which applies only to files that state none; a
disagreement is an error). The accepted unit names are :data:`rocklab.series.UNITS_TO_M_S2`."""

from __future__ import annotations

import re
from pathlib import Path

from ..._errors import InputError
from ...series import acc_unit_factor as _unit_factor

__all__: list[str] = []


def stated_wins(path: Path, stated: str, where: str, given: str | None) -> str:
    """The file's ``stated`` units; ``given`` (``--units``) must agree (the same factor)."""
    if given is not None and _unit_factor(given, f"{path}: ") != _unit_factor(stated, f"{path}: "):
        raise InputError(
            f"{path}: {where} states the units {stated} but the units given are {given}; a file's own units "
            "are used (--units and sources.table.units apply only to files that state none): drop them or fix the file"
        )
    return stated


# units named in an AT2 header ("IN UNITS OF G", "The units are (g)", "UNITS: CM/S/S")
_UNITS_FIELD = re.compile(
    r"\bUNITS?\b\s*(?:(?:OF|ARE|IN)\b\s*[(\[]?|[:=(\[])\s*[(\[]?\s*([A-Z][A-Z0-9/*^.\-]*(?:\s*/\s*[A-Z0-9*^]+)*)", re.I
)
_ACC_UNITS = {
    "G": "g",
    "GS": "g",
    "CM/S/S": "cm/s2",
    "CM/S2": "cm/s2",
    "CM/S**2": "cm/s2",
    "CM/S^2": "cm/s2",
    "CM/SEC/SEC": "cm/s2",
    "CM/SEC2": "cm/s2",
    "CM/SEC**2": "cm/s2",
    "CM/SEC^2": "cm/s2",
    "GAL": "cm/s2",
    "M/S/S": "m/s2",
    "M/S2": "m/s2",
    "M/S**2": "m/s2",
    "M/S^2": "m/s2",
    "M/SEC/SEC": "m/s2",
    "M/SEC2": "m/s2",
    "M/SEC**2": "m/s2",
    "MM/S/S": "mm/s2",
    "MM/S2": "mm/s2",
}
_OTHER_QUANTITY = {
    "CM/S": "velocity",
    "CM/SEC": "velocity",
    "M/S": "velocity",
    "M/SEC": "velocity",
    "IN/S": "velocity",
    "IN/SEC": "velocity",
    "CM": "displacement",
    "M": "displacement",
    "MM": "displacement",
    "IN": "displacement",
}


def at2_units(path: Path, header: list[str], given: str | None = None) -> tuple[str | None, int]:
    """``(units, line)`` an AT2 header names in a units field, or ``(None, 0)`` when it names none.

    Free text (a station called "Galway" or "Portugal") is never read as a unit; a
    velocity or displacement series is an error; so are unknown or two different units,
    unless the user ``given`` the units (``--units``): an unknown unit then leaves the
    file stating none, and of two units the given one must be one of them.
    """
    found = {}
    for i, ln in enumerate(header, start=1):
        if re.search(r"\b(VELOCITY|DISPLACEMENT)\s+TIME\s+SERIES\b", ln, re.I):
            kind = re.search(r"VELOCITY|DISPLACEMENT", ln, re.I).group(0).lower()  # type: ignore[union-attr]
            raise InputError(
                f"{path}, line {i}: this is a {kind} time series, not acceleration; give the "
                "matching .AT2 acceleration file"
            )
        for m in _UNITS_FIELD.finditer(ln):
            tok = re.sub(r"\s+", "", m.group(1)).upper().rstrip(".,;)]")
            if tok in _ACC_UNITS:
                found[_ACC_UNITS[tok]] = i
            elif tok in _OTHER_QUANTITY:
                raise InputError(
                    f"{path}, line {i}: units {m.group(1)!r} are {_OTHER_QUANTITY[tok]}, not "
                    "acceleration; give the acceleration record"
                )
            elif given is None:
                raise InputError(
                    f"{path}, line {i}: unknown units {m.group(1)!r} in the header; give --units "
                    "g|m/s2|cm/s2 to say what the file holds"
                )
    if len(found) > 1:
        same = [u for u in found if given is not None and _unit_factor(u) == _unit_factor(given, f"{path}: ")]
        if not same:
            raise InputError(
                f"{path}: header names two units ({', '.join(sorted(found))}); give --units to say which is right"
            )
        return same[0], found[same[0]]
    return next(iter(found.items()), (None, 0))
