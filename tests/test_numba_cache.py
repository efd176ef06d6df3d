"""numba's on-disk cache sees the modules a cached kernel compiles in (rocklab.models._numba_cache).

A cached kernel in one module calls a jitted function of another; after an edit of that other
module the next process must run the new code, not the machine code cached before the edit.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

from rocklab.models import _numba_cache

ROOT = Path(__file__).resolve().parents[1]

KERNEL = """
from numba import njit
from .helper import SCALE, value

@njit(cache=True)
def run(x):
    return SCALE * value(x)
"""
HELPER = """
from numba import njit
from ._deep import OFFSET

SCALE = {scale}

@njit
def value(x):
    return x + OFFSET
"""


def _write_pkg(tmp_path, scale, offset):
    pkg = tmp_path / "cachepkg"
    pkg.mkdir(exist_ok=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "kernel.py").write_text(KERNEL)
    (pkg / "helper.py").write_text(HELPER.format(scale=scale))
    (pkg / "_deep.py").write_text(f"OFFSET = {offset}\n")


def _run(tmp_path):
    code = textwrap.dedent(
        f"""
        import sys
        sys.path.insert(0, {str(tmp_path)!r})
        from rocklab.models import _numba_cache as nc
        nc.PACKAGES.append("cachepkg.")
        from cachepkg.kernel import run
        print(run(1.0), len(run.stats.cache_hits))
        """
    )
    env = dict(os.environ, PYTHONPATH=str(ROOT), NUMBA_CACHE_DIR="")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    value, hits = out.stdout.split()
    return float(value), int(hits)


def test_dependencies_are_read_from_the_imports():
    deps = {p.name for p in _numba_cache.module_dependencies("rocklab.models.rocking._newmark")}
    # the contact helpers and the lean loops (imported directly), blocks.G and what blocks imports
    assert {"_newmark_contact.py", "_newmark_lean.py", "blocks.py", "_errors.py"} <= deps
    assert "_newmark.py" not in deps and "_single.py" not in deps
    col = {p.name for p in _numba_cache.module_dependencies("rocklab.models.column._core")}
    assert {"_kernels.py", "_step.py", "_events.py"} <= col


def test_edit_of_an_imported_module_invalidates_the_cache(tmp_path):
    _write_pkg(tmp_path, scale=2.0, offset=1.0)
    assert _run(tmp_path) == (4.0, 0)  # compiled
    assert _run(tmp_path) == (4.0, 1)  # loaded from the cache
    # a constant and a function two imports away (helper -> _deep) change; kernel.py does not
    _write_pkg(tmp_path, scale=2.0, offset=5.0)
    assert _run(tmp_path) == (12.0, 0)
    _write_pkg(tmp_path, scale=3.0, offset=5.0)
    assert _run(tmp_path) == (18.0, 0)
    assert _run(tmp_path) == (18.0, 1)
