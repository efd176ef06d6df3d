"""What every target detector returns: one object's points in one frame (:class:`Detection`).

Kept apart from the detectors so that they depend on it and not on each other.
"""

from __future__ import annotations

import numpy as np

__all__ = ["Detection"]


class Detection:
    """One object's points in one frame.

    Attributes
    ----------
    img_pts : ndarray (n, 2)
        Measured image positions (px, distorted as in the video).
    obj_pts : ndarray (n, 2)
        Matching object-frame positions (m if ``metric`` else object units).
    metric : bool
    n_expected : int
        Points a complete detection would have (quality = n / n_expected ...).
    sigma_rad : float
        Orientation uncertainty from the shapes' own edges (the corners of one
        marker come from fitted lines and always form a near-perfect square, so
        the corner residual cannot show it).
    n_groups : int
        Independent rigid shapes (markers) behind the points. With one, the
        reported σ is ``hypot(σ_fit, sigma_rad)``; with several, the corner fit
        also carries their relative positions and the two are combined as
        independent estimates, ``(σ_fit⁻² + sigma_rad⁻²)^-1/2``.
    theta_why : str or None
        Why this frame's angle is not a measurement although the object's angle can be (the
        parts of its region that tell the angle do not match the pose), or None.
    score : float or None
        How well the pose re-explains the image, 0..1 (a markerless object: the correlation of
        the frame, warped back, with its template); when given, it is the frame's quality
        (times the fraction of points found) instead of the fit residual's.
    """

    __slots__ = ("img_pts", "obj_pts", "metric", "n_expected", "sigma_rad", "n_groups", "score", "theta_why")

    def __init__(self, img_pts, obj_pts, metric, n_expected, sigma_rad=0.0, n_groups=1, score=None, theta_why=None):
        self.img_pts = np.asarray(img_pts, float).reshape(-1, 2)
        self.obj_pts = np.asarray(obj_pts, float).reshape(-1, 2)
        self.metric = bool(metric)
        self.n_expected = int(n_expected)
        self.sigma_rad = float(sigma_rad) if np.isfinite(sigma_rad) else 0.0
        self.n_groups = int(n_groups)
        self.score = None if score is None else float(score)
        self.theta_why = theta_why

    def combined_sigma(self, sigma_fit):
        """The reported 1-σ of θ given the rigid fit's own σ (rad)."""
        if self.n_groups >= 2 and self.sigma_rad > 0 and sigma_fit > 0:
            return float((sigma_fit**-2 + self.sigma_rad**-2) ** -0.5)
        return float(np.hypot(sigma_fit, self.sigma_rad))
