"""``python -OO`` strips docstrings: the CLI must not build anything from them."""

import subprocess
import sys

import pytest


@pytest.mark.parametrize("args", [["--help"], ["run", "--help"], ["fit", "restitution", "--help"]])
def test_cli_help_under_OO(args):
    p = subprocess.run([sys.executable, "-OO", "-m", "rocklab", *args], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr[-400:]
    assert "usage: rocklab" in p.stdout


def test_example_toml_is_not_a_docstring():
    # the example config must survive -OO: it is a constant, not a slice of the module docstring
    p = subprocess.run(
        [sys.executable, "-OO", "-c", "from rocklab.config import EXAMPLE_TOML; print(len(EXAMPLE_TOML))"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert p.returncode == 0, p.stderr[-400:]
    assert int(p.stdout) > 1000
