"""``tracks.csv``: the tracked motion of every object, one row per object and frame.

The one definition of the table: its columns and their units (2D from a film, 3D from points),
the ``status`` vocabulary and which statuses are usable samples, and the one reader
(:func:`read_tracks`) and one writer (:func:`write_tracks`) of the file, CSV or Parquet. The
trackers build the rows (:meth:`rocklab.tracking.TrackResult.to_frame`,
:meth:`rocklab.tracking.rigid.Track3DResult.to_frame`); ``rocklab fit restitution``,
``rocklab run`` and the assumption audit read them through :class:`Tracks`, so they use the
same samples of the same file.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._errors import InputError, where

__all__ = [
    "Tracks",
    "read_tracks",
    "write_tracks",
    "TRACK_COLUMNS",
    "TRACK3D_COLUMNS",
    "COLUMN_UNITS",
    "STATUSES",
    "USABLE_STATUSES",
    "CORRECTION_STATUSES",
    "NOT_BLOCKS",
]

#: Columns of a plane track (``rocklab track``), in file order.
TRACK_COLUMNS = (
    "frame",
    "t_s",
    "object",
    "x_px",
    "y_px",
    "x_m",
    "y_m",
    "theta_rad",
    "sigma_theta_rad",
    "quality",
    "status",
)
#: Columns only a track from 3D points has (``rocklab track3d``, ``rocklab stereo track``).
EXTRA_3D_COLUMNS = ("out_of_plane_rad", "twist_rad", "pivot_slide_m", "pivot_uplift_m")
#: Columns of a track from 3D points: the plane track's, then the out-of-plane measures.
TRACK3D_COLUMNS = TRACK_COLUMNS + EXTRA_3D_COLUMNS
#: Unit of each column ("" for a count, a name or a 0..1 score).
COLUMN_UNITS = {
    "frame": "",
    "t_s": "s",
    "object": "",
    "x_px": "px",
    "y_px": "px",
    "x_m": "m",
    "y_m": "m",
    "theta_rad": "rad",
    "sigma_theta_rad": "rad",
    "quality": "",
    "status": "",
    "out_of_plane_rad": "rad",
    "twist_rad": "rad",
    "pivot_slide_m": "m",
    "pivot_uplift_m": "m",
}
#: Every status a tracker or a correction writes, and what it means (docs/track-toml.md).
STATUSES = {
    "ok": "measured (and, markerless, verified)",
    "lost": "no pose found",
    "occluded": "lost; the target's last window lost its contrast",
    "blur": "lost; the target's last window lost its fine detail",
    "mismatch": "markerless: the pose does not re-explain the image",
    "jump": "markerless: the pose leaves the motion of the verified frames",
    "background": "markerless: the pose sits on the still background",
    "drift": "markerless: the pose slid off the object's silhouette",
    "twin": "markerless: found again beside a look-alike that continuity cannot tell from it",
    "roundtrip": "markerless: tracked back to the keyframe's frame, the pose's patch lands elsewhere",
    "one_marker": "markers: only one of the object's small markers seen; no pose",
    "low_quality": "measured with a quality below targets.min_quality",
    "outlier": "an angle step no rocking block makes",
    "latch": "on pixels another object's tracker keeps (it jumped there)",
    "interpolated": "filled between two ok frames (motion.interpolate_max_gap_frames)",
    "corrected": "set by hand from a corrections file",
    "dropped": "removed by hand from a corrections file",
    "degenerate": "3D: the points seen do not fix a pose",
}
#: Statuses whose samples a fit or a comparison uses: measured, or vouched for by hand. An
#: interpolated sample is invented, so it is drawn but never fitted.
USABLE_STATUSES = ("ok", "corrected")
#: Statuses a correction gives a frame.
CORRECTION_STATUSES = ("corrected", "dropped")
#: Object ids that name the table or a reference, never a block.
NOT_BLOCKS = ("table", "base", "reference")


@dataclass(frozen=True)
class Tracks:
    """The rows of a ``tracks.csv`` (or of an IMU export with ``t_s, theta_rad``).

    Attributes
    ----------
    frame : pandas.DataFrame
        The rows, with ``t_s`` and ``theta_rad`` numeric (unreadable cells NaN) and ``line``,
        each row's line in the file (1 is the header).
    path : Path or None
        The file read (None for rows made in memory).
    """

    frame: object
    path: Path | None = None

    @classmethod
    def from_frame(cls, frame, path=None) -> "Tracks":
        """Rows made in memory (a tracker's :meth:`to_frame`), checked as a file's would be."""
        return cls(_checked(frame.reset_index(drop=True), path), None if path is None else Path(path))

    @property
    def is_3d(self) -> bool:
        """Whether the rows carry the out-of-plane columns of a track from 3D points."""
        return all(c in self.frame.columns for c in EXTRA_3D_COLUMNS)

    @property
    def objects(self) -> tuple:
        """The object ids in file order (empty when the file has no ``object`` column)."""
        if "object" not in self.frame.columns:
            return ()
        import pandas as pd

        return tuple(str(x) for x in pd.unique(self.frame["object"].astype(str)))

    def block_id(self, obj: str | None = None, fix: str = "--object") -> str | None:
        """The object the rows of a block are taken from: ``obj``, or the only object that is not
        the table (None when the file has no ``object`` column).

        Raises
        ------
        InputError
            ``obj`` is not in the file, or it is None and several blocks are (``fix`` names the
            option or key that chooses one).
        """
        ids = self.objects
        if not ids:
            return None
        if obj is None:
            cand = [i for i in ids if i.lower() not in NOT_BLOCKS]
            if len(cand) != 1:
                raise InputError(f"{where(self.path, key='object')}several objects {ids}; choose one with {fix}")
            return cand[0]
        if obj not in ids:
            raise InputError(
                f"{where(self.path, key='object')}object {obj!r} not in the file (has {list(ids)}); fix {fix}"
            )
        return obj

    def rows(self, obj: str | None = None, fix: str = "--object") -> "Tracks":
        """The rows of one object (:meth:`block_id` chooses it)."""
        oid = self.block_id(obj, fix)
        if oid is None:
            return self
        df = self.frame[self.frame["object"].astype(str) == oid]
        return Tracks(df.reset_index(drop=True), self.path)

    def usable(self) -> np.ndarray:
        """Boolean mask, shape (n,): rows whose ``t_s`` and ``theta_rad`` are finite and whose
        ``status`` (when the file has one) is one of :data:`USABLE_STATUSES`."""
        ok = np.isfinite(self.frame["t_s"].to_numpy(float)) & np.isfinite(self.frame["theta_rad"].to_numpy(float))
        if "status" in self.frame.columns:
            ok &= self.frame["status"].astype(str).str.strip().str.lower().isin(USABLE_STATUSES).to_numpy()
        return ok

    def theta(self) -> tuple[np.ndarray, np.ndarray]:
        """``(t_s, theta_rad)``, shape (n,) each, every row kept; θ NaN where a row is not usable.

        Call on one object's rows (:meth:`rows`).
        """
        t = self.frame["t_s"].to_numpy(float)
        th = np.where(self.usable(), self.frame["theta_rad"].to_numpy(float), np.nan)
        return t, th

    def column(self, name: str) -> np.ndarray:
        """One numeric column as floats, shape (n,)."""
        return self.frame[name].to_numpy(float)


def _checked(df, path):
    import pandas as pd

    missing = [c for c in ("t_s", "theta_rad") if c not in df.columns]
    if missing:
        raise InputError(f"{where(path, 1)}missing column(s) {missing}; a track needs t_s and theta_rad (SI units)")
    df = df.copy()
    for c in ("t_s", "theta_rad"):
        df[c] = pd.to_numeric(df[c], errors="coerce")
    df["line"] = np.arange(len(df)) + 2
    return df


def read_tracks(path) -> Tracks:
    """Read a ``tracks.csv`` (or ``.parquet``), or an IMU export with ``t_s, theta_rad``.

    Raises
    ------
    FileNotFoundError
        No such file.
    InputError
        Not a readable table, or no ``t_s`` / ``theta_rad`` column.
    """
    import pandas as pd

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(2, "not found", str(path))
    try:
        if path.suffix.lower() == ".parquet":
            df = pd.read_parquet(path)
        else:
            df = pd.read_csv(path)
    except pd.errors.EmptyDataError:
        raise InputError(f"{where(path)}empty file; need columns t_s,theta_rad") from None
    except Exception as e:  # noqa: BLE001 - pandas and pyarrow raise many types for a damaged file
        raise InputError(
            f"{where(path)}not a readable table ({type(e).__name__}); give a CSV or Parquet file with t_s, theta_rad"
        ) from None
    return Tracks(_checked(df, path), path)


def write_tracks(path, frame, *, side: bool = False) -> Path:
    """Write tracker rows to ``path`` atomically: Parquet for a ``.parquet`` name, CSV otherwise.

    In the CSV, coordinates have 9 significant digits (0.1 µm at 100 m) and ``t_s`` the shortest
    text that reads back to the same float (times may be absolute, ~1.7e9 s).

    Parameters
    ----------
    path : str or Path
    frame : pandas.DataFrame
        Rows with :data:`TRACK_COLUMNS` or :data:`TRACK3D_COLUMNS`, in that order.
    side : bool
        A user's file at ``path`` is kept beside (:func:`rocklab._io.atomic_path`).
    """
    from .._io import atomic_path

    cols = tuple(frame.columns)
    if cols not in (TRACK_COLUMNS, TRACK3D_COLUMNS):
        raise ValueError(f"tracks rows have columns {cols}; expected TRACK_COLUMNS or TRACK3D_COLUMNS")
    path = Path(path)
    with atomic_path(path, side=side) as tmp:
        if path.suffix.lower() == ".parquet":
            frame.to_parquet(tmp, index=False)
        else:
            out = frame.copy()
            out["t_s"] = [repr(float(v)) for v in out["t_s"].to_numpy(float)]
            out.to_csv(tmp, index=False, float_format="%.9g")
    return path
