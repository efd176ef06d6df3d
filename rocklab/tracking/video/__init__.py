"""Video tracking: from a film to each object's x, y and θ per frame.

- ``track.toml`` configs (:class:`TrackConfig`, :func:`load_track_config`; the reference page
  is generated from :mod:`rocklab.config`);
- reading films (:func:`probe_video`, :func:`iter_video_frames`);
- camera geometry: lens calibration, the image-to-plane map, similarity fits
  (:class:`PlaneMap`, :func:`calibrate_camera`, :func:`fit_similarity`);
- the tracker (:func:`track_video`, :class:`TrackResult`), levelling and the table's motion
  (:func:`table_motion`);
- ``rocklab track init``'s first-frame detection (:func:`suggest_config`);
- the target detectors in :mod:`.targets`.
"""

from ...config import (
    BoardConfig,
    MotionConfig,
    ObjectConfig,
    ReferenceConfig,
    TargetsConfig,
    TrackConfig,
    VideoConfig,
    load_track_config,
)
from ._camera_model import PlaneMap, SimilarityFit, calibrate_camera, fit_similarity, load_calibration
from ._init import find_markers, suggest_config
from ._level import level_from_reference
from ...series import TableMotion
from ._table_track import choose_sg_window, estimate_noise, table_motion
from ._track import TRACK_COLUMNS, ObjectTrack, Observation, TrackResult, assemble_tracks, track_frames, track_video
from ._video import VideoInfo, iter_video_frames, probe_video
from ._propose import propose_objects
from ._init import parse_region
from ._plane import make_plane_map
from .targets import table_top_edge


__all__ = [
    "load_calibration",
    "TrackConfig",
    "VideoConfig",
    "TargetsConfig",
    "ReferenceConfig",
    "BoardConfig",
    "MotionConfig",
    "ObjectConfig",
    "load_track_config",
    "PlaneMap",
    "SimilarityFit",
    "fit_similarity",
    "calibrate_camera",
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
    "level_from_reference",
    "VideoInfo",
    "probe_video",
    "iter_video_frames",
    "find_markers",
    "suggest_config",
    "propose_objects",
    "parse_region",
    "make_plane_map",
    "table_top_edge",
]
