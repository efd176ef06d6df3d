"""Pinhole camera with lens distortion looking at the rocking plane (synthetic sessions).

World frame: the rocking plane ``z = 0``, ``x`` right, ``y`` up, ``z`` towards
the camera, metres (the tracker's world frame, see ``_config.py``). Image:
``u`` right, ``v`` down, pixels, origin at the centre of the top-left pixel
(OpenCV). The camera follows OpenCV's model exactly (``cv2.projectPoints`` with
``K``, ``dist_coeffs`` = ``(k1, k2, p1, p2, k3)``, ``rvec``, ``tvec``), so a test
can project the true marker corners with the values saved in ``session.json``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["SynthCamera", "make_camera"]


def _rot(rx: float, ry: float, rz: float) -> np.ndarray:
    cx, sx, cy, sy, cz, sz = math.cos(rx), math.sin(rx), math.cos(ry), math.sin(ry), math.cos(rz), math.sin(rz)
    Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


@dataclass(frozen=True)
class SynthCamera:
    """A calibrated camera viewing the plane ``z = 0``.

    Attributes
    ----------
    size : (int, int)
        Image width and height, px.
    K : ndarray (3, 3)
        Camera matrix, px.
    dist : ndarray (5,)
        OpenCV distortion coefficients ``k1, k2, p1, p2, k3``.
    R : ndarray (3, 3)
        World -> camera rotation (``x_cam = R x_world + t``).
    t : ndarray (3,)
        World -> camera translation, m.
    """

    size: tuple
    K: np.ndarray
    dist: np.ndarray
    R: np.ndarray
    t: np.ndarray

    @property
    def rvec(self) -> np.ndarray:
        import cv2

        return cv2.Rodrigues(self.R)[0].ravel()

    @property
    def center_m(self) -> np.ndarray:
        """Camera centre in the world frame, m, shape (3,)."""
        return -self.R.T @ self.t

    def project(self, xy_m) -> np.ndarray:
        """Plane points (n, 2) m -> distorted pixel coordinates (n, 2) px."""
        xy = np.asarray(xy_m, float).reshape(-1, 2)
        pc = xy @ self.R[:, :2].T + self.t
        x, y = pc[:, 0] / pc[:, 2], pc[:, 1] / pc[:, 2]
        xd, yd = self._distort(x, y)
        K = self.K
        return np.stack([K[0, 0] * xd + K[0, 1] * yd + K[0, 2], K[1, 1] * yd + K[1, 2]], axis=1)

    def _distort(self, x, y):
        k1, k2, p1, p2, k3 = self.dist
        r2 = x * x + y * y
        rad = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
        return (x * rad + 2 * p1 * x * y + p2 * (r2 + 2 * x * x), y * rad + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y)

    def undistort_normalized(self, u, v, iters: int = 8):
        """Pixel coordinates -> ideal normalized coordinates by Newton iteration.

        Converges to ~1e-12 for the mild distortion used here; the forward
        model is :meth:`_distort`, so :meth:`project` inverts it exactly.
        """
        K = self.K
        yd = (np.asarray(v, float) - K[1, 2]) / K[1, 1]
        xd = (np.asarray(u, float) - K[0, 2] - K[0, 1] * yd) / K[0, 0]
        k1, k2, p1, p2, k3 = self.dist
        x, y = xd.copy(), yd.copy()
        for _ in range(iters):
            r2 = x * x + y * y
            rad = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
            drad = k1 + r2 * (2 * k2 + 3 * k3 * r2)  # d rad / d r2
            fx = x * rad + 2 * p1 * x * y + p2 * (r2 + 2 * x * x) - xd
            fy = y * rad + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y - yd
            a = rad + 2 * x * x * drad + 2 * p1 * y + 6 * p2 * x
            b = 2 * x * y * drad + 2 * p1 * x + 2 * p2 * y
            c = 2 * x * y * drad + 2 * p1 * x + 2 * p2 * y
            d = rad + 2 * y * y * drad + 6 * p1 * y + 2 * p2 * x
            det = a * d - b * c
            x = x - (d * fx - b * fy) / det
            y = y - (a * fy - c * fx) / det
        return x, y

    def pixel_to_plane(self, u, v):
        """Pixel coordinates (any shape) -> plane coordinates ``(X, Y)``, m."""
        x, y = self.undistort_normalized(u, v)
        Rt = self.R.T
        c = self.center_m
        dz = Rt[2, 0] * x + Rt[2, 1] * y + Rt[2, 2]
        s = -c[2] / dz
        X = c[0] + s * (Rt[0, 0] * x + Rt[0, 1] * y + Rt[0, 2])
        Y = c[1] + s * (Rt[1, 0] * x + Rt[1, 1] * y + Rt[1, 2])
        return X, Y

    def plane_maps(self, step: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Plane coordinates of every pixel centre, two float32 arrays (H, W), m.

        Exact (Newton-inverted lens model) on a grid every ``step`` px, bilinear in
        between: the mapping is smooth, so the interpolation error is ~(step^2 / 8)
        times its curvature, < 1e-3 px for the lenses of :func:`make_camera`
        (checked in the tests). The grid has a one-cell margin so border pixels
        are interpolated, not extrapolated.
        """
        import cv2

        W, H = self.size
        if step is None:
            step = 4 if W >= 1280 else 2
        nc, nr = (W + step - 1) // step + 3, (H + step - 1) // step + 3
        off = (step - 1) / 2.0 - step  # coarse node j sits at pixel off + step * j
        u = off + step * np.arange(nc, dtype=float)
        v = off + step * np.arange(nr, dtype=float)
        X, Y = (a.astype(np.float32) for a in self.pixel_to_plane(*np.meshgrid(u, v)))
        big = (nc * step, nr * step)
        X = cv2.resize(X, big, interpolation=cv2.INTER_LINEAR)[step : step + H, step : step + W]
        Y = cv2.resize(Y, big, interpolation=cv2.INTER_LINEAR)[step : step + H, step : step + W]
        return np.ascontiguousarray(X, np.float32), np.ascontiguousarray(Y, np.float32)

    def plane_homography(self) -> np.ndarray:
        """3x3 homography from *undistorted* pixel coordinates (same ``K``) to the plane, m."""
        Hm = self.K @ np.column_stack([self.R[:, 0], self.R[:, 1], self.t])
        Hinv = np.linalg.inv(Hm)
        return Hinv / Hinv[2, 2]

    def m_per_px(self, xy_m=(0.0, 0.0)) -> float:
        """Approximate plane scale at ``xy_m``, m/px."""
        p = self.project(np.array([xy_m, (xy_m[0] + 0.01, xy_m[1])]))
        return 0.01 / float(np.hypot(*(p[1] - p[0])))

    def to_dict(self) -> dict:
        """JSON-ready: ``size_px``, ``camera_matrix``, ``dist_coeffs``, ``rvec``, ``tvec_m``, ``R``."""
        return {
            "size_px": [int(self.size[0]), int(self.size[1])],
            "camera_matrix": self.K.tolist(),
            "dist_coeffs": self.dist.tolist(),
            "rvec": self.rvec.tolist(),
            "tvec_m": self.t.tolist(),
            "R": self.R.tolist(),
            "homography_undistorted_px_to_plane_m": self.plane_homography().tolist(),
            "model": "OpenCV pinhole + (k1, k2, p1, p2, k3); world plane z=0, x right, "
            "y up, z towards the camera; x_cam = R x_world + t",
        }

    @classmethod
    def from_dict(cls, d: dict) -> "SynthCamera":
        return cls(
            tuple(d["size_px"]),
            np.array(d["camera_matrix"], float),
            np.array(d["dist_coeffs"], float),
            np.array(d["R"], float),
            np.array(d["tvec_m"], float),
        )


