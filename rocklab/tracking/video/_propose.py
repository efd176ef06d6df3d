"""Objects to track proposed from a film without markers: what moves, and the table under it.

A film of rocking blocks without fiducials still says where the blocks are: they move and the
wall behind them does not. Frames sampled over the first seconds are compared with the first
frame; a pixel belongs to a moving object in the first frame when it differs from the first
frame in at least half of the samples in which anything moves (the object has left it, or its
texture has turned over it). The frames' common brightness change is taken out first, so
exposure hunting does not count as motion. Connected regions of that mask, closed over the
texture's gaps and merged when they touch, are the proposals: boxes in first-frame pixels. A
camera that moves (:func:`camera_motion`: the whole picture shifts between the frames compared)
gets no proposal: every pixel changes with it.
Parts thinner than :data:`THIN_PX` (a pendulum's string sweeping the wall) are dropped first,
a merge that would cover most of the frame leaves its parts apart, and a box narrower than the
markerless tracker's smallest region is no proposal. Nor is a box whose own first-frame content stays in
place in the samples (:func:`stays_in_place`): it is mostly still things round a moving part
(a stand round the stick sliding off it), and a tracker would follow the still things. The
first frame is the first of the film's scene: :func:`lead_in` finds blank, fading-in or title
frames before it.

Three movers are proposed as the object rather than as their change (:data:`LATE_SHARE`,
:func:`turning_region`, :func:`without_intruder`): one that starts to move late in the window
(a struck puck), a disc turning on a pin whose outline never moves (only its mark changes), and
an object a hand reaching in from the frame's edge lets go of.

The table is the long straight horizontal edge a block stands on: searched just below each
proposal's bottom, on either side of it, and accepted only when
:func:`~rocklab.tracking.video.targets._table_edge.table_top_edge` follows it over at least
twice the block's width, with a contrast well above the frame's own gradients and a small
angle. A proposal that lies below the table's top edge (the table itself moving on a shake
table) is not a block.

Pure functions on images; ``rocklab track init`` decodes the frames and writes the result.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._camera_motion import CAMERA_PX, CAMERA_SHARE, CAMERA_SPREAD, camera_motion  # noqa: F401 (re-exported)

from ._checks import cut_limit, region_overlap, small_grey

__all__ = [
    "Proposals",
    "propose_objects",
    "moving_boxes",
    "find_table_below",
    "lead_in",
    "camera_motion",
    "WORK_WIDTH_PX",
]

#: Frames are compared at this width at most (px): enough for boxes to a couple of pixels of the
#: full frame, and a 1080p film costs no more than a VGA one.
WORK_WIDTH_PX = 640
#: A pixel moves when it differs from the first frame by this many noise sigmas (and at least
#: ``MIN_DIFF_DN`` grey levels: compression blocks and sensor noise stay below it).
DIFF_SIGMAS = 6.0
MIN_DIFF_DN = 6.0
#: ... in at least this fraction of the samples in which something moves.
MOVING_FRACTION = 0.5
#: A region smaller than this fraction of the frame is noise, one larger than ``MAX_FRACTION``
#: is the whole scene changing (camera moved, light switched), not an object.
MIN_FRACTION = 4e-4
MAX_FRACTION = 0.5
#: When no part reaches ``MIN_FRACTION``, parts down to ``LONE_FRACTION`` of the frame are the
#: movers: the floor keeps specks out among larger movers (a string's top, a clock's needle, bits of a
#: cart's wheels on 9 real films at 1.5e-4-4e-4 of the frame), but a film whose one mover is a small bob (a 25 px
#: motion-blurred bob on a 1280 px frame leaves 86 px of 92 at the working width) has nothing else to
#: propose.
LONE_FRACTION = 2e-4
#: An object shows an outline or texture in the first frame: the 95th percentile of the gradient
#: inside its region is at least this many times the frame's median gradient (a soft shadow
#: sweeping the wall changes as much as an object but has neither).
MIN_STRUCTURE = 10.0
#: A table's top edge: its mean vertical gradient (Sobel, smoothed along the rows) at least this
#: many times the frame's median and at least ``MIN_EDGE`` (a 4 grey-level step); rendered tables
#: give 72-168, a lighting gradient on a plain wall 1.2.
EDGE_CONTRAST = 20.0
MIN_EDGE = 16.0
#: Gaps closed inside a region, and regions merged, within this fraction of the frame's short side.
CLOSE_FRACTION = 0.02
#: Moving parts thinner than this (px at the working width, after the 1 px blur and the closing
#: of gaps) are not objects.
THIN_PX = 5
#: Smallest side of a proposal, px of the full frame: the markerless tracker's smallest region.
MIN_SIDE_PX = 8


#: Lead-in frames before the film's own scene: a frame whose grey levels spread by less than
#: ``BLANK_STD_DN`` is blank (black, white, one colour); one whose spread is under ``FADE_RATIO``
#: of the scene's is still fading in; a cut (:func:`~._checks.cut_limit`) within ``CUT_WINDOW_S``
#: of the start ends a title card or another shot.
BLANK_STD_DN = 2.0
FADE_RATIO = 0.5
CUT_WINDOW_S = 1.0


def lead_in(grays, fps: float) -> tuple[int, str]:
    """Frames at the start of a film that are not its scene: ``(n, what)``, the index of the first
    frame of the scene in ``grays`` and what comes before it (``""`` when nothing does).

    Parameters
    ----------
    grays : sequence of ndarray (H, W) uint8
        The film's first frames, consecutive (a couple of seconds).
    fps : float
        Their rate, frames/s (a cut is looked for in the first :data:`CUT_WINDOW_S`).

    Returns
    -------
    (int, str)
        ``what`` is ``"blank"`` (frames of one grey level: black, white), ``"fade-in"`` (frames
        whose contrast is still rising to the scene's) or ``"cut"`` (a title card or another
        shot, ended by a cut).
    """
    small = [small_grey(g) for g in grays]
    if len(small) < 3:
        return 0, ""
    std = np.array([float(s.std()) for s in small])
    if np.all(std < BLANK_STD_DN):
        return 0, ""  # a film of one colour is refused elsewhere; there is no scene to start at
    k = int(np.argmax(std >= BLANK_STD_DN))
    what = "blank" if k else ""
    scene = float(np.median(std[k:]))
    while k < len(small) - 1 and std[k] < FADE_RATIO * scene:
        k, what = k + 1, "fade-in"
    step = np.array([float(np.mean(np.abs(a - b))) for a, b in zip(small[k:-1], small[k + 1 :])])
    if step.size >= 3:
        limit = cut_limit(step)
        n_win = max(1, int(round(CUT_WINDOW_S * fps)))
        cuts = np.flatnonzero(step[:n_win] > limit)
        if cuts.size:
            k, what = k + int(cuts[-1]) + 1, what or "cut"
    return k, what


@dataclass(frozen=True)
class Proposals:
    """What :func:`propose_objects` found.

    Attributes
    ----------
    blocks : tuple of (x, y, w, h)
        Boxes round the moving objects in the first frame, px (full frame), left to right.
    table : (x, y, w, h) or None
        A region round the table's top edge (for a markerless ``table`` object), px.
    table_moves : bool
        More than a fifth of the table's region changes in some sample (a shake table): the table is an object
        to track, not only a level line.
    table_edge : TopEdge or None
        The edge found there (angle, 1-sigma, the span followed).
    n_samples, n_moving : int
        Frames compared with the first, and those in which something moved.
    still : tuple of ((x, y, w, h), float, float)
        Boxes round something that moves whose own content stays in place (:func:`stays_in_place`):
        the box, the share of the samples in which it did, its median correlation there. Not
        proposed: a tracker would follow the still things in them.
    turning : tuple of (x, y, w, h)
        The blocks that are discs turning on a pin (:func:`turning_region`): only their mark moves.
    camera : (float, float)
        :func:`camera_motion` of the frames compared: the share of consecutive pairs in which the
        whole picture moved, and the median motion (px); from :data:`CAMERA_SHARE` on nothing is
        proposed (the camera moves).
    """

    blocks: tuple
    table: tuple | None
    table_edge: object | None
    table_moves: bool
    n_samples: int
    n_moving: int
    still: tuple = ()
    camera: tuple = (0.0, 0.0)
    turning: tuple = ()

    @property
    def camera_moves(self) -> bool:
        """Whether the camera moves over the frames compared (nothing is proposed then)."""
        return self.camera[0] >= CAMERA_SHARE


def prepare_frame(gray, scale):
    """``gray`` as the proposals compare frames: resized by ``scale`` (area), float32, blurred by a
    1 px Gaussian."""
    import cv2

    g = gray if scale == 1.0 else cv2.resize(gray, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
    return cv2.GaussianBlur(g.astype(np.float32), (0, 0), 1.0)


def changed_pixels(a, b):
    """Pixels that changed from ``b`` to ``a`` (float images of :func:`prepare_frame`): the difference,
    its median (a global change of light) taken out, over :data:`DIFF_SIGMAS` times its own robust
    noise (median / 0.954), at least :data:`MIN_DIFF_DN`; bool, the images' shape."""
    d = a - b
    d = np.abs(d - float(np.median(d)))
    return d > max(DIFF_SIGMAS * float(np.median(d)) / 0.954, MIN_DIFF_DN)


