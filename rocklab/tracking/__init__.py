"""Measurement: from films, IMU logs and 3D point exports to rotations and table motion.

Sub-packages:

- :mod:`rocklab.tracking.video`: one camera, any target style, ``track.toml``;
- :mod:`rocklab.tracking.imu`: x-IMU / x-IMU3 / Fusion logs, block rotation, table acceleration;
- :mod:`rocklab.tracking.rigid`: 3D point imports (CSV, C3D), rigid poses, the rocking
  decomposition and the assumption audit;
- :mod:`rocklab.tracking.stereo`: two cameras (calibration, sync, 3D dots and markers).
- :mod:`rocklab.tracking.calib`: camera calibration from checkerboard and ChArUco pictures (films,
  folders of photos): one camera's lens file, and the boards the stereo calibration reads.

The clock synchronisation of an IMU to a video track is here (:func:`sync_offset`,
:func:`sync_imu_to_track`). The most used names of the sub-packages are re-exported.
"""

from ._corrections import apply_corrections, load_corrections
from ._sync import SyncResult, sync_events, sync_imu_to_track, sync_offset, track_rate
from .calib import Board, Lens, calibrate_lens, load_lens, parse_board
from .imu import (
    ImuLog,
    ImuRotation,
    TableAcceleration,
    ahrs_quaternions,
    block_rotation,
    read_imu,
    read_ximu_registers,
    table_acceleration,
    ximu_rate_from_registers,
)
from .video import (
    TRACK_COLUMNS,
    BoardConfig,
    MotionConfig,
    ObjectConfig,
    ObjectTrack,
    Observation,
    PlaneMap,
    ReferenceConfig,
    SimilarityFit,
    TableMotion,
    TargetsConfig,
    TrackConfig,
    TrackResult,
    VideoConfig,
    VideoInfo,
    assemble_tracks,
    calibrate_camera,
    choose_sg_window,
    estimate_noise,
    fit_similarity,
    iter_video_frames,
    load_track_config,
    probe_video,
    table_motion,
    track_frames,
    track_video,
)

__all__: list[str] = [
    "load_corrections",
    "apply_corrections",
    "TrackConfig",
    "VideoConfig",
    "TargetsConfig",
    "ReferenceConfig",
    "BoardConfig",
    "MotionConfig",
    "ObjectConfig",
    "load_track_config",
    "track_video",
    "track_frames",
    "assemble_tracks",
    "TrackResult",
    "ObjectTrack",
    "Observation",
    "TRACK_COLUMNS",
    "TableMotion",
    "table_motion",
    "choose_sg_window",
    "estimate_noise",
    "VideoInfo",
    "probe_video",
    "iter_video_frames",
    "PlaneMap",
    "SimilarityFit",
    "fit_similarity",
    "calibrate_camera",
    "Board",
    "parse_board",
    "Lens",
    "calibrate_lens",
    "load_lens",
    "ImuLog",
    "read_imu",
    "read_ximu_registers",
    "ximu_rate_from_registers",
    "ImuRotation",
    "block_rotation",
    "ahrs_quaternions",
    "TableAcceleration",
    "table_acceleration",
    "SyncResult",
    "sync_offset",
    "sync_events",
    "sync_imu_to_track",
    "track_rate",
]
