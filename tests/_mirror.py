"""Public films and logs read from the fetch mirrors (/work/.mirror), never shipped: a test that
needs one skips, saying which, where the mirror is not (CI has none)."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

MIRRORS = Path("/work/.mirror")


def mirror_file(tmp_path_factory, repo: str, path: str, commit: str = "HEAD") -> Path:
    """Write ``path`` of the mirrored GitHub repository ``repo`` ("owner/name") at ``commit`` to a
    temporary file and return it; skip the test when the mirror or the file is not there."""
    git_dir = MIRRORS / repo.replace("/", "+") / "repo"
    if not git_dir.exists():
        pytest.skip(f"{repo} is not mirrored here")
    out = subprocess.run(["git", f"--git-dir={git_dir}", "show", f"{commit}:{path}"], capture_output=True)
    if out.returncode != 0:
        pytest.skip(f"the {repo} mirror does not hold {path} at {commit}")
    p = tmp_path_factory.mktemp("mirror") / Path(path).name
    p.write_bytes(out.stdout)
    return p
