"""Video input: probe a file and stream grey frames (OpenCV ``VideoCapture``), optionally
with the decoded colour picture alongside.

What OpenCV does not give is read from the container with PyAV (demuxing only, no decoding):
each frame's presentation time (phones record at a variable frame rate) and the pixel aspect
ratio (SD camcorders store 4:3 and 16:9 pictures with non-square pixels, PAL 16:15 or 64:45,
NTSC 8:9 or 32:27). Frames with non-square pixels are resampled to square pixels as they are
read, so every angle and distance downstream is measured on the true picture.

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

__all__ = ["VideoInfo", "probe_video", "iter_video_frames", "container_timing"]


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
        Size of the frames as yielded: square pixels (the stored width times ``pixel_aspect``).
    pixel_aspect : float
        Width / height of one stored pixel (the container's sample aspect ratio; 1 if it says none).
    frame_times_s : ndarray (n,) or None
        Each frame's presentation time from the container, s, the first frame at 0 (None when
        PyAV cannot read the container, e.g. an image sequence).
    """

    path: str
    n_frames: int
    fps: float | None
    width_px: int
    height_px: int
    pixel_aspect: float = 1.0
    frame_times_s: np.ndarray | None = None

    @property
    def variable_rate(self) -> bool:
        """True when the frame intervals differ by more than 1 % from their median."""
        t = self.frame_times_s
        if t is None or len(t) < 3:
            return False
        d = np.diff(t)
        med = float(np.median(d))
        return bool(med > 0 and np.max(np.abs(d - med)) > 0.01 * med)

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        return dict(path=self.path, n_frames=self.n_frames, fps=self.fps,
                    width_px=self.width_px, height_px=self.height_px, pixel_aspect=self.pixel_aspect,
                    variable_rate=self.variable_rate)


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


def container_timing(path) -> tuple[np.ndarray | None, float]:
    """Per-frame presentation times (s, first frame at 0) and the pixel aspect ratio of a video.

    Read with PyAV from the container's packets (no decoding). Returns ``(None, 1.0)`` where
    PyAV is missing or cannot open the file (image sequences, exotic containers): the caller
    then uses frame / fps and square pixels.
    """
    if "%" in str(path):
        return None, 1.0
    try:
        import av
    except ImportError:
        return None, 1.0
    try:
        with av.open(str(path)) as c:
            s = c.streams.video[0]
            sar = s.sample_aspect_ratio or s.codec_context.sample_aspect_ratio
            tb = s.time_base
            pts = [p.pts for p in c.demux(s) if p.pts is not None and p.size]
    except Exception:  # noqa: BLE001 - PyAV raises many types; the frame rate stays the fallback
        return None, 1.0
    aspect = float(sar) if sar and float(sar) > 0 else 1.0
    if not pts or tb is None:
        return None, aspect
    p = np.sort(np.asarray(pts, np.int64))
    return (p - p[0]) * float(tb), aspect


def probe_video(path) -> VideoInfo:
    """Open ``path`` and read its frame count, rate, size, pixel aspect and frame times.

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
    times, aspect = container_timing(path)
    if times is not None and len(times) > 1:
        # where OpenCV's nominal rate contradicts the packets (variable-rate files often report
        # the time base: 1000 fps and 681 "frames" for 24), count and rate come from the packets;
        # otherwise the header's count stays, so a cut file is still noticed (W-VIDEO-SHORT)
        rate = 1.0 / float(np.median(np.diff(times)))
        if fps is None or abs(fps - rate) > 0.01 * rate:
            fps, n = rate, len(times)
    return VideoInfo(str(path), max(n, 0), fps, _square_width(int(w), aspect), int(h), aspect, times)


def _square_width(w: int, aspect: float) -> int:
    return int(round(w * aspect)) if abs(aspect - 1.0) > 1e-6 else w


def _squared(img, aspect: float):
    """The picture resampled to square pixels (width times ``aspect``)."""
    if abs(aspect - 1.0) <= 1e-6:
        return img
    import cv2

    w = _square_width(img.shape[1], aspect)
    return cv2.resize(img, (w, img.shape[0]), interpolation=cv2.INTER_LINEAR if aspect > 1 else cv2.INTER_AREA)


def _to_gray(img):
    import cv2

    if img.ndim == 2:
        return img
    return cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)


def iter_video_frames(path, start: int = 0, stop: int | None = None, prefetch: int = 8,
                      color: bool = False, pixel_aspect: float = 1.0):
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
    pixel_aspect : float
        Width / height of a stored pixel (:attr:`VideoInfo.pixel_aspect`): frames are resampled
        to square pixels, ``width * pixel_aspect`` wide.

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
                img = _squared(img, pixel_aspect)
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
