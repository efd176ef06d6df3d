"""Numbers as people read them in summaries, reports and figure labels."""

from __future__ import annotations

import numpy as np

__all__ = ["sig"]


def sig(x, digits: int = 4) -> str:
    """``x`` to ``digits`` significant digits; "–" when it is missing, not a number or not finite."""
    try:
        v = float(x)
    except (TypeError, ValueError):
        return "–"
    return f"{v:.{digits}g}" if np.isfinite(v) else "–"