def _box_gap(a, b) -> float:
    """Distance between two boxes (x, y, w, h), px; 0 when they touch or overlap."""
    dx = max(a[0] - (b[0] + b[2]), b[0] - (a[0] + a[2]), 0.0)
    dy = max(a[1] - (b[1] + b[3]), b[1] - (a[1] + a[3]), 0.0)
    return math.hypot(dx, dy)


def _merge(boxes, joined):
    """Boxes (x, y, w, h) with every pair ``joined(a, b)`` says belongs together replaced by their
    union, until no such pair is left."""
    boxes = [tuple(float(v) for v in b) for b in boxes]
    merged = True
    while merged:
        merged = False
        for i in range(len(boxes)):
            for j in range(i + 1, len(boxes)):
                if joined(boxes[i], boxes[j]):
                    a, b = boxes[i], boxes.pop(j)
                    x0, y0 = min(a[0], b[0]), min(a[1], b[1])
                    x1, y1 = max(a[0] + a[2], b[0] + b[2]), max(a[1] + a[3], b[1] + b[3])
                    boxes[i] = (x0, y0, x1 - x0, y1 - y0)
                    merged = True
                    break
            if merged:
                break
    return boxes


#: An object that starts to move late in the window (a puck at rest until another strikes it) has
#: left its place in fewer than half the samples: a pixel changed in at least ``LATE_SHARE`` of
#: them also moves when it changed in at least ``LATE_STAY`` of the samples from the first in
#: which it changed (it left for good; an edge a late jitter of the picture shakes comes and goes).
LATE_SHARE = 0.25
LATE_STAY = 0.9
#: Such a late mover is proposed only apart from the others (late pixels never join parts), at
#: most this share of the frame, and
#: when its first-frame look is found elsewhere in the last sample (it moved, the light did not
#: change over it).
LATE_FRACTION = 0.05


