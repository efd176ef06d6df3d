"""One camera's lens from pictures of a board: ``rocklab calibrate`` and the lens file.

The intrinsics (focal lengths, principal point) and OpenCV's distortion ``k1, k2, p1, p2, k3``
come from ``cv2.calibrateCameraExtended`` on the board corners of every view where the board is
found, with the 1-sigma of each intrinsic from the same fit.

The lens file (``lens.json``, written atomically) holds::

    {"format": "rocklab-lens/1",
     "camera_matrix": [[fx, 0, cx], [0, fy, cy], [0, 0, 1]],   # px
     "fx_px": ..., "fy_px": ..., "cx_px": ..., "cy_px": ...,
     "sigma_px": {"fx": ..., "fy": ..., "cx": ..., "cy": ...},  # 1-sigma from the fit
     "dist_coeffs": [k1, k2, p1, p2, k3],
     "size_px": [width, height],                               # the pictures' size
     "rms_px": ...,                                            # reprojection RMS
     "board": "checkerboard,9x6,0.025", "n_views": ..., "views": [...], "source": "...",
     "status": "ok" | "weak", "message": "..."}

``[video] calibration = "lens.json"`` in ``track.toml`` (or ``rocklab track init --lens``)
undistorts every detected image point with it before any geometry; a film of another size than
``size_px`` is refused (the intrinsics scale with the picture).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..._errors import InputError, where
from ._boards import Board, parse_board
from ._views import open_views, warn_lost

__all__ = ["Lens", "calibrate_lens", "load_lens", "detect_views", "LENS_FORMAT"]

LENS_FORMAT = "rocklab-lens/1"
#: Fewest views where the board is found for a calibration (each view fixes a pose and adds
#: two constraints on the intrinsics).
MIN_VIEWS = 3
#: Fewest corners of a ChArUco board for a view to count (a checkerboard counts only whole).
MIN_CHARUCO_CORNERS = 8
#: A focal length whose 1-sigma exceeds this share of it is weakly determined (W-CALIB-WEAK):
#: too few views, or views that do not tilt the board.
WEAK_SIGMA_REL = 0.01
#: A reprojection RMS above this is a wrong board spec, blur or a moving board (W-CALIB-WEAK), px.
WEAK_RMS_PX = 1.0


@dataclass(frozen=True)
class Lens:
    """A calibrated camera lens.

    Attributes
    ----------
    K : ndarray, shape (3, 3)
        Intrinsics, px.
    dist : ndarray, shape (5,)
        OpenCV distortion ``k1, k2, p1, p2, k3``.
    size : tuple of int
        (width, height) of the pictures, px.
    rms_px : float
        Reprojection RMS over every corner of every view used, px.
    sigma_px : dict
        1-sigma of ``fx``, ``fy``, ``cx``, ``cy`` from the fit, px.
    board : str
        The board spec.
    views : tuple of str
        The views used (file names or ``frame N``).
    view_rms_px : tuple of float
        Each view's reprojection RMS, px.
    source : str
    status : {"ok", "weak"}
    message : str
        Why the status is not ``ok`` (empty when it is).
    n_seen : int
        Pictures looked at (the board found or not).
    """

    K: np.ndarray
    dist: np.ndarray
    size: tuple
    rms_px: float
    sigma_px: dict
    board: str
    views: tuple
    view_rms_px: tuple = ()
    source: str = ""
    status: str = "ok"
    message: str = ""
    n_seen: int = 0

    @property
    def n_views(self) -> int:
        return len(self.views)

    def to_dict(self) -> dict:
        """The lens file's object (see the module's doc)."""
        K = np.asarray(self.K, float)
        return {
            "format": LENS_FORMAT,
            "camera_matrix": K.tolist(),
            "fx_px": K[0, 0],
            "fy_px": K[1, 1],
            "cx_px": K[0, 2],
            "cy_px": K[1, 2],
            "sigma_px": dict(self.sigma_px),
            "dist_coeffs": np.asarray(self.dist, float).ravel().tolist(),
            "size_px": [int(v) for v in self.size],
            "rms_px": float(self.rms_px),
            "board": self.board,
            "n_views": self.n_views,
            "views": list(self.views),
            "view_rms_px": [float(v) for v in self.view_rms_px],
            "source": self.source,
            "status": self.status,
            "message": self.message,
        }

    def save(self, path, *, side: bool = False) -> Path:
        """Write the lens file atomically."""
        from ..._io import write_json_atomic

        return write_json_atomic(path, self.to_dict(), side=side)


def detect_views(views, board: Board, lost: list | None = None):
    """``(labels, detections, size)``: every view's ``{corner id: (u, v)}`` (empty where the board
    is not found) and the pictures' (width, height), px.

    Raises
    ------
    InputError
        Pictures of different sizes.
    """
    find = board.detector()
    labels, dets, size = [], [], None
    for label, gray in views.items(lost):
        s = (gray.shape[1], gray.shape[0])
        if size is None:
            size = s
        elif s != size:
            raise InputError(
                f"{views.source}: {label} is {s[0]}x{s[1]} px, the first picture {size[0]}x{size[1]}; a calibration "
                "uses pictures of one camera at one size (remove the others)"
            )
        labels.append(label)
        dets.append(find(gray))
    if size is None:
        raise InputError(f"{views.source}: no pictures to calibrate from")
    return labels, dets, size


def usable(det: dict, board: Board) -> bool:
    """Whether a view's corners count for a calibration."""
    need = board.n_corners if board.kind == "checkerboard" else MIN_CHARUCO_CORNERS
    return len(det) >= need


