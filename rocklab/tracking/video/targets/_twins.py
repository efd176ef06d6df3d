"""Look-alikes: which of two objects that look the same (identical pucks, balls) a tracker has found
again after frames it lost its own, told by how both moved before the loss.

Appearance cannot tell two white pucks with two dark dots apart: a tracker that loses its puck at
a collision re-finds whichever matches its template better, often the other one (a puck at rest
matches a keyframe better than a spinning one). So a re-acquisition is judged, when another match
of similar correlation lies within the object's reach, by continuity: the object and its look-alike
(the nearest such match in the last verified frame) are carried on from their last two verified
frames at constant velocity, or, when they touched in the last one (centres closer than
:data:`CONTACT_SIZES` region sizes), through an elastic collision of equal masses (the velocity
components along the line of centres are exchanged: momentum passes to the struck one). The
assignment of the two matches found now to the two predictions that misses by less (by
:data:`PICK_MARGIN_SIZES` of the region's larger side) picks the object; where neither does, the
frame is not trusted (status ``twin``).
"""

from __future__ import annotations

import collections
import math

import numpy as np

__all__ = ["TwinGuard", "match_peaks", "TWIN_CC_GAP"]

#: A match whose correlation is within this of the best one near the object looks alike (the
#: spinning striker 0.86-0.93 and the resting puck 0.88-0.98 against either's template on
#: CaromPuck/Rotation; the next best patch there, a lamp's reflection, 0.76 and out of reach).
TWIN_CC_GAP = 0.1
#: Turns of the template tried for a look-alike, degrees (a look-alike may be turned any way).
TWIN_TURNS_DEG = tuple(range(0, 360, 15))
#: The template is matched at most this many px across (a reduced copy of the frame beyond it).
TWIN_TEMPLATE_PX = 24.0
#: Two objects whose centres are closer than this many region sizes in the last verified frame
#: may have struck each other in the gap (two touching pucks: 1.0-1.1).
CONTACT_SIZES = 1.5
#: One assignment of the two matches to the two predictions wins when it misses by less than the
#: other by this share of the region's larger side (summed over both objects).
PICK_MARGIN_SIZES = 0.5


def match_peaks(gray, tmpl, centre, radius, turns_deg=TWIN_TURNS_DEG) -> list:
    """Matches of ``tmpl`` (float32, (h, w)), turned by each of ``turns_deg``, whose centres lie
    within ``radius`` px (a square) of ``centre`` (x, y px) in ``gray``: a list of (correlation,
    centre (2,) px, turn rad), best first, each a local maximum at least half the template's
    smaller side from a better one."""
    import cv2

    h, w = tmpl.shape
    f = min(1.0, TWIN_TEMPLATE_PX / max(w, h))
    H, W = gray.shape
    x0, y0 = int(max(centre[0] - radius - w, 0)), int(max(centre[1] - radius - h, 0))
    x1, y1 = int(min(centre[0] + radius + w, W)), int(min(centre[1] + radius + h, H))
    if x1 - x0 <= w or y1 - y0 <= h:
        return []
    win = gray[y0:y1, x0:x1].astype(np.float32)
    t = tmpl.astype(np.float32)
    if f < 1.0:
        win = cv2.resize(win, None, fx=f, fy=f, interpolation=cv2.INTER_AREA)
        t = cv2.resize(t, None, fx=f, fy=f, interpolation=cv2.INTER_AREA)
    hs, ws = t.shape
    if win.shape[0] <= hs or win.shape[1] <= ws:
        return []
    best, turn = None, None
    for deg in turns_deg:
        rot = cv2.warpAffine(
            t, cv2.getRotationMatrix2D((ws / 2, hs / 2), -deg, 1.0), (ws, hs), borderMode=cv2.BORDER_REPLICATE
        )
        r = cv2.matchTemplate(win, rot, cv2.TM_CCOEFF_NORMED)
        if best is None:
            best, turn = r, np.full(r.shape, math.radians(deg))
        else:
            up = r > best
            best, turn = np.where(up, r, best), np.where(up, math.radians(deg), turn)
    out = []
    sup = max(1, int(0.5 * min(hs, ws)))
    r = best.copy()
    for _ in range(4):
        _, val, _, (lx, ly) = cv2.minMaxLoc(r)
        if val <= 0:
            break
        c = np.array([x0 + (lx + ws / 2) / f, y0 + (ly + hs / 2) / f])
        out.append((float(val), c, float(turn[ly, lx])))
        r[max(ly - sup, 0) : ly + sup + 1, max(lx - sup, 0) : lx + sup + 1] = -1.0
    return out


def _similar(peaks, min_cc, top=None) -> list:
    """The peaks of :func:`match_peaks` whose correlation is within :data:`TWIN_CC_GAP` of ``top``
    (default: the best of them)."""
    if not peaks:
        return []
    top = peaks[0][0] if top is None else top
    return [p for p in peaks if p[0] >= max(min_cc, top - TWIN_CC_GAP)]


