"""Measurement: from films, IMU logs and 3D point exports to rotations and table motion.

Sub-packages:

- :mod:`rocklab.tracking.video`: one camera, any target style, ``track.toml``;
- :mod:`rocklab.tracking.imu`: x-IMU / x-IMU3 / Fusion logs, block rotation, table acceleration;
- :mod:`rocklab.tracking.rigid`: 3D point imports (CSV, C3D), rigid poses, the rocking
  decomposition and the assumption audit;
- :mod:`rocklab.tracking.stereo`: two cameras (calibration, sync, 3D dots and markers).
- :mod:`rocklab.tracking.imports`: other tools' tracking (Tracker, Kinovea, DLTdv) as plane
  tracks or 3D points.
- :mod:`rocklab.tracking.calib`: camera calibration from checkerboard and ChArUco pictures (films,
  folders of photos): one camera's lens file, and the boards the stereo calibration reads.

The table motion fused from the table IMU and the film (:func:`fuse_table_motion`) is here too.
The clock synchronisation of an IMU to a video track is here (:func:`sync_offset`,
:func:`sync_imu_to_track`), and the manual corrections of a track (:func:`load_corrections`,
:func:`apply_corrections`). Every public name of the sub-packages is also here: each
sub-package's ``__all__`` is the one list.
"""

from . import calib, imports, imu, rigid, stereo, video
from ._corrections import apply_corrections, load_corrections
from ._table_scale import FILM_SCALE_SD, IMU_SCALE_SD, TableScale, table_scale_agreement
from ._table_fusion import BIAS_MAX_M_S2, BIAS_WALK_M_S2, DISAGREE_NIS, MARGIN_S, TableFusion, fuse_table_motion
from ._sync import SyncResult, sync_events, sync_imu_to_track, sync_offset, track_rate
from .calib import *  # noqa: F403
from .imports import *  # noqa: F403
from .imu import *  # noqa: F403
from .rigid import *  # noqa: F403
from .stereo import *  # noqa: F403
from .video import *  # noqa: F403

__all__ = [
    "SyncResult",
    "sync_events",
    "sync_imu_to_track",
    "sync_offset",
    "track_rate",
    "load_corrections",
    "apply_corrections",
    "TableFusion",
    "TableScale",
    "table_scale_agreement",
    "FILM_SCALE_SD",
    "IMU_SCALE_SD",
    "fuse_table_motion",
    "BIAS_MAX_M_S2",
    "BIAS_WALK_M_S2",
    "DISAGREE_NIS",
    "MARGIN_S",
]
__all__ += video.__all__
__all__ += imu.__all__
__all__ += calib.__all__
__all__ += rigid.__all__
__all__ += stereo.__all__
__all__ += imports.__all__
