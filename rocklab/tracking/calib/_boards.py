"""Calibration boards: the spec a user types, the board's corners in its own plane, and their
detection in a picture.

Spec (``--board``), one of

- ``checkerboard,COLSxROWS,SQUARE_M``: a chessboard; ``COLSxROWS`` counts the **inner corners**
  (where four squares meet), OpenCV's pattern size: a board of 10 x 7 squares is ``9x6``;
  ``SQUARE_M`` is a square's side in metres. The whole board must be seen in a picture.
- ``charuco,COLSxROWS,SQUARE_M,MARKER_M,DICT``: a ChArUco board; ``COLSxROWS`` counts the
  **squares** (OpenCV's ``CharucoBoard`` size: its inner corners are one fewer each way),
  ``MARKER_M`` the printed ArUco marker's side, ``DICT`` the OpenCV dictionary name
  (``DICT_5X5_100``...). A partly seen board still counts.
- ``COLSxROWS,SQUARE_M,MARKER_M,DICT``: a ChArUco board (the form ``rocklab stereo calibrate``
  has always read).

Checkerboard corners are found with ``cv2.findChessboardCornersSB`` (the sector-based
detector, ``CALIB_CB_ACCURACY``) and refined with ``cv2.cornerSubPix``; ChArUco corners with
``cv2.aruco.CharucoDetector``, which interpolates them from the markers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..._errors import InputError

__all__ = ["Board", "parse_board", "board_from_dict"]

#: cornerSubPix's half-window as a share of the corner spacing.
SUBPIX_WINDOW = 0.2
_EXAMPLE = "e.g. checkerboard,9x6,0.025 or charuco,9x6,0.03,0.022,DICT_5X5_100"


@dataclass(frozen=True)
class Board:
    """A calibration board.

    Attributes
    ----------
    kind : {"checkerboard", "charuco"}
    cols, rows : int
        Checkerboard: inner corners across and down; ChArUco: squares across and down.
    square_m : float
        Side of a square, m.
    marker_m : float or None
        ChArUco marker side, m.
    dictionary : str or None
        ChArUco ArUco dictionary (OpenCV name).
    """

    kind: str
    cols: int
    rows: int
    square_m: float
    marker_m: float | None = None
    dictionary: str | None = None

    @property
    def spec(self) -> str:
        """The board as a ``--board`` spec."""
        if self.kind == "checkerboard":
            return f"checkerboard,{self.cols}x{self.rows},{self.square_m:g}"
        return f"charuco,{self.cols}x{self.rows},{self.square_m:g},{self.marker_m:g},{self.dictionary}"

    @property
    def n_corners(self) -> int:
        """Corners of the whole board (checkerboard: inner corners; ChArUco: its chessboard corners)."""
        if self.kind == "checkerboard":
            return self.cols * self.rows
        return (self.cols - 1) * (self.rows - 1)

    def object_points(self) -> np.ndarray:
        """Corner ``i``'s position on the board, m, shape (n_corners, 3) (z = 0)."""
        if self.kind == "checkerboard":
            ix, iy = np.meshgrid(np.arange(self.cols), np.arange(self.rows))
            xy = np.column_stack((ix.ravel(), iy.ravel())) * self.square_m
            return np.column_stack((xy, np.zeros(len(xy)))).astype(np.float64)
        return np.asarray(self._charuco().getChessboardCorners(), np.float64).reshape(-1, 3)

    def _charuco(self):
        import cv2

        d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, self.dictionary))
        return cv2.aruco.CharucoBoard((self.cols, self.rows), float(self.square_m), float(self.marker_m), d)

    def detector(self):
        """A callable ``gray -> {corner id: (u, v)}`` (empty where the board is not found)."""
        import cv2

        if self.kind == "charuco":
            det = cv2.aruco.CharucoDetector(self._charuco())

            def find(gray):
                cc, ci, _, _ = det.detectBoard(gray)
                return {} if ci is None else {int(i): c for i, c in zip(ci.ravel(), cc.reshape(-1, 2).astype(float))}

            return find
        pattern = (self.cols, self.rows)

        def find(gray):
            ok, corners = cv2.findChessboardCornersSB(gray, pattern, flags=cv2.CALIB_CB_ACCURACY)
            if not ok:
                return {}
            pts = corners.reshape(-1, 2).astype(np.float32)
            # the sector-based detector leaves ~0.2 px errors; cornerSubPix is exact on X-junctions while
            # its window stays clear of the neighbouring corners (on the OpenCV/Bouguet stereo set the
            # RMS is 0.18 px at a fifth of the spacing, 0.31 px at three tenths)
            steps = np.diff(pts.reshape(self.rows, self.cols, 2), axis=1).reshape(-1, 2)
            win = int(np.clip(SUBPIX_WINDOW * float(np.median(np.hypot(*steps.T))), 2, 10))
            crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 50, 1e-3)
            pts = cv2.cornerSubPix(gray, pts.reshape(-1, 1, 2), (win, win), (-1, -1), crit).reshape(
                self.rows, self.cols, 2
            )
            # the detector may number the corners from either end: start from the one on the left of
            # the picture, so two cameras side by side agree on corner i
            if pts[0, 0, 0] > pts[-1, -1, 0]:
                pts = pts[::-1, ::-1]
            return {i: p for i, p in enumerate(pts.reshape(-1, 2).astype(float))}

        return find