def not_found_hint(board: Board) -> str:
    """What to check when the board is found in too few views."""
    if board.kind == "checkerboard":
        return (
            f"check --board: {board.cols}x{board.rows} counts INNER corners (a board of "
            f"{board.cols + 1}x{board.rows + 1} squares), and the whole board must be in the picture"
        )
    return f"check --board: {board.cols}x{board.rows} counts squares, dictionary {board.dictionary}"


def calibrate_lens(source, board, *, every: int | None = None, fix_k3: bool = False) -> Lens:
    """Calibrate one camera from pictures of a board.

    Parameters
    ----------
    source : path-like or str
        A film, a folder of photos or a file pattern (:func:`~rocklab.tracking.calib.open_views`).
    board : Board or str
        The board (or its ``--board`` spec, :func:`~rocklab.tracking.calib.parse_board`).
    every : int or None
        A film: every ``every``-th frame (None: at most 100 frames).
    fix_k3 : bool
        Hold the sixth-order radial term ``k3`` at 0 (few views, or a lens with little distortion).

    Returns
    -------
    Lens
        ``status`` ``"weak"`` (and W-CALIB-WEAK) when a focal length's 1-sigma exceeds 1 % of it
        or the reprojection RMS exceeds 1 px.

    Raises
    ------
    InputError
        The board found in fewer than 3 views; pictures of different sizes.
    """
    import cv2

    board = parse_board(board) if isinstance(board, str) else board
    views = open_views(source, every)
    lost: list = []
    labels, dets, size = detect_views(views, board, lost)
    warn_lost(lost)
    keep = [k for k, d in enumerate(dets) if usable(d, board)]
    if len(keep) < MIN_VIEWS:
        raise InputError(
            f"{where(source)}the board is found in {len(keep)} of {len(dets)} pictures; need {MIN_VIEWS}: "
            f"{not_found_hint(board)}"
        )
    obj_all = board.object_points().astype(np.float32)
    obj = [obj_all[sorted(dets[k])] for k in keep]
    img = [np.array([dets[k][i] for i in sorted(dets[k])], np.float32).reshape(-1, 1, 2) for k in keep]
    flags = cv2.CALIB_FIX_K3 if fix_k3 else 0
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 100, 1e-12)
    rms, K, dist, _, _, std_in, _, per_view = cv2.calibrateCameraExtended(
        obj, img, size, None, None, flags=flags, criteria=crit
    )
    std = np.asarray(std_in, float).ravel()
    sigma = {"fx": std[0], "fy": std[1], "cx": std[2], "cy": std[3]}
    problems = []
    rel = max(sigma["fx"] / K[0, 0], sigma["fy"] / K[1, 1])
    if not rel <= WEAK_SIGMA_REL:
        problems.append(
            f"the focal length is known to {100 * rel:.3g} % (1-sigma) from {len(keep)} views: add views with the "
            "board tilted 20-45 degrees in different directions, filling the picture's corners"
        )
    if not rms <= WEAK_RMS_PX:
        problems.append(
            f"the reprojection RMS is {rms:.3g} px (expected well under {WEAK_RMS_PX:g}): check the board spec "
            "(square side, corner count), blur and that the board is flat and still in each picture"
        )
    message = "; ".join(problems)
    if problems:
        from ..._diagnostics import warn

        warn("W-CALIB-WEAK", f"{source}: {message}")
    return Lens(
        np.asarray(K, float),
        np.asarray(dist, float).ravel(),
        tuple(int(v) for v in size),
        float(rms),
        {k: float(v) for k, v in sigma.items()},
        board.spec,
        tuple(labels[k] for k in keep),
        tuple(float(v) for v in np.asarray(per_view).ravel()),
        str(source),
        "weak" if problems else "ok",
        message,
        len(dets),
    )


def load_lens(path) -> Lens:
    """Read a lens file written by :meth:`Lens.save`.

    Raises
    ------
    InputError
        Missing or unreadable file, or a camera matrix / distortion / size that is not one.
    """
    path = Path(path)
    fix = "make one with 'rocklab calibrate FILM_OR_FOLDER --board ...'"
    try:
        d = json.loads(path.read_text(encoding="utf-8"))
        K = np.array(d["camera_matrix"], float)
        dist = np.array(d["dist_coeffs"], float).ravel()
        size = tuple(int(v) for v in d["size_px"])
    except FileNotFoundError:
        raise InputError(f"{path}: lens file not found; {fix}") from None
    except (ValueError, KeyError, TypeError, AttributeError) as e:
        raise InputError(f"{path}: not a lens file ({type(e).__name__}: {e}); {fix}") from None
    if K.shape != (3, 3) or not np.all(np.isfinite(K)) or not (K[0, 0] > 0 and K[1, 1] > 0) or K[2, 2] != 1:
        raise InputError(
            f"{path}: 'camera_matrix' must be [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] with fx, fy > 0; {fix}"
        )
    if dist.size not in (4, 5, 8, 12, 14) or not np.all(np.isfinite(dist)):
        raise InputError(f"{path}: 'dist_coeffs' must be 4, 5, 8, 12 or 14 finite numbers (has {dist.size}); {fix}")
    if len(size) != 2 or min(size) <= 0:
        raise InputError(f"{path}: 'size_px' must be [width, height] in pixels; {fix}")
    return Lens(
        K,
        dist,
        size,
        float(d.get("rms_px", float("nan"))),
        dict(d.get("sigma_px", {})),
        str(d.get("board", "")),
        tuple(d.get("views", ())),
        tuple(d.get("view_rms_px", ())),
        str(d.get("source", "")),
        str(d.get("status", "ok")),
        str(d.get("message", "")),
    )
