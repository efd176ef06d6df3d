"""Atomic output writing: write to a temp file in the same folder, then rename.

A crash or a bad input never leaves a half-written output, and inputs are never
opened for writing.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from pathlib import Path

__all__ = ["atomic_path", "write_text_atomic", "write_json_atomic", "write_frame_atomic", "json_safe", "dumps_json"]


@contextlib.contextmanager
def atomic_path(path, suffix: str | None = None, *, side: bool = False, stamp: bool = True):
    """Yield a temporary path next to ``path``; rename it onto ``path`` on success.

    On an exception the temporary file is removed and ``path`` is untouched. A ``side``
    file (one the user did not name: ``<stem>_table.csv``, ``audit.json``, a default
    output name) never replaces a user's file: one rocklab did not write is kept as
    ``NAME.user-<time>`` (:func:`rocklab._outdir.set_aside_user_file`). The file is stamped as
    rocklab's (:func:`rocklab._outdir.stamp_output`: a later run replaces it and never reads it
    back from a folder of inputs) unless ``stamp`` is False (data made to be read as an input:
    ``rocklab synth``).
    """
    from ._errors import InputError
    from ._outdir import (
        claim_side_file,
        clean_stale,
        raise_pending_stop,
        set_aside_user_file,
        stale_prefix,
        stamp_output,
    )

    path = Path(path)
    if path.is_dir():
        raise InputError(f"{path}: is a folder; give a file name for this output")
    path.parent.mkdir(parents=True, exist_ok=True)
    clean_stale(path.parent, path.name)  # leftovers of a killed writer of this same file
    fd, tmp = tempfile.mkstemp(
        prefix=stale_prefix(path.name, "tmp"), suffix=suffix or path.suffix or ".tmp", dir=path.parent
    )
    os.close(fd)
    try:
        yield Path(tmp)
        # mkstemp makes the file private; an output gets the permissions any new file would (umask)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        # the extended attribute moves with the file; a stamp kept in the cache folder is named by
        # the final path, and made only once the file it replaces has been judged
        stamped = stamp and stamp_output(tmp, registry=False)
        kept = set_aside_user_file(path) if side else None
        raise_pending_stop()
        os.replace(tmp, path)
        if stamp and not stamped:
            stamp_output(path)
        if kept is not None:
            import sys

            sys.stderr.write(f"rocklab: kept your {path} as {kept.name} (rocklab did not write it) and wrote {path}\n")
        if side:
            claim_side_file(path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def write_text_atomic(path, text: str, *, side: bool = False, stamp: bool = True) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically and return the path (``side``, ``stamp``: see
    :func:`atomic_path`)."""
    with atomic_path(path, side=side, stamp=stamp) as tmp:
        Path(tmp).write_text(text, encoding="utf-8")
    return Path(path)


def write_json_atomic(path, obj, indent: int = 2, *, side: bool = False) -> Path:
    """Write ``obj`` as JSON to ``path`` atomically (NaN written as null; ``side``: see :func:`atomic_path`)."""
    return write_text_atomic(path, dumps_json(obj, indent=indent) + "\n", side=side)


def dumps_json(obj, indent: int | None = None) -> str:
    """Strict JSON text of ``obj``: NaN/inf as null, numpy scalars and arrays as numbers and lists,
    paths and other objects as strings."""
    return json.dumps(json_safe(obj), indent=indent, allow_nan=False, default=str)


def write_frame_atomic(path, frame, *, side: bool = False, **kwargs) -> Path:
    """Write a pandas DataFrame to CSV atomically (``index=False`` by default; ``side``: see
    :func:`atomic_path`)."""
    kwargs.setdefault("index", False)
    with atomic_path(path, side=side) as tmp:
        frame.to_csv(tmp, **kwargs)
    return Path(path)


def json_safe(obj):
    """``obj`` with NaN/inf replaced by None and numpy values by Python ones (recursively)."""
    import math

    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    try:
        import numpy as np

        if isinstance(obj, np.generic):
            return json_safe(obj.item())
        if isinstance(obj, np.ndarray):
            return json_safe(obj.tolist())
    except ImportError:  # pragma: no cover
        pass
    return obj
