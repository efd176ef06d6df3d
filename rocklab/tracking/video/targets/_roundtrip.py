"""Forward-backward check of a markerless pose: the frame's patch tracked back to the keyframe.

The tracker registers its keyframe forward into each frame. The check runs that backwards: the
frame warped back by the pose (the patch the pose says is the object) is searched for in the
keyframe's own frame, round the place the keyframe was cut from, by the normalised correlation
the tracker's re-acquisition uses (translation only: the forward fit has set the angle). On the
object the round trip lands where the keyframe was cut; a patch of something else lands where
that thing stood in the keyframe's frame, or nowhere (at the edge of the search). The distance
the round trip misses by must stay within a limit learned from the object's own verified
frames: :data:`FB_FACTOR` times their 99th percentile, at least :data:`FB_MIN_FRAC` of the
template (and that floor plus :data:`FB_COLD_FRAC` until :data:`FB_WARMUP` round trips are
learned).

The search costs a fraction of a fit, so it runs on the frames the other checks find doubtful
(:meth:`RoundTrip.doubtful`: a pose found after lost frames, or a correlation low for this
object) and on every :data:`FB_SAMPLE_FRAMES`-th verified frame, which teaches the limit.
This is the classical forward-backward error of point trackers (Kalal et al. 2010; OpenCV's
``lk_track.py`` sample keeps the points whose back-tracked position lands within 1 px) made for
a region tracker whose template is a keyframe, not the previous frame.
"""

from __future__ import annotations

import collections
import math

import numpy as np

from ._occlusion import subpixel_peak, warp_grown

__all__ = ["RoundTrip", "FB_FACTOR", "FB_MIN_FRAC"]

#: The round trip's allowed miss, in multiples of the verified frames' 99th percentile.
FB_FACTOR = 4.0
#: Smallest allowed miss, as a fraction of the template's larger side (plus 1 px): the keyframe
#: of a spinning ball is cut from a view that no later frame repeats exactly.
FB_MIN_FRAC = 0.05
#: Added to the floor while fewer than :data:`FB_WARMUP` round trips are learned.
FB_COLD_FRAC = 0.05
FB_WARMUP = 10
#: Margin searched round the keyframe's place in its frame, as a fraction of the template's larger
#: side: a miss beyond it is a miss whatever its size.
FB_MARGIN_FRAC = 0.25
#: Larger side of the template at which the search runs, px (a larger one is reduced).
FB_SIDE_PX = 40.0
#: A frame the other checks pass is doubtful when its correlation lies this many robust
#: deviations below the verified frames' median (or it was found after lost frames).
FB_DOUBT_MADS = 2.0
#: Every this many verified frames the round trip runs whatever the doubt (it teaches the limit).
FB_SAMPLE_FRAMES = 10


class RoundTrip:
    """One markerless object's forward-backward check (see the module's description).

    Parameters
    ----------
    size : tuple of int
        The template's (width, height), px.
    """

    def __init__(self, size):
        self.size = size
        side = max(size)
        self.f = min(1.0, FB_SIDE_PX / side)
        self.margin = int(math.ceil(FB_MARGIN_FRAC * side))
        #: the keyframe's frame resampled onto the template's grid grown by :attr:`margin` at the
        #: pose it was cut at, reduced by :attr:`f` (float32), or None before the first keyframe
        self.source = self.first_source = None
        self.misses: collections.deque = collections.deque(maxlen=300)
        self._since = 0
        self.last_miss = math.nan

    def keyframe(self, tr, gray, W):
        """Remember the frame ``gray`` a keyframe was cut from at the pose ``W`` (first-frame px
        -> image px; the first frame with the identity)."""
        grown = warp_grown(tr, gray, np.asarray(W, np.float32), self.margin)
        self.source = None if grown is None else self._reduce(grown)
        if self.first_source is None:
            self.first_source = self.source

    def to_first(self):
        """The keyframe is the first template again: its frame is the first frame."""
        self.source = self.first_source

    def _reduce(self, img):
        import cv2

        img = np.asarray(img, np.float32)
        return img if self.f == 1.0 else cv2.resize(img, None, fx=self.f, fy=self.f, interpolation=cv2.INTER_AREA)

    def limit(self) -> float:
        """The largest miss accepted now, px."""
        floor = FB_MIN_FRAC * max(self.size) + 1.0
        if len(self.misses) < FB_WARMUP:
            return floor + FB_COLD_FRAC * max(self.size)
        return max(floor, FB_FACTOR * float(np.percentile(self.misses, 99)))

    def doubtful(self, score, score_median, score_dev, gap) -> bool:
        """Whether the round trip runs for a pose with correlation ``score`` found ``gap`` frames
        after the last verified one (the verified frames' median correlation and its robust
        deviation given; None while they are not learned)."""
        if gap > 1 or score_median is None or self._since + 1 >= FB_SAMPLE_FRAMES:
            return True
        return score < score_median - FB_DOUBT_MADS * score_dev

    def miss(self, patch) -> float:
        """How far the round trip of ``patch`` (the frame warped back by the pose onto the template's
        grid) misses the keyframe's place, px; inf at the edge of the search, NaN without a keyframe."""
        import cv2

        if self.source is None or patch is None:
            return math.nan
        t = self._reduce(patch)
        if t.shape[0] >= self.source.shape[0] or t.shape[1] >= self.source.shape[1] or float(t.std()) == 0.0:
            return math.nan
        res = cv2.matchTemplate(self.source, t, cv2.TM_CCOEFF_NORMED)
        at, val = subpixel_peak(res)
        if not math.isfinite(val):
            return math.nan
        if min(at[0], at[1], res.shape[1] - 1 - at[0], res.shape[0] - 1 - at[1]) < 0.5:
            return math.inf
        centre = np.array([(res.shape[1] - 1) / 2, (res.shape[0] - 1) / 2])
        return float(np.hypot(*(at - centre))) / self.f

    def check(self, patch) -> bool:
        """Whether the round trip of ``patch`` misses by more than the limit (the pose fails)."""
        self.last_miss = self.miss(patch)
        return bool(self.last_miss > self.limit())  # inf fails, NaN (no keyframe) passes

    def accept(self):
        """Learn from a verified frame: its round trip's miss when the check ran on it."""
        self._since += 1
        if math.isfinite(self.last_miss):
            self.misses.append(self.last_miss)
            self._since = 0
        self.last_miss = math.nan