def _moved_off(moving) -> tuple[np.ndarray, np.ndarray]:
    """Pixels (bool, shape of a mask) that changed in at least :data:`MOVING_FRACTION` of the
    masks ``moving`` (bool, in time order), and those that changed in :data:`LATE_SHARE` of them
    and :data:`LATE_STAY` of those from the first in which they changed."""
    stack = np.asarray(moving, dtype=bool)
    n = stack.shape[0]
    count = stack.sum(axis=0)
    since = n - np.argmax(stack, axis=0)
    return count >= MOVING_FRACTION * n, (count >= LATE_SHARE * n) & (count >= LATE_STAY * since)


def _parts(mask, k, grad, floor, min_fraction=MIN_FRACTION) -> list:
    """Boxes (x, y, w, h px) of the parts of ``mask`` (bool): gaps of ``k`` px closed, parts thinner
    than :data:`THIN_PX`, smaller than ``min_fraction`` of it or without outline or texture (95th
    percentile of ``grad`` under ``floor``) dropped."""
    import cv2

    mask = cv2.morphologyEx(mask.astype(np.uint8), cv2.MORPH_OPEN, np.ones((3, 3), np.uint8))
    mask = cv2.morphologyEx(mask, cv2.MORPH_CLOSE, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k, k)))
    # what is thinner than THIN_PX once the texture's gaps are closed is no object to track: a
    # pendulum's string (it sweeps the wall, and merged with its bob it made the proposal a box
    # from the pivot to the bob, mostly still wall)
    mask = cv2.morphologyEx(mask, cv2.MORPH_OPEN, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (THIN_PX, THIN_PX)))
    n, labels, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
    return [
        tuple(stats[i, :4])
        for i in range(1, n)
        if stats[i, 4] >= min_fraction * mask.size and np.percentile(grad[labels == i], 95) >= floor
    ]