def parse_board(spec: str, option: str = "--board") -> Board:
    """The :class:`Board` of a ``--board`` spec (see the module's doc).

    Raises
    ------
    InputError
        One line naming the spec, the rule broken and an example.
    """
    import cv2

    parts = [p.strip() for p in str(spec).split(",")]
    kind = parts[0].lower()
    if kind not in ("checkerboard", "chessboard", "charuco"):
        kind, parts = "charuco", ["charuco", *parts]  # the legacy ChArUco form
        if len(parts) != 5:
            raise InputError(f"{option} {spec!r}: not a board; give {_EXAMPLE}")
    kind = "checkerboard" if kind == "chessboard" else kind
    want = 3 if kind == "checkerboard" else 5
    if len(parts) != want:
        form = (
            "checkerboard,COLSxROWS,SQUARE_M" if kind == "checkerboard" else "charuco,COLSxROWS,SQUARE_M,MARKER_M,DICT"
        )
        raise InputError(f"{option} {spec!r}: a {kind} is {form} ({want - 1} values after the kind); {_EXAMPLE}")
    try:
        c, r = (int(v) for v in parts[1].lower().split("x"))
        square = float(parts[2])
        marker = float(parts[3]) if kind == "charuco" else None
    except ValueError:
        raise InputError(
            f"{option} {spec!r}: COLSxROWS must be two whole numbers and the sizes numbers in metres; {_EXAMPLE}"
        ) from None
    if kind == "checkerboard" and not (math.isfinite(square) and 0 < square < 1):
        raise InputError(
            f"{option} {spec!r}: the square side {parts[2]} must be in metres (0 < SQUARE_M < 1, e.g. 0.025)"
        )
    if kind == "checkerboard":
        if min(c, r) < 2:
            raise InputError(f"{option} {spec!r}: a checkerboard has at least 2x2 inner corners (e.g. 9x6)")
        return Board("checkerboard", c, r, square)
    if min(c, r) < 3:
        raise InputError(f"{option} {spec!r}: a ChArUco board has at least 3x3 squares (e.g. 9x6)")
    if not (math.isfinite(square) and math.isfinite(marker) and 0 < marker < square < 1):
        raise InputError(
            f"{option} {spec!r}: the marker side ({parts[3]} m) must be positive and smaller than the square side "
            f"({parts[2]} m), both in metres, e.g. 0.03,0.022"
        )
    if not parts[4].startswith("DICT_") or not hasattr(cv2.aruco, parts[4]):
        raise InputError(
            f"{option} {spec!r}: unknown ArUco dictionary {parts[4]!r}; e.g. DICT_5X5_100, DICT_4X4_50, DICT_6X6_250"
        )
    return Board("charuco", c, r, square, marker, parts[4])


def board_from_dict(d: dict) -> Board:
    """The ChArUco :class:`Board` of a legacy ``{"squares", "square_m", "marker_m", "dictionary"}`` dict."""
    c, r = d["squares"]
    return Board("charuco", int(c), int(r), float(d["square_m"]), float(d["marker_m"]), str(d["dictionary"]))
