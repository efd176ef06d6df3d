"""Video input: probe a file and stream grey frames (OpenCV ``VideoCapture``), optionally
with the decoded colour picture alongside.

Decoding runs in a background thread (OpenCV releases the GIL) so it overlaps
with detection on a second core.
"""

from __future__ import annotations

import os
import queue
import threading
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..._errors import InputError

__all__ = ["VideoInfo", "probe_video", "iter_video_frames"]


@dataclass(frozen=True)
class VideoInfo:
    """What the container says about a video.

    Attributes
    ----------
    path : str
    n_frames : int
        Frame count from the container (0 if it does not say; then the frames are counted).
    fps : float or None
        Frames per second (None when the container has no rate).
    width_px, height_px : int
    """

    path: str
    n_frames: int
    fps: float | None
    width_px: int
    height_px: int

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        return dict(path=self.path, n_frames=self.n_frames, fps=self.fps,
                    width_px=self.width_px, height_px=self.height_px)


def _open(path):
    # FFmpeg would print its own complaints on stderr; rocklab reports one line itself.
    os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")
    import cv2

    p = Path(path)
    if "%" not in str(p) and not p.exists():
        raise InputError(f"{p}: video file not found; check the path")
    cap = cv2.VideoCapture(str(p))
    if not cap.isOpened():
        cap.release()
        raise InputError(f"{p}: cannot open as a video (unknown format or corrupt file); "
                         "convert it to .mkv/.mp4 or an image sequence 'dir/%05d.png'")
    return cap


def probe_video(path) -> VideoInfo:
    """Open ``path`` and read its frame count, rate and size.

    Raises
    ------
    InputError
        Missing/unreadable file, or a video without a single decodable frame.
    """
    import cv2

    cap = _open(path)
    try:
        n = int(cap.get(cv2.CAP_PROP_FRAME_COUNT) or 0)
        fps = float(cap.get(cv2.CAP_PROP_FPS) or 0.0)
        ok, img = cap.read()
        if not ok or img is None:
            raise InputError(f"{path}: the video has no decodable frame (empty or corrupt); "
                             "check the file")
        h, w = img.shape[:2]
    finally:
        cap.release()
    # Image sequences report a nominal rate (or none); only trust real containers.
    if not np.isfinite(fps) or fps <= 0 or fps > 1e5 or "%" in str(path):
        fps = None
    return VideoInfo(str(path), max(n, 0), fps, int(w), int(h))


def _to_gray(img):
    import cv2

    if img.ndim == 2:
        return img
    return cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)


def iter_video_frames(path, start: int = 0, stop: int | None = None, prefetch: int = 8,
                      color: bool = False):
    """Yield ``(index, gray)`` (``(index, gray, image)`` with ``color``) for frames
    ``start <= index < stop``.

    Parameters
    ----------
    path : path-like
        A video file or an OpenCV image-sequence pattern (``dir/%05d.png``).
    start, stop : int, int or None
        Half-open frame range.
    prefetch : int
        Frames decoded ahead in a background thread (0: decode inline).
    color : bool
        Also yield the decoded picture, so a caller can show the frames in colour
        without decoding the video a second time.

    Yields
    ------
    index : int
    gray : ndarray, shape (height, width), uint8
    image : ndarray, shape (height, width, 3), uint8, BGR
        Only with ``color``: the frame as decoded (a grey source decodes to three equal
        channels; ``gray`` itself when the reader returns one channel).
    """
    import cv2

    cap = _open(path)
    if start:
        cap.set(cv2.CAP_PROP_POS_FRAMES, start)

    def read():
        i = start
        try:
            while stop is None or i < stop:
                ok, img = cap.read()
                if not ok or img is None:
                    return
                yield (i, _to_gray(img), img) if color else (i, _to_gray(img))
                i += 1
        finally:
            cap.release()

    if prefetch <= 0:
        yield from read()
        return

    def produce(put):
        frames = read()
        try:
            for item in frames:
                if not put(item):
                    return
        finally:
            frames.close()  # releases the capture when the consumer stopped early

    q: queue.Queue = queue.Queue(maxsize=prefetch)
    stop_flag = threading.Event()
    done = object()

    def put(item):
        while not stop_flag.is_set():
            try:
                q.put(item, timeout=0.1)
                return True
            except queue.Full:
                continue
        return False

    def worker():
        try:
            produce(put)
        finally:
            put(done)

    th = threading.Thread(target=worker, daemon=True, name="rocklab-video")
    th.start()
    try:
        while True:
            item = q.get()
            if item is done:
                break
            yield item
    finally:
        stop_flag.set()
        th.join(timeout=2.0)
