"""numba's on-disk cache, made to see every module a cached kernel compiles in.

numba stamps a cached function with its own source file only. A kernel that compiles in
functions or constants from other modules (the Newmark step calls the lean loops and the
contact helpers; the column loop inlines four modules) would load stale machine code after
an edit there. :class:`DependencyLocator` wraps the cache locator numba would choose and
adds to its stamp the contents of every module of the same top-level package that the
kernel's module imports, directly or through those modules (read from their import
statements, so no list of files is kept by hand). It applies to functions of the packages
in :data:`PACKAGES`; :func:`install` (run when :mod:`rocklab.models` is imported, before any
of its kernels is defined) puts it first in numba's list of locators.
"""

from __future__ import annotations

import ast
import functools
import hashlib
import sys
from pathlib import Path

from numba.core import caching

__all__ = ["DependencyLocator", "PACKAGES", "install", "module_dependencies"]

#: Module-name prefixes whose cached kernels get the dependency stamp.
PACKAGES: list[str] = ["rocklab.models."]

# numba >= 0.61 names the class CacheImpl, older releases _CacheImpl
_IMPL = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl")


def _module_file(name: str) -> Path | None:
    """Source file of module ``name`` (``pkg/mod.py`` or ``pkg/mod/__init__.py``) without importing it."""
    root_file = getattr(sys.modules.get(name.split(".")[0]), "__file__", None)
    if root_file is None:
        return None
    base = Path(root_file).resolve().parent.parent.joinpath(*name.split("."))
    for cand in (base.with_suffix(".py"), base / "__init__.py"):
        if cand.is_file():
            return cand
    return None


def _imports(name: str, path: Path) -> set[str]:
    """Modules of ``name``'s top-level package imported by the module-level statements of ``path``."""
    root = name.split(".")[0]
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = set()
    for node in ast.parse(path.read_bytes()).body:
        if isinstance(node, ast.ImportFrom):
            if node.level:
                parts = package.split(".")
                target = ".".join(parts[: len(parts) - node.level + 1] + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] != root:
                continue
            for alias in node.names:
                sub = f"{target}.{alias.name}"
                out.add(sub if _module_file(sub) is not None else target)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name.split(".")[0] == root)
    return out


def module_dependencies(name: str) -> tuple[Path, ...]:
    """Source files of the modules ``name`` imports from its own top-level package, transitively.

    Parameters
    ----------
    name : str
        Dotted module name, e.g. ``"rocklab.models.rocking._newmark"``.

    Returns
    -------
    tuple of Path
        Sorted, without the module's own file.
    """
    own = _module_file(name)
    seen, todo, files = {name}, [name], set()
    while todo:
        mod = todo.pop()
        path = _module_file(mod)
        if path is None:
            continue
        if path != own:
            files.add(path)
        for dep in _imports(mod, path) - seen:
            seen.add(dep)
            todo.append(dep)
    return tuple(sorted(files))


@functools.lru_cache(maxsize=None)
def _digest(path: str, mtime_ns: int, size: int) -> bytes:
    # keyed by mtime and size so that a file edited while the process runs is read again
    return hashlib.sha256(Path(path).read_bytes()).digest()


class DependencyLocator(caching._CacheLocator):
    """numba's own locator for a function, with a stamp that also covers the modules it imports.

    The cache path and file names are the wrapped locator's; only the stamp (which numba
    compares before loading an index) changes: ``(own stamp, sha256 of the dependencies)``.
    """

    def __init__(self, inner, deps):
        self._inner = inner
        self._deps = deps

    def ensure_cache_path(self):
        return self._inner.ensure_cache_path()

    def get_cache_path(self):
        return self._inner.get_cache_path()

    def get_disambiguator(self):
        return self._inner.get_disambiguator()

    def get_source_stamp(self):
        h = hashlib.sha256()
        for p in self._deps:
            try:
                st = p.stat()
                h.update(str(p.name).encode() + _digest(str(p), st.st_mtime_ns, st.st_size))
            except OSError:  # a dependency gone: a stamp no stored index has
                h.update(b"missing:" + str(p).encode())
        return (self._inner.get_source_stamp(), h.hexdigest())

    @classmethod
    def from_function(cls, py_func, py_file):
        mod = getattr(py_func, "__module__", None) or ""
        if not any(mod.startswith(p) for p in PACKAGES):
            return None
        for other in _IMPL._locator_classes:
            if other is cls:
                continue
            inner = other.from_function(py_func, py_file)
            if inner is not None:
                return cls(inner, module_dependencies(mod))
        return None


def install() -> None:
    """Put :class:`DependencyLocator` first in numba's locator list (once).

    A numba without the list (a future release) keeps its own locators: kernels are still
    cached, stamped with their own file only.
    """
    classes = getattr(_IMPL, "_locator_classes", None)
    if isinstance(classes, list) and DependencyLocator not in classes:
        classes.insert(0, DependencyLocator)


install()
