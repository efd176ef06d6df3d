"""Why a target was lost in a frame (occluded or blurred), and what a finished video track is checked
for: frames the container promised but did not give, objects lost on more than 1 % of the frames,
a tracker that follows another object; and short gaps filled when the config asks.

Each finding is a named warning (``W-VIDEO-SHORT``, ``W-VIDEO-DROPPED``, ``W-VIDEO-DAMAGED``,
``W-VIDEO-FPS``, ``W-VIDEO-LOST``, ``W-VIDEO-MIRRORED``, ``W-TRACK-LATCH``).
"""

from __future__ import annotations

import math

import numpy as np

from ..._diagnostics import warn

__all__ = ["TABLE_TURN_MAX_RAD", "BLUR_RATIO", "MAX_REGION_OVERLAP", "check_mirrored", "region_overlap"]

#: A lost target whose window's sharpness fell below this fraction of the last good one is "blur".
BLUR_RATIO = 0.35


def region_leaves(roi, width_px: int, height_px: int, tol_px: float = 0.0) -> bool:
    """Whether a region ``(u, v, w, h)`` (px) reaches past a ``width_px`` x ``height_px`` frame by
    more than ``tol_px``."""
    u, v, w, h = (float(x) for x in roi)
    return u < -tol_px or v < -tol_px or u + w > width_px + tol_px or v + h > height_px + tol_px


#: Two objects' regions may overlap by at most this share of the smaller one: beyond it a tracker
#: would latch onto the other object (``track init`` refuses such regions and merges such proposals).
MAX_REGION_OVERLAP = 0.2


def region_overlap(a, b) -> tuple[float, bool]:
    """(overlap area px^2, whether it is more than :data:`MAX_REGION_OVERLAP` of the smaller region)
    of two regions ``(u, v, w, h)`` (px)."""
    ax, ay, aw, ah = (float(v) for v in a)
    bx, by, bw, bh = (float(v) for v in b)
    ix = max(0.0, min(ax + aw, bx + bw) - max(ax, bx))
    iy = max(0.0, min(ay + ah, by + bh) - max(ay, by))
    return ix * iy, ix * iy > MAX_REGION_OVERLAP * min(aw * ah, bw * bh)


def look(gray, box):
    """(Laplacian variance, grey std) of the window ``box`` = (u0, v0, u1, v1)."""
    import cv2

    x0, y0, x1, y1 = box
    crop = gray[y0:y1, x0:x1]
    if crop.size < 64:
        return np.nan, np.nan
    return float(cv2.Laplacian(crop, cv2.CV_32F).var()), float(crop.std())


def why_lost(now, ref):
    """Reason for a lost target from its last window now vs at the last good detection (how the
    window looks; :func:`lost_status` says whether that is true of the object).

    "blur": fine detail gone (Laplacian variance < 35 %) but the black/white
    contrast still there (grey std > 25 %); "occluded": the contrast itself is
    gone (something flat or different covers the window); else "lost".
    """
    if ref is None or not np.all(np.isfinite(now)):
        return "lost"
    sharp, std = now
    if std < 0.25 * ref[1]:
        return "occluded"
    if sharp < BLUR_RATIO * ref[0]:
        return "blur"
    return "lost"


#: A cut to another shot (a title card, a lead-in, an edit): the mean grey change to the next
#: frame, at :data:`CUT_WIDTH_PX` wide, more than ``CUT_FACTOR`` times the film's median change
#: and at least ``CUT_MIN_DN`` (the real films: 24.4 and 28.7 DN at the title cards of a film
#: whose frames change by 2.1 DN, 100.8 DN where a black lead-in ends). Inside a film, where a
#: hand passing the camera changes as much as a title card, a cut is a change of most of the
#: picture: its median pixel changes by ``CUT_MIN_DN`` (96 DN at the black lead-in's end, 1 DN
#: at a title card over a fifth of the picture).
CUT_FACTOR = 6.0
CUT_MIN_DN = 12.0
CUT_WIDTH_PX = 160.0


def small_grey(gray) -> np.ndarray:
    """``gray`` at most :data:`CUT_WIDTH_PX` wide, float32, for comparing whole frames."""
    import cv2

    s = min(1.0, CUT_WIDTH_PX / gray.shape[1])
    g = gray if s == 1.0 else cv2.resize(gray, None, fx=s, fy=s, interpolation=cv2.INTER_AREA)
    return g.astype(np.float32)


