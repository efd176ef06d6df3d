"""Where the pipelines draw: matplotlib on the Agg backend, PNGs written atomically.

Every report, CLI plot and paper figure goes through these three functions, so the backend and
the atomic write are decided once (``rocklab`` only writes files; it never opens a window).
"""

from __future__ import annotations

from pathlib import Path

from .._io import atomic_path

__all__ = ["pyplot", "save_png", "save_bgr_png"]


def pyplot():
    """``matplotlib.pyplot`` on the non-interactive Agg backend (rocklab only writes files)."""
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def save_png(fig, path, dpi: int = 110, tight: bool = True):
    """Write ``fig`` to ``path`` as a PNG atomically, close it, and return ``path``."""
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=dpi, format="png", **({"bbox_inches": "tight"} if tight else {}))
    pyplot().close(fig)
    return path


def save_bgr_png(path, image, *, side: bool = False):
    """Write a BGR (or grey) uint8 image to ``path`` as a PNG atomically; returns ``path``
    (``side``: a user's file there is kept, see :func:`rocklab._io.atomic_path`)."""
    import cv2

    ok, buf = cv2.imencode(".png", image)
    if not ok:
        raise OSError(f"{path}: PNG encoding failed")
    with atomic_path(path, suffix=".png", side=side) as tmp:
        Path(tmp).write_bytes(buf.tobytes())
    return path
