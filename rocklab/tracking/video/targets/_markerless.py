"""Markerless rigid tracker: an object's pose (x, y, θ) from its own texture and outline.

The object is a region of the first frame (``roi``). Every frame is registered
against a *keyframe* template by intensity (ECC, Euclidean motion, coarse to fine),
never chained frame to frame, so the pose does not drift:

1. predict the pose from the last two (constant velocity);
2. ECC on a 3-level pyramid from the prediction, against the first frame's template;
   if its correlation is low (appearance changed: a spinning ball, lighting), against
   the latest keyframe — a keyframe is the current frame warped back into the first
   template's coordinates, so both templates share one coordinate frame;
3. if ECC fails (occlusion, a jump at an impact), re-acquire: normalised cross-
   correlation of the template, turned by up to ±8°, over a search window around the
   prediction (after lost frames: the first frame's place, then the last pose seen), then ECC;
4. verify the pose (:mod:`._verify`: appearance, motion, background, limits learned from the
   object's own verified frames); a pose that fails, or no pose, sends the template over the
   whole frame; still nothing verified: the frame is lost (NaN, status ``lost`` or the failed
   check's name) and the next frame searches. Only verified frames renew the keyframe.

A keyframe is not renewed from a frame in which part of the object is covered (most cells
of a 4 x 4 grid match, one does not: a hand, the thread), so the keyframe never learns an
occluder; the covered frames then fail and are lost, and the object is found again after.

The per-frame orientation uncertainty is the Gauss-Newton covariance of the fit
(:func:`._observability.sigma_theta`), and on a keyframe the keyframe's own (the angle it was cut
at was itself measured: a chain of keyframes walks, and its σ grows with it). A frame whose cells
holding most of the turning information no longer match the pose while the rest do reports no
angle (:func:`._observability.unmatched_turn_share`: the angle was set by the rest, a still
background in the region's corners), nor does a pose on a keyframe cut at such a frame; such a
pose is held at the last angle measured about the point its matching cells turn about (a disk's
centre; on such a keyframe, the point the frame it was cut at was held about), so the point
reported does not follow the background's turn. The fits that follow such a frame off the last
angle measured report none either (they go on along the same wrong turn) until they come back to
it or the rotation check (:meth:`MarkerlessTracker._turn_check`) finds nothing to doubt. An object
whose appearance tells no angle (a disk) is held upright about its centre of symmetry, reports
that centre, and no angle (:mod:`._observability`); so is a round object whose texture, once a lit
sphere's shading is taken out, tells none (:func:`._observability.unshaded_turn_share`: a plain
ball's dark and lit sides stay with the light) when the film ends before its views can judge it
(:attr:`MarkerlessTracker.shading_note`, ``theta_pending``). A round
object (a ball) reports the place of its disk's centre: its texture slides over it as it spins, so
its points are moved to within :data:`DISK_AGREE_FRAC` of where the outline puts that centre; once
its angle is known not to be reported (a round outline), its points come from the pose turned back
to the first angle about that centre, so that no point hangs on the texture's angle; the frames
tracked before are moved the same way once the track is assembled (:meth:`MarkerlessTracker.disk_lever`).
"""

from __future__ import annotations

import math

import numpy as np

from ...._errors import InputError
from ._detection import Detection
from ._ic import ICAffine, ICRigid
from ._observability import (
    CELL_TURN_GAP,
    MAX_UNMATCHED_ABOUT_MATCHED,
    MAX_UNMATCHED_TURN,
    MIN_TURN_SHARE,
    cell_turn_info,
    sigma_theta,
    theta_unobservable,
    unmatched_turn_share,
    unshaded_turn_share,
)
from ._occlusion import CELL_CC, GRID, ROUND_MIN, cell_correlations, masked_fit, partly_covered
from ._turn_search import MIN_DISC_RADIUS_PX, PolarRings, inscribed_disc
from ._twins import TwinGuard
from ._verify import PoseVerifier, best_turned_match

__all__ = ["MarkerlessTracker", "MarkerlessDetector", "MIN_CC", "REKEY_CC", "ROUND_MIN"]

#: ECC correlation below which a registration is rejected.
MIN_CC = 0.6
#: Correlation with the first template below which the latest keyframe is used (and renewed).
REKEY_CC = 0.9
#: An outline at least this round (:data:`._occlusion.ROUND_MIN`) tells no angle: the texture alone
#: does, and a ball's texture turns as the ball spins in depth; its angle is not reported ...
#: ... when, over at least ROUND_MIN_FRAMES verified frames, this share of them no longer
#: correlates with the first view to REKEY_CC (a disk with a mark turning in the plane does).
OTHER_VIEW_SHARE = 0.25
ROUND_MIN_FRAMES = 30
#: A round object whose texture, its shading taken out, holds under MIN_TURN_SHARE of the turning
#: information keeps its angle after ROUND_MIN_FRAMES verified frames only if the angles fitted on
#: them span more than this many times their median 1-sigma: a turn beyond the noise, which only
#: something on it that turns with it (an ornament's cap) can show. Two angles each within 3 sigma
#: of one value span at most 6 sigma. A plain lit ball swinging 17 deg on a pendulum: the fitted
#: angles span 3.6 sigma (0.85 deg, its shading staying with the light); juangomez's ornament, 2.2 %
#: left after its shading, 9.4 sigma on its first 17 frames (16 deg, following the swing).
TURN_SEEN_SIGMAS = 6.0
#: A disk's centre as its texture places it may be this far from its outline's, as a fraction of
#: the template's larger side: where the texture holds it places the centre more finely than the
#: outline (development film: within 2.6 px of the ball's silhouette on 99 % of the frames, the
#: outline alone 3.7 px, as the wall's shadow band changes behind it), while a spinning ball's
#: texture slides up to 10 px off it. The least allowance that kept every frame of the
#: development film within 1 % of the width for three boxes (3.5 % left 5 frames off for a box
#: drawn 87 px tall).
DISK_AGREE_FRAC = 0.055
#: Smallest grey-level standard deviation of a region worth tracking.
MIN_TEXTURE_STD = 3.0
#: Margin of the full-resolution ECC window round the coarse footprint, px (the half-resolution
#: pose is good to about a pixel; ECC's 5x5 smoothing needs a border).
FINE_MARGIN_PX = 12
#: Correlation the fast (inverse-compositional) fit must reach to be kept; below it, the frame is
#: registered by OpenCV's ECC on the wide window (a spinning or changing object).
FAST_CC = 0.97
#: Correlations closer than this are equal (float32 sums over the template).
CC_ROUNDING = 1e-6
#: Turns of the template tried round the predicted angle when re-acquiring, degrees.
SEARCH_TURNS_DEG = (0.0, -2.0, 2.0, -4.0, 4.0, -6.0, 6.0, -8.0, 8.0)
#: The rotation search (:mod:`._turn_search`) looks this far round the predicted angle, rad; a
#: best turn farther than this from the fitted angle fails the fit's angle whatever its score.
TURN_SEARCH_RAD = math.radians(45.0)
#: A fitted angle fails the rotation check when a turn of the template's inscribed disc within
#: :data:`TURN_SEARCH_RAD` of the prediction correlates better than the fitted angle's by this
#: much (normalised correlation) ...
TURN_SCORE_GAP = 0.1
#: ... and lies more than this from it, rad.
TURN_DIFF_RAD = math.radians(3.0)
#: Least correlation of the best turn near the predicted angle; under it the disc's turn is
#: looked for all round.
MIN_TURN_SCORE = 0.5
#: ... and also where the cells of the region that do not match the fitted pose hold at least this
#: share of its turning information (:func:`._observability.unmatched_turn_share`, about the region's
#: centre): part of what tells the angle disagrees with the fit.
TURN_CHECK_SHARE = 0.25
#: A turn found by the rotation check at least this well correlated, within :data:`TURN_DIFF_RAD`
#: of the fitted angle, confirms that angle (it ends a branch, :meth:`MarkerlessTracker._settle`).
TURN_CONFIRM_SCORE = REKEY_CC
#: ECC stopping rule: 60 iterations or a correlation gain below 1e-5.
ECC_CRITERIA = (3, 60, 1e-5)  # cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT


def texture_std(first_gray, roi) -> float:
    """Grey standard deviation of a region ``(u, v, w, h)`` (px) of ``first_gray``: the markerless
    tracker needs at least :data:`MIN_TEXTURE_STD` to register it."""
    u, v, w, h = (int(round(x)) for x in roi)
    if w <= 0 or h <= 0:
        return 0.0
    return float(first_gray[max(v, 0) : v + h, max(u, 0) : u + w].astype(np.float32).std())


def _euclid(theta, tx, ty):
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s, tx], [s, c, ty]], np.float32)


def _params(W):
    """(θ, tx, ty) of the rigid part of a 2x3 warp (polar angle of its linear part)."""
    th = math.atan2(float(W[1, 0] - W[0, 1]), float(W[0, 0] + W[1, 1]))
    return th, float(W[0, 2]), float(W[1, 2])


def _rigid(W):
    """The rigid warp nearest to ``W`` (same translation, the polar rotation)."""
    return _euclid(*_params(W))


def _near_rigid(W, tol=0.05):
    """An affine refinement is accepted only as a small correction of a rigid motion."""
    A = np.asarray(W[:, :2], float)
    sv = np.linalg.svd(A, compute_uv=False)
    return bool(abs(sv[0] - 1) < tol and abs(sv[1] - 1) < tol)