def cut_limit(steps) -> float:
    """The change between two frames (DN, :func:`small_grey`) above which it is a cut, from the
    film's own changes ``steps``; inf while fewer than 3 are known."""
    return max(CUT_FACTOR * float(np.median(steps)), CUT_MIN_DN) if len(steps) >= 3 else math.inf


#: ... from a picture with texture to another: the grey levels of the changed pixels spread by
#: at least this on both sides (a grey card over two thirds of a rendered film, put in front and
#: taken away: 1.5 DN on its side; a cover is an occluder, not a cut).
CUT_TEXTURE_DN = 5.0


def is_cut(before, after) -> bool:
    """Whether frame ``after`` follows ``before`` (both :func:`small_grey`) by a cut to another
    shot: most of the picture changed (the median pixel by :data:`CUT_MIN_DN`), from texture to
    texture (:data:`CUT_TEXTURE_DN`): a flat cover put in front or taken away (a hand, a card)
    is an occluder, and a lead-in from black is found by ``track init``."""
    change = np.abs(after - before)
    if float(np.median(change)) < CUT_MIN_DN:
        return False
    moved = change >= CUT_MIN_DN
    return min(float(before[moved].std()), float(after[moved].std())) >= CUT_TEXTURE_DN


def check_cuts(steps, cuts, frames, path) -> None:
    """W-VIDEO-CUT when the tracked frames cut to another shot: ``cuts``, the frames at which most
    of the picture changed (the median pixel by :data:`CUT_MIN_DN`), or a first frame tracked that
    differs from the next as no other pair does (``steps[0]`` beyond :func:`cut_limit` of the
    others: a title card over the scene, a lead-in); ``steps[i]`` is the mean change (DN) from
    ``frames[i]`` to ``frames[i + 1]``."""
    first = len(steps) >= 4 and steps[0] > cut_limit(steps[1:])
    if not cuts and not first:
        return
    at = sorted(set(cuts) | ({int(frames[1])} if first else set()))
    why = (
        f"; the first frame tracked, {frames[0]}, differs from the next as no other pair does (a title card, "
        f"a lead-in): the objects' templates and the background come from it, so set [video] start_frame = "
        f"{frames[1]}"
        if first
        else "; the frames after a cut show another scene: track a span without one ([video] start_frame, stop_frame)"
    )
    warn(
        "W-VIDEO-CUT",
        f"{path}: the film cuts to another shot at frame(s) {', '.join(map(str, at[:5]))} (the picture "
        f"changes by up to {max(steps):.3g} grey levels against {float(np.median(steps)):.3g} a frame){why}",
    )


def ring_look(gray, box):
    """(mean, std) grey of the ring round the window ``box`` = (u0, v0, u1, v1): the window grown
    by half its size on each side, less the window; None when the ring is under 64 px."""
    u0, v0, u1, v1 = box
    H, W = gray.shape[:2]
    du, dv = (u1 - u0) // 2, (v1 - v0) // 2
    x0, y0, x1, y1 = max(u0 - du, 0), max(v0 - dv, 0), min(u1 + du, W), min(v1 + dv, H)
    outer = gray[y0:y1, x0:x1].astype(np.float32)
    keep = np.ones(outer.shape, bool)
    keep[max(v0 - y0, 0) : v1 - y0, max(u0 - x0, 0) : u1 - x0] = False
    ring = outer[keep]
    return (float(ring.mean()), float(ring.std())) if ring.size >= 64 else None


def shows_background(gray, box, ring) -> bool:
    """Whether the window ``box`` now looks like the ring round it did at the object's last good
    frame (``ring``, :func:`ring_look`): mean within half the ring's spread (and 3 grey levels),
    spread at most 1.5 times it (and 2). Then the object has left the window, and what stands
    there is the scene behind it: the window says nothing about the object (lost, neither
    occluded nor blurred)."""
    if ring is None:
        return False
    u0, v0, u1, v1 = box
    crop = gray[v0:v1, u0:u1].astype(np.float32)
    if crop.size < 64:
        return False
    mean, std = ring
    return abs(float(crop.mean()) - mean) <= 0.5 * std + 3.0 and float(crop.std()) <= 1.5 * std + 2.0