def _edges(img, box) -> float:
    """Mean gradient magnitude of ``img`` (working grey) in ``box`` (working px): an object that
    left its place shows a plainer background there than its own outline; one that came to
    stand there (a cart pushed onto a bare track) shows more."""
    import cv2

    x, y, w, h = (int(v) for v in box)
    a = img[y : y + h, x : x + w]
    return float(np.mean(cv2.magnitude(cv2.Sobel(a, cv2.CV_32F, 1, 0), cv2.Sobel(a, cv2.CV_32F, 0, 1))))


def _found_elsewhere(f0, last, box) -> bool:
    """Whether the first frame's content of ``box`` (working px) is in ``last`` (working grey)
    with a correlation of at least :data:`IN_PLACE_CC`, moved by at least half its smaller side."""
    import cv2

    x, y, w, h = (int(v) for v in box)
    tmpl = f0[y : y + h, x : x + w]
    if float(tmpl.std()) < 1e-3:
        return False
    _, cc, _, at = cv2.minMaxLoc(cv2.matchTemplate(last, tmpl, cv2.TM_CCOEFF_NORMED))
    return cc >= IN_PLACE_CC and math.hypot(at[0] - x, at[1] - y) >= 0.5 * min(w, h)


def _with_late(f0, last, main, both, gap) -> list:
    """The parts ``main`` with the late movers: a part of ``both`` (main and late pixels) holding
    no main part, more than ``gap`` px from every one, of at most :data:`LATE_FRACTION` of the
    frame, whose first-frame look is found elsewhere in ``last`` and whose place there is plainer
    than it was (:func:`_edges`: it left, nothing came); a part that grew round main parts stays
    those parts: late pixels do not join things."""
    late = [
        u
        for u in both
        if not any(region_overlap(m, u)[0] > 0 for m in main)
        and all(_box_gap(u, m) > gap for m in main)
        and u[2] * u[3] <= LATE_FRACTION * f0.size
        and _found_elsewhere(f0, last, u)
        and _edges(f0, u) > _edges(last, u)
    ]
    return list(main) + late


def moving_boxes(first_gray, samples, masks: bool = False) -> tuple[list, int]:
    """Boxes round what moves, where it is in the first frame.

    Parameters
    ----------
    first_gray : ndarray (H, W) uint8
    samples : sequence of ndarray (H, W) uint8
        Later frames (a few dozen spread over the first seconds).

    masks : bool
        Return ``(changed, scale)`` instead: per sample in which something moves, the pixels that
        differ from the first frame (bool), at ``scale`` times the frame's size.

    Returns
    -------
    (boxes, n_moving)
        ``boxes``: (x, y, w, h) px of the full frame, left to right; ``n_moving``: samples in
        which something moved.
    """
    import cv2

    H, W = first_gray.shape[:2]
    scale = min(1.0, WORK_WIDTH_PX / W)
    f0 = prepare_frame(first_gray, scale)
    diffs = []
    for s in samples:
        d = prepare_frame(s, scale) - f0
        diffs.append(np.abs(d - float(np.median(d))))
    if not diffs:
        return ([], scale) if masks else ([], 0)
    # static pixels dominate every difference: their median is the noise (|N(0, s sqrt 2)| median
    # = 0.954 s)
    sigma = float(np.median([np.median(d) for d in diffs])) / 0.954
    thr = max(DIFF_SIGMAS * sigma, MIN_DIFF_DN)
    n_px = f0.size
    moving = [m for m in (d > thr for d in diffs) if m.sum() >= MIN_FRACTION * n_px]
    if masks:
        return moving, scale
    if not moving:
        return [], 0
    main, late = _moved_off(moving)
    k = max(3, int(round(CLOSE_FRACTION * min(f0.shape))) | 1)
    grad = cv2.magnitude(cv2.Sobel(f0, cv2.CV_32F, 1, 0), cv2.Sobel(f0, cv2.CV_32F, 0, 1))
    floor = MIN_STRUCTURE * (float(np.median(grad)) + 1e-3)
    last = prepare_frame(samples[-1], scale)
    boxes = _with_late(f0, last, _parts(main, k, grad, floor), _parts(main | late, k, grad, floor), k)
    if not boxes:  # nothing larger moves: a small lone mover is the object (LONE_FRACTION)
        boxes = _parts(main, k, grad, floor, LONE_FRACTION)
    merged = []
    for m in _merge(boxes, lambda a, b: _box_gap(a, b) <= k):
        if m[2] * m[3] <= MAX_FRACTION * n_px:
            merged.append(m)
        else:  # neighbours merged into most of the frame: each part is a proposal of its own
            merged += [b for b in boxes if _box_gap(b, m) == 0.0 and b[2] * b[3] <= MAX_FRACTION * n_px]
    out = []
    for x, y, w, h in merged:
        # back to full-frame pixels, out to the outer edge of the last pixel, inside the frame
        x0, y0 = max(0.0, x / scale), max(0.0, y / scale)
        x1, y1 = min(float(W), (x + w) / scale), min(float(H), (y + h) / scale)
        if min(x1 - x0, y1 - y0) < MIN_SIDE_PX:
            continue
        out.append(tuple(float(round(v)) for v in (x0, y0, x1 - x0, y1 - y0)))
    return sorted(out), len(moving)


