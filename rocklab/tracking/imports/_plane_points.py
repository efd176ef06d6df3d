"""Points tracked in a film by another tool, and the plane tracks (``tracks.csv`` rows) they give.

Tracker, Kinovea and one camera of DLTdv give the image positions of named points, frame by frame;
some also give them in a calibrated plane. :class:`PlanePoints` holds both, and
:func:`plane_tracks` turns the points of each rigid body into its rocking angle and position:
the body's rotation since its rest shape (a 2D Kabsch fit, counter-clockwise as the camera sees
it), the centroid in pixels and, where the tool was calibrated, in metres.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._errors import InputError, where

__all__ = ["PlanePoints", "plane_tracks", "parse_plane_bodies", "REST_SAMPLES"]

#: Samples (with every point of a body seen) that make its rest shape at ``first`` / ``last``.
REST_SAMPLES = 10


@dataclass(frozen=True)
class PlanePoints:
    """Named points tracked in one film.

    Attributes
    ----------
    t_s : ndarray, shape (n,)
        Frame times, s, strictly increasing.
    frame : ndarray of int, shape (n,)
        The film's frame numbers.
    labels : tuple of str, length p
        Point (track) names as the tool has them.
    xy_px : ndarray, shape (n, p, 2) or None
        Image positions, px, x right and y down; NaN where the point was not marked. None when
        the tool exported only calibrated coordinates.
    xy_m : ndarray, shape (n, p, 2) or None
        Positions in the tool's calibrated plane, m, y up; None without a calibration.
    source : str
        The file read (for messages).
    notes : tuple of str
        What the reader converted (units, time base, coordinate system).
    """

    t_s: np.ndarray
    frame: np.ndarray
    labels: tuple
    xy_px: np.ndarray | None
    xy_m: np.ndarray | None
    source: str = ""
    notes: tuple = field(default=())

    def positions(self) -> np.ndarray:
        """Positions with y up for the angle, shape (n, p, 2): metres when calibrated, else pixels
        with y flipped. A rotation is the same in either (Tracker's and Kinovea's calibrations are
        similarities: one scale, a rotation, an origin)."""
        if self.xy_m is not None:
            return self.xy_m
        return self.xy_px * np.array([1.0, -1.0])


def parse_plane_bodies(specs, labels, source="") -> dict:
    """``{"NAME": (P1, P2, ...)}`` from ``NAME=P1,P2,...`` strings; none: one body ``block_1`` of
    every point. A body of one point is a position only (its angle is not measured). The rules
    and messages are :func:`rocklab.tracking.rigid.parse_bodies`'s."""
    from ..rigid import parse_bodies

    return parse_bodies(specs, labels, source, default_name="block_1", min_points=1)


def _rest_shape(xy, seen, t, rest, name, source):
    """Centred rest shape (k, 2) of a body: the mean of its centred points over the rest samples."""
    idx = np.flatnonzero(seen)
    if idx.size == 0:
        raise InputError(f"{where(source)}body {name!r}: its points are never all marked in one frame")
    if rest in ("auto", "last"):
        pick = idx[-REST_SAMPLES:]
    elif rest == "first":
        pick = idx[:REST_SAMPLES]
    else:
        t0, t1 = rest
        pick = idx[(t[idx] >= t0) & (t[idx] <= t1)]
        if pick.size == 0:
            raise InputError(
                f"{where(source)}body {name!r}: no frame with all its points between t = {t0} and {t1} s; fix --rest"
            )
    centred = xy[pick] - xy[pick].mean(axis=1, keepdims=True)
    return centred.mean(axis=0)


def plane_tracks(points: PlanePoints, bodies: dict, rest="auto"):
    """``tracks.csv`` rows (:data:`rocklab.series.TRACK_COLUMNS`) of each body.

    Parameters
    ----------
    points : PlanePoints
    bodies : dict
        ``{name: (label, ...)}`` (:func:`parse_plane_bodies`); a body of one point gets its
        position and ``theta_rad`` NaN, as a film's ``kind = "point"`` object.
    rest : {"auto", "last", "first"} or (t0_s, t1_s)
        Where the body stands upright: its rest shape is the mean of its centred points over
        the last (``auto``, ``last``: free rocking ends upright) or first :data:`REST_SAMPLES`
        frames with every point seen, or over the frames in ``[t0_s, t1_s]``.

    Returns
    -------
    pandas.DataFrame
        One row per body and frame: ``theta_rad`` the counter-clockwise rotation of the body's
        points from their rest shape (rad), ``x_px, y_px`` and ``x_m, y_m`` their centroid (y up
        in metres; NaN without the tool's calibration), ``sigma_theta_rad`` and ``quality`` NaN
        (the tools give none), ``status`` ``ok``, or ``lost`` where a point was not marked.
    """
    import pandas as pd

    from ...series import TRACK_COLUMNS

    pos = points.positions()
    n = points.t_s.size
    parts = []
    for name, labs in bodies.items():
        idx = [points.labels.index(lab) for lab in labs]
        xy = pos[:, idx, :]
        seen = np.isfinite(xy).all(axis=(1, 2))
        ref = _rest_shape(xy, seen, points.t_s, rest, name, points.source)
        cur = xy - xy.mean(axis=1, keepdims=True)
        cross = (ref[None, :, 0] * cur[:, :, 1] - ref[None, :, 1] * cur[:, :, 0]).sum(axis=1)
        dot = (ref[None, :, 0] * cur[:, :, 0] + ref[None, :, 1] * cur[:, :, 1]).sum(axis=1)
        # one point has a position, never an angle (as a film's kind = "point" object)
        theta = np.where(seen & (len(labs) > 1), np.arctan2(cross, dot), np.nan)
        nan = np.full(n, np.nan)
        px = points.xy_px[:, idx, :].mean(axis=1) if points.xy_px is not None else np.full((n, 2), np.nan)
        m = points.xy_m[:, idx, :].mean(axis=1) if points.xy_m is not None else np.full((n, 2), np.nan)
        parts.append(
            pd.DataFrame(
                {
                    "frame": points.frame,
                    "t_s": points.t_s,
                    "object": name,
                    "x_px": np.where(seen, px[:, 0], np.nan),
                    "y_px": np.where(seen, px[:, 1], np.nan),
                    "x_m": np.where(seen, m[:, 0], np.nan),
                    "y_m": np.where(seen, m[:, 1], np.nan),
                    "theta_rad": theta,
                    "sigma_theta_rad": nan,
                    "quality": nan,
                    "status": np.where(seen, "ok", "lost"),
                }
            )
        )
    df = pd.concat(parts, ignore_index=True)
    return df.sort_values(["frame", "object"], kind="stable").reset_index(drop=True)[list(TRACK_COLUMNS)]
