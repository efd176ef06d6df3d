"""TOML files as rocklab reads and writes them: one reader, one line finder, one unknown-key rule.

:class:`TomlDoc` holds a parsed file and its text. A key is a path of table names, array indices
and a key name, ``("objects", 1, "markers")``, shown as ``objects[1].markers``; every error is one
line ``FILE, line N: 'KEY' RULE; FIX``. :func:`dumps_toml` writes the plain mappings a schema's
``to_dict`` returns, tables after the keys they follow, in insertion order.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import re
import tomllib
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import NoReturn

from .._errors import InputError

__all__ = ["TomlDoc", "key_name", "dumps_toml", "default_of"]

Key = tuple  # of str (table or key names) and int (index in an array of tables)


def key_name(key: Key) -> str:
    """``("objects", 1, "markers")`` -> ``"objects[1].markers"``."""
    out = ""
    for p in key:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out


def default_of(cls, name: str):
    """The default of dataclass field ``name`` of ``cls`` (its one home: readers take it from here)."""
    f = next(f for f in dataclasses.fields(cls) if f.name == name)
    if f.default is not dataclasses.MISSING:
        return f.default
    if f.default_factory is not dataclasses.MISSING:
        return f.default_factory()
    raise KeyError(f"{cls.__name__}.{name} has no default")


class TomlDoc:
    """A parsed TOML mapping with its text and file, for typed reads whose errors name file:line.

    Parameters
    ----------
    data : dict
        The parsed mapping (``tomllib.loads``).
    text : str or None
        The file's text, to find lines; without it errors name the key only.
    source : path or None
        The file, named in errors.
    """

    def __init__(self, data: dict, text: str | None = None, source=None):
        self.data, self.text, self.source = data, text, source

    @classmethod
    def read(cls, path, what: str = "TOML file") -> "TomlDoc":
        """Read and parse ``path``; a missing file or a syntax error is an :class:`InputError`."""
        path = Path(path)
        if not path.is_file():
            raise InputError(f"{path}: {what} not found; check the path")
        # undecodable bytes become U+FFFD: harmless in comments, and a path or name holding one
        # then fails its own check with its line instead of a traceback
        text = path.read_text(encoding="utf-8", errors="replace")
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as e:
            raise InputError(f"{path}: TOML syntax error ({e}); fix the syntax") from None
        return cls(data, text, path)

    # ------------------------------------------------------------------ where
    def line_of(self, key: Key) -> int | None:
        """1-based line of ``key``: its ``name =`` line under the innermost table header of its
        path found in the text (``[a.b]``, or the n-th ``[[a]]`` for ``("a", n, ...)``), else
        that header's line; a key of the root is looked for above the first header. None when the
        text is unknown or has neither."""
        if self.text is None or not key:
            return None
        lines = self.text.splitlines()
        for cut in range(len(key), 0, -1):
            head = key[:cut]
            if isinstance(head[-1], int):
                at = _header(lines, head[:-1], head[-1], array=True)
            elif cut < len(key) and isinstance(key[cut], int):
                continue  # the table of an array of tables: its n-th [[header]] is tried above
            else:
                at = _header(lines, head, 0, array=False)
            if at is None:
                continue
            rest = key[cut:]
            found = _key_line(lines, at + 1, rest) if rest else None
            return found if found is not None else at + 1
        return _key_line(lines, 0, key)

    # ------------------------------------------------------------------ errors
    def fail(self, key: Key, msg: str) -> NoReturn:
        """Raise the one-line :class:`InputError` ``FILE, line N: 'KEY' MSG``."""
        loc = [] if self.source is None else [str(self.source)]
        ln = self.line_of(key)
        if ln is not None:
            loc.append(f"line {ln}")
        name = f"'{key_name(key)}' " if key else ""
        raise InputError((", ".join(loc) + ": " if loc else "") + name + msg)

    def reject_unknown(self, key: Key, table: dict, known: Iterable[str]) -> None:
        """The one rule for names a schema does not have: an error at the first unknown name of
        ``table`` (at path ``key``), with the nearest known name and the list of them."""
        known = sorted(known)
        for k, v in table.items():
            if k in known:
                continue
            what = "table" if isinstance(v, dict) or _array_of_tables(v) else "key"
            near = difflib.get_close_matches(str(k), known, n=1)
            hint = f"did you mean '{near[0]}'? " if near else ""
            section = key_name(key)
            self.fail(
                key + (k,),
                f"is not a known {what}{' of [' + section + ']' if section else ''}; {hint}"
                f"known: {', '.join(known) or '(none)'}; fix or remove the unknown {what}",
            )

    # ------------------------------------------------------------------ typed values
    def table(self, key: Key, v) -> dict:
        """``v`` when it is a TOML table (a missing one reads as empty)."""
        if v is None:
            return {}
        if not isinstance(v, dict):
            self.fail(key, "must be a table ([name] with keys below it)")
        return v

    def number(self, key: Key, v, *, positive=False, integer=False, allow_none=True):
        """``v`` as a finite float (an int with ``integer``); ``positive``: > 0."""
        if v is None and allow_none:
            return None
        ok = isinstance(v, int) if integer else isinstance(v, (int, float))
        if isinstance(v, bool) or not ok or not math.isfinite(v):
            self.fail(key, f"must be {'an integer' if integer else 'a finite number'}, got {v!r}")
        if positive and not v > 0:
            self.fail(key, f"must be positive (> 0), got {v!r}")
        return int(v) if integer else float(v)

    def string(self, key: Key, v, choices: Sequence | None = None):
        """``v`` as a string, one of ``choices`` when given (None stays None)."""
        if v is None:
            return None
        if not isinstance(v, str):
            self.fail(key, f"must be a string, got {v!r}")
        if choices is not None and v not in choices:
            self.fail(key, f"must be one of {', '.join(map(str, choices))}, got {v!r}")
        return v

    def boolean(self, key: Key, v):
        if v is not None and not isinstance(v, bool):
            self.fail(key, f"must be true or false, got {v!r}")
        return v

    def vector(self, key: Key, v, *, n: int | None = None, integer=False):
        """``v`` as a tuple of numbers (``n`` of them when given)."""
        if v is None:
            return None
        if not isinstance(v, (list, tuple)):
            self.fail(key, "must be an array")
        out = tuple(self.number(key, x, allow_none=False, integer=integer) for x in v)
        if n is not None and len(out) != n:
            self.fail(key, f"must have {n} elements, got {len(out)}")
        return out

    def matrix(self, key: Key, v, shape):
        """``v`` as a tuple of ``shape[0]`` tuples of ``shape[1]`` finite floats."""
        if v is None:
            return None
        try:
            rows = tuple(tuple(float(x) for x in r) for r in v)
        except (TypeError, ValueError):
            rows = ()
        if (
            len(rows) != shape[0]
            or any(len(r) != shape[1] for r in rows)
            or not all(math.isfinite(x) for r in rows for x in r)
        ):
            self.fail(key, f"must be a {shape[0]}x{shape[1]} array of numbers")
        return rows


def _header(lines, head: Key, index: int, array: bool) -> int | None:
    """Index of the ``index``-th header ``[a.b]`` (``[[a.b]]`` with ``array``) of table path
    ``head`` (array indices inside it are not part of a header's name)."""
    dotted = r"\s*\.\s*".join(re.escape(str(p)) for p in head if not isinstance(p, int))
    pat = re.compile((r"^\s*\[\[\s*%s\s*\]\]" if array else r"^\s*\[\s*%s\s*\]\s*(#.*)?$") % dotted)
    count = -1
    for i, ln in enumerate(lines):
        if pat.match(ln):
            count += 1
            if count == index:
                return i
    return None


def _key_line(lines, start: int, rest: Key) -> int | None:
    """1-based line of the (dotted) key ``rest`` from line index ``start`` to the next header."""
    if any(isinstance(p, int) for p in rest):
        return None
    pat = re.compile(r"^\s*%s\s*=" % r"\s*\.\s*".join(re.escape(str(p)) for p in rest))
    for i in range(start, len(lines)):
        if re.match(r"^\s*\[", lines[i]):
            break
        if pat.match(lines[i]):
            return i + 1
    return None


# ---------------------------------------------------------------------- writing
def dumps_toml(d: dict, header: Sequence[str] = ()) -> str:
    """TOML text of a plain mapping (str, bool, int, float, arrays, tables, arrays of tables);
    None values are left out; ``header`` lines are written first as ``#`` comments.

    A mapping that ``tomllib.loads`` reads back equal (floats by ``repr``, so exactly).
    """
    out = [f"# {h}" for h in header]
    if out:
        out.append("")
    _table(out, (), d)
    return "\n".join(out).rstrip("\n") + "\n"


def _table(out: list, path: tuple, d: dict) -> None:
    keys = {k: v for k, v in d.items() if v is not None and not isinstance(v, dict) and not _array_of_tables(v)}
    out += [f"{_key(k)} = {_value(v)}" for k, v in keys.items()]
    if keys:
        out.append("")
    for k, v in d.items():
        if isinstance(v, dict):
            sub = path + (k,)
            if any(x is not None and not isinstance(x, dict) for x in v.values()) or not v:
                out.append(f"[{'.'.join(map(_key, sub))}]")
            _table(out, sub, v)
        elif _array_of_tables(v):
            for e in v:
                out.append(f"[[{'.'.join(map(_key, path + (k,)))}]]")
                _table(out, path + (k,), e)


def _array_of_tables(v) -> bool:
    return isinstance(v, (list, tuple)) and bool(v) and all(isinstance(x, dict) for x in v)


def _key(k: str) -> str:
    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else _value(k)


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ("nan" if v != v else ("inf" if v > 0 else "-inf"))
    if isinstance(v, int):
        return str(v)
    if isinstance(v, Path):
        return _value(v.as_posix())
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")