def make_camera(size, center_m, view_height_m: float, rng: np.random.Generator, distortion: bool = True) -> SynthCamera:
    """A camera framing ``view_height_m`` of the plane around ``center_m``.

    The focal length is 1.25 image widths (about a 44° horizontal field);
    roll, pitch and yaw of a few degrees and a principal point a few pixels
    off-centre are drawn from ``rng`` so the view is not perfectly square-on.
    """
    W, H = int(size[0]), int(size[1])
    f = 1.25 * W
    D = f * view_height_m / H
    cx = (W - 1) / 2 + rng.uniform(-0.004, 0.004) * W
    cy = (H - 1) / 2 + rng.uniform(-0.004, 0.004) * H
    K = np.array([[f, 0.0, cx], [0.0, f * (1 + rng.uniform(-5e-4, 5e-4)), cy], [0.0, 0.0, 1.0]])
    dist = (
        np.array(
            [
                rng.uniform(-0.12, -0.06),
                rng.uniform(0.02, 0.08),
                rng.uniform(-5e-4, 5e-4),
                rng.uniform(-5e-4, 5e-4),
                0.0,
            ]
        )
        if distortion
        else np.zeros(5)
    )
    # Looking along -z with image y down: x_cam = x, y_cam = -y, z_cam = -z, then a small tilt.
    R0 = np.diag([1.0, -1.0, -1.0])
    tilt = _rot(
        math.radians(rng.uniform(-3, 3)), math.radians(rng.uniform(-3, 3)), math.radians(rng.uniform(-1.5, 1.5))
    )
    R = tilt @ R0
    # Put the camera so that the optical axis hits the plane at center_m.
    axis_w = R.T @ np.array([0.0, 0.0, 1.0])  # optical axis in the world
    target = np.array([center_m[0], center_m[1], 0.0])
    C = target - D * axis_w / (-axis_w[2])
    t = -R @ C
    return SynthCamera((W, H), K, dist, R, t)