def last_seen(prev, frame: int, centre_px) -> tuple:
    """An object's last ok frame, its centre (px) and its speed (px/frame, from the ok frame
    before: 0 for the first), given ``prev``, the same for the ok frame before (or None)."""
    c = np.asarray(centre_px, float)
    if prev is None or frame <= prev[0]:
        return frame, c, 0.0
    return frame, c, float(np.hypot(*(c - prev[1]))) / (frame - prev[0])


def may_have_left(seen, frame: int, box) -> bool:
    """Whether an object last seen at ``seen`` (:func:`last_seen`) may have moved out of its last
    window ``box`` (u0, v0, u1, v1 px) by ``frame``: at its last speed, farther than a quarter of
    the window's smaller side."""
    f, _, speed = seen
    return speed * (frame - f) > 0.25 * min(box[2] - box[0], box[3] - box[1])


def lost_status(gray, box, sharp_ref, ring, seen, frame) -> str:
    """Why an object is lost, from its last window ``box`` in ``gray`` (:func:`why_lost`), said
    only when true of the object: "occluded" when the window does not show the scene that stood
    round it (:func:`shows_background`: the object left, the scene behind it shows), "blur" while
    the object cannot have left the window (:func:`may_have_left`: a window the object is leaving
    loses its fine detail too); else "lost"."""
    why = why_lost(look(gray, box), sharp_ref)
    if (why == "occluded" and shows_background(gray, box, ring)) or (why == "blur" and may_have_left(seen, frame, box)):
        return "lost"
    return why


def check_frames(res, expected: int, path, info=None, config=None) -> None:
    """Frames lost, counted per cause: W-VIDEO-SHORT (a note) when the header counts frames the
    file does not hold; W-VIDEO-DROPPED (a note) for slots of the container's clock without a
    frame (the camera dropped them; the times stay true); W-VIDEO-DAMAGED when frames the
    container holds do not decode; W-VIDEO-LOST when an object is lost on more than 1 % of the
    frames."""
    n_header = getattr(info, "n_header", 0)
    n_held = getattr(info, "n_frames", expected)
    if n_header and n_held < 0.99 * n_header:
        # a note, not suspect: every frame the file holds is measured
        warn(
            "W-VIDEO-SHORT",
            f"{path}: the container's header counts {n_header} frames but the file holds "
            f"{n_held} (file cut, or a header that over-counts)",
        )
    if getattr(info, "n_dropped", 0):
        t = info.frame_times_s
        at = np.flatnonzero(np.diff(t) > 1.5 / info.fps)[:3] if t is not None and info.fps else []
        warn(
            "W-VIDEO-DROPPED",
            f"{path}: the camera dropped {info.n_dropped} frame(s) (gaps in the container's "
            f"{info.fps:.6g} frames/s clock, first after t = "
            f"{', '.join(f'{t[i]:.4f}' for i in at)} s); each frame keeps its own time",
        )
    if expected > 0 and res.n_frames < expected:
        warn(
            "W-VIDEO-DAMAGED",
            f"{path}: {expected - res.n_frames} of the {expected} frames the container holds "
            "did not decode (damaged packets); the frames around them keep their times, "
            "the gaps are in t_s",
        )
    check_mirrored(info, path)
    _check_latch(res, path, config)
    for t in res.tracks:
        twin = np.flatnonzero(t.status == "twin")
        if twin.size:
            warn(
                "W-TRACK-TWIN",
                f"{path}: object {t.object!r} found again beside a look-alike on {twin.size} frames from frame "
                f"{t.frame[twin[0]]} (another match of its template as good, within its reach), and its motion "
                "before the loss does not tell which is the object: those frames are status twin, not ok; "
                "track the look-alike too, or track the object over the frames it is not beside it",
            )
    for t in res.tracks:
        lost = int(np.sum(~np.isin(t.status, ("ok", "interpolated"))))
        if lost > 0.01 * len(t.status):
            warn(
                "W-VIDEO-LOST",
                f"{path}: object {t.object!r} lost on {lost} of {len(t.status)} frames "
                f"({100 * lost / len(t.status):.3g} %); see the status column",
            )


