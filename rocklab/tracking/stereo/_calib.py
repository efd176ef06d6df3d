"""Stereo calibration from a film of a ChArUco board seen by both cameras.

Each camera's intrinsics and distortion come from ``cv2.calibrateCamera`` on
the ChArUco corners it sees (OpenCV's ``CharucoDetector``, which interpolates
the chessboard corners from the ArUco markers, so a partly seen board still
counts); the relative pose from ``cv2.stereoCalibrate`` on the corners both see
in the same frame, with the intrinsics refined jointly. The board is held
still in each pose, so the two films need no synchronisation for this step,
only the same number of frames in the same order.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..._errors import InputError, where

__all__ = ["StereoRig", "calibrate_stereo", "load_rig", "DEFAULT_BOARD", "charuco_board"]

#: Default board: 9 x 6 squares of 30 mm, 22 mm markers, DICT_5X5_100.
DEFAULT_BOARD = {"squares": (9, 6), "square_m": 0.03, "marker_m": 0.022, "dictionary": "DICT_5X5_100"}
#: Fewest ChArUco corners for a frame to count, and fewest frames for a calibration.
MIN_CORNERS = 8
MIN_FRAMES = 6
#: Median distance between two films' image points below which they are one film, px
#: (detector rounding on identical pixels is far below this; two cameras a few cm apart
#: see a lab scene with tens of pixels of disparity).
SAME_FILM_PX = 0.05
#: Smallest camera separation that triangulates a lab scene (a few cm at 1-3 m), m.
MIN_BASELINE_M = 0.01


@dataclass(frozen=True)
class StereoRig:
    """Two calibrated cameras.

    Attributes
    ----------
    K1, K2 : ndarray, shape (3, 3)
        Intrinsics, px.
    dist1, dist2 : ndarray, shape (5,)
        OpenCV distortion ``k1, k2, p1, p2, k3``.
    R : ndarray, shape (3, 3)
        Rotation from camera 1 to camera 2 (``x2 = R x1 + T``).
    T : ndarray, shape (3,)
        Translation, m.
    size : tuple of int
        (width, height), px.
    rms_px : dict
        Reprojection RMS: ``cam1``, ``cam2`` (single-camera) and ``stereo``, px.
    n_frames : int
        Board poses both cameras saw.
    """

    K1: np.ndarray
    dist1: np.ndarray
    K2: np.ndarray
    dist2: np.ndarray
    R: np.ndarray
    T: np.ndarray
    size: tuple
    rms_px: dict
    n_frames: int

    @property
    def baseline_m(self) -> float:
        """Distance between the camera centres, m."""
        return float(np.linalg.norm(self.T))

    def projection_matrices(self):
        """``P1 = K1 [I | 0]``, ``P2 = K2 [R | T]`` (camera-1 axes)."""
        P1 = self.K1 @ np.hstack([np.eye(3), np.zeros((3, 1))])
        P2 = self.K2 @ np.hstack([self.R, self.T.reshape(3, 1)])
        return P1, P2

    def to_dict(self) -> dict:
        """The ``stereo.json`` object (SI units, px)."""
        return {
            "K1": self.K1.tolist(),
            "dist1": self.dist1.tolist(),
            "K2": self.K2.tolist(),
            "dist2": self.dist2.tolist(),
            "R": self.R.tolist(),
            "T_m": self.T.tolist(),
            "size_px": list(self.size),
            "rms_px": dict(self.rms_px),
            "n_frames": self.n_frames,
            "baseline_m": self.baseline_m,
        }

    def save(self, path) -> Path:
        """Write ``stereo.json`` atomically."""
        from ..._io import write_json_atomic

        return write_json_atomic(path, self.to_dict())


def load_rig(path) -> StereoRig:
    """Read a ``stereo.json`` written by :meth:`StereoRig.save`."""
    path = Path(path)
    try:
        d = json.loads(path.read_text())
        return StereoRig(
            np.array(d["K1"], float),
            np.array(d["dist1"], float),
            np.array(d["K2"], float),
            np.array(d["dist2"], float),
            np.array(d["R"], float),
            np.array(d["T_m"], float),
            tuple(d["size_px"]),
            dict(d.get("rms_px", {})),
            int(d.get("n_frames", 0)),
        )
    except FileNotFoundError:
        raise InputError(f"{where(path)}not found; make one with 'rocklab stereo calibrate'") from None
    except (ValueError, KeyError, TypeError) as e:
        raise InputError(
            f"{where(path)}not a stereo calibration ({type(e).__name__}: {e}); make one with 'rocklab stereo calibrate'"
        ) from None


def charuco_board(spec: dict):
    """The OpenCV ``CharucoBoard`` of a board ``spec`` (see :data:`DEFAULT_BOARD`)."""
    import cv2

    d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, spec["dictionary"]))
    return cv2.aruco.CharucoBoard(tuple(spec["squares"]), float(spec["square_m"]), float(spec["marker_m"]), d)


def frames_by_index(path, lost: list | None = None):
    """Grey frames of the film at ``path``, one per slot of its container's clock.

    A frame the camera dropped or a damaged packet lost is a black picture (nothing is detected
    in it), so frame ``i`` of one camera stays frame ``i`` of the other. ``(path, n_undecoded,
    n_dropped, n_slots)`` is appended to ``lost`` at the end, for the caller to warn from its own
    thread (:func:`warn_lost`).
    """
    from ..video._video import iter_video_frames, probe_video

    info = probe_video(path)
    slot = np.arange(info.n_frames)
    if info.n_dropped and info.frame_times_s is not None and info.fps:
        slot = np.rint(info.frame_times_s * info.fps).astype(int)
    n = int(slot[-1]) + 1 if len(slot) else 0
    nxt, n_undecoded, blank = 0, 0, None
    for i, gray in iter_video_frames(path):
        k = int(slot[i]) if i < len(slot) else i
        blank = np.zeros_like(gray) if blank is None else blank
        for _ in range(nxt, k):
            yield blank
        n_undecoded += max(k - nxt, 0)
        yield gray
        nxt = k + 1
    if blank is not None:
        for _ in range(nxt, n):
            yield blank
        n_undecoded += max(n - nxt, 0)
    if lost is not None:
        lost.append((str(path), n_undecoded - info.n_dropped, info.n_dropped, max(n, nxt)))


def warn_lost(lost) -> None:
    """W-VIDEO-DROPPED and W-VIDEO-DAMAGED for each film of :func:`frames_by_index` that lost frames."""
    from ..._diagnostics import warn

    for path, n_bad, n_dropped, n in lost:
        if n_dropped:
            warn(
                "W-VIDEO-DROPPED",
                f"{path}: the camera dropped {n_dropped} of {n} frames (gaps in the container's clock); "
                "they count as frames without targets, so the two films stay paired frame by frame",
            )
        if n_bad > 0:
            warn(
                "W-VIDEO-DAMAGED",
                f"{path}: {n_bad} of the {n} frames the container holds did not decode (damaged "
                "packets); they count as frames without targets, so the two films stay paired frame by frame",
            )


def _detect(path, board, lost=None):
    """Per frame ``{corner id: (u, v)}`` of the ChArUco corners in the film at ``path``."""
    import cv2

    from ..video._video import probe_video

    info = probe_video(path)
    det = cv2.aruco.CharucoDetector(board)
    out = []
    for gray in frames_by_index(path, lost):
        cc, ci, _, _ = det.detectBoard(gray)
        out.append({} if ci is None else {int(i): c for i, c in zip(ci.ravel(), cc.reshape(-1, 2))})
    return out, (info.width_px, info.height_px)


def calibrate_stereo(film1, film2, board: dict | None = None) -> StereoRig:
    """Calibrate two cameras from films of a ChArUco board.

    Parameters
    ----------
    film1, film2 : path-like
        The two cameras' films, frame ``i`` of each showing the same board pose.
    board : dict, optional
        ``squares`` (columns, rows), ``square_m``, ``marker_m``, ``dictionary``
        (default :data:`DEFAULT_BOARD`).

    Returns
    -------
    StereoRig
    """
    import cv2

    spec = dict(DEFAULT_BOARD, **(board or {}))
    b = charuco_board(spec)
    obj_all = b.getChessboardCorners()
    lost: list = []
    det1, size1 = _detect(film1, b, lost)
    det2, size2 = _detect(film2, b, lost)
    warn_lost(lost)
    from ..video._checks import check_mirrored
    from ..video._video import probe_video

    for film in (film1, film2):
        check_mirrored(probe_video(film), film)
    if len(det1) != len(det2):
        raise InputError(
            f"{where(film2)}{len(det2)} frames, but {Path(film1).name} has {len(det1)}; the two "
            "calibration films must show the same board poses frame by frame (trim them to match)"
        )
    if size1 != size2:
        raise InputError(
            f"{where(film2)}frame size {size2} differs from {Path(film1).name}'s {size1}; "
            "calibrate cameras of one size (or give each its own calibration)"
        )

    def per_camera(dets, film):
        ok = [d for d in dets if len(d) >= MIN_CORNERS]
        if len(ok) < MIN_FRAMES:
            raise InputError(
                f"{where(film)}the board is seen (>= {MIN_CORNERS} corners) in {len(ok)} of "
                f"{len(dets)} frames; need {MIN_FRAMES}: film more poses, closer, sharper, and check "
                f"the board ({spec['squares'][0]}x{spec['squares'][1]} squares, {spec['dictionary']})"
            )
        obj = [obj_all[sorted(d)].astype(np.float32) for d in ok]
        img = [np.array([d[i] for i in sorted(d)], np.float32) for d in ok]
        rms, K, dist, _, _ = cv2.calibrateCamera(obj, img, size1, None, None, flags=cv2.CALIB_FIX_K3)
        return float(rms), K, dist.ravel()

    rms1, K1, d1 = per_camera(det1, film1)
    rms2, K2, d2 = per_camera(det2, film2)
    obj, img1, img2 = [], [], []
    for a, c in zip(det1, det2):
        common = sorted(set(a) & set(c))
        if len(common) >= MIN_CORNERS:
            obj.append(obj_all[common].astype(np.float32))
            img1.append(np.array([a[i] for i in common], np.float32))
            img2.append(np.array([c[i] for i in common], np.float32))
    if len(obj) < MIN_FRAMES:
        raise InputError(
            f"{where(film1)}the board is seen by both cameras at once in {len(obj)} frames; need "
            f"{MIN_FRAMES}: hold it where both see it (check {Path(film2).name} too)"
        )
    # one film given twice (or two copies of one camera) calibrates to a zero baseline that
    # triangulates nothing: the corners then agree to the detector's rounding in every frame
    gap_px = float(np.median([np.median(np.linalg.norm(a - c, axis=1)) for a, c in zip(img1, img2)]))
    if gap_px < SAME_FILM_PX:
        raise InputError(
            f"{where(film2)}the board's corners sit where they sit in {Path(film1).name} (median "
            f"{gap_px:.2g} px apart): the same film twice, or one camera's; give the second camera's film"
        )
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-10)
    rms, K1, d1, K2, d2, R, T, _, _ = cv2.stereoCalibrate(
        obj, img1, img2, K1, d1, K2, d2, size1, criteria=crit, flags=cv2.CALIB_USE_INTRINSIC_GUESS | cv2.CALIB_FIX_K3
    )
    baseline_m = float(np.linalg.norm(T))
    if baseline_m < MIN_BASELINE_M:
        raise InputError(
            f"{where(film2)}the two cameras are {baseline_m:.3g} m apart after calibration: no depth can be "
            f"triangulated; film the board with two cameras at least {MIN_BASELINE_M:g} m apart"
        )
    return StereoRig(
        K1,
        np.asarray(d1, float).ravel(),
        K2,
        np.asarray(d2, float).ravel(),
        R,
        np.asarray(T).ravel(),
        tuple(size1),
        {"cam1": rms1, "cam2": rms2, "stereo": float(rms)},
        len(obj),
    )