#: A mark turning on a disc: the mark moves, the disc's outline does not, so only the mark's
#: first place is a proposal. Round a proposal, the first frame's region of one grey level (within
#: ``TURN_GREY_DN`` of the grey just outside the proposal) is the object carrying it when that
#: region is bounded (inside the frame, at most :data:`MAX_FRACTION` of it, at least
#: ``TURN_AREA`` times the proposal), its outline stays in place (at most ``TURN_EDGE_MOVES`` of
#: it changes), and what changes inside it keeps one distance from its centre (a mark turning
#: round a pin there: the distances' quartiles within ``TURN_RING`` of their median, which is
#: at least ``TURN_RADIUS`` of the region's radius). A block moving over a panel behind it fails
#: the last test, a ball on a wall the first.
TURN_GREY_DN = 14.0
TURN_AREA = 6.0
TURN_EDGE_MOVES = 0.2
TURN_RING = 0.2
TURN_RADIUS = 0.3


def turning_region(first_gray, changed, scale, box):
    """The box (x, y, w, h px, full frame) of the object a moving ``box`` turns on (a disc that a
    mark turns with, its outline still), or None; see :data:`TURN_GREY_DN`. ``changed, scale``:
    :func:`moving_boxes` with ``masks=True``."""
    import cv2

    if not changed:
        return None
    f0 = prepare_frame(first_gray, scale)
    h, w = f0.shape
    x, y, bw, bh = (int(round(v * scale)) for v in box)
    pad = max(2, int(round(0.25 * max(bw, bh))))
    x0, y0, x1, y1 = max(x - pad, 0), max(y - pad, 0), min(x + bw + pad, w), min(y + bh + pad, h)
    ring = np.ones((y1 - y0, x1 - x0), bool)
    ring[y - y0 : y - y0 + bh, x - x0 : x - x0 + bw] = False
    grey = f0[y0:y1, x0:x1][ring]
    if grey.size == 0:
        return None
    level = float(np.median(grey))
    vs, us = np.nonzero(ring & (np.abs(f0[y0:y1, x0:x1] - level) <= 2.0))
    if not vs.size:
        return None
    mask = np.zeros((h + 2, w + 2), np.uint8)
    flags = 8 | cv2.FLOODFILL_FIXED_RANGE | cv2.FLOODFILL_MASK_ONLY | (1 << 8)
    cv2.floodFill(f0.copy(), mask, (int(us[0] + x0), int(vs[0] + y0)), 0, TURN_GREY_DN, TURN_GREY_DN, flags)
    region = mask[1:-1, 1:-1]
    cnts, _ = cv2.findContours(region, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    if not cnts:
        return None
    c = max(cnts, key=cv2.contourArea)
    filled = np.zeros_like(region)
    cv2.drawContours(filled, [c], -1, 1, -1)
    rx, ry, rw, rh = cv2.boundingRect(c)
    area = float(filled.sum())
    if rx == 0 or ry == 0 or rx + rw == w or ry + rh == h or not TURN_AREA * bw * bh <= area <= MAX_FRACTION * h * w:
        return None
    if not (rx <= x and ry <= y and x + bw <= rx + rw and y + bh <= ry + rh):
        return None
    moved = np.logical_or(*_moved_off(changed))
    edge = c.reshape(-1, 2)
    if float(moved[edge[:, 1], edge[:, 0]].mean()) > TURN_EDGE_MOVES:
        return None
    # inside, away from the outline (it may wobble a little as the disc turns)
    k = max(3, int(round(0.1 * math.sqrt(area))))
    inner = cv2.erode(filled, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k, k))).astype(bool)
    vv, uu = np.nonzero(np.any(changed, axis=0) & inner)
    if vv.size < 0.5 * bw * bh:
        return None
    m = cv2.moments(filled, binaryImage=True)
    cx, cy = m["m10"] / m["m00"], m["m01"] / m["m00"]
    r = np.hypot(uu - cx, vv - cy)
    q1, med, q3 = np.percentile(r, [25, 50, 75])
    if med < TURN_RADIUS * math.sqrt(area / math.pi) or max(med - q1, q3 - med) > TURN_RING * med:
        return None
    H, W = first_gray.shape[:2]
    bx0, by0 = max(0.0, (rx - 1) / scale), max(0.0, (ry - 1) / scale)
    bx1, by1 = min(float(W), (rx + rw + 1) / scale), min(float(H), (ry + rh + 1) / scale)
    return tuple(float(round(v)) for v in (bx0, by0, bx1 - bx0, by1 - by0))