def check_mirrored(info, path) -> None:
    """W-VIDEO-MIRRORED when the film's display matrix mirrors the picture: it is read as shown,
    and whether the mirror undoes one (a camera that stores its picture mirrored) or adds one (a
    front camera's selfie view, an editor's flip) only the lab knows; the sign of every angle
    depends on it."""
    if getattr(info, "mirrored", False):
        r = info.rotation_deg
        warn(
            "W-VIDEO-MIRRORED",
            f"{path}: the container's display matrix mirrors the picture (turn {r} deg, then a mirror); "
            "the frames are tracked as shown, so theta has the sign of the mirrored picture; if the "
            "mirror was added for display (front camera, an editor's flip), theta's sign is reversed: "
            f"check it against the lab, or re-mux the film without the mirror (ffmpeg -display_rotation {r} "
            "-i FILM -c copy OUT)",
        )


def check_rate(given: float, info, path, where: str) -> None:
    """W-VIDEO-FPS when a frame rate given by the user contradicts the container's own clock."""
    kind = "mean" if info.variable_rate and not info.n_dropped else "constant"
    warn(
        "W-VIDEO-FPS",
        f"{where} = {given:.6g} frames/s, but {path} holds its frames at a {kind} "
        f"{info.fps:.6g} frames/s: t_s follows the given rate; remove it to use the "
        "container's times (keep it only for a film whose clock is known wrong)",
    )


#: A table turning by more than this (rad, 5th to 95th percentile) is following something else.
TABLE_TURN_MAX_RAD = math.radians(1.0)


def _as_latch(series, idx) -> None:
    """Mark the frames ``idx`` (index array or slice) of one object's raw series (as
    :func:`settle_latches` takes it) ``latch``, their measured values NaN: another object's pixels."""
    series[1][idx] = "latch"
    for q in ("X", "Y", "th", "sig"):
        series[0][q][idx] = np.nan


def _first_sides(config) -> dict:
    """Object id -> the smaller side of its first region (px), for objects given one."""
    return {
        o.id: min(float(o.roi[2]), float(o.roi[3]))
        for o in (getattr(config, "objects", None) or ())
        if getattr(o, "roi", None) is not None
    }


def latch_distance(sides: dict, a: str, b: str) -> float:
    """Two objects' reference points closer than this (px) are on the same pixels: 3 px, or half
    the smaller side of the smaller of their first regions (two objects side by side keep about a
    size apart)."""
    return max(3.0, 0.5 * min(sides.get(a, 0.0), sides.get(b, 0.0)))


def _shared_runs(uv_a, uv_b, ok_a, ok_b, near: float) -> list:
    """Runs (first, last index) of the frames both objects are ok within ``near`` px of each
    other, consecutive among the frames both are ok (a frame either is not ok does not end one)."""
    both = np.flatnonzero(ok_a & ok_b)
    close = np.hypot(*(uv_a[both] - uv_b[both]).T) < near
    runs, start = [], None
    for j, c in enumerate(close):
        if c and start is None:
            start = j
        if start is not None and (not c or j == len(close) - 1):
            runs.append((int(both[start]), int(both[j if c else j - 1])))
            start = None
    return runs


def _entry_miss(uv, ok, s: int) -> float:
    """How far (px) an object's pose at index ``s`` lies from where its own ok frames before
    ``s`` lead (the last one moved on at the velocity between the last two); NaN without one."""
    before = np.flatnonzero(ok[:s])
    if before.size == 0:
        return math.nan
    p1 = before[-1]
    pred = uv[p1]
    if before.size >= 2:
        p0 = before[-2]
        pred = pred + (uv[p1] - uv[p0]) * (s - p1) / (p1 - p0)
    return float(np.hypot(*(uv[s] - pred)))


def _near_edge(c, width_px: int, height_px: int, reach: float) -> bool:
    """Whether a centre ``c`` (u, v px) lies within ``reach`` px of the frame's border."""
    return bool(min(c[0], c[1], width_px - c[0], height_px - c[1]) < reach)


def _leaving(uv, ok, p: int, size: float, wh) -> bool:
    """Whether an object last trusted ok at index ``p`` may have left the frame in the frames
    after: its region (half ``size`` about its centre) would cross the border one step on (its
    speed between its last two trusted ok frames), and its centre lies within ``size`` of it. A
    cart that bounces a size from an edge, its whole region in view, has not left (a latch named
    "left the frame" for it says a false thing)."""
    before = np.flatnonzero(ok[: p + 1])
    step = 0.0
    if before.size >= 2:
        p0 = int(before[-2])
        step = float(np.hypot(*(uv[p] - uv[p0]))) / (p - p0)
    # and never farther than its larger side: a fast ball hitting a floor near the bottom edge
    # would be one long step from it without leaving
    return _near_edge(uv[p], *wh, min(size, 0.5 * size + step))


