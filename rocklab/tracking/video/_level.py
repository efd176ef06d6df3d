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

__all__ = ["level_from_reference", "anchored", "world_angle", "final_rest"]


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
        rest, why = rest_finding(th, fps)
        if rest is None:
            warn(
                "W-LEVEL-NONE",
                f"{src}: level = 'rest' but no final rest of {oid!r} (1 s still) is found: {why}; "
                'angles are not levelled; set reference.level = "line", "value" or "none"',
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


def final_rest(th, fps, min_s=1.0):
    """Whether a track comes to rest at its end, the one test of it: indices of the last still
    stretch of ``th`` (>= ``min_s`` long, ending at the last sample seen), or None. Still:
    frame-to-frame steps within 4 sigma of the measurement noise, its scale from the smallest
    fifth of the steps (the 20 % quantile of |N(0, s)| is 0.253 s), and a spread within 5 % of
    the whole track's. :func:`rest_finding` says what was measured when there is none."""
    return rest_finding(th, fps, min_s)[0]


def rest_finding(th, fps, min_s=1.0):
    """(:func:`final_rest`'s indices or None, what was measured: a clause for a message, ``""``
    when a rest was found)."""
    ok = np.flatnonzero(np.isfinite(th))
    if ok.size < 10:
        return None, f"its angle is measured on {ok.size} of {len(th)} frames (10 needed)"
    steps = np.abs(np.diff(th[ok]))
    # 4 / 0.253 = 16: a still step beyond it is one in 16 000 (at 5 quantiles, one in five, which
    # broke every tracked rest of more than a few frames)
    still_rad = max(16.0 * float(np.quantile(steps, 0.2)), 1e-5)
    k = ok.size - 1
    while k > 0 and steps[k - 1] <= still_rad:
        k -= 1
    idx = ok[k:]
    need = max(10, int(min_s * fps))
    if idx.size < need:
        return None, (
            f"its angle's last still stretch (steps within {math.degrees(still_rad):.3g} deg) is "
            f"{idx.size} frames, {need} needed"
        )
    # still against the motion before it: the noise scale above holds only when a fifth of the
    # steps are still, and a film that rocks to its end has no such fifth
    spread, whole = float(np.ptp(th[idx])), float(np.ptp(th[ok]))
    if spread > 0.05 * whole:
        return None, (
            f"its angle over its last {idx.size} frames spreads {math.degrees(spread):.3g} deg, more "
            f"than 5 % of its whole range ({math.degrees(whole):.3g} deg): no rest stands out from "
            "its motion or noise"
        )
    return idx, ""


def anchored(o, config) -> bool:
    """Whether object ``o``'s angle is its rotation since the first frame plus ``theta0_rad`` (a
    block followed by its texture) rather than measured against the image (markers, outlines)."""
    return o.kind != "table" and (o.style or config.targets.style) in ("region", "markerless")


#: A final rest further from upright than this is not taken as upright (an overturned block).
MAX_REST_OFFSET_RAD = math.radians(45.0)


def world_angle(o, config, th, sig, fps, level, level_src, src="config"):
    """Object ``o``'s levelled angle (rad) from its plane angles ``th`` (n,) and their 1-sigma ``sig``.

    Measured objects lose the camera's roll (``level``). An anchored object (:func:`anchored`)
    carries none: its angle is its rotation plus ``theta0_rad``, an angle in the levelled frame.
    Without ``theta0_rad`` it is assumed upright at the first frame, unless it ends at rest
    (:func:`final_rest`, the test ``level = "rest"`` makes) at an angle that differs from upright
    by more than 3 sigma and less than 45 deg:
    free rocking ends upright, so the rest sets the starting angle (warning W-THETA0-REST). With
    ``level = "rest"`` of the object itself, that rest is the level and is taken off as before.
    """
    if not anchored(o, config) or level_src == f"rest of {o.id}":
        return th - level
    if o.theta0_rad is not None:
        return th
    # the same decision as level = "rest" (one answer to "does it come to rest" per run: the
    # level's W-LEVEL-NONE and this W-THETA0-REST cannot both be said of one track)
    rest = final_rest(th, fps)
    if rest is None:
        return th
    off = float(np.nanmedian(th[rest]))
    unc = max(_robust_sem(th[rest]), float(np.nanmedian(sig[rest])))
    if not 3.0 * unc < abs(off) < MAX_REST_OFFSET_RAD:
        return th
    warn(
        "W-THETA0-REST",
        f"{src}: object {o.id!r} has no theta0_rad and comes to rest at {math.degrees(off):.4g} deg: "
        f"its starting angle is taken as {-math.degrees(off):.4g} deg from the final rest (free "
        "rocking ends upright); set theta0_rad if it really rests tilted",
    )
    return th - off