#: A proposal that reaches the frame's edge may hold a hand or an arm reaching in with the object
#: (it releases it, then leaves the frame). Late in the window, between samples ``LEFT_LAG`` apart,
#: what still moves and is clear of the frame's edge is the object; its look there, found in the
#: first frame inside the proposal with a normalised correlation of at least ``LEFT_CC``, is the
#: proposal instead, when that is at most ``LEFT_AREA`` of the proposal's area.
LEFT_LAG = 3
LEFT_CC = 0.6
LEFT_AREA = 0.8
#: ... and at least this share of it (the object is no speck of the proposal: a corner of a puck
#: the frame's edge cuts is no object let go of).
LEFT_MIN_AREA = 0.15


def touches_edge(box, shape) -> bool:
    """Whether ``box`` (x, y, w, h px) reaches an edge of a frame of ``shape`` (H, W)."""
    x, y, w, h = box
    return x <= 0 or y <= 0 or x + w >= shape[1] or y + h >= shape[0]


def without_intruder(first_gray, samples, box):
    """``box`` without the hand or arm that reaches into it from the frame's edge (the object
    alone, where it is in the first frame), or None; see :data:`LEFT_LAG`."""
    import cv2

    scale = min(1.0, WORK_WIDTH_PX / first_gray.shape[1])
    f0 = prepare_frame(first_gray, scale)
    h, w = f0.shape
    bx, by, bw, bh = (v * scale for v in box)
    prep = [prepare_frame(s, scale) for s in samples]
    k_close = max(3, int(round(CLOSE_FRACTION * min(h, w))) | 1)
    for k in range(len(prep) - 1, max(LEFT_LAG, len(prep) // 2) - 1, -1):
        m = cv2.morphologyEx(
            changed_pixels(prep[k], prep[k - LEFT_LAG]).astype(np.uint8), cv2.MORPH_OPEN, np.ones((3, 3), np.uint8)
        )
        m = cv2.morphologyEx(m, cv2.MORPH_CLOSE, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k_close, k_close)))
        n, _, stats, _ = cv2.connectedComponentsWithStats(m, connectivity=8)
        parts = [
            tuple(int(v) for v in stats[i, :4])
            for i in range(1, n)
            if stats[i, 4] >= MIN_FRACTION * h * w
            and min(stats[i, 2], stats[i, 3]) >= 2 * THIN_PX
            and not touches_edge(stats[i, :4], (h, w))
        ]
        if not parts:
            continue
        px, py, pw, ph = min(parts, key=lambda p: _box_gap(p, (bx, by, bw, bh)))
        tmpl = prep[k][py : py + ph, px : px + pw]
        u0, v0 = int(max(bx - pw // 2, 0)), int(max(by - ph // 2, 0))
        area = f0[v0 : int(min(by + bh + ph // 2, h)), u0 : int(min(bx + bw + pw // 2, w))]
        if area.shape[0] < ph or area.shape[1] < pw or float(tmpl.std()) < 1e-3:
            return None
        _, cc, _, at = cv2.minMaxLoc(cv2.matchTemplate(area, tmpl, cv2.TM_CCOEFF_NORMED))
        found = (at[0] + u0, at[1] + v0, pw, ph)
        if cc < LEFT_CC or not LEFT_MIN_AREA * bw * bh <= pw * ph <= LEFT_AREA * bw * bh:
            return None
        if region_overlap(found, (bx, by, bw, bh))[0] < 0.9 * pw * ph:
            return None  # not the object let go of: that is inside the proposal
        return tuple(float(round(v / scale)) for v in found)
    return None


#: A box "stays in place" when the first frame's content of it matches a sample best within
#: ``IN_PLACE_PX`` (working pixels) of where it was in at least ``IN_PLACE_SHARE`` of the samples,
#: with a median correlation of at least ``IN_PLACE_CC``: the still things in it outweigh what
#: moves (a launcher's stand round the stick that slides off it; measured on the real films: 0.87
#: for that stand, 0.06-0.34 of the samples in place for a pendulum's ball, pucks, carts and the
#: rendered rocking blocks).
IN_PLACE_PX = 1.5
IN_PLACE_SHARE = 0.9
IN_PLACE_CC = 0.7


def stays_in_place(first_gray, samples, box) -> tuple[bool, float, float]:
    """Whether the first frame's content of ``box`` (x, y, w, h px) stays where it is in the
    ``samples``: (verdict, share of samples with the best match in place, median correlation of
    the best matches). Searched within half the box's larger side round it, at the working width."""
    import cv2

    scale = min(1.0, WORK_WIDTH_PX / first_gray.shape[1])
    f0 = prepare_frame(first_gray, scale)
    x, y, w, h = (int(round(v * scale)) for v in box)
    tmpl = f0[y : y + h, x : x + w]
    if not samples or min(tmpl.shape) < 3 or float(tmpl.std()) < 1e-3:
        return False, 0.0, 0.0
    m = max(w, h) // 2
    u0, v0 = max(x - m, 0), max(y - m, 0)
    shifts, ccs = [], []
    for smp in samples:
        area = prepare_frame(smp, scale)[v0 : y + h + m, u0 : x + w + m]
        _, cc, _, at = cv2.minMaxLoc(cv2.matchTemplate(area, tmpl, cv2.TM_CCOEFF_NORMED))
        shifts.append(math.hypot(at[0] + u0 - x, at[1] + v0 - y))
        ccs.append(cc)
    share = float(np.mean(np.asarray(shifts) <= IN_PLACE_PX))
    cc = float(np.median(ccs))
    return share >= IN_PLACE_SHARE and cc >= IN_PLACE_CC, share, cc


def find_table_below(first_gray, box):
    """A table's top edge just below the block ``box`` (x, y, w, h px): ``(roi, TopEdge)`` or None.

    The edge is searched in rows within 15 % of the block's height of its bottom, beside the block
    (the wider side), the topmost row at least half as strong as the strongest; accepted when followed over at least twice the block's
    width, at less than 10 degrees, with a contrast of at least :data:`EDGE_CONTRAST` times the
    frame's median vertical gradient and :data:`MIN_EDGE`.
    """
    import cv2

    from ._camera_model import PlaneMap
    from .targets._table_edge import BLUR_PX, table_top_edge

    H, W = first_gray.shape[:2]
    x, y, w, h = box
    gy = cv2.blur(cv2.Sobel(first_gray.astype(np.float32), cv2.CV_32F, 0, 1, ksize=3), (BLUR_PX, 1))
    noise = float(np.median(np.abs(gy))) + 1e-3
    v_lo, v_hi = int(max(y + 0.85 * h, 1)), int(min(y + 1.15 * h, H - 2))
    if v_hi - v_lo < 3:
        return None
    sides = [(int(max(x - 2 * w, 0)), int(x)), (int(x + w), int(min(x + 3 * w, W)))]
    u0, u1 = max(sides, key=lambda s: s[1] - s[0])
    if u1 - u0 < max(0.5 * w, 10):
        return None
    prof = np.abs(gy[v_lo:v_hi, u0:u1]).mean(axis=1)
    v_edge = v_lo + int(np.argmax(prof >= 0.5 * prof.max()))
    if prof.max() < max(EDGE_CONTRAST * noise, MIN_EDGE):
        return None
    pad = max(4, int(round(0.05 * h)))
    depth = max(2 * pad, int(round(0.3 * h)))
    roi = (float(u0), float(max(v_edge - pad, 0)), float(u1 - u0), float(min(depth, H - max(v_edge - pad, 0))))
    edge = table_top_edge(first_gray, roi, PlaneMap(W, H), follow=True)
    if edge is None or edge.u_span_px[1] - edge.u_span_px[0] < 2 * w or abs(edge.angle_rad) > math.radians(10):
        return None
    return roi, edge


def _refine(first_gray, samples, boxes) -> tuple[list, list]:
    """Each moving box as the object it belongs to: (boxes, turning objects). A mark's box becomes
    the disc it turns on (:func:`turning_region`), a box reaching the frame's edge the object a
    hand reaching in let go of (:func:`without_intruder`); boxes inside a turning object are part
    of it."""
    if not boxes:
        return boxes, []
    changed, scale = moving_boxes(first_gray, samples, masks=True)
    out, turners = [], []
    for b in boxes:
        t = turning_region(first_gray, changed, scale, b)
        if t is not None:
            turners.append(t)
            continue
        if touches_edge(b, first_gray.shape[:2]):
            b = without_intruder(first_gray, samples, b) or b
        out.append(b)
    inside = [b for b in out if any(region_overlap(b, t)[0] >= 0.5 * b[2] * b[3] for t in turners)]
    return [b for b in out if b not in inside], _merge(turners, lambda a, b: region_overlap(a, b)[1])


def propose_objects(first_gray, samples) -> Proposals:
    """Blocks (what moves) and the table (the edge they stand on) from the first frame and later
    samples; see the module docstring.

    Parameters
    ----------
    first_gray : ndarray (H, W) uint8
    samples : sequence of ndarray (H, W) uint8

    Returns
    -------
    Proposals
    """
    share, shift = camera_motion([first_gray, *samples])
    if share >= CAMERA_SHARE:  # every pixel moves with the camera: what differs is no object
        return Proposals((), None, None, False, len(samples), 0, camera=(share, shift))
    boxes, n_moving = moving_boxes(first_gray, samples)
    boxes, turners = _refine(first_gray, samples, boxes)
    # a box round something that moves but mostly of still things is no object to track: the
    # tracker follows the still things (a stand, the wall), and reports a still "object" as ok.
    # A turning disc stays in place by its outline, and is the object.
    verdicts = [stays_in_place(first_gray, samples, b) for b in boxes]
    still = tuple((b, share, cc) for b, (yes, share, cc) in zip(boxes, verdicts) if yes)
    boxes = sorted([b for b, v in zip(boxes, verdicts) if not v[0]] + turners)
    table = edge = None
    moves = False
    for b in boxes:
        found = find_table_below(first_gray, b)
        if found is not None:
            table, edge = found
            break
    if edge is not None:
        # what lies below the table's top (the table itself on a shake table) is no block, and a
        # block's box stops at the table's top
        (ua, va), (ub, vb) = edge.ends_px

        def top_at(u):
            return va + (vb - va) * (u - ua) / max(ub - ua, 1e-9)

        kept = []
        for x, y, w, h in boxes:
            v_top = max(top_at(x), top_at(x + w))
            h = float(min(y + h, math.ceil(v_top + 2)) - y)
            if y >= v_top - 2 or h < MIN_SIDE_PX:
                continue
            kept.append((x, y, w, h))
        boxes = kept
        # a shake table moves and comes back: changed in any sample, not in most
        changed, scale = moving_boxes(first_gray, samples, masks=True)
        x, y, w, h = (int(round(v * scale)) for v in table)
        moves = any(float(m[y : y + max(h, 1), x : x + max(w, 1)].mean()) > 0.2 for m in changed)
    # padded boxes of two moving things may overlap more than track init lets two regions: they
    # become one proposal (the user sees it drawn and may split it), never a refused config
    boxes = _merge(boxes, lambda a, b: region_overlap(a, b)[1])
    if moves:  # the table is an object of its own: a block's box stops above the table's region
        boxes = [
            b if not region_overlap(b, table)[1] else (b[0], b[1], b[2], float(table[1] - b[1]))
            for b in boxes
            if not region_overlap(b, table)[1] or table[1] - b[1] >= MIN_SIDE_PX
        ]
    turning = tuple(b for b in boxes if b in turners)
    return Proposals(tuple(boxes), table, edge, moves, len(samples), n_moving, still, turning=turning)
