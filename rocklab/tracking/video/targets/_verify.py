"""Does a fitted markerless pose re-explain the image? Checks after every fit, learned per object.

A registration converges somewhere; it does not say whether that is the object. After the fit
the frame, warped back onto the template's grid by the pose, is checked three ways, each against
limits learned from the object's own verified frames (robust statistics, not global constants)
and, for the outline, its own first frame:

* **appearance** (``mismatch``): its correlation with the first template or the last verified
  keyframe must reach the median of the verified frames' correlations less
  :data:`APPEARANCE_MADS` robust deviations (at least :data:`MIN_DEVIATION`; never below
  :data:`MIN_SCORE`); and while that limit is not learned yet, a pose found after lost frames
  must be a turned copy of the first view (:data:`COLD_FIRST_CC`), or of the first view smeared
  along the object's last verified velocity by up to its fastest verified speed, on the scene behind
  the pose (a ball swinging 20 px a frame is a streak that matches its still first view at
  0.83-0.88; a ball's streak fades into the wall behind it): a keyframe renewed
  from a lamp or a hand that the template half matched would otherwise follow it at 0.99; on the
  frame after a verified one, while cold, it must still match that first view or its smear at
  :data:`COLD_STEP_CC` (a ball let go from the fingers drawn into its region leaves the keyframe
  on the fingers, renewed there, with nothing learned to refuse them). So must, at
  any time, a pose found after lost frames (or after a slide) farther than the template's larger
  side both from the last verified pose and from where its velocity carries it: the motion
  vouches for nothing there, and a small ball's keyframe half matches a forearm or an edge;
  and the patch's contrast (its grey standard deviation over the first template's) must reach
  :data:`CONTRAST_FRACTION` of the median of the verified frames' (of the first template's own
  until :data:`WARMUP_FRAMES` are learned): the correlation is blind to contrast, so the ball's
  soft shadow on the wall, or a faint gradient of a bare wall, matches a dark ball's keyframe at
  0.84-0.99 with a tenth of its contrast;
* **picture**: a pose whose reported point lies outside the picture is lost;
* **motion** (``jump``): the pose may leave the constant-velocity prediction by no more than
  the verified frames' residuals allow (:data:`MOTION_FACTOR` times their 99th percentile, at
  least :data:`MIN_RESIDUAL_FRAC` of the template; after ``g`` lost frames the prediction is
  carried over them and the allowance is ``g (g + 1) / 2`` times that: a change of velocity each
  frame), unless it lies no farther from the last verified pose than the prediction does plus
  that allowance (an impact on a spring, a wall or the floor stops or turns the object at once
  but gains it no speed), nor turn by more than :data:`MAX_STEP_RAD` a frame since the last
  verified pose;
* **background** (``background``): the warped patch must not match the still background
  (the first frame, with the object's first region filled in once the object has left it)
  on nearly all of its pixels, nor correlate with it as well as with the object's template:
  a pose frozen on a patch of wall, or on a detail of the scene that looks like the object,
  is a lost lock. The first
  frame shows the object in its first region, so that region's background is learned apart:
  from a verified frame in which the object has left it, or, sooner, from the median of the
  frames in which the object was lost (:data:`LOST_SAMPLES`), once the object's template
  registers nowhere in that median (the object has gone from its first place: a bob hanging
  still before it was shot off would otherwise make its own empty place look like the object),
  and again from every later such median of the same run of lost frames: an object that slides
  off slowly is lost while it still covers part of its place, so the run's first median holds
  part of it, and its later ones show the empty place once it has gone. An object that stayed
  under a hand is found again when the hand leaves; that verified frame ends the run, and the
  background is not learned again until the next lost frame, so medians of the object back in
  view (a rocking block the turned template does not register in) never become its background;
  and the patch must not be what the latest scene snapshot taken while the object stood
  elsewhere showed there (one every :data:`SNAP_FRAMES` verified frames): a pose left on the
  object's empty start place, whose look the keyframe learned, matches its keyframe at 0.998;
* **outline** (``drift``): once the background behind the object's first region is known, the
  object's silhouette against it, registered round the pose (:mod:`._occlusion`), must lie where
  the pose puts it, within :data:`._occlusion.DRIFT_FRAC` of the template: a spinning object's
  texture, or a keyframe renewed over a still edge of the wall, lets the pose slide off the
  object while every correlation stays high. The pose moved onto the outline is where the
  object is searched for first (and verified like any other pose); the motion checks forget
  the poses of the slide. The outline is learned as soon as the template has left the user's
  region (the first frame round it as its background: the region is drawn round the object),
  and again once the region grown by the outline's margin is seen; a disk's centre stays where
  it was first placed.
* **round trip** (``roundtrip``): the frame warped back by the pose, searched for in the
  keyframe's own frame round the place the keyframe was cut from, must land there within a
  limit learned from the object's verified frames (:mod:`._roundtrip`: the forward-backward
  check); run on the frames the other checks find doubtful and on a sample of the rest.
* **disk** (not a check: the position a ball reports): for a round outline, the centre of the
  object's disk against the background (:meth:`._occlusion.OutlineRef.disk_centre`), kept in
  :attr:`PoseVerifier.disk_at` for the tracker; the disk itself is learned again from the
  verified frames' edge circle where the first frame's is missing or of another size
  (:class:`._occlusion.SeenDisk`: a hand held the disc in the first frame).

A frame that fails is lost with that reason; only verified frames renew the keyframe and teach
the limits, so a wrong lock cannot teach the tracker to accept itself.
"""

