"""Rotation search: the angle by which a template's disc is turned in a frame, about a given point.

The template's inscribed disc is resampled on polar rings about its centre (``cv2.warpPolar``);
the frame's disc about the point the pose puts that centre on, the same way. A turn of the
object about that point is a circular shift along the angle axis, so the circular
cross-correlation of the rings (by FFT, each ring's mean removed: a ring's mean does not turn)
scores every angle at once. Pixels outside the inscribed disc are not used: a region's corners
often hold a still background, which pulls an intensity fit back to the first view's angle while
a small mark on the object turns (PhysTrack's turning disc with a box drawn inside it).

The score is a normalised correlation (-1..1) over the rings, each ring weighted by its
radius (its pixels' share of the disc).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["PolarRings", "inscribed_disc", "N_ANGLES", "MIN_RADIUS_PX", "MIN_DISC_RADIUS_PX", "MIN_ENERGY"]

#: Samples round a ring (1 degree apart).
N_ANGLES = 360
#: Rings closer to the centre than this hold too few pixels to tell an angle, px.
MIN_RADIUS_PX = 3.0
#: ... nor closer than this share of the disc's radius (a centre a pixel off the object's turns
#: a mark there into a shift of the whole ring).
MIN_RADIUS_FRAC = 0.15
#: Harmonics round a ring below this are left out: a still, smooth shading across the object
#: (light from one side) varies round a ring as its first harmonic and outweighs a small mark.
MIN_HARMONIC = 3
#: Least radius of the inscribed disc for the search, px: a smaller disc's rings are a few dozen
#: pixels round, its turn a fraction of a pixel per degree (a 15 px pendulum bob), and a turn
#: found there is noise.
MIN_DISC_RADIUS_PX = 16.0
#: Least mean-square grey variation round the template's rings (grey levels squared) for the
#: disc to tell an angle at all: below it the disc is the same at every angle.
MIN_ENERGY = 1.0


def inscribed_disc(shape):
    """The disc a template of ``shape`` (h, w) is searched on: its centre (x, y px from pixel
    (0, 0)), its radius px (a pixel in from the template's edge) and its pixel mask (h, w) bool."""
    h, w = shape[:2]
    centre, radius = ((w - 1) / 2.0, (h - 1) / 2.0), 0.5 * min(w, h) - 1.0
    yy, xx = np.mgrid[0:h, 0:w]
    return centre, radius, np.hypot(xx - centre[0], yy - centre[1]) <= radius


class PolarRings:
    """A template's inscribed disc on polar rings, to score its turns in a frame.

    Parameters
    ----------
    tmpl : ndarray (h, w), float32
        The template.
    """

    def __init__(self, tmpl):
        import cv2

        self._cv2 = cv2
        #: centre (x, y px) and radius (px) of the inscribed disc used, and its pixel mask
        self.centre, self.radius, self.mask = inscribed_disc(tmpl.shape)
        self.n_r = max(int(round(self.radius)), 4)
        rings = self._rings(tmpl, self.centre)
        r = (np.arange(self.n_r) + 0.5) * self.radius / self.n_r
        self.weight = np.where(r >= max(MIN_RADIUS_PX, MIN_RADIUS_FRAC * self.radius), r, 0.0)
        spec = _high_pass(np.fft.rfft(rings, axis=0))
        self.energy = _energy(spec, self.weight)
        self._spec = np.conj(spec * self.weight)

    @property
    def tells_angle(self) -> bool:
        """Whether the disc is large enough (:data:`MIN_DISC_RADIUS_PX`) and changes when turned
        (its rings vary by more than :data:`MIN_ENERGY`)."""
        return (
            self.radius >= MIN_DISC_RADIUS_PX
            and self.energy / (N_ANGLES * float(self.weight.sum()) + 1e-12) > MIN_ENERGY
        )

    def _rings(self, img, centre):
        """(N_ANGLES, n_r) float64: ``img`` on rings about ``centre`` (x, y px) out to :attr:`radius`."""
        cv2 = self._cv2
        p = cv2.warpPolar(
            np.ascontiguousarray(img, np.float32),
            (self.n_r, N_ANGLES),
            (float(centre[0]), float(centre[1])),
            self.radius,
            cv2.WARP_POLAR_LINEAR | cv2.INTER_LINEAR,
        )
        return p.astype(np.float64)

    def scores(self, gray, centre):
        """The correlation of the template turned by each angle with ``gray``'s disc about
        ``centre`` (x, y image px, where the pose puts the template's centre).

        Returns
        -------
        ndarray (N_ANGLES,)
            Score of the turn by ``k`` degrees (image angle, y down: the sense of the pose's θ)
            at index ``k``; NaN everywhere when the disc leaves the frame.
        """
        H, W = gray.shape[:2]
        x, y, r = float(centre[0]), float(centre[1]), self.radius + 2
        if x - r < 0 or y - r < 0 or x + r >= W or y + r >= H:
            return np.full(N_ANGLES, np.nan)
        x0, y0 = int(x - r), int(y - r)
        crop = gray[y0 : int(math.ceil(y + r)) + 1, x0 : int(math.ceil(x + r)) + 1]
        spec = _high_pass(np.fft.rfft(self._rings(crop, (x - x0, y - y0)), axis=0))
        energy = _energy(spec, self.weight)
        cc = np.fft.irfft((spec * self._spec).sum(axis=1), n=N_ANGLES)
        return cc / (math.sqrt(energy * self.energy) + 1e-12)

    @staticmethod
    def at(scores, theta_rad) -> float:
        """The score of the turn ``theta_rad`` (linear between the whole degrees)."""
        k = (math.degrees(theta_rad) % 360.0) * N_ANGLES / 360.0
        i = int(math.floor(k)) % N_ANGLES
        a = k - math.floor(k)
        return float((1 - a) * scores[i] + a * scores[(i + 1) % N_ANGLES])

    @staticmethod
    def best_near(scores, theta_rad, half_width_rad):
        """(angle rad, score) of the best turn within ``half_width_rad`` of ``theta_rad``, the
        angle refined by a parabola through the peak and its neighbours; the angle is the one
        nearest to ``theta_rad`` (not wrapped into one turn)."""
        k0 = math.degrees(theta_rad) * N_ANGLES / 360.0
        half = int(math.ceil(math.degrees(half_width_rad) * N_ANGLES / 360.0))
        ks = np.arange(int(math.floor(k0)) - half, int(math.ceil(k0)) + half + 1)
        s = scores[ks % N_ANGLES]
        j = int(np.nanargmax(s))
        k = float(ks[j])
        a, b, c = scores[(ks[j] - 1) % N_ANGLES], s[j], scores[(ks[j] + 1) % N_ANGLES]
        den = a - 2 * b + c
        if den < 0:
            k += 0.5 * (a - c) / den
        return math.radians(k * 360.0 / N_ANGLES), float(b)


def _high_pass(spec):
    """A ring spectrum (rfft along the angle) without its harmonics below :data:`MIN_HARMONIC`."""
    spec[:MIN_HARMONIC] = 0.0
    return spec


def _energy(spec, weight) -> float:
    """The weighted sum of squares round the rings of a one-sided ring spectrum (Parseval)."""
    p = np.abs(spec) ** 2
    p[1:] *= 2.0
    if N_ANGLES % 2 == 0:
        p[-1] /= 2.0
    return float(np.sum(weight * p.sum(axis=0)) / N_ANGLES)
