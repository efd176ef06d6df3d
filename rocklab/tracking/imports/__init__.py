"""Imports from the tools labs already use: Tracker, Kinovea, DLTdv and GOM exports.

- plane tools (Tracker ``.trk``/``.trz`` and its exported data tables, Kinovea's spreadsheet ``.xml`` and Gnuplot ``.txt``): named points per frame, in pixels and, when the tool
  was calibrated, in metres (:class:`PlanePoints`), and the ``tracks.csv`` rows of the rigid
  bodies they mark (:func:`plane_tracks`);
- 3D tools (DLTdv ``xypts`` with DLT coefficients, or its ``xyzpts``): the 3D points reader's
  :class:`rocklab.tracking.rigid.PointSeries`, for ``rocklab track3d``.

Every reader converts at the file boundary (time in s, lengths in m) and names the file, line and
fix of a file it cannot read.
"""

from ._detect import IMPORT_TOOLS, PLANE_TOOLS, detect_tool, read_plane_points
from ._dltdv import dlt_project, dlt_reconstruct, dlt_residual, read_dlt_coefs, read_dltdv
from ._kinovea import KINOVEA_UNITS_M, read_kinovea
from ._plane_points import REST_SAMPLES, PlanePoints, parse_plane_bodies, plane_tracks
from ._tracker_table import looks_like_tracker_table, read_tracker_table
from ._tracker_trk import TRACKER_LENGTH_UNITS_M, read_trk

__all__ = [
    "PlanePoints",
    "plane_tracks",
    "parse_plane_bodies",
    "REST_SAMPLES",
    "read_trk",
    "read_tracker_table",
    "looks_like_tracker_table",
    "TRACKER_LENGTH_UNITS_M",
    "read_dltdv",
    "read_dlt_coefs",
    "dlt_reconstruct",
    "dlt_project",
    "dlt_residual",
    "detect_tool",
    "IMPORT_TOOLS",
    "PLANE_TOOLS",
    "read_plane_points",
    "read_kinovea",
    "KINOVEA_UNITS_M",
]
