"""The documentation's examples run as written: ``console`` blocks as shell commands, ``pycon`` as doctests.

A ``console`` block holds ``$ command`` lines, each followed by its expected output; ``...``
matches anything (doctest's ELLIPSIS), whitespace differences are ignored. All blocks of a page
run in order in one empty folder, so later commands use earlier outputs, as a reader would.
"""

from __future__ import annotations

import doctest
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = ["getting-started.md"]
FENCE = re.compile(r"^```(console|pycon)\n(.*?)^```", re.M | re.S)
CHECK = doctest.OutputChecker()
FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def _console_steps(body: str):
    """(command, expected output) pairs of one console block."""
    steps: list[list] = []
    for line in body.splitlines():
        if line.startswith("$ "):
            steps.append([line[2:], []])
        elif steps:
            steps[-1][1].append(line)
    return [(cmd, "\n".join(out).strip() + "\n") for cmd, out in steps]


def _env():
    env = dict(os.environ)
    env["PATH"] = str(Path(sys.executable).parent) + os.pathsep + env.get("PATH", "")
    env["COLUMNS"] = "200"
    return env


@pytest.mark.parametrize("page", PAGES)
def test_page_examples_run_as_written(page, tmp_path, monkeypatch):
    text = (ROOT / "docs" / page).read_text(encoding="utf-8")
    blocks = FENCE.findall(text)
    assert sum(kind == "console" for kind, _ in blocks) >= 3
    monkeypatch.chdir(tmp_path)
    n_cmd = 0
    for kind, body in blocks:
        if kind == "pycon":
            test = doctest.DocTestParser().get_doctest(body, {}, page, page, 0)
            runner = doctest.DocTestRunner(optionflags=FLAGS)
            runner.run(test, out=lambda s: pytest.fail(f"{page}: doctest failed:\n{s}"))
            assert runner.tries >= 3
            continue
        for cmd, want in _console_steps(body):
            argv = shlex.split(cmd)
            assert argv[0] == "rocklab", cmd
            p = subprocess.run(argv, capture_output=True, text=True, env=_env(), timeout=300)
            assert p.returncode == 0, f"{cmd}\n{p.stderr}"
            assert CHECK.check_output(want, p.stdout, FLAGS), f"{cmd}\nexpected:\n{want}\ngot:\n{p.stdout}"
            n_cmd += 1
    assert n_cmd >= 6


def _makefile_var(name: str) -> str:
    m = re.search(rf"^{name}\s*:?=\s*(\S+)", (ROOT / "Makefile").read_text(encoding="utf-8"), re.M)
    assert m, f"Makefile sets no {name}"
    return m.group(1)


def test_setup_says_where_the_commands_are():
    """After ``make demo`` the commands are in the Makefile's venv, not on PATH: README and
    getting-started say how to reach them (activate, the path, or ``make install-user``), and
    those paths are where pip puts the entry points of this environment."""
    venv = _makefile_var("VENV")
    targets = set(re.findall(r"^([\w-]+):", (ROOT / "Makefile").read_text(encoding="utf-8"), re.M))
    bin_dir = Path(sys.executable).parent
    for cmd in ("rocklab", "rerun"):  # both are entry points of the environment the docs describe
        assert (bin_dir / cmd).is_file(), f"{cmd} is not installed beside {sys.executable}"
    for page in (ROOT / "README.md", ROOT / "docs" / "getting-started.md"):
        text = page.read_text(encoding="utf-8")
        assert f"source {venv}/bin/activate" in text, page.name
        for cmd in ("rocklab", "rerun"):
            assert f"{venv}/bin/{cmd}" in text, (page.name, cmd)
        for target in re.findall(r"`make ([\w-]+)", text):  # every make target named exists
            assert target in targets, (page.name, target)
        assert "install-user" in text and "--web-viewer" in text, page.name


def test_demo_names_the_viewer_it_installed(monkeypatch, tmp_path):
    """``rocklab demo`` ends by saying how to open its recordings: ``rerun`` when that is on the
    PATH, else the viewer installed beside this Python (``.venv/bin/rerun`` after ``make demo``)."""
    from rocklab.pipelines.cli.commands._cmd_demo import viewer_command

    bin_dir = Path(sys.executable).parent
    monkeypatch.setenv("PATH", str(tmp_path))  # nothing on the PATH
    monkeypatch.chdir(bin_dir.parent)
    assert viewer_command() == str(Path(bin_dir.name) / "rerun")  # e.g. bin/rerun, from the venv's folder
    monkeypatch.chdir(tmp_path)
    assert Path(viewer_command()) == bin_dir / "rerun"
    monkeypatch.setenv("PATH", str(bin_dir))
    assert viewer_command() == "rerun"
