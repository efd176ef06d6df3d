"""Geometry: image -> rocking-plane mapping, rigid/similarity fits, levelling,
camera calibration from a board video.

Plane coordinates are ``y`` up. Without a homography they are pixels about the
image centre (``X = u - cx``, ``Y = cy - v``) and become metres only at the
output boundary (:mod:`rocklab.tracking.video._track`), with the scale measured from
the targets.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._errors import InputError

__all__ = [
    "PlaneMap",
    "SimilarityFit",
    "fit_similarity",
    "calibrate_camera",
    "board_homography",
    "load_calibration",
    "plane_homography_from_points",
]


@dataclass(frozen=True)
class SimilarityFit:
    """Least-squares ``q ≈ k R(θ) p + t`` between object points ``p`` and plane points ``q``.

    Attributes
    ----------
    theta_rad : float
        Counter-clockwise rotation (plane ``y`` up).
    scale : float
        Plane units per object unit ``k``.
    t : ndarray, shape (2,)
        Image of the object-frame origin (plane units).
    rms : float
        Residual per coordinate (plane units), ``sqrt(Σ|r|² / (2n - 4))``
        (``sqrt(Σ|r|² / 2n)`` when ``n = 2``).
    sigma_theta_rad : float
        1-σ uncertainty of ``theta_rad`` from the residual: ``rms / sqrt(Σ|q - q̄|²)``.
    n : int
        Number of point pairs.
    """

    theta_rad: float
    scale: float
    t: np.ndarray
    rms: float
    sigma_theta_rad: float
    n: int


def fit_similarity(p, q, weights=None, scale=None) -> SimilarityFit:
    """Closed-form 2-D similarity (Umeyama) fit of plane points ``q`` to object points ``p``.

    Parameters
    ----------
    p, q : array_like, shape (n, 2)
        Object-frame points and their measured plane positions, ``n >= 2``.
    weights : array_like, shape (n,), optional
    scale : float, optional
        Fix the scale ``k`` (a rigid fit when 1): with a metric plane, or a scale
        known from earlier frames, a partial view of a wide target (one marker
        of two) cannot turn a size error into a lever-arm error of the origin.
    """
    p = np.asarray(p, float)
    q = np.asarray(q, float)
    n = len(p)
    w = np.ones(n) if weights is None else np.asarray(weights, float)
    w = w / w.sum()
    pm = w @ p
    qm = w @ q
    P = p - pm
    Q = q - qm
    # With complex numbers the 2-D similarity is q = z p + t, z = k e^{iθ}.
    pc = P[:, 0] + 1j * P[:, 1]
    qc = Q[:, 0] + 1j * Q[:, 1]
    z = np.sum(w * qc * np.conj(pc)) / np.sum(w * np.abs(pc) ** 2)
    if scale is not None:
        z = scale * z / abs(z)
    theta = float(np.angle(z))
    k = float(np.abs(z))
    t = qm - np.array([(z * (pm[0] + 1j * pm[1])).real, (z * (pm[0] + 1j * pm[1])).imag])
    r = qc - z * pc
    n_par = 4 if scale is None else 3
    dof = 2 * n - n_par if n > 2 else 2 * n
    rms = float(np.sqrt(np.sum(np.abs(r) ** 2) / dof))
    spread = float(np.sqrt(np.sum(np.abs(qc) ** 2)))
    sig = rms / spread if spread > 0 else np.inf
    return SimilarityFit(theta, k, t, rms, float(sig), n)


class PlaneMap:
    """Image pixels -> plane coordinates (y up): undistortion, then homography or centring.

    Parameters
    ----------
    width_px, height_px : int
    camera_matrix : (3, 3) array_like or None
    dist_coeffs : array_like or None
    homography : (3, 3) array_like or None
        Undistorted image px -> plane metres; then :attr:`metric` is True.
    """

    def __init__(self, width_px, height_px, camera_matrix=None, dist_coeffs=None, homography=None):
        self.cx = (width_px - 1) / 2.0
        self.cy = (height_px - 1) / 2.0
        self.K = None if camera_matrix is None else np.asarray(camera_matrix, float)
        self.dist = None if dist_coeffs is None else np.asarray(dist_coeffs, float)
        self.H = None if homography is None else np.asarray(homography, float)
        self.metric = self.H is not None
        #: where the mapping came from: "image", "homography", "board" or "table"
        self.source = "image" if self.H is None else "homography"

    def undistort(self, uv):
        """Undistorted pixel positions, shape (n, 2)."""
        uv = np.asarray(uv, float).reshape(-1, 2)
        if self.K is None or self.dist is None or not np.any(self.dist):
            return uv
        import cv2

        return cv2.undistortPoints(uv.reshape(-1, 1, 2), self.K, self.dist, P=self.K).reshape(-1, 2)

    def to_plane(self, uv):
        """Plane coordinates (px about the centre, or metres with a homography), shape (n, 2)."""
        uv = self.undistort(uv)
        if self.H is not None:
            h = uv @ self.H[:, :2].T + self.H[:, 2]
            return h[:, :2] / h[:, 2:3]
        return np.column_stack((uv[:, 0] - self.cx, self.cy - uv[:, 1]))

    def to_image(self, XY):
        """Image pixels (distorted, as in the video) of plane points ``XY``, shape (n, 2): the
        inverse of :meth:`to_plane`."""
        XY = np.asarray(XY, float).reshape(-1, 2)
        X, Y = XY[:, 0], XY[:, 1]
        if self.H is not None:
            h = np.column_stack((X, Y, np.ones_like(X))) @ np.linalg.inv(self.H).T
            uv = h[:, :2] / h[:, 2:3]
        else:
            uv = np.column_stack((X + self.cx, self.cy - Y))
        if self.K is not None and self.dist is not None and np.any(self.dist):
            import cv2

            ok = np.all(np.isfinite(uv), axis=1)
            out = np.full(uv.shape, np.nan)
            if ok.any():
                xn = (uv[ok] - self.K[:2, 2]) / np.array([self.K[0, 0], self.K[1, 1]])
                obj = np.column_stack((xn, np.ones(len(xn))))
                pr, _ = cv2.projectPoints(obj, np.zeros(3), np.zeros(3), self.K, self.dist)
                out[ok] = pr.reshape(-1, 2)
            uv = out
        return uv


def plane_homography_from_points(img_px, obj_m, plane_map: PlaneMap):
    """Homography undistorted px -> plane (m) from points of known plane position.

    With a camera matrix: planar PnP (IPPE, 6 unknowns, robust with few points),
    ``H = (K [r1 r2 t])^-1``. Without: a direct homography fit (needs >= 4
    points spread over the field for the 8 unknowns).

    Parameters
    ----------
    img_px : ndarray (n, 2)
        Measured (distorted) image points.
    obj_m : ndarray (n, 2)
        Their plane coordinates, m (y up).
    """
    import cv2

    img = np.asarray(img_px, float).reshape(-1, 2)
    obj = np.asarray(obj_m, float).reshape(-1, 2)
    if plane_map.K is not None:
        obj3 = np.column_stack((obj, np.zeros(len(obj))))
        dist = plane_map.dist if plane_map.dist is not None else np.zeros(5)
        ok, rvec, tvec = cv2.solvePnP(obj3, img, plane_map.K, dist, flags=cv2.SOLVEPNP_IPPE)
        if not ok:
            return None
        ok, rvec, tvec = cv2.solvePnP(obj3, img, plane_map.K, dist, rvec, tvec, True, flags=cv2.SOLVEPNP_ITERATIVE)
        R, _ = cv2.Rodrigues(rvec)
        G = plane_map.K @ np.column_stack((R[:, 0], R[:, 1], tvec.ravel()))
        H = np.linalg.inv(G)
        return H / H[2, 2]
    H, _ = cv2.findHomography(plane_map.undistort(img), obj, 0)
    return H


def load_calibration(path, size_px=None):
    """Read ``camera_matrix`` (3, 3) and ``dist_coeffs`` (k,) from a lens file or a ``.npz``.

    Parameters
    ----------
    path : path-like
        A lens file (``.json``, :func:`rocklab.tracking.calib.calibrate_lens`) or a ``.npz`` with
        ``camera_matrix`` and ``dist_coeffs`` (:func:`calibrate_camera`).
    size_px : (int, int) or None
        The film's (width, height): a lens file calibrated at another size is refused.
    """
    if str(path).lower().endswith(".json"):
        from ..calib import load_lens

        lens = load_lens(path)
        if size_px is not None and tuple(int(v) for v in size_px) != tuple(lens.size):
            w, h = lens.size
            raise InputError(
                f"{path}: the lens was calibrated on {w}x{h} px pictures, the film is {size_px[0]}x{size_px[1]} px; "
                "its focal length and centre do not apply: calibrate at the film's size (rocklab calibrate)"
            )
        return lens.K, lens.dist
    try:
        with np.load(path) as z:
            K = np.asarray(z["camera_matrix"], float).reshape(3, 3)
            d = np.asarray(z["dist_coeffs"], float).ravel()
    except (OSError, KeyError, ValueError) as e:
        raise InputError(
            f"{path}: not a calibration .npz with camera_matrix and dist_coeffs "
            f"({e}); run rocklab.tracking.calibrate_camera"
        ) from None
    return K, d


def _find_board(gray, board):
    """Image corners (n, 2) and board-plane corners (n, 2) in metres (y up), or None."""
    import cv2

    if board.kind == "checkerboard":
        pattern = (board.squares_x - 1, board.squares_y - 1)
        ok, corners = cv2.findChessboardCornersSB(gray, pattern, flags=cv2.CALIB_CB_ACCURACY)
        if not ok:
            return None
        # The sector-based detector leaves ~0.2 px errors; cornerSubPix is exact on X-junctions.
        spacing = float(np.median(np.hypot(*np.diff(corners.reshape(-1, 2), axis=0).T)))
        # a fifth of the spacing: at three tenths real photos gave 0.31 px RMS instead of 0.18 (calib)
        from ..calib._boards import SUBPIX_WINDOW

        win = int(np.clip(SUBPIX_WINDOW * spacing, 2, 10))
        corners = cv2.cornerSubPix(
            gray,
            corners.astype(np.float32).reshape(-1, 1, 2),
            (win, win),
            (-1, -1),
            (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 50, 0.001),
        )
        pts = corners.reshape(pattern[1], pattern[0], 2).astype(float)
        # OpenCV may start from any corner of a symmetric board: make the origin the
        # top-left inner corner as seen in the image, x to the right (y up).
        if pts[0, -1, 0] < pts[0, 0, 0]:
            pts = pts[::-1, ::-1]
        ix, iy = np.meshgrid(np.arange(pattern[0]), np.arange(pattern[1]))
        obj = np.column_stack((ix.ravel(), -iy.ravel())) * board.square_m
        return pts.reshape(-1, 2), obj.astype(float)
    d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, board.dictionary))
    b = cv2.aruco.CharucoBoard(
        (board.squares_x, board.squares_y), board.square_m, board.marker_m or 0.7 * board.square_m, d
    )
    det = cv2.aruco.CharucoDetector(b)
    ch_corners, ch_ids, _, _ = det.detectBoard(gray)
    if ch_ids is None or len(ch_ids) < 4:
        return None
    obj = b.getChessboardCorners()[ch_ids.ravel(), :2]
    return ch_corners.reshape(-1, 2).astype(float), np.c_[obj[:, 0], -obj[:, 1]].astype(float)


def board_homography(gray, board, plane_map: PlaneMap | None = None):
    """Homography undistorted image px -> board plane (m, y up) from one image of ``board``.

    Raises
    ------
    InputError
        The board is not found in the image.
    """

    found = _find_board(gray, board)
    if found is None:
        raise InputError(
            f"reference.board: no {board.kind} {board.squares_x}x{board.squares_y} "
            f"found in frame {board.frame}; check squares_x/squares_y or the frame"
        )
    img, obj = found
    return plane_homography_from_points(img, obj, plane_map or PlaneMap(*gray.shape[::-1]))


def calibrate_camera(frames, board, every: int = 10, out=None):
    """Camera matrix and distortion from a calibration video of a board.

    Parameters
    ----------
    frames : iterable of (index, gray ndarray)
        E.g. :func:`rocklab.tracking.iter_video_frames`.
    board : BoardConfig
    every : int
        Use every ``every``-th frame.
    out : path-like, optional
        Write ``camera_matrix``, ``dist_coeffs``, ``rms_px`` to this ``.npz``.

    Returns
    -------
    camera_matrix : ndarray (3, 3)
    dist_coeffs : ndarray (5,)
    rms_px : float
        Reprojection RMS error.
    """
    import cv2

    obj_pts, img_pts, size = [], [], None
    for i, gray in frames:
        if i % every:
            continue
        size = gray.shape[::-1]
        f = _find_board(gray, board)
        if f is not None and len(f[0]) >= 6:
            img_pts.append(f[0].astype(np.float32).reshape(-1, 1, 2))
            obj_pts.append(np.c_[f[1], np.zeros(len(f[1]))].astype(np.float32))
    if len(img_pts) < 3:
        raise InputError(
            f"calibration video: the board was found in {len(img_pts)} frames, "
            "need at least 3; film the board at several angles"
        )
    rms, K, dist, _, _ = cv2.calibrateCamera(obj_pts, img_pts, size, None, None)
    dist = dist.ravel()
    if out is not None:
        from ..._io import atomic_path

        with atomic_path(out, suffix=".npz") as tmp:
            with open(tmp, "wb") as fh:
                np.savez(fh, camera_matrix=K, dist_coeffs=dist, rms_px=rms)
    return K, dist, float(rms)
