"""Stereo calibration from films or photos of a board seen by both cameras.

The board is a checkerboard or a ChArUco board (:mod:`rocklab.tracking.calib`: a ChArUco
board still counts when partly seen, a checkerboard only whole). Each camera's intrinsics and
distortion come from ``cv2.calibrateCamera`` on the corners it sees; the relative pose from
``cv2.stereoCalibrate`` on the corners both see in the same picture, with the intrinsics
refined jointly. The board is held still in each pose, so the two films need no
synchronisation for this step, only the same poses in the same order (photos: paired by
the number in their names).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..._errors import InputError, where
from ..calib._views import frames_by_index, warn_lost

__all__ = [
    "StereoRig",
    "calibrate_stereo",
    "load_rig",
    "DEFAULT_BOARD",
    "charuco_board",
    "frames_by_index",
    "warn_lost",
]

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
    board : str
        The board's ``--board`` spec.
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
    board: str = ""

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
            "board": self.board,
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
            str(d.get("board", "")),
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


def _board(board):
    from ..calib._boards import board_from_dict, parse_board

    if board is None or isinstance(board, dict):
        return board_from_dict(dict(DEFAULT_BOARD, **(board or {})))
    return parse_board(board) if isinstance(board, str) else board


def _pair(v1, v2, n1, n2, film1, film2):
    """Views of two cameras paired: by the number in the photos' names where both have one
    (``left03.jpg`` with ``right03.jpg``), else in order."""
    if v1.numbers is not None and v2.numbers is not None and not (v1.is_film or v2.is_film):
        if len(set(v1.numbers)) == len(v1.numbers) and len(set(v2.numbers)) == len(v2.numbers):
            miss = sorted(set(v1.numbers) ^ set(v2.numbers))
            if miss:
                k = miss[0]
                has, lacks = (film1, film2) if k in v1.numbers else (film2, film1)
                raise InputError(
                    f"{where(lacks)}no picture numbered {k}, which {has} has ({len(miss)} unpaired); the two cameras' "
                    "photos are paired by the number in their names: remove the unpaired ones"
                )
            return [v1.numbers.index(k) for k in sorted(v1.numbers)], [v2.numbers.index(k) for k in sorted(v1.numbers)]
    if n1 != n2:
        raise InputError(
            f"{where(film2)}{n2} frames, but {Path(str(film1)).name} has {n1}; the two "
            "calibration films must show the same board poses frame by frame (trim them to match)"
        )
    return list(range(n1)), list(range(n2))


def calibrate_stereo(film1, film2, board=None, *, every: int | None = None) -> StereoRig:
    """Calibrate two cameras from films or photos of a board both see.

    Parameters
    ----------
    film1, film2 : path-like or str
        The two cameras' pictures: films (frame ``i`` of each showing the same board pose),
        folders of photos or file patterns (paired by the number in their names, else in order;
        :func:`rocklab.tracking.calib.open_views`).
    board : Board, str or dict, optional
        A :class:`~rocklab.tracking.calib.Board`, a ``--board`` spec (``checkerboard,9x6,0.025``,
        ``charuco,9x6,0.03,0.022,DICT_5X5_100``) or a ChArUco dict with ``squares`` (columns,
        rows), ``square_m``, ``marker_m``, ``dictionary`` (default :data:`DEFAULT_BOARD`).
    every : int or None
        Films: every ``every``-th frame (None: every frame).

    Returns
    -------
    StereoRig
        ``k3`` is held at 0 in both cameras (the rig's distortion has ``k1, k2, p1, p2``).
    """
    import cv2

    from ..calib._lens import detect_views, not_found_hint, usable
    from ..calib import open_views

    b = _board(board)
    if b.kind == "checkerboard" and b.cols == b.rows:
        raise InputError(
            f"--board {b.spec}: a square pattern of inner corners can be numbered from any of its four corners, "
            "so two cameras cannot agree on corner i; use a board with unequal counts (e.g. 9x6)"
        )
    obj_all = b.object_points()
    v1, v2 = open_views(film1, every or 1), open_views(film2, every or 1)
    lost: list = []
    _, det1, size1 = detect_views(v1, b, lost)
    _, det2, size2 = detect_views(v2, b, lost)
    warn_lost(lost)
    from ..video._checks import check_mirrored
    from ..video import probe_video

    for v in (v1, v2):
        if v.is_film:
            check_mirrored(probe_video(v.source), v.source)
    i1, i2 = _pair(v1, v2, len(det1), len(det2), film1, film2)
    det1, det2 = [det1[i] for i in i1], [det2[i] for i in i2]
    if size1 != size2:
        raise InputError(
            f"{where(film2)}frame size {size2} differs from {Path(str(film1)).name}'s {size1}; "
            "calibrate cameras of one size (or give each its own calibration)"
        )

    def per_camera(dets, film):
        ok = [d for d in dets if usable(d, b)]
        if len(ok) < MIN_FRAMES:
            raise InputError(
                f"{where(film)}the board is seen (whole, or >= {MIN_CORNERS} ChArUco corners) in {len(ok)} of "
                f"{len(dets)} pictures; need {MIN_FRAMES}: "
                f"film more poses, closer, sharper, and {not_found_hint(b)}"
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
        if usable(a, b) and usable(c, b) and len(common) >= MIN_CORNERS:
            obj.append(obj_all[common].astype(np.float32))
            img1.append(np.array([a[i] for i in common], np.float32))
            img2.append(np.array([c[i] for i in common], np.float32))
    if len(obj) < MIN_FRAMES:
        raise InputError(
            f"{where(film1)}the board is seen by both cameras at once in {len(obj)} pictures; need "
            f"{MIN_FRAMES}: hold it where both see it (check {Path(str(film2)).name} too)"
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
    from ..calib._lens import WEAK_RMS_PX

    if not max(rms1, rms2, float(rms)) <= WEAK_RMS_PX:
        from ..._diagnostics import warn

        warn(
            "W-CALIB-WEAK",
            f"{film1}, {film2}: reprojection RMS {rms1:.3g} / {rms2:.3g} px (each camera), {float(rms):.3g} px "
            f"(stereo), expected well under {WEAK_RMS_PX:g} px: check the board spec (square side, corner count), "
            "blur, and that the board is flat and still in each pose",
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
        b.spec,
    )
