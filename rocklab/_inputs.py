"""Inputs are never outputs: a command's files are compared before any work.

Every command lists what it reads (the files named on the command line, the files
a config names, the files it reads inside an input folder) and what it writes (the
files named on the command line, default names and side files such as
``<stem>_table.csv`` or ``audit.json``). :func:`check_outputs_not_inputs` refuses,
before anything is read or computed, an output that is one of the inputs (the same
file after symlinks and hard links) and two outputs that are the same file.
"""

from __future__ import annotations

import os
from pathlib import Path

from ._errors import InputError

__all__ = ["check_outputs_not_inputs", "check_folder_keeps_inputs", "sequence_files"]


def _file_id(path) -> tuple[int, int] | None:
    try:
        st = os.stat(path)
    except (OSError, ValueError):  # missing (the reader reports it), or an unusable name
        return None
    return (st.st_dev, st.st_ino)


def sequence_files(pattern) -> list[Path]:
    """The files an image-sequence pattern (``dir/%05d.png``) names; every visible file of a folder
    of frames (its timestamps too); a Photron header and its ``.mraw``; ``[pattern]`` for a plain path."""
    import re

    p = Path(pattern)
    if p.is_dir():
        return sorted(f for f in p.iterdir() if f.is_file() and not f.name.startswith("."))
    if p.suffix.lower() in (".cih", ".cihx", ".mraw"):
        return [p] + [q for q in (p.with_suffix(s) for s in (".cih", ".cihx", ".mraw")) if q != p and q.exists()]
    if "%" not in p.name:
        return [p]
    try:
        rx = re.compile(
            re.sub(r"%0?(\d*)d", lambda m: r"\d{%s,}" % (m.group(1) or 1), re.escape(p.name).replace(r"\%", "%"))
        )
        names = os.listdir(p.parent)
    except (OSError, re.error):
        return []
    return [p.parent / n for n in sorted(names) if rx.fullmatch(n)]


def check_outputs_not_inputs(inputs, outputs) -> None:
    """Refuse an output that is one of the inputs, or two outputs that are the same file.

    Parameters
    ----------
    inputs : iterable of (str, path)
        ``(label, path)`` of every file the command reads (missing ones are skipped:
        their reader reports them).
    outputs : iterable of (str, path or None)
        ``(label, path)`` of every file the command will write (None: not written).

    Raises
    ------
    InputError
        An output is an input (same file, also through a symlink or a hard link), or
        two outputs name the same file.
    """
    ins = [(label, Path(p), _file_id(p)) for label, p in inputs if p is not None]
    seen: dict[str, tuple[str, Path]] = {}
    for label, o in outputs:
        if o is None:
            continue
        o = Path(o)
        oid = _file_id(o)
        if oid is not None:
            for in_label, p, pid in ins:
                if pid == oid:
                    same = "" if o == p else f" {p} (the same file)"
                    raise InputError(
                        f"{o}: {label} would overwrite the input {in_label}{same}; rocklab never overwrites "
                        "its inputs; choose another output name"
                    )
        key = os.path.realpath(o)
        if key in seen:
            other_label, other = seen[key]
            raise InputError(
                f"{o}: {other_label} and {label} are the same file; one output would replace the other; "
                "choose another output name"
            )
        seen[key] = (label, o)


def check_folder_keeps_inputs(out_dir, inputs, option: str = "--out") -> None:
    """Refuse an output folder that holds one of the inputs among the entries rocklab would replace.

    A folder rocklab wrote is replaced whole, and its own entries one by one when the user's
    files sit beside them (:func:`rocklab._outdir.publish_dir`): an input inside one of those
    entries (a ``tracks.csv`` of an earlier run used as a source) would be destroyed.
    """
    from ._outdir import MARKER, owned_entries

    out_dir = Path(out_dir)
    if not out_dir.is_dir():
        return
    root = Path(os.path.realpath(out_dir))
    owned = owned_entries(out_dir) | {MARKER}
    for label, p in inputs:
        rp = Path(os.path.realpath(p))
        try:
            top = rp.relative_to(root).parts[0]
        except (ValueError, IndexError):
            continue
        if top in owned:
            raise InputError(
                f"{option} {out_dir}: holds the input {label} {p}, written there by an earlier rocklab run "
                "and replaced by this one; copy the input elsewhere or choose another output folder"
            )
