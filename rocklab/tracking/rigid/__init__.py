"""Rigid-body motion from tracked points, and the audit of the planar-rocking assumptions.

What lives here:

- readers for 3D point exports of optical systems: a long CSV
  (``t_s, point, x_m, y_m, z_m``) and C3D (:func:`read_points`, :class:`PointSeries`);
- the rigid pose of a point set in every sample (:func:`kabsch`, :func:`body_poses`);
- the rocking decomposition: rocking angle about the bottom edge, out-of-plane
  rotation, twist, and the motion of the active pivot edge (:func:`track_points3d`);
- the assumption audit (:func:`audit_rocking`): sliding, jumping, twist,
  out-of-plane rotation and double impacts against stated tolerances, for 3D
  and 2D tracks alike.
"""

from ._audit import FLAG_KINDS, AuditFlag, AuditResult, AuditTolerances, audit_rocking
from ._pose import BodyPoses, body_poses, kabsch, reference_shape
from ._read_points import PointSeries, read_c3d, read_points, read_points_csv, write_c3d, write_points_csv
from ._plane_audit import audit_plane_track, plane_pivot_motion
from ._rocking import RockingGeometry, find_impacts, fit_pivots, rocking_axes, split_rotation
from ._track3d import TRACK3D_COLUMNS, Body3D, Track3DResult, parse_bodies, track_points3d

__all__ = [
    "PointSeries",
    "read_points",
    "read_points_csv",
    "read_c3d",
    "write_points_csv",
    "write_c3d",
    "kabsch",
    "body_poses",
    "BodyPoses",
    "reference_shape",
    "RockingGeometry",
    "rocking_axes",
    "split_rotation",
    "find_impacts",
    "fit_pivots",
    "track_points3d",
    "Track3DResult",
    "Body3D",
    "TRACK3D_COLUMNS",
    "parse_bodies",
    "audit_rocking",
    "audit_plane_track",
    "plane_pivot_motion",
    "AuditResult",
    "AuditFlag",
    "AuditTolerances",
    "FLAG_KINDS",
]
