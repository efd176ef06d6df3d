"""Experiment pipelines, Rerun logging, reports and the ``rocklab`` CLI.

The only subpackage that imports rerun or matplotlib.
"""

from ._cli import main

__all__ = ["main"]
