"""Video tracking: from a film to each object's x, y and θ per frame.

- ``track.toml`` configs are read with :mod:`rocklab.config`'s schema
  (:class:`rocklab.config.TrackConfig`, :func:`rocklab.config.load_track_config`), its one home;
- reading films (:func:`probe_video`, :func:`iter_video_frames`);
- camera geometry: lens calibration, the image-to-plane map, similarity fits
  (:class:`PlaneMap`, :func:`calibrate_camera`, :func:`fit_similarity`);
- the tracker (:func:`track_video`, :class:`TrackResult`), levelling and the table's motion
  (:func:`table_motion`);
- ``rocklab track init``'s first-frame detection (:func:`suggest_config`) and whether the camera
  moves (:func:`camera_motion`);
- the target detectors in :mod:`.targets`.
"""

from ._camera_model import PlaneMap, SimilarityFit, calibrate_camera, fit_similarity, load_calibration
from ._init import find_markers, suggest_config
from ._level import REST_WINDOW_S, level_from_reference, rests_at_end
from ._table_track import choose_sg_window, estimate_noise, table_motion
from ._track import (
    TRACK_COLUMNS,
    ObjectTrack,
    Observation,
    TrackResult,
    assemble_tracks,
    no_rate_error,
    track_frames,
    track_video,
)
from ._video import VideoInfo, iter_video_frames, probe_video
from ._propose import lead_in, propose_objects
from ._camera_motion import CAMERA_SHARE, camera_motion
from ._init import MIN_TEXTURE_STD, parse_region, texture_std
from ._plane import make_plane_map


__all__ = [
    "load_calibration",
    "PlaneMap",
    "SimilarityFit",
    "fit_similarity",
    "calibrate_camera",
    "track_video",
    "track_frames",
    "no_rate_error",
    "assemble_tracks",
    "TrackResult",
    "ObjectTrack",
    "Observation",
    "TRACK_COLUMNS",
    "table_motion",
    "choose_sg_window",
    "estimate_noise",
    "level_from_reference",
    "rests_at_end",
    "REST_WINDOW_S",
    "VideoInfo",
    "probe_video",
    "iter_video_frames",
    "find_markers",
    "suggest_config",
    "propose_objects",
    "lead_in",
    "camera_motion",
    "CAMERA_SHARE",
    "parse_region",
    "texture_std",
    "MIN_TEXTURE_STD",
    "make_plane_map",
]
