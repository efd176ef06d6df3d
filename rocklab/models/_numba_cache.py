"""numba's on-disk cache checks only the timestamp of the file that holds a cached function.

A kernel that compiles in functions from sibling modules would run stale machine code after an
edit there; :func:`drop_stale_cache` deletes the cache index when any of those files is newer.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["drop_stale_cache"]


def drop_stale_cache(index_glob: str, sources, module_file: str) -> None:
    """Delete ``__pycache__/<index_glob>`` numba index files older than any of ``sources``.

    Parameters
    ----------
    index_glob : str
        Glob of the cache index files, e.g. ``"_newmark.*.nbi"``.
    sources : iterable of str
        Module file names (in the caller's package folder) the cached kernels depend on.
    module_file : str
        The caller's ``__file__``: its folder holds ``sources`` and the ``__pycache__``.
    """
    here = Path(module_file).resolve().parent
    try:
        newest = max((here / f).stat().st_mtime for f in sources)
        for idx in (here / "__pycache__").glob(index_glob):
            if idx.stat().st_mtime < newest:
                idx.unlink()
    except OSError:  # read-only install or a concurrent clean-up: numba decides on its own
        pass