class MarkerlessTracker:
    """One object's markerless tracker.

    Parameters
    ----------
    obj : ObjectConfig
        Needs ``roi = (u, v, w, h)``, px, first frame.
    plane_map : PlaneMap
    first_gray : ndarray (H, W) uint8

    Raises
    ------
    InputError
        The region leaves the frame or holds no texture to register.
    """

    def __init__(self, obj, plane_map, first_gray):
        import cv2

        self.obj, self.pm = obj, plane_map
        H, W = first_gray.shape[:2]
        u, v, w, h = (int(round(x)) for x in obj.roi)
        u0, v0, u1, v1 = max(u, 0), max(v, 0), min(u + w, W), min(v + h, H)
        if u1 - u0 < 8 or v1 - v0 < 8 or w > W or h > H:
            raise InputError(
                f"object {obj.id!r}: roi {list(obj.roi)} lies outside the {W}x{H} frame, is larger "
                "than it, or is smaller than 8x8 px; draw the region round the object in the first frame"
            )
        tmpl = first_gray[v0:v1, u0:u1].astype(np.float32)
        std = texture_std(first_gray, obj.roi)
        if std < MIN_TEXTURE_STD:
            raise InputError(
                f"object {obj.id!r}: roi {list(obj.roi)} holds no texture (grey std "
                f"{std:.3g}); draw it round the object's edges or surface detail"
            )
        self.origin = np.array([u0, v0], float)  # template pixel (0, 0) in the first frame
        self.tmpl0 = tmpl
        self.key = tmpl
        #: 1-sigma of the angle at which the keyframe was cut from its frame, rad (inf: that
        #: frame's angle was not a measurement); a pose registered on the keyframe inherits it
        self.key_sigma_rad = 0.0
        #: the template point (px from its centre) the pose was held about on the frame the keyframe
        #: was cut at, when that frame's angle was not a measurement (:meth:`_settle`), else None
        self.key_at = None
        self._ic: list = []  # (template, ICAffine): the first template's, then the keyframe's
        self.size = (u1 - u0, v1 - v0)
        self.poses: list = []  # last two accepted (theta, tx, ty): first-frame px -> image px
        self.last = None  # the last accepted pose before a run of lost frames
        self._norm = None  # (template, its normalised copy) for the uncertainty
        #: 1-sigma of the object's first-frame angle (a table's top edge), rad: a floor of every frame's
        self.theta0_sigma_rad = 0.0
        # reference points: a 3x3 grid over the template, as plane points of the first frame
        gx, gy = np.meshgrid(np.linspace(0, self.size[0] - 1, 3), np.linspace(0, self.size[1] - 1, 3))
        self.grid = np.column_stack((gx.ravel(), gy.ravel()))
        #: why this object's angle cannot be measured (its appearance does not change when it
        #: turns), or None: then every pose is held upright about the template's centre
        self.theta_note, sym = (None, None) if obj.kind == "table" else theta_unobservable(tmpl)
        self.sym0 = None if sym is None else self.origin + sym  # the centre of symmetry, first-frame px
        # the point reported: the region's centre; with no angle, any point but the centre of
        # symmetry would be reported where it would be had the object not turned
        ref_px = np.array([u + w / 2, v + h / 2], float)
        if sym is not None and 0 <= sym[0] <= self.size[0] and 0 <= sym[1] <= self.size[1]:
            ref_px = self.sym0
        q = plane_map.to_plane(self.grid + self.origin)
        centre = plane_map.to_plane(ref_px[None, :])[0]
        th0 = obj.theta0_rad or 0.0
        c, s = math.cos(-th0), math.sin(-th0)
        self.obj_pts = (q - centre) @ np.array([[c, -s], [s, c]]).T
        self._obj_frame = (centre, th0)  # the point reported and the first angle, plane units
        self._cv2 = cv2
        self.centre0 = self.origin + np.array(self.size, float) / 2  # template centre, first-frame px
        self.verifier = PoseVerifier(first_gray, (u0, v0, u1, v1), self.size)
        self.verifier.check_turn = self.theta_note is None
        self.twins = TwinGuard(self.size)  # the last verified frames, against a look-alike found instead
        self.verifier.fb.keyframe(self, first_gray, _euclid(0.0, 0.0, 0.0))
        #: why the angle is not reported although the texture gives one (a round outline), or None
        self.round_note = None
        self._shading_checked = False  # the first disk's texture was weighed against its shading
        #: (why, frame found) while a round object's texture, its shading taken out, tells no angle
        #: and it has been verified on fewer than ROUND_MIN_FRAMES frames; else None
        self.shading_note = None
        self.views = [0, 0]  # verified frames, and those not a turned copy of the first view
        #: (angle, its 1-sigma), rad, of the first ROUND_MIN_FRAMES verified frames with a measured angle
        self._turns: list = []
        self._unshaded = math.nan  # the first disk's unshaded turn share (:func:`unshaded_turn_share`)
        self.reason = None  # why the last frame was lost ("mismatch", "jump", "background", "twin", "lost")
        self.min_cc = MIN_CC
        self._turn_info: tuple = (None, None)  # (template, its cells' turning information)
        #: verified frames, and those whose angle was not a measurement (:meth:`_angle_unmatched`)
        self.theta_frames = [0, 0]
        self._rings: tuple = (None, None)  # (template, its PolarRings)
        self._disc = inscribed_disc(tmpl.shape)  # the templates' inscribed disc: centre, radius, mask
        self._back: tuple = (None, None, None)  # (image, pose bytes, the last _warp_back)
        self._disc_tmpl: tuple = (None, None)  # (template, its disc's pixels normalised for _disc_cc)
        #: the last frame's angle was not a measurement, its fit off the last angle measured by over
        #: TURN_DIFF_RAD and not confirmed by the rotation check: the fits that follow are on its branch
        self._off_branch = False
        self._unmatched: tuple = (None, None, None, None)  # (image, template, (pose bytes, cc), _angle_unmatched)
        self._turn_confirmed = False  # the rotation check found the fitted angle's turn, well correlated
        self._turn_failed = False  # this frame's fitted angle failed the rotation check (:meth:`_turn_check`)
        #: the last angle measured (first-frame px -> image px), rad: a pose whose angle is not a
        #: measurement is held at it
        self.theta_hold = 0.0
        #: the disk's centre in the first frame (first-frame px) once an outline found it, or None
        self.disk_c0 = None
        #: the first frame whose points came from the pose turned upright about the disk's centre
        #: (:meth:`_upright_disk`): the round note's, or later when the disk was learned after it
        self.upright_at = None

    # -- registration -------------------------------------------------------------
    def _window(self, gray, W, margin):
        """The part of ``gray`` round the template's footprint under W (float32: a copy, or a view
        to read only when ``gray`` is float32 already) and its offset (px)."""
        w, h = self.size
        corners = (np.array([[0, 0], [w, 0], [0, h], [w, h]], float) + self.origin) @ W[:, :2].T.astype(float) + W[
            :, 2
        ].astype(float)
        H, Wd = gray.shape[:2]
        x0, y0 = (int(max(np.floor(corners[:, i].min() - margin), 0)) for i in (0, 1))
        x1, y1 = int(min(np.ceil(corners[:, 0].max() + margin), Wd)), int(min(np.ceil(corners[:, 1].max() + margin), H))
        if x1 - x0 < 8 or y1 - y0 < 8:
            return None, None
        return np.asarray(gray[y0:y1, x0:x1], np.float32), np.array([x0, y0], np.float32)

    def _ecc(self, tmpl, gray, W0, levels=3, direct=False):
        """ECC of ``tmpl`` in ``gray`` from the warp W0 (first-frame px -> image px); (W, cc) or None.

        The reduced levels run on a window wide enough for the prediction's error; the full-
        resolution pass on a window a few pixels round the coarse footprint (ECC takes the
        gradient of its whole input image, so the window's size is its cost).
        """

        def ic_fine(window, W):
            return self._ic_fine(tmpl, window, W)

        if direct:
            # a prediction from smooth motion is good to a pixel: the fine fit alone, from it
            r = self.fit_near(gray, W0, ic_fine)
            if r is not None:
                return r
        crop, off = self._window(gray, W0, 0.5 * max(self.size) + 16)
        if crop is None:
            return None
        W = W0.copy()
        W[:, 2] -= off
        W = self._ecc_coarse(tmpl, crop, W, levels)
        if W is None:
            return None
        Wg = W.copy()
        Wg[:, 2] += off
        r = self.fit_near(gray, Wg, ic_fine)
        if r is not None:
            return r
        r = self._ecc_fine(tmpl, crop, W)  # the robust path, on the wide window
        if r is None:
            return None
        r[0][:, 2] += off
        return r

    def fit_near(self, gray, W, fit, margin_px=FINE_MARGIN_PX):
        """``fit(window, W_window)`` on the part of ``gray`` ``margin_px`` round the template's
        footprint under the pose ``W`` (first-frame px -> image px); its pose ``(W, cc, ...)`` with
        the window's offset put back, or None (the footprint off the frame, or the fit failing)."""
        window, off = self._window(gray, W, margin_px)
        if window is None:
            return None
        Ww = W.copy()
        Ww[:, 2] -= off
        r = fit(window, Ww)
        if r is not None:
            r[0][:, 2] += off
        return r

    def _ic_for(self, tmpl):
        """(:class:`ICRigid`, :class:`ICAffine`) of ``tmpl`` (the first template's are kept, the
        keyframe's renewed with it)."""
        for t, ic in self._ic:
            if t is tmpl:
                return ic
        ic = (ICRigid(tmpl), ICAffine(tmpl))
        self._ic = [self._ic[0], (tmpl, ic)] if self._ic else [(tmpl, ic)]
        return ic

    def _to_tmpl(self, W):
        """First-frame px -> image px  into  template px -> image px (:meth:`_from_tmpl` undoes it)."""
        W = W.copy()
        W[:, 2] += (W[:, :2] @ self.origin).astype(np.float32)
        return W

    def _from_tmpl(self, W):
        W = W.copy()
        W[:, 2] -= (W[:, :2] @ self.origin).astype(np.float32)
        return W

    def _ecc_coarse(self, tmpl, gray_f, W0, levels=3):
        """Rigid ECC on the reduced pyramid levels (robust, 3 parameters); W0 and the result map
        first-frame px -> ``gray_f`` px. None when every level tried fails; a level that fails
        while a finer one converges is passed over (a dark disc with little texture, 8 px across
        at the coarsest level, gives ECC a NaN there and fits at the next)."""
        cv2 = self._cv2
        W = self._to_tmpl(_rigid(W0))
        tried, fitted = 0, 0
        for lvl in range(levels - 1, 0, -1):
            f = 0.5**lvl
            t = cv2.resize(tmpl, None, fx=f, fy=f, interpolation=cv2.INTER_AREA)
            if min(t.shape) < 8:
                continue
            img = cv2.resize(gray_f, None, fx=f, fy=f, interpolation=cv2.INTER_AREA)
            Wl = W.copy()
            Wl[:, 2] *= f
            tried += 1
            try:
                _, Wl = cv2.findTransformECC(t, img, Wl, cv2.MOTION_EUCLIDEAN, ECC_CRITERIA, None, 3)
            except cv2.error:
                continue
            Wl[:, 2] /= f
            W, fitted = Wl, fitted + 1
        return None if tried and not fitted else self._from_tmpl(W)

    def _ic_fine(self, tmpl, gray_f, W0):
        """Full-resolution inverse-compositional fit (:mod:`._ic`) from the coarse pose: (W, cc),
        or None when it fails or matches poorly (appearance changing, a spinning object).

        Rigid first, then affine from the rigid pose: perspective and lens distortion make a
        planar object's image motion slightly non-rigid (0.7 % in scale across a table on the
        demo render); the affine fit is kept when it is near-rigid and matches at least as well,
        and the rigid pose comes from the warped points in the plane afterwards.
        """
        rigid, affine = self._ic_for(tmpl)
        smooth = rigid.smooth(gray_f)
        fit = rigid.refine(smooth, self._to_tmpl(W0), smoothed=True)
        if fit is None or fit[1] < FAST_CC:
            return None
        W, cc = self._keep_affine(tmpl, gray_f, fit, affine.refine(smooth, fit[0], smoothed=True))
        return self._from_tmpl(W), cc

    def _ecc_fine(self, tmpl, gray_f, W0):
        """The same two steps with OpenCV's ECC (slower, wider basin): (W, cc) or None."""
        cv2 = self._cv2
        try:
            cc, W = cv2.findTransformECC(tmpl, gray_f, self._to_tmpl(W0), cv2.MOTION_EUCLIDEAN, ECC_CRITERIA, None, 5)
        except cv2.error:
            return None
        W, cc = self._keep_affine(tmpl, gray_f, (W, float(cc)))
        return self._from_tmpl(W), cc

    def _keep_affine(self, tmpl, gray_f, rigid_fit, aff=None):
        """The affine refinement of ``rigid_fit`` (template px -> ``gray_f`` px, cc) where it is
        near-rigid and matches at least as well, else ``rigid_fit``.

        ``aff``: an affine fit already made (the fast one); OpenCV's ECC from the rigid pose where
        it is missing or worse, as a thin template (a table edge) leaves the affine terms weakly
        determined for the fast fit.
        """
        cv2 = self._cv2
        # "at least as well" up to float32 rounding of the correlation (1e-7 on a 2e5 px template)
        if aff is None or aff[1] < rigid_fit[1] - CC_ROUNDING:
            try:
                cc_a, Wa = cv2.findTransformECC(
                    tmpl, gray_f, rigid_fit[0].copy(), cv2.MOTION_AFFINE, ECC_CRITERIA, None, 5
                )
                aff = (Wa, float(cc_a))
            except cv2.error:
                aff = None
        if aff is not None and aff[1] >= rigid_fit[1] - CC_ROUNDING and _near_rigid(aff[0]):
            return aff[0], float(aff[1])
        return rigid_fit[0], float(rigid_fit[1])

    def _search(self, tmpl, gray, W_pred):
        """Re-acquire by normalised cross-correlation of the rotated template round the prediction.

        The template is tried at the predicted angle and at SEARCH_TURNS_DEG from it (after lost
        frames the object may have turned); the best match above MIN_CC wins.
        """
        th_pred, tx, ty = _params(W_pred)
        w, h = self.size
        ctr = self.origin + (w / 2, h / 2)
        cx, cy = W_pred[:, :2] @ ctr + W_pred[:, 2]
        H, Wd = gray.shape
        m = max(w, h)
        x0, y0 = int(max(cx - w / 2 - m, 0)), int(max(cy - h / 2 - m, 0))
        x1, y1 = int(min(cx + w / 2 + m, Wd)), int(min(cy + h / 2 + m, H))
        if x1 - x0 <= w or y1 - y0 <= h:
            return None
        window = gray[y0:y1, x0:x1].astype(np.float32)
        found = best_turned_match(window, tmpl, th_pred, SEARCH_TURNS_DEG, MIN_CC)
        if found is None:
            return None
        _, th, loc = found
        new_ctr = np.array([x0 + loc[0] + w / 2, y0 + loc[1] + h / 2])
        R = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
        t = new_ctr - R @ ctr
        return _euclid(th, t[0], t[1])

    def _centred(self, W):
        """(θ, tx, ty) of the rigid pose that puts the template's centre where ``W`` does: an
        affine fit's scale (up to 5 %) would otherwise move the prediction by that share of the
        centre's distance from the image's origin."""
        th = _params(W)[0]
        c = W[:, :2].astype(float) @ self.centre0 + W[:, 2].astype(float)
        t = c - np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]]) @ self.centre0
        return th, float(t[0]), float(t[1])

    def _search_near(self, gray, W_pred, frame):
        """The keyframe searched round the prediction ``W_pred`` (:meth:`_search`), fitted and
        verified: (W, cc), or None."""
        W_s = self._search(self.key, gray, W_pred)
        alt = None if W_s is None else self._ecc(self.key, gray, W_s)
        if alt is None or alt[1] < MIN_CC:
            return None
        alt = (self._held(alt[0]), alt[1])
        return alt if self.verifier.verify(self, gray, alt[0], frame, alt[1]) is None else None

    def _twin_check(self, gray, frame, fit):
        """The verified fit ``(W, cc)`` of a frame found again after lost frames, judged against a
        look-alike (:class:`._twins.TwinGuard`): ``fit`` itself, the look-alike's match fitted and
        verified in its place when continuity says that is the object, or None (cannot tell)."""
        W = fit[0]
        found = W[:, :2].astype(float) @ self.centre0 + W[:, 2]
        verdict, rival = self.twins.judge(self.key, gray, frame, found, MIN_CC)
        if verdict == "keep":
            return fit
        if verdict == "swap":
            _, c, th = rival
            R = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
            t = c - R @ self.centre0
            alt = self._ecc(self.key, gray, _euclid(th, t[0], t[1]))
            if alt is not None and alt[1] >= MIN_CC:
                alt = (self._held(alt[0]), alt[1])
                at = alt[0][:, :2].astype(float) @ self.centre0 + alt[0][:, 2]
                near = np.hypot(*(at - c)) < 0.25 * max(self.size)
                if near and self.verifier.verify(self, gray, alt[0], frame, alt[1]) is None:
                    return alt
        return None

    def _round_check(self, first_view, frame):
        """Sets :attr:`round_note` once the outline is known to be round and the region is no
        longer a turned copy of its first view on :data:`OTHER_VIEW_SHARE` of the verified frames
        (a ball spinning in depth; also a rolling disk whose region holds a background that does not
        turn with it: the note says what was measured, not which)."""
        self.views[0] += 1
        self.views[1] += not first_view
        out = self.verifier.outline
        if self.round_note is not None or self.theta_note is not None or out is None or out.roundness < ROUND_MIN:
            return
        if out.disk0 is not None and not self._shading_checked:
            # once, from the first frame's disk: a plain ball's dark and lit sides are the light's,
            # and a turn of them tells no angle
            self._shading_checked = True
            share = unshaded_turn_share(self.tmpl0, np.asarray(out.disk0[0], float) - self.origin, float(out.disk0[1]))
            self._unshaded = share
            if not share >= MIN_TURN_SHARE:
                self.shading_note = (
                    f"its outline is round (circularity {out.roundness:.2f}), so its angle would come from "
                    f"its texture alone; once a lit ball's shading is taken out its texture holds "
                    f"{100 * share:.2g} % of its region's turning information (under {100 * MIN_TURN_SHARE:.3g} %), "
                    f"and it was verified on fewer than {ROUND_MIN_FRAMES} frames, too few for its views to tell "
                    "whether its texture turns with it",
                    frame,
                )
        n, other = self.views
        if n >= ROUND_MIN_FRAMES and self.shading_note is not None:
            # a small mark (an ornament's cap) tells the angle though the share is low: it shows as
            # a turn beyond the noise; a plain ball's fitted angle stays at its first, the light's
            self.round_note = self._turn_unseen(out.roundness)
            self.shading_note = None
            if self.round_note is not None:
                return
        if n >= ROUND_MIN_FRAMES:
            # its views judge from here on: a ball spinning in depth is found by its views
            self.shading_note = None
        if n >= ROUND_MIN_FRAMES and other >= OTHER_VIEW_SHARE * n:
            self.round_note = (
                f"its outline is round (circularity {out.roundness:.2f}), so its angle would come from "
                f"its texture alone, and on {100 * other / n:.0f} % of {n} frames its region does not "
                f"match a turned copy of its first view (correlation under {REKEY_CC:g})"
            )

    def _turn_unseen(self, roundness):
        """Why a round object whose texture, its shading taken out, tells under
        :data:`._observability.MIN_TURN_SHARE` has no angle after :data:`ROUND_MIN_FRAMES` verified
        frames: its fitted angles (:attr:`_turns`) span no more than :data:`TURN_SEEN_SIGMAS` times
        their median 1-sigma; None when they turned beyond that."""
        th = np.array([a for a, _ in self._turns])
        sig = float(np.median([s for _, s in self._turns])) if self._turns else math.inf
        span = float(np.ptp(th)) if th.size else 0.0
        if th.size >= 2 and span > TURN_SEEN_SIGMAS * sig:
            return None
        return (
            f"its outline is round (circularity {roundness:.2f}), so its angle would come from its "
            f"texture alone, which, once a lit ball's shading is taken out, holds {100 * self._unshaded:.2g} % "
            f"of its region's turning information (under {100 * MIN_TURN_SHARE:.3g} %), and over {self.views[0]} "
            f"frames its fitted angle spans {math.degrees(span):.2g} deg, no more than "
            f"{TURN_SEEN_SIGMAS:g} times its 1-sigma ({math.degrees(sig):.2g} deg): nothing on it shows a turn"
        )

    def _held(self, W):
        """``W`` turned back upright about the object's centre of symmetry when its angle is not
        observable (there the fitted angle is noise, and it would swing the template's centre)."""
        if self.theta_note is None:
            return W
        return _euclid(0.0, *(W[:, :2].astype(float) @ self.sym0 + W[:, 2] - self.sym0))

    def _upright_disk(self, W, W_pts):
        """The pose the points of a round object whose angle is not reported (:attr:`round_note`)
        come from: ``W`` turned back to the first frame's angle about its disk's centre, which
        stays where ``W`` puts it; else ``W_pts``. The reported point is then where the region's
        centre would be had the disk not turned: the angle it would hang on is its texture's,
        not reported (PhysTrack RollingCylinder, a region 10 % off the disk's centre: held at a
        texture angle stopped near -90 deg while the disk rolled on, 8-9 px from where the box
        centre carried by the disk's centre was)."""
        out = self.verifier.outline
        if out is not None and out.disk0 is not None:
            # kept: an outline learned again over a filled-in background may not find the disk
            self.disk_c0 = np.asarray(out.disk0[0], float)
        if self.round_note is None or self.disk_c0 is None:
            return W_pts
        c = self.disk_c0
        return _euclid(0.0, *(W[:, :2].astype(float) @ c + W[:, 2] - c))

    def disk_lever(self):
        """``(d_pose, d_first, th0, frame, measured)`` for an object whose angle was found unmeasurable on
        the way (a round outline, :attr:`round_note`; ``frame``: the first whose points came
        upright, :attr:`upright_at`): its disk's centre in the
        object's own frame (the frame of :attr:`obj_pts`, plane units) where the poses put it
        (``d_pose``: :class:`._occlusion.SeenDisk` learned it under them) and where the first
        frame shows it (``d_first``), the first angle ``th0`` (rad), and ``measured``: frame -> the
        disk's centre (2,) in plane units where its own edge showed it in that frame
        (:meth:`._occlusion.SeenDisk.measured`); else None.

        The frames tracked before the angle was dropped report the point as the texture turned
        it; with no angle reported, the point is the one the disk's centre carries without
        turning: ``t + s R(theta) d_pose - R(th0) d_first`` for a frame fitted at ``(t, theta, s)``
        (PhysTrack RollingCylinder, the box moved by 10 %: 8-9 px off on the 35 frames before
        the note). So do the frames after the note tracked before the disk was known (a 25 px box
        inside the disc learned it 57 frames after the note: 4-6 px off there). A frame whose
        disk edge was measured reports that centre less ``R(th0) d_first``: held poses chained
        over keyframes place the disk up to 6 px off where its edge lies."""
        if self.round_note is None or self.disk_c0 is None:
            return None
        centre, th0 = self._obj_frame
        c, s = math.cos(-th0), math.sin(-th0)
        seen = self.verifier.seen_disk.pose_c
        pose_c = self.disk_c0 if seen is None else seen
        d_pose, d_first = (
            (self.pm.to_plane(p[None, :])[0] - centre) @ np.array([[c, -s], [s, c]]).T for p in (pose_c, self.disk_c0)
        )
        seen_at = self.verifier.seen_disk.measured()
        measured = dict(zip(seen_at, self.pm.to_plane(np.array(list(seen_at.values()), float)))) if seen_at else {}
        return d_pose, d_first, th0, self.upright_at, measured

    def _sigma_theta(self, tmpl, gray, W, mask=None):
        """Gauss-Newton σ of θ (rad) of ``tmpl`` registered by ``W`` (:func:`._observability.sigma_theta`)."""
        warped = self._warp_back(gray, W)
        if warped is None:
            return math.inf
        return sigma_theta(tmpl, warped, mask, None if mask is not None else self._normalised(tmpl))

    def _normalised(self, tmpl):
        """``tmpl`` at zero mean and unit variance (kept for the first template and the keyframe)."""
        hit = self._norm if self._norm is not None and self._norm[0] is tmpl else None
        if hit is None:
            self._norm = hit = (tmpl, (tmpl - tmpl.mean()) / (tmpl.std() + 1e-9))
        return hit[1]

    def _warp_back(self, gray, W, keep=True):
        """The current image resampled onto the template grid by the pose W (float32), or None.
        ``keep``: remembered for the next call with this image and pose (False for another image
        than the frame's, as a scene snapshot, that would push the frame's patch out)."""
        key = W.tobytes()
        if self._back[0] is gray and self._back[1] == key:  # the checks of one pose share it
            return self._back[2]
        cv2 = self._cv2
        crop, off = self._window(gray, W, 4)
        if crop is None:
            return None
        Wfull = W.copy()
        Wfull[:, 2] += (W[:, :2] @ self.origin).astype(np.float32) - off
        h, w = self.tmpl0.shape
        back = cv2.warpAffine(
            crop, Wfull, (w, h), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP, borderMode=cv2.BORDER_REPLICATE
        )
        if keep:
            self._back = (gray, key, back)
        return back

    def detect(self, gray, frame):
        """The object's reference points in ``gray``: a :class:`Detection`, or None (lost)."""
        if len(self.poses) >= 2:
            (a0, x0, y0), (a1, x1, y1) = self.poses[-2], self.poses[-1]
            W_pred = _euclid(2 * a1 - a0, 2 * x1 - x0, 2 * y1 - y0)
        elif self.poses:
            W_pred = _euclid(*self.poses[-1])
        else:
            W_pred = _euclid(0.0, 0.0, 0.0)
        self._turn_failed = self._turn_confirmed = False
        self._back = (None, None, None)  # a frame's buffer may be reused for the next frame
        fit = self._ecc(self.tmpl0, gray, W_pred, direct=len(self.poses) >= 2)
        tmpl = self.tmpl0
        first_view = fit is not None and fit[1] >= REKEY_CC  # the frame is a turned copy of the first
        if (fit is None or fit[1] < REKEY_CC) and self.key is not self.tmpl0:
            alt = self._ecc(self.key, gray, W_pred if fit is None else fit[0])
            if alt is not None and (fit is None or alt[1] > fit[1]):
                fit, tmpl = alt, self.key
        if fit is None or fit[1] < MIN_CC:
            # re-acquire round the prediction, then (after lost frames) round the last pose seen
            starts = [W_pred] if self.last is None or self.poses else [W_pred, _euclid(*self.last)]
            for W_start in starts:
                W_s = self._search(self.key, gray, W_start)
                if W_s is not None:
                    alt = self._ecc(self.key, gray, W_s)
                    if alt is not None and alt[1] >= MIN_CC:
                        fit, tmpl = alt, self.key
                        break
        mask, visible = None, 1.0
        if (fit is None or fit[1] < MIN_CC) and self.poses:
            # part of the object may be covered (a hand): fit the part still in view
            part = masked_fit(self, self.key, gray, W_pred)
            if part is not None:
                fit, tmpl, mask, visible = part[:2], self.key, part[2], part[3]
        self.reason = None
        if (
            fit is not None
            and fit[1] >= MIN_CC
            and mask is None
            and self.theta_note is None
            and self.round_note is None
        ):
            self._turn_check(tmpl, gray, fit, W_pred)
        if fit is not None and fit[1] >= MIN_CC:
            fit = (self._held(fit[0]), fit[1])
            self.reason = self.verifier.verify(self, gray, fit[0], frame, fit[1])
        if self.reason is not None and self.poses:
            # the fit converged on something else (a blurred fast frame): the template searched
            # round the prediction first, then anywhere in the frame
            near = self._search_near(gray, W_pred, frame)
            if near is not None:
                fit, tmpl, mask, visible, self.reason = near, self.key, None, 1.0, None
        if fit is None or fit[1] < MIN_CC or self.reason is not None:
            # converged on something else, or nowhere: the template anywhere in the frame
            alt = self.verifier.reacquire(self, gray, frame, MIN_CC)
            if alt is not None:
                fit, tmpl, mask, visible, self.reason = (self._held(alt[0]), alt[1]), self.key, None, 1.0, None
            self.reason = self.reason or (None if fit is not None and fit[1] >= MIN_CC else "lost")
        if self.reason is None and not self.poses and self.last is not None:
            # found again after lost frames: a look-alike beside it (identical pucks) is told apart by
            # continuity, or the frame is not trusted
            twin = self._twin_check(gray, frame, fit)
            if twin is None:
                self.reason = "twin"
            elif twin is not fit:
                fit, tmpl, mask, visible = twin, self.key, None, 1.0
        if self.reason is not None:
            if self.reason == "drift":  # the keyframe learned the slide
                self.key, self.key_sigma_rad, self.key_at = self.tmpl0, 0.0, None
                self.verifier.fb.to_first()
            self.verifier.lost_frame(gray, frame, MIN_CC)
            if self.poses:
                self.last = self.poses[-1]
            self._off_branch = False
            self.poses = []  # the next frame searches from the first frame's place, then the last seen
            return None
        self.verifier.confirm(gray, self.size)
        self._round_check(first_view, frame)
        (W, cc), mask, visible, why, sig, W_pts = self._settle(tmpl, gray, fit, mask, visible)
        self.verifier.seen_disk.held = why is not None  # the poses the next looks are taken under
        if why is None and math.isfinite(sig) and len(self._turns) < ROUND_MIN_FRAMES:
            self._turns.append((_params(W)[0], sig))
        W_pts = self._upright_disk(W, W_pts)
        if self.upright_at is None and self.round_note is not None and self.disk_c0 is not None:
            self.upright_at = frame
        self.poses = (self.poses + [self._centred(W)])[-2:]
        self.twins.remember(frame, gray, W[:, :2].astype(float) @ self.centre0 + W[:, 2])
        pts = (self.grid + self.origin) @ W_pts[:, :2].T.astype(float) + W_pts[:, 2]
        at = self.verifier.disk_at
        if at is not None and mask is None:
            # a disk (a ball): its texture slides over it as it spins, its outline does not. The
            # texture places the disk's centre more finely while it holds; beyond the outline's
            # own noise the points are moved to within it of the disk's centre
            gap = W_pts[:, :2].astype(float) @ self.verifier.outline.disk0[0] + W_pts[:, 2] - at
            n, lim = float(np.hypot(*gap)), DISK_AGREE_FRAC * max(self.size)
            if n > lim:
                pts = pts - gap * (1.0 - lim / n)
        # a partial view: fewer points than a whole one would give (its quality says so, and the
        # rigid fit keeps the object's known scale)
        n_expected = len(self.grid) if mask is None else int(math.ceil(len(self.grid) / max(visible, 1e-3)))
        return Detection(pts, self.obj_pts, False, n_expected, sigma_rad=sig, n_groups=1, score=cc, theta_why=why)

    def _turn_check(self, tmpl, gray, fitted, W_pred) -> None:
        """The rotation check of the fitted pose ``fitted = (W, cc)`` on ``tmpl`` (:mod:`._turn_search`):
        sets :attr:`_turn_failed` (this frame's angle is not reported) when the template's
        inscribed disc, turned about the point ``W`` (or the prediction) puts its centre on, matches
        best more than :data:`TURN_SEARCH_RAD` from the fitted angle, or more than
        :data:`TURN_DIFF_RAD` from it and :data:`TURN_SCORE_GAP` better than at it.

        Run only where the disc matches the fitted pose :data:`._observability.CELL_TURN_GAP` worse
        than the whole region (a still background in the region's corners held the fit while a mark
        on the object turned), or where the cells that do not match it hold :data:`TURN_CHECK_SHARE`
        of the turning information (the hand-held pendulum's disc before a post's edge: the rod's
        cells unmatched, 0.45-0.50 of it, on the first frame of each wrong turn). Sets
        :attr:`_turn_confirmed` where it finds nothing to doubt, or the fitted angle's turn within
        :data:`TURN_DIFF_RAD` at :data:`TURN_CONFIRM_SCORE`. The fit itself is kept, and so is all
        the tracker learns from the frame: a pose refitted from the turn found changed the keyframes
        and the outline learned (PhysTrack RollingCylinder, a 37 px region: its first outline 0.76
        round instead of a round one, so its angle was not known to be unmeasurable, and 253 later
        angles were over 5 deg off). Near the fitted angle and no better there the disc agrees with
        the fit (the development pendulum's ball, its texture changing as it spins in depth: best
        turn within 7.4 deg of the fit).
        """
        W, cc = fitted
        disc_cc = self._disc_cc(tmpl, gray, W) if self._disc[1] >= MIN_DISC_RADIUS_PX else math.inf
        if disc_cc > cc - CELL_TURN_GAP and self._angle_unmatched(tmpl, gray, W, cc)[2] < TURN_CHECK_SHARE:
            # the region's disc matches the fitted pose as well as the whole region does (as a
            # cell that matches, :data:`._observability.CELL_TURN_GAP`), and so do the cells that
            # tell the angle: nothing to doubt
            self._turn_confirmed = True
            return
        found = self._best_turn(tmpl, gray, W, W_pred)
        if found is None:
            return
        th, best, s_fit = found[:3]
        gap = abs(math.remainder(th - _params(W)[0], 2 * math.pi))
        if gap > TURN_SEARCH_RAD or (best - s_fit >= TURN_SCORE_GAP and gap >= TURN_DIFF_RAD):
            self._turn_failed = True
        self._turn_confirmed = gap < TURN_DIFF_RAD and best >= TURN_CONFIRM_SCORE

    def _rings_of(self, tmpl) -> PolarRings:
        """``tmpl``'s :class:`PolarRings` (kept for the last template)."""
        if self._rings[0] is not tmpl:
            self._rings = (tmpl, PolarRings(tmpl))
        return self._rings[1]

    def _disc_cc(self, tmpl, gray, W) -> float:
        """Correlation of ``tmpl``'s inscribed disc with ``gray`` warped back by the pose ``W``."""
        back = self._warp_back(gray, W)
        if back is None:
            return -1.0
        w = self._disc[2].ravel().astype(np.float64)
        if self._disc_tmpl[0] is not tmpl:  # the template's disc at zero mean and unit norm (it runs every frame)
            a = (tmpl.ravel() - float(tmpl.ravel() @ w) / w.sum()) * w
            self._disc_tmpl = (tmpl, a / (math.sqrt(float(a @ a)) + 1e-12))
        b = back.ravel().astype(np.float64)
        s1, s2 = float(b @ w), float((b * b) @ w)
        return float(self._disc_tmpl[1] @ b) / (math.sqrt(max(s2 - s1 * s1 / w.sum(), 0.0)) + 1e-9)

    def _best_turn(self, tmpl, gray, W, W_pred):
        """The best turn of ``tmpl``'s inscribed disc in ``gray``: ``(θ rad, its score, the fitted
        angle's score, the centre turned about (image px), that centre in first-frame px)``,
        about the better of the centres ``W`` and ``W_pred`` give; None when the disc tells no
        angle or leaves the frame."""
        rings = self._rings_of(tmpl)
        if not rings.tells_angle:
            return None
        c0 = self.origin + np.asarray(rings.centre)
        th_fit, th_pred = _params(W)[0], _params(W_pred)[0]
        out = None
        for Wc in (W, W_pred) if self.poses else (W,):
            c = Wc[:, :2].astype(float) @ c0 + Wc[:, 2].astype(float)
            scores = rings.scores(gray, c)
            if not np.isfinite(scores).all():
                continue
            th, best = PolarRings.best_near(scores, th_pred, TURN_SEARCH_RAD)
            if best < MIN_TURN_SCORE:  # not near the prediction (after lost frames): anywhere round
                th, best = PolarRings.best_near(scores, th_fit, math.pi)
            if out is None or best > out[1]:
                out = (th, best, PolarRings.at(scores, th_fit), c, c0)
        return out

    def _settle(self, tmpl, gray, fit, mask, visible):
        """The verified fit ``(W, cc)`` on ``tmpl`` made final: ``((W, cc), mask, visible, why, σ, W_pts)``.

        A partly covered view is refitted on the cells still in view; a view drifted from the
        first one (correlation under :data:`REKEY_CC`) becomes the keyframe. ``why``: why this
        frame's angle is not a measurement (:meth:`_angle_unmatched`, or a keyframe cut where the
        angle was not one), or None; σ: the angle's 1-sigma, rad, the keyframe's own included (a
        chain of keyframes walks, and its σ grows with it).
        """
        W, cc = fit
        why, turn_at, share, held = None, None, 0.0, None
        if mask is None and self.theta_note is None:
            why, turn_at, share = self._angle_unmatched(tmpl, gray, W, cc)
        if why is None and tmpl is not self.tmpl0 and not math.isfinite(self.key_sigma_rad):
            why = "keyframe"
        if why is None and self._turn_failed:
            why = "turn"  # the inscribed disc's best turn is far from the fitted angle
        off = mask is None and abs(math.remainder(_params(W)[0] - self.theta_hold, 2 * math.pi)) > TURN_DIFF_RAD
        if why is None and self._off_branch and off and not self._turn_confirmed:
            # the fit goes on from a frame whose angle was no measurement and was off the last one
            # measured: it is on that frame's branch (a still background's turn), not back on the
            # object's, until it comes back within TURN_DIFF_RAD of that angle or the rotation check
            # confirms it (the hand-held pendulum's left turns: 8-12 deg past, sigma 0.5 deg, on the
            # 4 frames after the one the check failed; the check, its disc holding the post's edge
            # too, scored their wrong turns best)
            why = "branch"
        if mask is None:
            self._off_branch = off and why is not None and not self._turn_confirmed
        if why == "keyframe" and self.key_at is not None:
            # registered on a keyframe cut where the angle was no measurement: the keyframe's own
            # cells turn about a point of that wrong view, not the object's; the point the cut frame
            # was held about is the object's (a turning disc: its centre, 9-13 px from the
            # keyframe's point on tests/test_track_markerless_turn.py), carried by the fit since
            turn_at = self.key_at
        if why is not None and turn_at is not None:
            # the fitted angle was set by what does not move with the object (a still background in
            # the region): so was the place of every point off the one the matching part turns
            # about. The points are reported from the pose held there at the last angle measured
            # (the fitted pose stays the registration's: its prediction and keyframe)
            held = self._held_about(W, turn_at)
        elif why is None and mask is None:
            self.theta_hold = _params(W)[0]
        if self.theta_note is None:
            self.theta_frames[0] += 1
            self.theta_frames[1] += why is not None
        if cc < REKEY_CC and mask is None:
            back = self._warp_back(gray, W)
            if back is not None and partly_covered(cell_correlations(tmpl, back)):
                # covered in part: no new keyframe from here (it would learn the occluder), and
                # the pose from the cells still in view
                part = masked_fit(self, tmpl, gray, W)
                if part is not None:
                    (W, cc), mask, visible = part[:2], part[2], part[3]
            elif back is not None:  # appearance drifted from the first frame: renew the keyframe here
                # a keyframe cut where the angle was no measurement carries no angle on
                key_sig = self._chained_sigma(tmpl, gray, W) if why is None else math.inf
                self.key, self.key_sigma_rad = back, key_sig
                self.key_at = None if held is None else turn_at
                self.verifier.fb.keyframe(self, gray, W)
        # the angle's information is that of the cells the pose re-explains, not the whole region's
        sig = self._chained_sigma(tmpl, gray, W, mask) / math.sqrt(1.0 - share) if why is None else math.nan
        return (W, cc), mask, visible, why, math.hypot(sig, self.theta0_sigma_rad), W if held is None else held

    def _chained_sigma(self, tmpl, gray, W, mask=None):
        """σ of θ (rad) of the pose ``W`` registered on ``tmpl``: the fit's own, and on a keyframe
        the keyframe's (its angle was itself measured)."""
        sig = self._sigma_theta(tmpl, gray, W, mask)
        return sig if tmpl is self.tmpl0 else math.hypot(sig, self.key_sigma_rad)

    def _cells_seen(self, W, shape):
        """(GRID, GRID) bool: the template's cells whose corners all fall inside a frame of ``shape``
        under the pose ``W``."""
        w, h = self.size
        xs, ys = np.linspace(0, w, GRID + 1), np.linspace(0, h, GRID + 1)
        gx, gy = np.meshgrid(xs, ys)
        c = (np.column_stack((gx.ravel(), gy.ravel())) + self.origin) @ W[:, :2].T.astype(float) + W[:, 2]
        inside = ((c[:, 0] >= 0) & (c[:, 0] <= shape[1]) & (c[:, 1] >= 0) & (c[:, 1] <= shape[0])).reshape(gy.shape)
        return inside[:-1, :-1] & inside[1:, :-1] & inside[:-1, 1:] & inside[1:, 1:]

    def _held_about(self, W, at):
        """``W`` turned to the last angle measured about the template point ``at`` (px from the
        template's centre), which stays where ``W`` puts it."""
        c = self.centre0 - 0.5 + np.asarray(at, float)
        p = W[:, :2].astype(float) @ c + W[:, 2].astype(float)
        th = self.theta_hold
        t = p - np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]]) @ c
        return _euclid(th, t[0], t[1])

    def _angle_unmatched(self, tmpl, gray, W, cc):
        """Why the pose ``W``'s angle is not a measurement on this frame, or None: the cells of the
        template that hold more than :data:`._observability.MAX_UNMATCHED_TURN` of its turning
        information (more than :data:`._observability.MAX_UNMATCHED_ABOUT_MATCHED` about the point
        the rest turns about: a round disc matching before a still corner) do not match the frame
        warped back, while the rest does. Its Gauss-Newton
        sigma then says nothing: the angle was set by the cells that still match (on the turning
        disc, the still rod and wall in its region's corners, 28-177 deg from the mark's angle).

        Returns ``(why, at, share)``: ``at`` the template point the matching cells turn about (px
        from the template's centre, :func:`._observability.turn_information`), where the pose is
        held when the angle is not a measurement; ``share`` the unmatched share (its σ is that of
        the rest: divided by ``sqrt(1 - share)``)."""
        key = (W.tobytes(), cc)
        m = self._unmatched
        if m[0] is gray and m[1] is tmpl and m[2] == key:  # the rotation check's, then _settle's
            return m[3]
        out = self._unmatched_of(tmpl, gray, W, cc)
        self._unmatched = (gray, tmpl, key, out)
        return out

    def _unmatched_of(self, tmpl, gray, W, cc):
        """:meth:`_angle_unmatched` computed."""
        if self._turn_info[0] is not tmpl:
            self._turn_info = (tmpl, cell_turn_info(tmpl, GRID))
        back = self._warp_back(gray, W)
        if back is None:
            return None, None, 0.0
        ccs = cell_correlations(tmpl, back)
        # only a view refitted on its cells in view (:meth:`_settle`) is judged by that fit; a cell
        # that matches nothing while the pose stands as fitted (a still background's corner the
        # object left) is the part that set its angle
        covered = cc < REKEY_CC and partly_covered(ccs)
        share, share_at, at = unmatched_turn_share(
            self._turn_info[1], ccs, self._cells_seen(W, gray.shape), CELL_CC if covered else -1.0
        )
        if share <= MAX_UNMATCHED_TURN and share_at <= MAX_UNMATCHED_ABOUT_MATCHED:
            return None, at, share
        if share > MAX_UNMATCHED_TURN:
            return f"{100 * share:.0f} %", at, share
        return f"{100 * share_at:.0f} % about the matching part's turning point", at, share