from __future__ import annotations

import bisect
import collections
import math

import numpy as np

from ._occlusion import OUTLINE_MARGIN_FRAC, ROUND_MIN, OutlineRef, SeenDisk, pair, warp_grown
from ._roundtrip import RoundTrip

__all__ = ["PoseVerifier", "Window", "search_whole_frame", "MIN_SCORE", "MAX_STEP_RAD"]

#: Lowest correlation of the warped frame with the template that can ever count as the object.
MIN_SCORE = 0.2
#: Robust standard deviations below the verified median correlation still accepted.
APPEARANCE_MADS = 6.0
#: Smallest robust deviation of the correlation assumed: a rendered object matches its template
#: to 0.99 on every frame, and a 0.97 is not a different object.
MIN_DEVIATION = 0.05
#: Verified frames before the learned appearance limit is used (the floor applies until then).
WARMUP_FRAMES = 15
#: Verified frames between two updates of the learned limits (sorting 300 values every frame
#: would cost a few percent of the tracker's time).
RELEARN_FRAMES = 10
#: Prediction residual allowed, in multiples of the verified frames' 99th percentile.
MOTION_FACTOR = 4.0
#: Smallest residual limit, as a fraction of the template's larger side (a frame's impact or a
#: change of swing direction moves the object off the constant-velocity line by a few pixels).
MIN_RESIDUAL_FRAC = 0.08
#: Largest turn between consecutive frames, rad (as the track's outlier rule), and the largest
#: turn since the last verified pose whatever the gap.
MAX_STEP_RAD = 0.35
MAX_TURN_RAD = 1.0
#: Background check: a grey difference below this is "unchanged"; a patch unchanged on this
#: fraction of the pixels whose background is known is background.
BG_TOL = 10.0
BG_FRACTION = 0.9
#: A pose whose template correlation beats the outline's pose's by more than this is not said to
#: have slid off the outline (collisionOne.webm's red cart: 0.97 against 0.36 where the first
#: frame's background held the other cart).
OUTLINE_CC_GAP = 0.3
#: Steps towards the outline tried when a pose has slid off it.
HINT_STEPS = 3
#: Fraction of the patch whose background must be known for the background check to apply.
BG_KNOWN = 0.5
#: Share of the first region that must have changed from the first frame in that median.
BG_CHANGED = 0.05
#: Frames since the object was first lost whose first region's median is tried as the
#: background there: every first number of them, the last second number kept.
LOST_SAMPLES = (3, 15)
#: Turns of the template tried in that median (degrees): a median that holds the object turned
#: (a block lost while it rocked) is not its background.
MEDIAN_TURNS_DEG = (0.0, -5.0, 5.0, -10.0, 10.0)
#: Correlation with the first view that a pose found after lost frames must reach while the limits
#: are cold (fewer than :data:`WARMUP_FRAMES` verified frames): a turned copy of the first view
#: (the markerless tracker's keyframe rule). Nothing learned yet says how far the object's look may
#: stray from it, and a lamp or a hand that the template half matches (0.6-0.85) is not the object.
COLD_FIRST_CC = 0.9
#: Correlation with the first view (or its smear, as for :data:`COLD_FIRST_CC`) that a pose on the
#: frame after a verified one must reach while the limits are cold: a ball let go from the hand
#: drawn into its region leaves the fingers, half the template, matching it at 0.46-0.68 (the
#: keyframe at 0.77-0.96); the ball itself in the hand, turning and blurring, kept 0.79-1.0. Asked
#: only of a pose whose keyframe correlation is below :data:`COLD_FIRST_CC`.
COLD_STEP_CC = 0.75
#: Smear lengths tried on the first view for that rule, as fractions of the fastest verified speed
#: (px/frame): the exposure's share of the frame interval is not known.
SMEAR_FRACS = (0.33, 0.67, 1.0)
#: Least contrast of a verified patch, as a fraction of the median contrast of the object's verified
#: frames (grey standard deviation of the frame warped back by the pose over the first template's).
#: The correlation normalises contrast away: a shadow, or a bare wall's faint gradient, correlates
#: with a dark object's template as well as the object does, with a tenth of its contrast. Motion
#: blur and a change of light lower it by far less (a ball falling 120 px a frame kept 0.78 of it).
CONTRAST_FRACTION = 1.0 / 3.0
#: Scene snapshots for the background check: one every :data:`SNAP_FRAMES` verified frames, the
#: last :data:`SNAPS` kept (a grey frame each).
SNAP_FRAMES = 10
SNAPS = 8


