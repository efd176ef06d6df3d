"""Numbers as people read them in summaries, reports and figure labels."""

from __future__ import annotations

import numpy as np

__all__ = ["sig"]


def sig(x, digits: int = 4) -> str:
    """``x`` to ``digits`` significant digits (zero as "0", never "-0"); "–" when it is missing, not a
    number or not finite."""
    try:
        v = float(x)
    except (TypeError, ValueError):
        return "–"
    return f"{v + 0.0:.{digits}g}" if np.isfinite(v) else "–"  # + 0.0: -0.0 becomes 0.0
