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

__all__ = ["level_from_reference", "anchored", "world_angle", "final_rest", "rests_at_end", "REST_WINDOW_S"]


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


#: ``level = "rest"`` needs the block still over its last second in view (:func:`final_rest`);
#: ``track init`` looks at the film's last ``REST_WINDOW_S`` seconds for it (:func:`rests_at_end`).
REST_WINDOW_S = 1.2
#: Still there: at most ``REST_MOVING`` of the pixels round the object's first place (its box
#: padded by half its larger side) change between the last frames (the noise rule of
#: :func:`~._propose.moving_boxes`): 0 for rendered blocks at rest, 18-59 % for real pendulums and
#: bouncing balls still moving at their films' ends.
REST_MOVING = 0.01
#: In place there: the middle of the first frame's box, turned by up to ``REST_TURN_DEG`` (in steps
#: of ``REST_TURN_STEP_DEG``), is found in the last frame with a normalised correlation of at least
#: ``REST_CC``, within ``REST_SHIFT`` of the box's larger side of its first place: a block rocks in
#: place (rendered blocks, held tilted then at rest upright: 0.95-0.99 at 0.09-0.12 of the side; a
#: still ball that rolled away, on real films: 0.29-0.88 at 0.42-0.96).
REST_CC = 0.7
REST_TURN_DEG = 20.0
REST_TURN_STEP_DEG = 2.5
REST_SHIFT = 0.25


def rests_at_end(first_gray, box, end_frames) -> tuple[bool, str]:
    """Whether the object in ``box`` (x, y, w, h px of ``first_gray``) is at rest, in view and in
    place at the end of the film, the condition ``level = "rest"`` needs: (verdict, what was
    measured, a clause for a note).

    Still: at most :data:`REST_MOVING` of the pixels round the box change between ``end_frames``;
    in place: its first look, turned by up to :data:`REST_TURN_DEG`, is found in the last of them
    with a correlation of at least :data:`REST_CC`, within :data:`REST_SHIFT` of the box's larger
    side of where it was.

    Parameters
    ----------
    first_gray : ndarray (H, W) uint8
        The first frame tracked.
    box : (x, y, w, h)
        The object there, px.
    end_frames : sequence of ndarray (H, W) uint8
        Frames spread over the film's last :data:`REST_WINDOW_S` seconds, in order.
    """

    from ._propose import WORK_WIDTH_PX, prepare_frame, changed_pixels  # frames as the proposals see them

    if len(end_frames) < 2:
        return False, f"the film's last {REST_WINDOW_S:g} s could not be read"
    scale = min(1.0, WORK_WIDTH_PX / first_gray.shape[1])
    f0 = prepare_frame(first_gray, scale)
    h_img, w_img = f0.shape
    x, y, w, h = (int(round(v * scale)) for v in box)
    m = max(w, h) // 2
    u0, v0, u1, v1 = max(x - m, 0), max(y - m, 0), min(x + w + m, w_img), min(y + h + m, h_img)
    ends = [prepare_frame(g, scale) for g in end_frames]
    moving = 0.0
    for e in ends[:-1]:
        moving = max(moving, float(np.mean(changed_pixels(e, ends[-1])[v0:v1, u0:u1])))
    if moving > REST_MOVING:
        return False, (
            f"it still moves at the film's end ({100 * moving:.0f} % of the pixels round it change over the last "
            f"{REST_WINDOW_S:g} s)"
        )
    cc, shift = _found_in_place(f0, ends[-1], (x, y, w, h), (u0, v0, u1, v1))
    if cc < REST_CC or shift > REST_SHIFT * max(w, h):
        return False, (
            f"it is not found at rest in its place at the film's end (best match of its first look: correlation "
            f"{cc:.2f}, {shift / scale:.0f} px away)"
        )
    return True, f"it is still, in its place, over the film's last {REST_WINDOW_S:g} s"


def _found_in_place(f0, last, box, area_box) -> tuple[float, float]:
    """(best correlation, its distance from the box's place, px) of the middle of ``box``'s content
    in ``f0``, turned by up to :data:`REST_TURN_DEG`, searched in ``area_box`` (u0, v0, u1, v1) of
    ``last`` (working grey)."""
    import cv2

    x, y, w, h = box
    u0, v0, u1, v1 = area_box
    area = last[v0:v1, u0:u1]
    # the middle of the box: a turned box's corners hold the wall round it
    mx, my = max(1, int(0.2 * w)), max(1, int(0.2 * h))
    best, shift = -1.0, math.inf
    centre = (x + w / 2.0, y + h / 2.0)
    for deg in np.arange(-REST_TURN_DEG, REST_TURN_DEG + 1e-9, REST_TURN_STEP_DEG):
        rot = cv2.warpAffine(f0, cv2.getRotationMatrix2D(centre, float(deg), 1.0), f0.shape[::-1])
        tmpl = rot[y + my : y + h - my, x + mx : x + w - mx]
        if min(tmpl.shape) < 3 or area.shape[0] < tmpl.shape[0] or area.shape[1] < tmpl.shape[1] or tmpl.std() < 1e-3:
            continue
        _, cc, _, at = cv2.minMaxLoc(cv2.matchTemplate(area, tmpl, cv2.TM_CCOEFF_NORMED))
        if cc > best:
            best, shift = float(cc), math.hypot(at[0] + u0 - x - mx, at[1] + v0 - y - my)
    return best, shift