class MarkerlessDetector:
    """Detector for the ``markerless`` style: one :class:`MarkerlessTracker` per object."""

    def __init__(self, config, plane_map, first_gray):
        import dataclasses

        from ._table_edge import table_top_edge

        self.trackers = {}
        for o in config.objects:
            edge = None
            if o.kind == "table" and o.theta0_rad is None:
                # the table top's angle in the first frame, so that levelling from the table works
                edge = table_top_edge(first_gray, o.roi, plane_map)
                if edge is None and config.reference.level == "table":
                    raise InputError(
                        f"object {o.id!r}: roi {list(o.roi)} holds no horizontal top edge to level "
                        "from; draw the roi round the table's top edge (the edge crossing it from side "
                        "to side), or set reference.level to 'rest', 'line', 'value' or 'none'"
                    )
                o = dataclasses.replace(o, theta0_rad=edge.angle_rad if edge is not None else 0.0)
            t = MarkerlessTracker(o, plane_map, first_gray)
            # the table's angle is measured from its top edge: that edge's uncertainty is in every frame
            t.theta0_sigma_rad = edge.sigma_rad if edge is not None else 0.0
            self.trackers[o.id] = t

    def detect(self, gray, frame):
        return {oid: t.detect(gray, frame) for oid, t in self.trackers.items()}

    def theta_note(self, oid):
        """Why object ``oid``'s angle cannot be measured from its appearance (from its first
        region, or once its outline is known, a round outline), or None."""
        t = self.trackers.get(oid)
        return None if t is None else t.theta_note or t.round_note

    def theta_pending(self, oid):
        """``(why, frame)`` while object ``oid``'s angle is held for a verdict (a round object whose
        texture, its shading taken out, tells none, verified on too few frames for its views to
        judge), or None: if the film ends so, no frame's angle is reported."""
        t = self.trackers.get(oid)
        return None if t is None or t.theta_note or t.round_note else t.shading_note

    def disk_lever(self, oid):
        """:meth:`MarkerlessTracker.disk_lever` of object ``oid``."""
        t = self.trackers.get(oid)
        return None if t is None else t.disk_lever()

    def theta_unmatched(self, oid):
        """(frames verified, frames among them whose angle was not a measurement) of object ``oid``."""
        t = self.trackers.get(oid)
        return (0, 0) if t is None else tuple(t.theta_frames)

    def lost_reason(self, oid):
        """Why object ``oid`` was lost in the last frame (a status word), or None."""
        t = self.trackers.get(oid)
        return None if t is None or t.reason in (None, "lost") else t.reason
