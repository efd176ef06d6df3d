"""Inverse-compositional affine registration of a template (Baker & Matthews 2004), gain and
offset invariant like ECC.

The markerless tracker's full-resolution step: its Gauss-Newton matrix depends on the template
alone, so it is built once per template and every iteration costs one warp, one blur and two
matrix-vector products — against OpenCV's ``findTransformECC``, which rebuilds the Jacobian
and Hessian from the image gradients at every iteration (about 4x the time here).
The photometric invariance comes from normalising the warped patch to zero mean and unit
variance at each iteration, as the template is. Template and picture are smoothed before the
warp, as ECC smooths them.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["ICAffine", "ICRigid"]

#: Gaussian smoothing of template and warped patch (the ``gaussFiltSize`` ECC uses), px.
BLUR_PX = 5
#: Pixels at the template border left out (the 3x3 gradient is not defined there).
BORDER_PX = 1


class ICAffine:
    """A template prepared for inverse-compositional affine registration.

    Parameters
    ----------
    tmpl : ndarray (h, w), float32
        Grey levels of the template.

    Attributes
    ----------
    n_px : int
        Pixels used (the template less a border).
    """

    def __init__(self, tmpl: np.ndarray):
        import cv2

        t = cv2.GaussianBlur(np.asarray(tmpl, np.float32), (BLUR_PX, BLUR_PX), 0)
        self.h, self.w = t.shape
        tn = (t - t.mean()) / (t.std() + 1e-9)
        gx = cv2.Sobel(tn, cv2.CV_32F, 1, 0, ksize=3) / 8.0
        gy = cv2.Sobel(tn, cv2.CV_32F, 0, 1, ksize=3) / 8.0
        yy, xx = np.mgrid[0 : self.h, 0 : self.w].astype(np.float32)
        # parameters about the template's centre: a well-conditioned Gauss-Newton matrix (about
        # pixel (0, 0) rotation and translation are nearly collinear on a wide template)
        self.cx, self.cy = (self.w - 1) / 2.0, (self.h - 1) / 2.0
        xx, yy = xx - self.cx, yy - self.cy
        b = BORDER_PX
        inner = (slice(b, self.h - b), slice(b, self.w - b))
        sd = self._steepest_descent(xx[inner], yy[inner], gx[inner], gy[inner])
        self.sd_t = np.ascontiguousarray(sd.T)  # (k, n) float32
        hess = self.sd_t.astype(float) @ self.sd_t.T.astype(float)
        self.hess_inv = np.linalg.inv(hess)
        self.tn = np.ascontiguousarray(tn[inner]).ravel()
        self.n_px = int(self.tn.size)
        # the inner pixels are sampled directly: template px (b, b) is the patch's (0, 0)
        self._shift = np.array([[1.0, 0.0, b], [0.0, 1.0, b], [0.0, 0.0, 1.0]])

    @staticmethod
    def _steepest_descent(xx, yy, gx, gy):
        """Steepest-descent images for W(x; p) = [[1 + p0, p2, p4], [p1, 1 + p3, p5]] at p = 0, (n, 6)."""
        return np.stack((xx * gx, xx * gy, yy * gx, yy * gy, gx, gy), axis=-1).reshape(-1, 6)

    @staticmethod
    def _increment(dp):
        """The 3x3 warp of the parameter update ``dp``."""
        return np.array([[1 + dp[0], dp[2], dp[4]], [dp[1], 1 + dp[3], dp[5]], [0.0, 0.0, 1.0]])

    @staticmethod
    def _step_px(dp, ext):
        """Largest displacement of a template pixel by the update, px."""
        return max(float(np.abs(dp[:4]).max()) * ext, float(np.abs(dp[4:]).max()))

    def _patch(self, image, W):
        """The template's pixels (less the border) sampled from ``image`` through ``W``, (n,) float32."""
        import cv2

        b = BORDER_PX
        Wi = np.asarray(W, np.float64) @ self._shift
        warped = cv2.warpAffine(
            image,
            Wi.astype(np.float32),
            (self.w - 2 * b, self.h - 2 * b),
            flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
            borderMode=cv2.BORDER_REPLICATE,
        )
        return warped.ravel()

    @staticmethod
    def smooth(image: np.ndarray) -> np.ndarray:
        """``image`` smoothed as :meth:`refine` needs it (float32), for several fits on one picture."""
        import cv2

        return cv2.GaussianBlur(np.asarray(image, np.float32), (BLUR_PX, BLUR_PX), 0)

    def _masked(self, mask):
        """(steepest-descent images, normalised template, inverse Gauss-Newton matrix, pixel
        selector) over the pixels ``mask`` keeps (all without one)."""
        if mask is None:
            return self.sd_t, self.tn, self.hess_inv, slice(None)
        m = np.asarray(mask, bool)[BORDER_PX : self.h - BORDER_PX, BORDER_PX : self.w - BORDER_PX].ravel()
        t = self.tn[m]
        sd_t = self.sd_t[:, m]
        # the kept part normalised on its own, as the patch will be: the gradients scale with it
        sd_ = float(t.std()) + 1e-9
        t = (t - float(t.mean())) / sd_
        sd_t = np.ascontiguousarray(sd_t / sd_)
        return sd_t, t, np.linalg.inv(sd_t.astype(float) @ sd_t.T.astype(float)), m

    def refine(
        self,
        image: np.ndarray,
        W: np.ndarray,
        max_iter: int = 30,
        tol_px: float = 1e-3,
        smoothed: bool = False,
        mask: np.ndarray | None = None,
    ):
        """Refine the warp ``W`` (template px -> ``image`` px) by Gauss-Newton.

        Parameters
        ----------
        image : ndarray (H, W), float32
        W : ndarray (2, 3)
            Starting warp, good to a pixel or two.
        max_iter : int
        tol_px : float
            Stop when the update moves no template pixel by more than this, px.
        smoothed : bool
            ``image`` is already :meth:`smooth`'s output.
        mask : ndarray (h, w) of bool, optional
            Template pixels to use (the rest covered by something): the fit and the correlation
            are made on these alone.

        Returns
        -------
        (W, cc) or None
            The refined warp and the correlation coefficient of the normalised patches, or None
            when the patch has no contrast or the iteration diverged.
        """
        W = np.asarray(W, np.float64)
        ext = float(max(self.w, self.h))
        # smoothed once, before warping, with the real picture round the object (as ECC does)
        if not smoothed:
            image = self.smooth(image)
        sd_t, tn, hess_inv, keep = self._masked(mask)
        if tn.size < 16:
            return None
        n = tn.size
        g_t = (sd_t @ tn).astype(float)
        T = np.array([[1.0, 0.0, self.cx], [0.0, 1.0, self.cy], [0.0, 0.0, 1.0]])
        Ti = np.array([[1.0, 0.0, -self.cx], [0.0, 1.0, -self.cy], [0.0, 0.0, 1.0]])
        for _ in range(max_iter):
            v = self._patch(image, W)[keep]
            d = v - float(v.mean())
            ss = float(np.dot(d, d))
            if not ss > 1e-12 * n:  # no contrast (sigma below 1e-6 grey levels)
                return None
            sd = math.sqrt(ss / n)
            # with vn = d / sd the patch normalised like the template (vn . vn = n): the residual
            # of the best gain, rho vn - tn, whose fixed point is ECC's optimum (the correlation's
            # stationary point), not that of a plain difference of normalised patches; its
            # projection sd_t (rho vn - tn) taken without forming vn
            rho = float(np.dot(d, tn)) / (sd * n)
            dp = hess_inv @ ((rho / sd) * (sd_t @ d).astype(float) - g_t)
            if not np.all(np.isfinite(dp)):
                return None
            inc = self._increment(dp)
            W = (np.vstack((W, (0.0, 0.0, 1.0))) @ np.linalg.inv(T @ inc @ Ti))[:2]
            step = self._step_px(dp, ext)
            if step > ext:  # a jump larger than the template: diverged
                return None
            if step < tol_px:
                break
        # the correlation at the final warp (not the one before the last update), so that fits of
        # different motion models compare fairly
        v = self._patch(image, W)[keep]
        v = v - float(v.mean())
        cc = float(np.dot(v, tn)) / (float(np.linalg.norm(tn)) * float(np.linalg.norm(v)) + 1e-12)
        return W.astype(np.float32), cc


class ICRigid(ICAffine):
    """The same registration restricted to rigid (Euclidean) motion: rotation about the template's
    centre and translation, ``dp = (dθ, dx, dy)``."""

    @staticmethod
    def _steepest_descent(xx, yy, gx, gy):
        return np.stack((-yy * gx + xx * gy, gx, gy), axis=-1).reshape(-1, 3)

    @staticmethod
    def _increment(dp):
        c, s = np.cos(dp[0]), np.sin(dp[0])
        return np.array([[c, -s, dp[1]], [s, c, dp[2]], [0.0, 0.0, 1.0]])

    @staticmethod
    def _step_px(dp, ext):
        return max(abs(float(dp[0])) * ext, float(np.abs(dp[1:]).max()))
