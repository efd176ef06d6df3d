"""Levelling: the camera's roll from a level reference, with its source and uncertainty.

Sources (``reference.level`` of ``track.toml``): the table (its markers, or a markerless table's
top edge), the block's final rest (free rocking ends upright), a line the user marked on a
horizontal edge, a given value, or none (the camera is said to be level). A missing reference
is a warning (``W-LEVEL-NONE``), never a silent zero.
"""

from __future__ import annotations

import math

import numpy as np

from ..._diagnostics import warn
from ..._errors import InputError

__all__ = ["level_from_reference"]


def _robust_sem(x) -> float:
    """Standard error of the median of ``x`` (1.4826 MAD, n effective samples), rad."""
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    if x.size < 2:
        return math.nan
    mad = 1.4826 * float(np.median(np.abs(x - np.median(x))))
    return 1.2533 * mad / math.sqrt(x.size)


def level_from_reference(config, raw, fps, metric_plane, plane_map):
    """(level angle rad, its source, its 1-σ rad) from ``config.reference.level``; warns
    W-LEVEL-NONE when the asked-for reference is not there.

    ``raw``: object id -> (per-frame arrays ``th``, ``sig`` in plane radians, status, metric), as
    assembled by :func:`rocklab.tracking.assemble_tracks`; ``plane_map``: the image -> plane
    mapping the observations were made in (None only for a metric plane given without one).
    """
    ref = config.reference
    src = config.source or "config"
    if ref.level == "value":
        return float(ref.level_rad), "value", 0.0
    if ref.level == "none":
        return 0.0, "none (camera level)", math.nan
    if ref.level == "line":
        if plane_map is None:
            raise InputError(
                f"{src}: level = 'line' needs the image -> plane mapping the frames were tracked "
                "with; pass plane_map to assemble_tracks"
            )
        q = plane_map.to_plane(np.asarray(ref.level_line_px, float))
        d = q[1] - q[0]
        if d[0] < 0:
            d = -d
        length_px = float(np.hypot(*np.subtract(*np.asarray(ref.level_line_px, float))))
        return float(math.atan2(d[1], d[0])), "line", 0.5 * math.sqrt(2) / length_px  # 0.5 px at each end
    if ref.level == "rest":
        oid = ref.level_object or next((o.id for o in config.objects if o.kind == "block"), None)
        if oid is None or oid not in raw:
            warn(
                "W-LEVEL-NONE",
                f"{src}: level = 'rest' but there is no block {oid or ''} to take the final rest "
                "of; name one with reference.level_object",
            )
            return 0.0, "none", math.nan
        a, st, _ = raw[oid]
        th = np.where(st == "ok", a["th"], np.nan)
        rest = _final_rest(th, fps)
        if rest is None:
            warn(
                "W-LEVEL-NONE",
                f"{src}: level = 'rest' but {oid!r} does not come to rest at the end of the video "
                "(1 s still needed); angles are not levelled",
            )
            return 0.0, "none", math.nan
        # the frames' scatter understates a bias shared by all frames: one frame's σ is the floor
        sig = max(_robust_sem(th[rest]), float(np.nanmedian(a["sig"][rest])))
        return float(np.nanmedian(th[rest])), f"rest of {oid}", sig
    # "table"
    if config.table is not None:
        ta, tst, _ = raw[config.table.id]
        if np.any(tst == "ok"):
            th = ta["th"][tst == "ok"]
            sig = max(_robust_sem(th), float(np.nanmedian(ta["sig"][tst == "ok"])))
            return float(np.nanmedian(th)), f"table {config.table.id}", sig
    if metric_plane:
        return 0.0, f"plane ({plane_map.source if plane_map is not None else 'homography'})", math.nan
    why = "no object of kind 'table'" if config.table is None else "the table was never seen"
    warn(
        "W-LEVEL-NONE",
        f"{src}: level = 'table' but {why}: angles are not levelled (camera roll stays in "
        "theta); add a table object, use level = 'rest' / 'line' / 'value', or 'none' if the "
        "camera is level",
    )
    return 0.0, "none", math.nan


def _final_rest(th, fps, min_s=1.0):
    """Indices of the last still stretch of ``th`` (>= ``min_s`` long, ending at the last sample
    seen), or None. Still: frame-to-frame steps within 5x the smallest steps' scale."""
    ok = np.flatnonzero(np.isfinite(th))
    if ok.size < 10:
        return None
    steps = np.abs(np.diff(th[ok]))
    still_rad = max(5.0 * float(np.quantile(steps, 0.2)), 1e-5)
    k = ok.size - 1
    while k > 0 and steps[k - 1] <= still_rad:
        k -= 1
    idx = ok[k:]
    return idx if idx.size >= max(10, int(min_s * fps)) else None