class Window:
    """The last ``maxlen`` values appended, kept in order of arrival and sorted: their median and
    percentiles without a sort of the whole window each time (the verifier asks for them every
    frame). Equal to ``np.median`` and ``np.percentile`` (its default, linear) of the window's
    values: NaN when one is NaN.

    >>> w = Window(3)
    >>> for x in (5.0, 1.0, 4.0, 2.0):
    ...     w.append(x)
    >>> list(w), w.median(), w.percentile(50.0)
    ([1.0, 4.0, 2.0], 2.0, 2.0)
    """

    def __init__(self, maxlen: int):
        self._order: collections.deque = collections.deque(maxlen=maxlen)
        self._sorted: list = []  # the values but NaN, ascending
        self._nans = 0

    def append(self, x: float) -> None:
        x = float(x)
        if len(self._order) == self._order.maxlen:
            old = self._order[0]
            if old != old:
                self._nans -= 1
            else:
                del self._sorted[bisect.bisect_left(self._sorted, old)]
        self._order.append(x)
        if x != x:
            self._nans += 1
        else:
            bisect.insort(self._sorted, x)

    def __len__(self) -> int:
        return len(self._order)

    def __iter__(self):
        return iter(self._order)

    def median(self) -> float:
        """``np.median`` of the values (NaN when empty)."""
        s, n = self._sorted, len(self._sorted)
        if self._nans or n == 0:
            return math.nan
        # numpy's mean of the two middle values: their sum over 2
        return s[n // 2] if n % 2 else (s[n // 2 - 1] + s[n // 2]) / 2

    def percentile(self, q: float) -> float:
        """``np.percentile`` of the values at ``q`` (0-100; linear interpolation, NaN when empty)."""
        s, n = self._sorted, len(self._sorted)
        if self._nans or n == 0:
            return math.nan
        v = (n - 1) * (q / 100)
        if v >= n - 1:
            return s[-1]
        i = math.floor(v)
        t, a, b = v - i, s[i], s[i + 1]
        # numpy's lerp: from the nearer end
        return b - (b - a) * (1 - t) if t >= 0.5 else a + (b - a) * t


class PoseVerifier:
    """One markerless object's checks (see the module's description).

    Parameters
    ----------
    first_gray : ndarray (H, W) uint8
        The first frame: the background everywhere but the object's region.
    box : tuple of int
        The object's region in the first frame, (u0, v0, u1, v1) px.
    size : tuple of int
        The template's (width, height), px.
    """

    def __init__(self, first_gray, box, size):
        self.bg = first_gray.astype(np.float32)
        self.first = self.bg.copy()
        self.box = box
        #: the outline's margin round the template, px, and the first region grown by it (the
        #: part of the first frame whose background is learned once the object has left it)
        self.margin = int(math.ceil(OUTLINE_MARGIN_FRAC * max(size)))
        self.outline = None  # the object's outline in the user's region, once its background is known
        self.hint = None  # a pose that failed the outline, moved onto the outline
        #: a round object's disk centre in the last frame verified (image px), or None
        self.disk_at = None
        #: the disk as the verified frames show it (a first frame joined by a hand, or not round)
        self.seen_disk = SeenDisk()
        self._disk_look: tuple | None = None  # the pose being verified's look for it
        H, W = first_gray.shape[:2]
        m = self.margin
        self.outer = (max(box[0] - m, 0), max(box[1] - m, 0), min(box[2] + m, W), min(box[3] + m, H))
        self.filled = False  # the first region's background seen (the object has left it)
        self.early = False  # the user's region's background seen (the template has left it)
        #: the first region's background taken from the median of lost frames (the check applies
        #: there; the outline is learned only from a verified frame)
        self.first_known = False
        self.lost_crops: collections.deque = collections.deque(maxlen=LOST_SAMPLES[1])
        self.n_lost, self._sampled_at, self.since_lost = 0, -1, False
        #: lost since the last verified frame: each median of the run may replace the last one
        self.lost_run = False
        self.first_outer = first_gray[self.outer[1] : self.outer[3], self.outer[0] : self.outer[2]].astype(np.float32)
        self.tmpl0 = first_gray[box[1] : box[3], box[0] : box[2]].astype(np.float32)
        self.size = size
        self.scores = Window(300)
        #: the verified frames' contrast over the first template's (:meth:`faint`)
        self.contrasts = Window(300)
        self._tmpl0_std = float(self.tmpl0.std())
        self._contrast = math.nan  # the pose being verified's
        self.residuals = Window(300)
        self.speeds = Window(300)
        self.n_verified = 0
        self._limits, self._learned_at = None, 0
        #: (median, robust deviation) of the verified correlations, once learned
        self.score_stats: tuple | None = None
        #: the forward-backward check (:mod:`._roundtrip`); its keyframe's frame is set by the tracker
        self.fb = RoundTrip(size)
        #: (centre (2,), theta, frame) of the last two verified poses
        self.recent: list = []
        #: (centre (2,), velocity (2,) px/frame, frame) of the last verified pose, kept when a slide
        #: makes the motion checks forget :attr:`recent`: where a re-found object may be
        self.seen = None
        #: whether the angle is checked (False for an object whose appearance tells no angle)
        self.check_turn = True
        #: (grey frame, the object's footprint in it grown by the margin (x0, y0, x1, y1) px) of
        #: verified frames: what the scene shows where the object was not
        self.snaps: collections.deque = collections.deque(maxlen=SNAPS)
        self._snap_at = -SNAP_FRAMES

    def motion_context(self, frame: int):
        """(last verified (centre, theta, frame) or None, frames since it (1 without one), the
        constant-velocity prediction (centre, theta) from the last two verified poses when they
        are consecutive frames, else None) for a pose at ``frame``."""
        last = self.recent[-1] if self.recent else None
        gap = frame - last[2] if last is not None else 1
        pred = None
        if len(self.recent) == 2 and self.recent[1][2] - self.recent[0][2] == 1:
            # extrapolated over the gap: after lost frames the object is still where its own
            # motion carries it (a lock that jumped to something else near it is not)
            (c0, t0, _), (c1, t1, _) = self.recent
            pred = (c1 + gap * (c1 - c0), t1 + gap * (t1 - t0))
        return last, gap, pred

    # -- learned limits ------------------------------------------------------------
    def score_limit(self) -> float:
        """The lowest correlation accepted now."""
        if len(self.scores) < WARMUP_FRAMES:
            return MIN_SCORE
        s = np.fromiter(self.scores, float, len(self.scores))
        med = self.scores.median()
        dev = max(1.4826 * float(np.median(np.abs(s - med))), MIN_DEVIATION)
        self.score_stats = (med, dev)
        return max(MIN_SCORE, med - APPEARANCE_MADS * dev)

    def residual_limit(self) -> float:
        """Largest distance from the constant-velocity prediction accepted for one frame, px."""
        floor = MIN_RESIDUAL_FRAC * max(self.size) + 1.0
        if len(self.residuals) < WARMUP_FRAMES:
            return max(floor, 0.25 * max(self.size))
        return max(floor, MOTION_FACTOR * self.residuals.percentile(99))

    # -- the checks ------------------------------------------------------------------
    def limits(self):
        """(score, residual, speed) limits, learned again every :data:`RELEARN_FRAMES` verified frames."""
        if (
            self._limits is None
            or self.n_verified >= self._learned_at + RELEARN_FRAMES
            # until warm, every frame: limits learned from fewer samples fall back to cold floors
            or min(len(self.scores), len(self.residuals)) <= WARMUP_FRAMES
        ):
            self._limits = (self.score_limit(), self.residual_limit(), self.speed_limit())
            self._learned_at = self.n_verified
        return self._limits

    def check(self, score, centre, theta, pred, last, gap, bg_back=None, back=None, known_back=None):
        """The reason the pose fails, or None when it is verified.

        Parameters
        ----------
        score : float
            Correlation of the warped frame with the better of the two templates.
        centre : ndarray (2,)
            The template's centre under the pose, image px.
        theta : float
            The pose's angle, rad.
        pred : tuple or None
            (centre (2,), theta) predicted from the last two verified frames; None without them.
        last : tuple or None
            (centre (2,), theta) of the last verified pose; None before any.
        gap : int
            Frames since the last verified one (1: the previous frame).
        bg_back, back, known_back : ndarray (h, w), optional
            The background, the frame and the background's known mask, warped onto the template
            (no mask: the background is known on every pixel).
        """
        score_lim, lim, speed_lim = self.limits()
        if score < score_lim:
            return "mismatch"
        if last is not None:
            turn = abs(math.remainder(theta - last[1], 2 * math.pi))
            if self.check_turn and turn > min(MAX_STEP_RAD * gap, MAX_TURN_RAD):
                return "jump"
            slack = lim * gap * (gap + 1) / 2
            if (
                pred is not None
                and float(np.hypot(*(centre - pred[0]))) > slack
                # an impact (a spring, a wall, the floor) stops or turns the object at once but
                # gains it no speed: within its own motion of the last pose it may be anywhere
                and float(np.hypot(*(centre - last[0]))) > float(np.hypot(*(pred[0] - last[0]))) + slack
            ):
                # off the constant-velocity prediction by more than the largest change of
                # velocity the verified frames allow in each frame since (its sum over the gap)
                return "jump"
            if (pred is None or gap > 1) and float(np.hypot(*(centre - last[0]))) > (lim + speed_lim) * gap:
                return "jump"  # no farther than the fastest verified motion allows
        if bg_back is not None:
            k = None if known_back is None else known_back > 0.5
            # the known pixels, taken once (all of them, in the same order, when all are known)
            known = 1.0 if k is None else k.mean()
            kb, kg = (back.ravel(), bg_back.ravel()) if known == 1.0 else (back[k], bg_back[k])
            if known >= BG_KNOWN and (
                _share(np.abs(kb - kg) < BG_TOL) >= BG_FRACTION
                # the still background explains the patch at least as well as the object does (a
                # detail of the scene that looks like a small object, under compression noise)
                or _ncc(kb, kg) >= score
            ):
                return "background"
        return None

    def speed_limit(self) -> float:
        """Largest believable motion per frame, px: three times the fastest verified one, at
        least a tenth of the template."""
        top = self.speeds.percentile(99) if len(self.speeds) else 0.0
        return max(3.0 * top, 0.1 * max(self.size))

    def accept(self, score, centre, pred, last, gap, gray=None, footprint=None, tight=None):
        """Learn from a verified frame: its correlation, its residual, its speed, and (once the
        object has left its first region) the background there: the user's region as soon as the
        template's footprint (``tight``: its bounding box under the pose) has left it, the region
        grown by the outline's margin once ``footprint`` (a square that holds it at any turn)
        has left that."""
        self.n_verified += 1
        self.scores.append(float(score))
        if pred is not None and gap == 1:
            self.residuals.append(float(np.hypot(*(centre - pred[0]))))
        if last is not None and gap == 1:
            self.speeds.append(float(np.hypot(*(centre - last[0]))))
        if gray is not None and footprint is not None and not self.filled:
            x0, y0, x1, y1 = footprint
            u0, v0, u1, v1 = self.outer
            if x1 < u0 or x0 > u1 or y1 < v0 or y0 > v1:  # the grown first region is uncovered now
                self.bg[v0:v1, u0:u1] = gray[v0:v1, u0:u1]
                self.filled = True
        if gray is not None and tight is not None and not (self.filled or self.early):
            x0, y0, x1, y1 = tight
            u0, v0, u1, v1 = self.box
            if x1 < u0 or x0 > u1 or y1 < v0 or y0 > v1:  # the user's region is: the first frame round it
                self.bg[v0:v1, u0:u1] = gray[v0:v1, u0:u1]
                self.early = True

    def lost_frame(self, gray, frame, min_cc):
        """Learn from a frame in which the object was lost: from then on every frame's first
        region is a sample of what stands there (:meth:`_sample`)."""
        self.since_lost = self.lost_run = True
        self._sample(gray, frame, min_cc)

    def _sample(self, gray, frame, min_cc):
        """Keep ``gray``'s first region (once per frame) and, every first number of :data:`LOST_SAMPLES`
        samples, take their median as the background there when the object's template registers
        in it nowhere at ``min_cc`` and it differs from the first view (the object has left its
        place); again at every such median until a frame is verified (:attr:`lost_run`: a median
        taken while the object was sliding off holds part of it). Decided on copies reduced until
        the template is about 40 px across."""
        if self.filled or (self.first_known and not self.lost_run) or frame == self._sampled_at:
            return
        self._sampled_at = frame
        import cv2

        u0, v0, u1, v1 = self.outer
        crop = np.array(gray[v0:v1, u0:u1])
        f = min(1.0, 40.0 / max(self.size))

        def small(img):
            return img if f == 1.0 else cv2.resize(img, None, fx=f, fy=f, interpolation=cv2.INTER_AREA)

        self.lost_crops.append((crop, small(crop)))
        self.n_lost += 1
        if self.n_lost % LOST_SAMPLES[0]:  # tried every few frames: a median costs
            return
        med = np.median(np.stack([c[1] for c in self.lost_crops]), axis=0).astype(np.float32)
        if float(np.mean(np.abs(med - small(self.first_outer)) >= BG_TOL)) < BG_CHANGED:
            return  # the first view is still there: the object did not leave (or was lost in place)
        if best_turned_match(med, small(self.tmpl0), 0.0, MEDIAN_TURNS_DEG, min_cc) is not None:
            return  # the object, or an object like it, stands there
        self.bg[v0:v1, u0:u1] = np.median(np.stack([c[0] for c in self.lost_crops]), axis=0)
        self.first_known = True

    def learn_outline(self):
        """Once the background is known: the object's outline in the user's region, first with
        the first frame as the background round the region (the region drawn round the object),
        again once the grown region is seen (a region drawn smaller than the object). A disk's
        centre stays where it was first placed: it is the point the track reports."""
        if self.first is None or not (self.filled or self.early) or (self.outline is not None and not self.filled):
            return
        ref = OutlineRef(self.first, self.bg, self.box)
        if (
            self.outline is not None
            and self.outline.disk0 is not None
            and (ref.disk0 is not None or not ref.roundness >= ROUND_MIN)
        ):
            # a disk stays one where the filled-in background's outline is not round (a hand that
            # held it in the first frame joins it there: it tells nothing of the disk); a round
            # outline without a disk overrides the first (a disk drawn too large against the first
            # frame round the region)
            ref.disk0 = self.outline.disk0
        self.seen_disk.teach(ref)
        self.outline = ref
        if self.filled:
            self.first = None  # needed no more

    # -- with a tracker ----------------------------------------------------------------
    def verify(self, tr, gray, W, frame, score):
        """Check the pose ``W`` (first-frame px -> image px) of the tracker ``tr`` in ``gray``.

        Parameters
        ----------
        score : float
            The fit's correlation of the template with the frame warped back by ``W``.

        Returns
        -------
        reason : str or None
            None when verified (then :meth:`confirm` learns from it).
        """
        Wd = np.asarray(W, float)
        centre = Wd[:, :2] @ tr.centre0 + Wd[:, 2]
        theta = math.atan2(Wd[1, 0] - Wd[0, 1], Wd[0, 0] + Wd[1, 1])
        last, gap, pred = self.motion_context(frame)
        if self.since_lost:  # what stands in the first region now, the frame checked included
            self._sample(gray, frame, tr.min_cc)
        bg = back = bg_g = back_g = None
        self.hint = self.disk_at = self._disk_look = None
        if not (0.0 <= centre[0] < gray.shape[1] and 0.0 <= centre[1] < gray.shape[0]):
            return "lost"  # the point reported would lie outside the picture: no measurement
        # the background is known where the first frame did not show the object, and everywhere
        # once the object has left its first region: only then is the check worth its two warps
        if self.filled or self.early or self.first_known or self._clear(centre):
            m = 2 * self.margin
            bg_g, back_g = warp_grown(tr, self.bg, W, m, also=gray)
            if bg_g is not None and back_g is not None:
                bg, back = bg_g[m:-m, m:-m], back_g[m:-m, m:-m]  # known on every pixel
        last2 = None if last is None else last[:2]
        far = self._far(centre, frame)
        # frames since the last verified one: after a slide the motion checks have no anchor
        # (``gap`` is then 1), but the pose is still one found after lost frames
        since = gap if self.seen is None else max(gap, frame - self.seen[2])
        reason = self.check(float(score), centre, theta, pred, last2, gap, bg, back)
        if reason is None and self.faint(back if back is not None else tr._warp_back(gray, W)):
            reason = "mismatch"
        if reason is None:
            reason = self._look_again(tr, gray, W, centre, float(score), gap, far)
        self.fb.last_miss = math.nan
        if reason is None and self.fb.doubtful(float(score), *(self.score_stats or (None, None)), since):
            # tracked back to the keyframe's frame, the patch must land where the keyframe was cut
            if self.fb.check(back if back is not None else tr._warp_back(gray, W)):
                reason = "roundtrip"
        self.learn_outline()
        if reason is None and self.outline is not None and back is not None and self._in_frame(tr, W, gray.shape):
            # the object's outline against the background is not where the pose puts it: the
            # pose slid off the object (a spinning object's texture, a keyframe that learned a
            # still edge of the wall)
            grown = pair(back_g, bg_g)  # shared by the outline and the disk
            found = self.outline.locate(tr, gray, self.bg, W, grown)
            if (
                found is not None
                and self.outline.moved(found)
                and not self._texture_outweighs(tr, gray, found[2], score)
            ):
                # the poses since the last frame checked here were the slide: no anchor for motion
                reason, self.hint, self.recent = "drift", found[2], []
            elif found is not None:
                if not self.seen_disk.done:
                    self._disk_look = (self.seen_disk.look(tr, grown, 2 * self.margin), W)
                self.disk_at = self.outline.disk_centre(tr, W, grown)
        self._pending = (float(score), centre, theta, pred, last2, gap, frame)
        return reason

    def faint(self, patch) -> bool:
        """Whether ``patch`` (the frame warped back by the pose onto the template's grid) has less
        than :data:`CONTRAST_FRACTION` of the contrast the object shows on its verified frames
        (the first template's own until :data:`WARMUP_FRAMES` are learned): a shadow or a bare
        wall that the correlation, blind to contrast, matches. Remembers the patch's contrast for
        :meth:`confirm`."""
        self._contrast = math.nan if patch is None else _std(patch) / max(self._tmpl0_std, 1e-6)
        if not math.isfinite(self._contrast):
            return False
        usual = self.contrasts.median() if len(self.contrasts) >= WARMUP_FRAMES else 1.0
        return self._contrast < CONTRAST_FRACTION * usual

    def _far(self, centre, frame) -> bool:
        """Whether a pose centred at ``centre`` (px) in ``frame`` is found after lost frames farther
        than the template's larger side both from the last verified pose and from where that
        pose's velocity carries it over the gap: a re-acquisition that the object's motion does not
        vouch for (a forearm or an edge that a small ball's keyframe half matches, hundreds of px
        from where the ball was lost)."""
        if self.seen is None or frame - self.seen[2] <= 1:
            return False
        c, v, f = self.seen
        reach = max(self.size)
        return min(float(np.hypot(*(centre - c))), float(np.hypot(*(centre - c - v * (frame - f))))) > reach

    def _look_again(self, tr, gray, W, centre, score, gap, far=False):
        """The checks a template that adapts cannot pass by adapting: ``mismatch`` for a pose found
        after lost frames that is no turned copy of the first view (:data:`COLD_FIRST_CC`), nor of
        the first view smeared by the object's verified motion (:meth:`_smeared`), while the
        limits are cold, for a pose on the frame after a verified one that matches neither at
        :data:`COLD_STEP_CC` while they are cold, or no turned copy of the sharp first view when out of the object's reach
        (``far``: :meth:`_far`) at any time;
        ``background`` for a patch that the latest snapshot taken while
        the object stood elsewhere already showed there (unchanged on :data:`BG_FRACTION` of its
        pixels, or correlating with it at least as well as with the object): a pose left on the
        object's empty start place, or on a detail of the scene the keyframe has learned."""
        now = None
        warming = len(self.scores) < WARMUP_FRAMES
        cold = gap > 1 and warming
        # the next frame while cold: nothing learned bounds the keyframe's correlation yet (the
        # floor is :data:`MIN_SCORE`), so a ball released from a hand drawn into its region would
        # leave the keyframe on the fingers, renewed there at 0.95-0.99. Only a pose the keyframe
        # itself half matches is asked (0.78-0.82 on the fingers): a 15 px bob crossing grid lines
        # keeps the keyframe at 0.95 while its first view drops to 0.70, and refused there it
        # would stay lost behind the rule for poses found after lost frames
        step = warming and gap == 1 and bool(self.recent) and score < COLD_FIRST_CC
        if cold or far or step:
            now = tr._warp_back(gray, W)
            # while cold, the first view may be smeared by the object's own verified motion (a
            # swinging ball is a streak across the frame); a far pose has no motion to vouch for it
            views = self._smeared(tr, W) if (cold or step) and not far else [tr.tmpl0]
            need = COLD_STEP_CC if step and not far else COLD_FIRST_CC
            if now is None or max(_ncc(now, v) for v in views) < need:
                return "mismatch"
        half = 0.5 * math.hypot(*self.size) + self.margin
        for snap, (x0, y0, x1, y1) in reversed(self.snaps):
            if centre[0] + half < x0 or centre[0] - half > x1 or centre[1] + half < y0 or centre[1] - half > y1:
                now = tr._warp_back(gray, W) if now is None else now
                then = tr._warp_back(snap, W, keep=False)  # the frame's patch stays for the tracker
                if now is None or then is None:
                    return None
                same = _share(np.abs(now - then) < BG_TOL)
                return "background" if same >= BG_FRACTION or _ncc(now, then) >= score else None
        return None

    def _smeared(self, tr, W):
        """The first template and its copies smeared along the last verified velocity by
        :data:`SMEAR_FRACS` of the fastest verified speed (turned into the template's frame by the
        pose ``W``): how the first view looks on a frame exposed while the object moved. The view
        is smeared as it stands on the scene where the pose puts it (the background image round
        the pose, the first view pasted on the template's grid): a moving object's streak fades
        into the wall behind it, and a first view smeared on its own edges (a template cut inside
        a ball is green to its borders) matched a falling ball at 0.73 where the pasted one
        matched it at 0.89."""
        import cv2

        tmpl = tr.tmpl0
        if self.seen is None or not len(self.speeds):
            return [tmpl]
        v = np.asarray(self.seen[1], float)
        top = self.speeds.percentile(99)
        if not np.any(v) or top < 2.0:
            return [tmpl]
        Wd = np.asarray(W, float)
        ang = math.atan2(v[1], v[0]) - math.atan2(Wd[1, 0] - Wd[0, 1], Wd[0, 0] + Wd[1, 1])
        m = max(int(round(max(SMEAR_FRACS) * top)), 2)
        scene = warp_grown(tr, self.bg, W, m)
        h, w = tmpl.shape
        if scene is not None:
            scene[m : m + h, m : m + w] = tmpl
        out = [tmpl]
        for frac in SMEAR_FRACS:
            n = max(int(round(frac * top)), 2)
            k = np.zeros((2 * n + 1, 2 * n + 1), np.float32)
            t = np.linspace(-0.5 * n, 0.5 * n, 4 * n + 1)
            k[np.round(n + t * math.sin(ang)).astype(int), np.round(n + t * math.cos(ang)).astype(int)] = 1.0
            src = tmpl if scene is None else scene
            smeared = cv2.filter2D(src, -1, k / k.sum(), borderType=cv2.BORDER_REPLICATE)
            out.append(smeared if scene is None else smeared[m : m + h, m : m + w])
        return out

    @staticmethod
    def _texture_outweighs(tr, gray, at, score) -> bool:
        """Whether the pose's texture match ``score`` beats the outline's pose ``at`` by more than
        :data:`OUTLINE_CC_GAP`: then the outline is the one that is off (the background behind it
        is stale: another object stood there in the first frame, as the second cart of a
        collision film), not the pose."""
        back = tr._warp_back(gray, at)
        cc = -1.0 if back is None else max(_ncc(back, tr.tmpl0), _ncc(back, tr.key))
        return score - cc > OUTLINE_CC_GAP

    def _in_frame(self, tr, W, shape):
        """Whether the grown template grid under the pose ``W`` lies inside a frame of ``shape``
        (an object partly out of the picture has no whole outline to place)."""
        m = self.margin
        w, h = self.size
        (a, b, tx), (c, d, ty) = np.asarray(W, float).tolist()
        ox, oy = float(tr.origin[0]), float(tr.origin[1])
        for x in (ox - m, ox + (w + m)):  # the grid's four corners, in plain floats (it runs every frame)
            for y in (oy - m, oy + (h + m)):
                u, v = x * a + y * b + tx, x * c + y * d + ty
                if not (0 <= u <= shape[1] and 0 <= v <= shape[0]):
                    return False
        return True

    def _clear(self, centre):
        """Whether a pose centred at ``centre`` (px) keeps the template off the first region."""
        half = 0.5 * math.hypot(*self.size)
        u0, v0, u1, v1 = self.box
        return centre[0] + half < u0 or centre[0] - half > u1 or centre[1] + half < v0 or centre[1] - half > v1

    def reacquire(self, tr, gray, frame, min_cc):
        """The object anywhere in ``gray`` (:func:`search_whole_frame` from the last verified angle,
        then the tracker's fit from there), verified: (W, cc, score), or None."""
        for _ in range(HINT_STEPS):
            hint, self.hint = self.hint, None
            if hint is None:
                break
            # the object where its outline is: the outline found it, the template's correlation
            # and every other check must agree (a slide beyond the margin takes a few steps)
            back = tr._warp_back(gray, hint)
            cc = -1.0 if back is None else max(_ncc(back, tr.tmpl0), _ncc(back, tr.key))
            if cc < min_cc:
                break
            if self.verify(tr, gray, hint, frame, cc) is None:
                return hint, cc, cc
        th = self.recent[-1][1] if self.recent else 0.0
        W_s = search_whole_frame(tr, tr.key, gray, th)
        alt = tr._ecc(tr.key, gray, W_s) if W_s is not None else None
        if alt is None or alt[1] < min_cc:
            return None
        return None if self.verify(tr, gray, alt[0], frame, alt[1]) is not None else (alt[0], alt[1], alt[1])

    def confirm(self, gray, size):
        """Learn from the pose just verified (its correlation, motion and the background it uncovers)."""
        score, centre, theta, pred, last, gap, frame = self._pending
        if self._disk_look is not None and self.seen_disk.add(self._disk_look[0], frame, self._disk_look[1]):
            self.seen_disk.place_first(self.first_outer, self.outer[:2])
            self.seen_disk.teach(self.outline)
        if math.isfinite(self._contrast):
            self.contrasts.append(self._contrast)
        w, h = size
        half = 0.5 * math.hypot(w, h)
        footprint = (centre[0] - half, centre[1] - half, centre[0] + half, centre[1] + half)
        c, s = abs(math.cos(theta)), abs(math.sin(theta))
        hx, hy = 0.5 * (c * w + s * h), 0.5 * (s * w + c * h)
        self.accept(
            score,
            centre,
            pred,
            last,
            gap,
            gray,
            footprint,
            (centre[0] - hx, centre[1] - hy, centre[0] + hx, centre[1] + hy),
        )
        v = np.zeros(2) if self.seen is None or frame - self.seen[2] != 1 else centre - self.seen[0]
        self.seen = (np.asarray(centre, float), v, frame)
        self.recent = (self.recent + [(centre, theta, frame)])[-2:]
        self.fb.accept()
        self.lost_run = False
        if self.n_verified - self._snap_at >= SNAP_FRAMES:
            m = half + self.margin
            self.snaps.append((np.array(gray), (centre[0] - m, centre[1] - m, centre[0] + m, centre[1] + m)))
            self._snap_at = self.n_verified


def _mean32(a):
    """``a.mean()`` of a float32 array, as numpy takes it (a float32 sum over the count), without
    its generic wrapper: the verifier takes a few means every frame."""
    return np.float32(float(np.add.reduce(a, axis=None)) / a.size)


def _std(a) -> float:
    """``float(a.std())`` of a float32 array, as numpy takes it (float32 sums), in fewer calls."""
    n = np.intp(a.size)
    m = np.add.reduce(a, axis=None, keepdims=True)
    np.true_divide(m, n, out=m, casting="unsafe")
    x = a - m
    np.multiply(x, x, out=x)
    v = np.add.reduce(x, axis=None)
    return float(np.sqrt(v.dtype.type(v / n)))


def _share(mask) -> float:
    """``float(np.mean(mask))`` of a boolean array: the share of its true pixels."""
    return np.count_nonzero(mask) / mask.size


def _ncc(a, b):
    """Zero-mean normalised correlation of two images of one shape."""
    a, b = a - _mean32(a), b - _mean32(b)
    add = np.add.reduce
    # the float32 sum over a Python float: a float32 quotient, as numpy's scalars divide
    return float(
        add(a * b, axis=None) / (math.sqrt(float(add(a * a, axis=None)) * float(add(b * b, axis=None))) + 1e-9)
    )


def best_turned_match(image, tmpl, theta, turns_deg, min_cc):
    """The template turned to ``theta + turn`` (rad; ``turns_deg`` in degrees) that matches
    ``image`` best by normalised cross-correlation.

    Parameters
    ----------
    image : ndarray, shape (H, W), float32
    tmpl : ndarray, shape (h, w), float32
        Smaller than ``image``.
    theta : float
        Angle the template is turned to before the trial turns, rad.
    turns_deg : sequence of float
    min_cc : float
        Correlations below this are no match.

    Returns
    -------
    (correlation, angle_rad, (x, y)) or None
        The best match and its top-left corner in ``image``, px; None when none reaches ``min_cc``.
    """
    import cv2

    h, w = tmpl.shape
    best = None
    for turn in turns_deg:
        th = theta + math.radians(turn)
        rot = cv2.warpAffine(
            tmpl,
            cv2.getRotationMatrix2D((w / 2, h / 2), -math.degrees(th), 1.0),
            (w, h),
            borderMode=cv2.BORDER_REPLICATE,
        )
        _, val, _, loc = cv2.minMaxLoc(cv2.matchTemplate(image, rot, cv2.TM_CCOEFF_NORMED))
        if val >= min_cc and (best is None or val > best[0]):
            best = (val, th, loc)
    return best


def search_whole_frame(tr, tmpl, gray, theta, turns_deg=(0.0, -5.0, 5.0, -10.0, 10.0), min_cc=0.5):
    """Re-acquire anywhere in the frame: the template, turned round ``theta`` (rad) by ``turns_deg``,
    matched by normalised cross-correlation on a copy reduced until the template is about 40 px
    across; the best match's pose (first-frame px -> image px), or None below ``min_cc``."""
    import cv2

    h, w = tmpl.shape
    f = min(1.0, 40.0 / max(w, h))
    small = cv2.resize(gray, None, fx=f, fy=f, interpolation=cv2.INTER_AREA).astype(np.float32)
    t_small = cv2.resize(tmpl, None, fx=f, fy=f, interpolation=cv2.INTER_AREA)
    hs, ws = t_small.shape
    if small.shape[0] <= hs or small.shape[1] <= ws:
        return None
    best = best_turned_match(small, t_small, theta, turns_deg, min_cc)
    if best is None:
        return None
    _, th, loc = best
    new_ctr = np.array([(loc[0] + ws / 2) / f, (loc[1] + hs / 2) / f])
    c, s = math.cos(th), math.sin(th)
    t = new_ctr - np.array([[c, -s], [s, c]]) @ tr.centre0
    return np.array([[c, -s, t[0]], [s, c, t[1]]], np.float32)