def _run_ends(ok, before: int) -> np.ndarray:
    """Indices where an object's ok runs ended (the next frame not ok) before index ``before``."""
    return np.flatnonzero(ok[: before - 1] & ~ok[1:before])


def _place_of(o, s: int, uv, trusted, regions) -> np.ndarray | None:
    """Where object ``o`` is at index ``s``: its centre there when it is ok, else where it was last
    seen (its last ok centre before ``s``, or its first region's centre when it has none)."""
    if trusted[o][s]:
        return uv[o][s]
    before = np.flatnonzero(trusted[o][:s])
    if before.size:
        return uv[o][before[-1]]
    roi = regions.get(o)
    if roi is None:
        return None
    return np.array([float(roi[0]) + 0.5 * float(roi[2]), float(roi[1]) + 0.5 * float(roi[3])])


#: A re-acquisition this many times nearer to another object's place than to its own last trusted
#: pose has found the other object (two identical bobs side by side: 47 px from the other's place,
#: over 190 px from its own).
OTHER_NEARER = 2.0


def _on_other(k, s, p, uv, trusted, regions, size) -> bool:
    """Whether object ``k`` found again at index ``s`` (last trusted ok at ``p``) has jumped onto
    another object of the config (a look-alike: two identical bobs, pucks, balls): outside the span
    of its own trusted ok centres before ``s`` grown by ``size`` (a pendulum re-found across its
    swing stays inside it), and :data:`OTHER_NEARER` times nearer to another object's place
    (:func:`_place_of`) than to its own last trusted pose. Its view cannot tell: a look-alike
    re-explains it. Where the other object is ok within half ``size`` of it, :func:`settle_latches`
    decides which of the two keeps the pixels."""
    before = np.flatnonzero(trusted[k][: p + 1])
    c = uv[k][s]
    seen = uv[k][before]
    if np.all((c >= np.nanmin(seen, axis=0) - size) & (c <= np.nanmax(seen, axis=0) + size)):
        return False
    d_own = float(np.hypot(*(c - uv[k][p])))
    for o in uv:
        if o == k:
            continue
        at = _place_of(o, s, uv, trusted, regions)
        if at is None or not np.all(np.isfinite(at)):
            continue
        d = float(np.hypot(*(c - at)))
        if trusted[o][s] and d < 0.5 * size:
            continue  # both ok on the same pixels: the shared-pixels rule (settle_latches) decides
        if OTHER_NEARER * d < d_own:
            return True
    return False


def _reacquired_wrong(k, s, p, uv, trusted, size, wh) -> str | None:
    """Why object ``k`` found again at index ``s`` (last trusted ok at ``p``) is not ok, or None:
    "left" when it may have left through the frame's edge (:func:`_leaving`) and
    comes back neither through an edge nor where it left; "ended" when it comes back where another
    object's ok run ended and no ok frame of that object has been there since (this frame included)."""
    near = 0.5 * size
    if _leaving(uv[k], trusted[k], p, size, wh) and not _near_edge(uv[k][s], *wh, size):
        if np.hypot(*(uv[k][s] - uv[k][p])) > near:
            return "left"
    for o in uv:
        if o == k:
            continue
        for e in _run_ends(trusted[o], s):
            if np.hypot(*(uv[o][e] - uv[k][s])) >= near:
                continue
            # the other object ok there now too: the shared-pixels rule (settle_latches) decides
            later = np.flatnonzero(trusted[o][e + 1 : s + 1]) + e + 1
            if not np.any(np.hypot(*(uv[o][later] - uv[k][s]).T) < near):
                return "ended"
    return None


#: The share of an object's own ok frames (before a loss) whose registration quality may lie below
#: the threshold a re-acquisition far out of reach must reach (the low tail: impacts, blur).
REACH_Q_TAIL = 0.01


