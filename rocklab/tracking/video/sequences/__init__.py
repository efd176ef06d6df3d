"""Films that are not video files: folders of numbered frames (:mod:`._imageseq`) and high-speed
cameras' own formats, Photron MRAW and Phantom CINE (:mod:`._highspeed`), read with the contract of
a video file (:func:`rocklab.tracking.probe_video`, :func:`rocklab.tracking.iter_video_frames`)."""

from ._highspeed import HIGHSPEED_SUFFIXES, frame_store, open_highspeed
from ._imageseq import IMAGE_SUFFIXES, TIMESTAMPS_FILE, FrameStoreReader, depth_gain, open_image_sequence

__all__ = [
    "frame_store",
    "open_highspeed",
    "open_image_sequence",
    "FrameStoreReader",
    "depth_gain",
    "HIGHSPEED_SUFFIXES",
    "IMAGE_SUFFIXES",
    "TIMESTAMPS_FILE",
]
