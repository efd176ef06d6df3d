"""Base-motion records: horizontal ground/table acceleration histories.

Readers convert to SI once, at the file boundary: every :class:`BaseMotion`
holds ``t_s`` (s) and ``acc_m_s2`` (m/s^2) on a uniform grid.

Formats
-------
- PEER ``.AT2``, NGA-West2 header (``NPTS=   5372, DT=   .0100 SEC``) and the
  older style (``NPTS=  1559, DT= .02000 SEC`` with free text above), units g
  unless the header says otherwise.
- CSV with a header ``t_s,acc_m_s2`` (or ``acc_g`` / ``acc_cm_s2``).
- Two-column whitespace text ``t a`` without header; ``units`` is required
  (``g``, ``m/s2``, ``cm/s2``).

Units are never guessed or overridden: a unit the file states (an AT2 units
field, a CSV column name) is used; ``units`` (``--units``) applies only to a
file that states none, and one that disagrees with the file's is an error.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..._errors import InputError
from ...blocks import G
from ...series import BaseMotion
from ...series import acc_unit_factor as _unit_factor
from ._record_units import at2_units, stated_wins

__all__ = ["load_base_motion", "not_a_record", "check_plausible", "MIN_SAMPLES", "bundled_record", "BUNDLED_RECORDS"]

_NUM = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?")


# -- readers ------------------------------------------------------------------


def load_base_motion(
    path, units: str | None = None, dt_s: float | None = None, name: str | None = None, default_units: str | None = None
) -> BaseMotion:
    """Read a base-motion record file into SI units.

    Parameters
    ----------
    path : str or Path
        ``.AT2`` (PEER), ``.csv`` with header, or two-column text ``t a``.
    units : str, optional
        Acceleration units the user states (``g``, ``m/s2``, ``cm/s2``; ``--units``):
        used for a file that states none (headerless text, an AT2 without a units
        field); a file that states other units is an error (never overridden).
    default_units : str, optional
        A documented default (a config's) for a file that states none when ``units``
        is None; it never conflicts with a file's own units.
    dt_s : float, optional
        Only for single-column text files: the sample spacing, s.
    name : str, optional
        Label; defaults to the file stem.

    Raises
    ------
    InputError
        Unreadable file, NPTS disagreeing with the data, NaN, non-monotonic or
        non-uniform time, unknown units, ``units`` disagreeing with the file's.
    """
    path = Path(path)
    for u in (units, default_units):
        if u is not None:
            _unit_factor(u, f"{path}: ")  # fail on a bad option before reading anything
    if path.is_dir():
        raise InputError(f"{path}: is a folder; give the record file (.AT2, .csv or two-column text)")
    if not path.is_file():
        raise InputError(f"{path}: base-motion file not found; check the path")
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as e:
        raise InputError(f"{path}: cannot read ({e.strerror})") from None
    if not text.strip():
        raise InputError(f"{path}: file is empty; give a record with samples")
    nm = name or path.stem
    if "\x00" in text[:4096]:
        raise InputError(f"{path}: binary file, not a record; give an .AT2, CSV or two-column text file")
    if re.search(r"NPTS\s*=", text[:4000], re.I):
        bm = _read_at2(path, text, units, nm, default_units)
    elif path.suffix.lower() == ".csv" or re.match(r"\s*[A-Za-z_]", text):
        bm = _read_csv(path, units, nm)
    else:
        bm = _read_columns(path, text, units or default_units, dt_s, nm)
    return check_plausible(bm)


def not_a_record(path) -> str:
    """Why the file ``path`` is plainly not a record ("" when it may be one), from its first 4 kB.

    A folder of records often holds other files (a licence, a README, a figure): they are told
    apart by what :func:`load_base_motion` would read, not by their names. A record is a file with
    an ``NPTS=`` header (AT2), a ``.csv``, or text whose first data line is numbers (or a CSV
    header naming ``t_s``/``acc_``); anything else (binary, prose, JSON) is not one. A damaged
    record still looks like one, so its reader reports the damage.
    """
    path = Path(path)
    try:
        with open(path, "rb") as f:
            head = f.read(4096)
    except OSError as e:
        return f"cannot be read ({e.strerror})"
    if b"\x00" in head:
        return "a binary file"
    text = head.decode("utf-8", errors="replace")
    if not text.strip() or re.search(r"NPTS\s*=", text, re.I) or path.suffix.lower() == ".csv":
        return ""
    for ln in text.splitlines():
        s = ln.strip()
        if not s or s.startswith("#"):
            continue
        toks = s.replace(",", " ").split()
        if all(_NUM.fullmatch(t) for t in toks) or re.search(r"\bt_s\b|\bacc_", s):
            return ""
        break
    return "neither an AT2 (NPTS header), a CSV nor numeric columns"


def _read_at2(path: Path, text: str, units: str | None, name: str, default_units: str | None = None) -> BaseMotion:
    lines = text.splitlines()
    hdr_i = next(i for i, ln in enumerate(lines) if re.search(r"NPTS\s*=", ln, re.I))
    hdr = lines[hdr_i]
    m_n = re.search(r"NPTS\s*=\s*(\d+)", hdr, re.I)
    m_dt = re.search(r"DT\s*=\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)", hdr, re.I)
    if not (m_n and m_dt):
        raise InputError(f"{path}, line {hdr_i + 1}: AT2 header must hold 'NPTS=<n>, DT=<s> SEC'; fix the header")
    npts, dt = int(m_n.group(1)), float(m_dt.group(1))
    if dt <= 0:
        raise InputError(f"{path}, line {hdr_i + 1}: DT={dt} must be positive")
    file_units, line = at2_units(path, lines[:hdr_i], given=units)
    if file_units is not None:
        units, units_from = stated_wins(path, file_units, f"the header (line {line})", units), "header"
    elif units is not None:
        units_from = "option"
    else:  # PEER's documented convention when the file names no units
        units, units_from = default_units or "g", "default" if default_units else "PEER convention (g)"
    f = _unit_factor(units, f"{path}: ")
    vals: list[float] = []
    for j, ln in enumerate(lines[hdr_i + 1 :], start=hdr_i + 2):
        toks = ln.split()
        for tok in toks:
            if not _NUM.fullmatch(tok):
                # fixed-width Fortran fields can run together ("0.000000.00000")
                parts = _NUM.findall(tok)
                if not parts or "".join(parts) != tok:
                    raise InputError(f"{path}, line {j}: {tok!r} is not a number; fix or remove it")
                vals.extend(float(p.replace("D", "E").replace("d", "e")) for p in parts)
            else:
                vals.append(float(tok.replace("D", "E").replace("d", "e")))
    a = np.asarray(vals, float)
    _check_last_token(path, lines[hdr_i + 1 :], hdr_i + 2)
    if a.size != npts:
        raise InputError(
            f"{path}: header says NPTS={npts} but the file holds {a.size} values; "
            "the file is truncated or the header is wrong"
        )
    bm = BaseMotion(
        dt * np.arange(npts),
        a * f,
        name=name,
        source=str(path),
        meta={"format": "AT2", "units_in_file": units, "header": lines[: hdr_i + 1], "units_from": units_from},
    )
    return bm


def _token_shape(tok: str) -> tuple:
    """(exponent?, digits after the point) of a number as written."""
    t = tok.upper().replace("D", "E")
    mant, _, exp = t.partition("E")
    dec = mant.split(".", 1)[1] if "." in mant else ""
    return (bool(exp), len(dec))


def _check_last_token(path: Path, data_lines: list[str], first_lineno: int) -> None:
    """A value cut mid-token at the end of the file ("-.17901" for "-.1790158E-03") is an error:
    every value of a PEER file is written in one format, so the last one must share it."""
    toks = []
    for ln in data_lines[-50:]:
        toks.extend(ln.split())
    if len(toks) < 5:
        return
    shapes = [_token_shape(t) for t in toks[:-1]]
    common = max(set(shapes), key=shapes.count)
    if shapes.count(common) >= 0.9 * len(shapes) and _token_shape(toks[-1]) != common:
        last_line = first_lineno + max(i for i, ln in enumerate(data_lines) if ln.strip())
        raise InputError(
            f"{path}, line {last_line}: the last value {toks[-1]!r} is not written like the "
            "others (cut off mid-number?); restore the file's end from its source"
        )


#: Fewest samples a record needs for its pulse parameters and spectra (fewer: W-RECORD-SHORT
#: when read, an error in the pulse and spectrum analysis).
MIN_SAMPLES = 16


def check_plausible(bm: BaseMotion) -> BaseMotion:
    """Warn (``W-RECORD-*``) when a record's amplitude, step or length is implausible for an
    earthquake or shake-table record. Returns ``bm``."""
    from ..._diagnostics import warn

    src = f"{bm.source}: " if bm.source != "array" else f"{bm.name}: "
    pga_g = bm.pga_m_s2 / G
    if pga_g > 5.0:
        warn(
            "W-RECORD-PGA",
            f"{src}peak acceleration {pga_g:.4g} g is above 5 g; check the units "
            f"(read as {bm.meta.get('units_in_file', 'given')}) or --units",
        )
    if bm.dt_s > 0.05:
        warn("W-RECORD-DT", f"{src}sample step {bm.dt_s:.4g} s is above 0.05 s; check DT in the header")
    if bm.t_s.size < MIN_SAMPLES or bm.duration_s < 0.2:
        warn(
            "W-RECORD-SHORT", f"{src}only {bm.t_s.size} samples ({bm.duration_s:.4g} s); check the whole file was read"
        )
    return bm


def _read_csv(path: Path, units: str | None, name: str) -> BaseMotion:
    import pandas as pd

    try:
        df = pd.read_csv(path, comment="#")
    except Exception as e:  # pandas raises several types for malformed CSV
        raise InputError(f"{path}: not a readable CSV ({type(e).__name__}: {str(e).splitlines()[0]})") from None
    cols = {c.strip(): c for c in df.columns}
    if "t_s" not in cols:
        raise InputError(f"{path}, line 1: missing column 't_s'; header must be 't_s,acc_m_s2' (or acc_g / acc_cm_s2)")
    acc_col, file_units = None, None
    for c, u in (("acc_m_s2", "m/s2"), ("acc_g", "g"), ("acc_cm_s2", "cm/s2")):
        if c in cols:
            acc_col, file_units = cols[c], u
            break
    if acc_col is None:
        raise InputError(f"{path}, line 1: no acceleration column; name it acc_m_s2, acc_g or acc_cm_s2")
    t = pd.to_numeric(df[cols["t_s"]], errors="coerce").to_numpy(float)
    a = pd.to_numeric(df[acc_col], errors="coerce").to_numpy(float)
    bad = ~np.isfinite(t) | ~np.isfinite(a)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InputError(f"{path}, line {i + 2}: NaN or non-numeric value; clean the record")
    _check_time(path, t, first_line=2)
    file_units = stated_wins(path, str(file_units), f"its column {acc_col.strip()!r}", units)
    f = _unit_factor(file_units, f"{path}: ")
    meta = {"format": "csv", "units_in_file": file_units, "units_from": "column name"}
    return BaseMotion(t, a * f, name=name, source=str(path), meta=meta)


def _read_columns(path: Path, text: str, units: str | None, dt_s: float | None, name: str) -> BaseMotion:
    rows, linenos = [], []
    for j, ln in enumerate(text.splitlines(), start=1):
        s = ln.strip()
        if not s or s.startswith("#"):
            continue
        toks = s.replace(",", " ").split()
        try:
            rows.append([float(x) for x in toks])
        except ValueError:
            raise InputError(f"{path}, line {j}: {s[:40]!r} is not numeric; expected 't a' columns") from None
        linenos.append(j)
    ncol = {len(r) for r in rows}
    if len(ncol) != 1:
        raise InputError(f"{path}: rows have {sorted(ncol)} columns; expected the same number on every line")
    if units is None:
        raise InputError(f"{path}: headerless record; say its units (--units g|m/s2|cm/s2)")
    f = _unit_factor(units, f"{path}: ")
    arr = np.asarray(rows, float)
    if arr.shape[1] == 1:
        if dt_s is None:
            raise InputError(f"{path}: one column of accelerations; give the sample spacing dt_s")
        return BaseMotion.from_samples(arr[:, 0] * f, dt_s, name=name)
    t, a = arr[:, 0], arr[:, 1]
    bad = ~np.isfinite(t) | ~np.isfinite(a)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InputError(f"{path}, line {linenos[i]}: NaN value; clean the record")
    _check_time(path, t, linenos=linenos)
    return BaseMotion(t, a * f, name=name, source=str(path), meta={"format": "columns"})


def _check_time(path, t, first_line: int = 1, linenos=None):
    d = np.diff(t)
    if (d <= 0).any():
        i = int(np.flatnonzero(d <= 0)[0]) + 1
        ln = linenos[i] if linenos is not None else i + first_line
        raise InputError(
            f"{path}, line {ln}: time {t[i]} does not increase (previous {t[i - 1]}); sort or remove duplicate rows"
        )


#: Records bundled in ``rocklab/data/records`` (see PROVENANCE.md there).
BUNDLED_RECORDS = {"elcentro": "RSN6_IMPVALL.I_I-ELC180.AT2"}


def bundled_record(name: str = "elcentro") -> BaseMotion:
    """A record shipped with rocklab, in SI units.

    ``"elcentro"``: 1940 Imperial Valley, El Centro Array #9, 180° (PEER NGA-West2,
    via NHERI-SimCenter/EE-UQ, BSD-2).
    """
    from importlib.resources import files

    if name not in BUNDLED_RECORDS:
        raise InputError(f"record {name!r} is not bundled; choose one of {', '.join(BUNDLED_RECORDS)}")
    path = files("rocklab") / "data" / "records" / BUNDLED_RECORDS[name]
    return load_base_motion(str(path), units="g", name=name)