def _out_of_reach(s, p, uv, ok, q, size) -> bool:
    """Whether a re-acquisition at index ``s`` (last trusted ok at ``p``) is out of the object's
    reach and not confirmed by its view. Out of reach: farther from its last trusted pose than its
    speed there (px per frame, between its last two trusted ok frames) times the gap, plus its
    first region's larger side ``size`` (px): a resting object cannot jump across the frame.
    Not confirmed: the registration quality of that first frame, against the template or keyframe
    the object was last verified with, lies below all but the lowest :data:`REACH_Q_TAIL` of its
    own ok frames before the loss (a pendulum re-found across its swing re-explains its view)."""
    before = np.flatnonzero(ok[: p + 1])
    if before.size < 5 or not np.isfinite(q[s]):
        return False
    v = 0.0
    if before.size >= 2:
        p0 = before[-2]
        v = float(np.hypot(*(uv[p] - uv[p0]))) / (p - p0)
    reach = v * (s - p) + size
    if np.hypot(*(uv[s] - uv[p])) <= reach:
        return False
    q_ok = q[before][np.isfinite(q[before])]
    return bool(q_ok.size >= 5 and q[s] < np.quantile(q_ok, REACH_Q_TAIL))


def settle_reacquisitions(raw, config, plane_map, frames, source, width_px: int, height_px: int) -> None:
    """An object found again after frames it was not ok must be where it can be: one that may
    have left the frame through an edge (its region one step from the border, :func:`_leaving`) comes back through an edge or where it left; one found where another object's ok run
    ended (within half that side), with that object not ok there since, has found the other
    object (identical pucks, balls); one found out of its reach on a patch that does not re-explain
    its view (:func:`_out_of_reach`) has found something else, and so has every later run found
    where that one was (its keyframe learnt the other thing). Else the ok run that starts there,
    and every later one found from the same last trusted pose, is ``latch`` (NaN values), named
    by W-TRACK-LATCH. Tables are left out. Arguments as :func:`settle_latches`."""
    if plane_map is None:
        return
    regions = {o.id: o.roi for o in config.objects if getattr(o, "roi", None) is not None}
    ids = [o.id for o in config.objects if o.kind != "table" and o.id in raw and o.id in regions]
    uv = {k: plane_map.to_image(np.column_stack((raw[k][0]["X"], raw[k][0]["Y"]))) for k in ids}
    trusted = {k: raw[k][1] == "ok" for k in ids}
    for k in ids:
        size = max(float(regions[k][2]), float(regions[k][3]))
        ok = trusted[k]
        starts = np.flatnonzero(ok[1:] & ~ok[:-1]) + 1
        bad, reached = [], []
        for s in starts:
            before = np.flatnonzero(trusted[k][:s])
            if before.size == 0:
                continue
            p = int(before[-1])
            why = _reacquired_wrong(k, int(s), p, uv, trusted, size, (width_px, height_px))
            if why is None and _on_other(k, int(s), p, uv, trusted, regions, size):
                why = "other"
            if why is None and _out_of_reach(int(s), p, uv[k], trusted[k], raw[k][0]["q"], size):
                why = "reach"
            e = s + (int(np.argmin(ok[s:])) if not ok[s:].all() else len(ok) - s)
            if why is None and reached:  # found again where it was followed out of reach: same object
                if np.any(np.hypot(*(uv[k][reached] - uv[k][s]).T) < 0.5 * size):
                    why = "reach"
            if why is None:
                continue
            if why in ("reach", "other"):
                reached.extend(range(s, e))
            _as_latch(raw[k], slice(s, e))
            trusted[k][s:e] = False
            bad.append((why, int(before[-1]), int(s), int(e)))
        if bad:
            why, p, s, _ = bad[0]
            where = {
                "left": "away from the frame's edge where it was last seen leaving (its region one step from the border), not through an edge",
                "ended": "where another object's track ended",
                "reach": "farther than it could move in the gap, its view not confirming it",
                "other": "outside the span of its own track, nearer to where another object is (or was last seen) than to its own last place",
            }[why]
            n = sum(e - s for _, _, s, e in bad)
            warn(
                "W-TRACK-LATCH",
                f"{source}: object {k!r} found again at frame {frames[s]} {where} (last ok at frame {frames[p]}): "
                f"{n} frames from {frames[s]} to {frames[bad[-1][3] - 1]} are status latch, not ok; "
                "its tracker follows something else there",
            )


