"""From triangulated targets in camera 1's axes to labelled points in a table frame (z up).

The targets are split into rigid groups (their mutual distances hold over the
film); a group that stays still is the table, the moving ones are blocks. The
table's plane gives the vertical (pointing to the blocks) and the origin (its
targets' centroid), so ``rocklab track3d``'s ``--up z`` holds whatever the
cameras' tilt. Targets on an upright plate give the vertical within their
plane, across camera 1's image rows; without three still targets
the vertical is camera 1's image-up direction; both with a note.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from ..rigid import PointSeries
from ..rigid._rigidity import rigid_groups
from ._dots3d import StereoPoints

__all__ = ["stereo_point_series"]

#: A group whose centroid moves less than this over the film is the table, m.
STILL_M = 2e-3


def stereo_point_series(sp: StereoPoints, source: str = ""):
    """``(PointSeries in a table frame, bodies {name: labels}, notes)`` from triangulated targets."""
    k = sp.xyz_m.shape[1]
    labels = list(sp.labels) if sp.labels is not None else [f"P{i + 1}" for i in range(k)]
    xyz = sp.xyz_m
    groups = rigid_groups(xyz, labels)
    still, moving = [], []
    for g in groups:
        idx = [labels.index(lab) for lab in g]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            cen = np.nanmean(xyz[:, idx], axis=1)
            span = float(np.nanmax(np.nanpercentile(cen, 99, axis=0) - np.nanpercentile(cen, 1, axis=0)))
        (still if span < STILL_M else moving).append((g, idx))
    notes = []
    bodies = {}
    for i, (g, _) in enumerate(moving):
        bodies["block" if i == 0 else f"block{i + 1}"] = tuple(g)
    table = still[0] if still and len(still[0][0]) >= 3 else None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        rest = np.nanmedian(xyz, axis=0)  # (k, 3)
    cam_up = np.array([0.0, -1.0, 0.0])  # camera 1's image-up direction
    if table is not None:
        bodies["table"] = tuple(table[0])
        q = rest[table[1]]
        origin = q.mean(axis=0)
        _, sv, vt = np.linalg.svd(q - origin)
        normal = vt[2]
        if sv[1] < 1e-3 * sv[0]:
            table = None
            notes.append("the still targets lie on a line: the vertical is camera 1's image-up direction")
        elif abs(normal @ cam_up) > math.cos(math.radians(45.0)):
            up = normal  # targets on the table top
        else:
            # targets on an upright plate (the table's edge): the vertical lies in its plane, and camera 1's
            # x axis is horizontal when the camera is not rolled, so the vertical is across both
            up = np.cross(normal, np.array([1.0, 0.0, 0.0]))
            up /= np.linalg.norm(up)
            up = up if up @ cam_up > 0 else -up
            notes.append(
                "the table's targets stand upright: the vertical is taken across their plane and "
                "camera 1's image rows (a camera roll stays in it; put three targets on the table top)"
            )
    if table is None:
        up = cam_up
        origin = np.nanmean(rest, axis=0)
        if not notes:
            notes.append("no three still targets (a table): the vertical is camera 1's image-up direction")
    blocks_c = np.nanmean(rest[[labels.index(lab) for g in bodies.values() for lab in g]], axis=0) if moving else origin
    if (blocks_c - origin) @ up < 0:
        up = -up
    e1 = np.array([1.0, 0.0, 0.0]) - up[0] * up
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(up, e1)
    Rw = np.stack([e1, e2, up])
    world = (xyz - origin) @ Rw.T
    if not moving:
        notes.append("no moving rigid group of targets: nothing rocks in this film")
    return PointSeries(sp.t_s, tuple(labels), world, source, tuple(notes)), bodies, notes
