"""Two-camera (stereo) measurement: calibration, synchronisation and 3D dot tracking.

- :func:`calibrate_stereo`: intrinsics, distortion and relative pose from films of a
  ChArUco board seen by both cameras (:class:`StereoRig`, saved as ``stereo.json``);
- :func:`track_dots_stereo`: dot targets found in both films, matched along epipolar
  lines, triangulated and followed over time, giving a
  :class:`~rocklab.tracking.rigid.PointSeries` for :func:`~rocklab.tracking.rigid.track_points3d`;
- :func:`track_markers_stereo`: the same for ArUco markers, each corner a target named by id;
- :func:`sync_offset_stereo`: the sub-frame clock offset between two cameras that
  share no trigger, from the motion both see.
"""

from ._calib import DEFAULT_BOARD, StereoRig, calibrate_stereo, charuco_board, load_rig
from ._dots3d import (
    DotTracks2D,
    StereoPoints,
    SyncOffset,
    detect_dots,
    match_tracks,
    sync_offset_stereo,
    track_dots_2d,
    track_dots_stereo,
    triangulate_tracks,
)
from ._markers import track_markers_2d, track_markers_stereo
from ._world import stereo_point_series

__all__ = [
    "StereoRig",
    "calibrate_stereo",
    "load_rig",
    "DEFAULT_BOARD",
    "charuco_board",
    "detect_dots",
    "track_dots_2d",
    "DotTracks2D",
    "match_tracks",
    "sync_offset_stereo",
    "SyncOffset",
    "triangulate_tracks",
    "StereoPoints",
    "track_dots_stereo",
    "stereo_point_series",
    "track_markers_2d",
    "track_markers_stereo",
]