def settle_latches(raw, config, plane_map, frames, source) -> None:
    """Give pixels two trackers share to one object: where two objects are both ok within
    :func:`latch_distance` of each other, the one whose own track runs on into those frames (its
    pose where they start within that distance of where its ok frames before lead,
    :func:`_entry_miss`) keeps them, and the other's ok frames of the run become ``latch`` (NaN
    values); when both or neither run on (two trackers that drifted together, objects first seen
    there), the one whose template correlates better over the run (median ``quality``) keeps
    them. W-TRACK-LATCH names each run. Tables are left out.

    ``raw``: object id -> ({"X", "Y", "th", "sig", "q", ...} arrays (n,) in plane units,
    statuses (n,), metric), changed in place; ``frames``: the film frame of each index.
    """
    if plane_map is None:
        return
    sides = _first_sides(config)
    # a table's region is a strip round its edge, under the blocks: its point need not keep a size
    # apart from theirs (a table that follows a block turns: _check_latch)
    ids = [o.id for o in config.objects if o.kind != "table" and o.id in raw]
    uv = {k: plane_map.to_image(np.column_stack((raw[k][0]["X"], raw[k][0]["Y"]))) for k in ids}
    for i, a in enumerate(ids):
        for b in ids[i + 1 :]:
            near = latch_distance(sides, a, b)
            for s, e in _shared_runs(uv[a], uv[b], raw[a][1] == "ok", raw[b][1] == "ok", near):
                on = {k: _entry_miss(uv[k], raw[k][1] == "ok", s) < near for k in (a, b)}
                if on[a] != on[b]:
                    lose = b if on[a] else a
                else:
                    both = (raw[a][1][s : e + 1] == "ok") & (raw[b][1][s : e + 1] == "ok")
                    qa, qb = (float(np.median(raw[k][0]["q"][s : e + 1][both])) for k in (a, b))
                    lose = b if qa >= qb else a
                keep = b if lose == a else a
                st = raw[lose][1]
                hit = np.flatnonzero(st[s : e + 1] == "ok") + s
                _as_latch(raw[lose], hit)
                uv[lose][hit] = np.nan
                why = "its track runs on into them" if on[keep] != on[lose] else "its template matches them better"
                warn(
                    "W-TRACK-LATCH",
                    f"{source}: object {lose!r} sits on the pixels of {keep!r} (within {near:.3g} px) from frame "
                    f"{frames[s]} to {frames[e]}: those {hit.size} frames of {lose!r} are status latch; "
                    f"{keep!r} keeps them ({why}); redraw the region of {lose!r}, or track it over the frames it is in view",
                )


def _check_latch(res, path, config=None) -> None:
    """W-TRACK-LATCH when a tracker has latched onto another object: a table that turns (tables
    translate), or two objects whose reference points coincide on more than 10 % of the frames
    both are ``ok`` (closer than 3 px, or than half the smaller side of the smaller of their first
    regions: two objects side by side keep about a size apart)."""
    for t in res.tracks:
        th = t.theta_rad[t.ok]
        if t.kind == "table" and th.size >= 5:
            turn = float(np.percentile(th, 95) - np.percentile(th, 5))
            if turn > TABLE_TURN_MAX_RAD:
                warn(
                    "W-TRACK-LATCH",
                    f"{path}: table {t.object!r} turns by {math.degrees(turn):.4g} deg over the video; "
                    "a table translates: its region or markers probably follow another object",
                )
    sides = _first_sides(config)
    tr = [t for t in res.tracks if t.x_px is not None]
    for i, a in enumerate(tr):
        for b in tr[i + 1 :]:
            both = a.ok & b.ok
            if both.sum() < 5:
                continue
            near = latch_distance(sides, a.object, b.object)
            d = np.hypot(a.x_px[both] - b.x_px[both], a.y_px[both] - b.y_px[both])
            if np.mean(d < near) > 0.1:
                warn(
                    "W-TRACK-LATCH",
                    f"{path}: objects {a.object!r} and {b.object!r} sit within {near:.3g} px of each other "
                    f"on {100 * np.mean(d < near):.3g} % of the frames both are ok; one follows the "
                    "other's target",
                )


def tee(frames, fn):
    for i, g, img in frames:
        fn(i, g, img)
        yield i, g


def interpolate(arrs, status, max_gap):
    """Fill runs of at most ``max_gap`` frames between two ``ok`` frames linearly, in place (each
    array of ``arrs``, shape (n,)); their ``status`` becomes ``"interpolated"``."""
    ok = status == "ok"
    idx = np.flatnonzero(ok)
    if len(idx) < 2:
        return
    for a, b in zip(idx[:-1], idx[1:]):
        if 1 < b - a <= max_gap + 1:
            for arr in arrs:
                arr[a + 1 : b] = np.interp(np.arange(a + 1, b), [a, b], [arr[a], arr[b]])
            status[a + 1 : b] = "interpolated"
