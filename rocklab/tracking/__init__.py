"""rocklab.tracking (see the package docs)."""

from ._config import (BoardConfig, MotionConfig, ObjectConfig, ReferenceConfig, TargetsConfig,
                      TrackConfig, VideoConfig, load_track_config)
from ._imu_read import ImuLog, read_imu, read_ximu_registers, ximu_rate_from_registers
from ._imu_rotation import ImuRotation, ahrs_quaternions, block_rotation
from ._imu_table import TableAcceleration, table_acceleration
from ._sync import SyncResult, sync_events, sync_imu_to_track, sync_offset, track_rate
from ._geometry import PlaneMap, SimilarityFit, calibrate_camera, fit_similarity
from ._motion import TableMotion, choose_sg_window, estimate_noise, table_motion
from ._track import (TRACK_COLUMNS, ObjectTrack, Observation, TrackResult, assemble_tracks,
                     track_frames, track_video)
from ._video import VideoInfo, iter_video_frames, probe_video

__all__: list[str] = [
    # video tracking (helper "track")
    "TrackConfig", "VideoConfig", "TargetsConfig", "ReferenceConfig", "BoardConfig",
    "MotionConfig", "ObjectConfig", "load_track_config",
    "track_video", "track_frames", "assemble_tracks", "TrackResult", "ObjectTrack", "Observation",
    "TRACK_COLUMNS", "TableMotion", "table_motion", "choose_sg_window", "estimate_noise",
    "VideoInfo", "probe_video", "iter_video_frames", "PlaneMap", "SimilarityFit",
    "fit_similarity", "calibrate_camera",
    # IMU and clock sync (helper "imu")
    "ImuLog", "read_imu", "read_ximu_registers", "ximu_rate_from_registers",
    "ImuRotation", "block_rotation", "ahrs_quaternions", "TableAcceleration", "table_acceleration",
    "SyncResult", "sync_offset", "sync_events", "sync_imu_to_track", "track_rate",
]

#: Names that moved to :mod:`rocklab.synth` (simulated lab sessions are a simulator of the lab, not a
#: measurement); reachable here for one release with a DeprecationWarning.
_MOVED_TO_SYNTH = ("synth_session", "SynthSession", "load_synth_session", "simulate_imu_log", "write_ximu_csv",
                   "write_ximu3_csv")


def __getattr__(name):
    if name in _MOVED_TO_SYNTH:
        import warnings

        import rocklab.synth as synth

        warnings.warn(f"rocklab.tracking.{name} moved to rocklab.synth.{name}; import it from there",
                      DeprecationWarning, stacklevel=2)
        return getattr(synth, name)
    raise AttributeError(f"module 'rocklab.tracking' has no attribute {name!r}")