def _collide(ck, vk, co, vo, touch_px):
    """Velocities after the gap of two equal masses at ``ck``, ``co`` moving at ``vk``, ``vo``: an
    elastic collision along their line of centres when they touch (closer than ``touch_px``) and
    approach, else unchanged."""
    d = co - ck
    n = float(np.hypot(*d))
    if n >= touch_px or n == 0.0:
        return vk, vo
    e = d / n
    closing = float((vk - vo) @ e)
    if closing <= 0.0:
        return vk, vo
    return vk - closing * e, vo + closing * e


class TwinGuard:
    """One tracked object's last two verified frames, to judge a re-acquisition beside a look-alike.

    Parameters
    ----------
    size : (w, h)
        The object's template, px.
    """

    def __init__(self, size):
        self.size = float(max(size))
        self.seen: collections.deque = collections.deque(maxlen=2)  # (frame, grey copy, centre px)

    def remember(self, frame: int, gray, centre) -> None:
        """A verified frame: its grey image and the object's centre (px) there."""
        self.seen.append((int(frame), np.array(gray), np.asarray(centre, float)))

    def _own(self):
        """(frame, centre px, velocity px/frame) of the object at its last verified frame."""
        p, _, c_p = self.seen[-1]
        if len(self.seen) < 2:
            return p, c_p, np.zeros(2)
        p0, _, c0 = self.seen[0]
        return p, c_p, (c_p - c0) / max(p - p0, 1)

    def _lookalike(self, tmpl, radius, min_cc, top):
        """(centre px, velocity px/frame) of the object's nearest look-alike at its last verified
        frame, or None: a match within :data:`TWIN_CC_GAP` of ``top``, the best correlation now (the
        template is often cut from that frame: its own match there is 1)."""
        p, g_p, c_p = self.seen[-1]
        half = 0.5 * self.size
        peaks = _similar(match_peaks(g_p, tmpl, c_p, radius), min_cc, top)
        others = [q[1] for q in peaks if np.hypot(*(q[1] - c_p)) > half]
        if not others:
            return None
        o_p = min(others, key=lambda c: float(np.hypot(*(c - c_p))))
        v_o = np.zeros(2)
        if len(self.seen) == 2:
            p0, g0, c0 = self.seen[0]
            peaks = _similar(match_peaks(g0, tmpl, o_p, self.size), 0.0, top)
            before = [q[1] for q in peaks if np.hypot(*(q[1] - c0)) > half]
            if before:
                o0 = min(before, key=lambda c: float(np.hypot(*(c - o_p))))
                if np.hypot(*(o0 - o_p)) < self.size * (p - p0):
                    v_o = (o_p - o0) / max(p - p0, 1)
        return o_p, v_o

    def judge(self, tmpl, gray, frame: int, found, min_cc: float):
        """Whether the object found again at ``found`` (centre px) in ``gray`` (frame ``frame``,
        after lost frames) is the tracked one: ("keep", None); ("swap", (correlation, centre px,
        turn rad)) when the look-alike's match is; ("twin", None) when continuity cannot tell."""
        if not self.seen:
            return "keep", None
        found = np.asarray(found, float)
        p, c_p, v_k = self._own()
        gap = max(frame - p, 1)
        radius = float(np.hypot(*v_k)) * gap + 2.0 * self.size
        half = 0.5 * self.size
        now = _similar(match_peaks(gray, tmpl, c_p, radius), min_cc)
        rivals = [q for q in now if np.hypot(*(q[1] - found)) > half]
        if not rivals:
            return "keep", None
        other = self._lookalike(tmpl, radius, min_cc, now[0][0])
        if other is None:  # no look-alike before the loss: the object's own path decides
            pred_k = c_p + v_k * gap
            rival = min(rivals, key=lambda q: float(np.hypot(*(q[1] - pred_k))))
            d_found, d_rival = float(np.hypot(*(found - pred_k))), float(np.hypot(*(rival[1] - pred_k)))
        else:
            o_p, v_o = other
            vk2, vo2 = _collide(c_p, v_k, o_p, v_o, CONTACT_SIZES * self.size)
            pred_k, pred_o = c_p + vk2 * gap, o_p + vo2 * gap
            rival = min(rivals, key=lambda q: float(np.hypot(*(q[1] - pred_k)) + np.hypot(*(found - pred_o))))
            d_found = float(np.hypot(*(found - pred_k)) + np.hypot(*(rival[1] - pred_o)))
            d_rival = float(np.hypot(*(rival[1] - pred_k)) + np.hypot(*(found - pred_o)))
        margin = PICK_MARGIN_SIZES * self.size
        if d_found + margin < d_rival:
            return "keep", None
        if d_rival + margin < d_found:
            return "swap", rival
        return "twin", None
