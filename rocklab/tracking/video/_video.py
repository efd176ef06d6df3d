"""Video input: probe a file and stream grey frames (OpenCV ``VideoCapture``), optionally
with the decoded colour picture alongside.

What OpenCV does not give is read from the container with PyAV (demuxing only, no decoding):
each frame's presentation time (phones record at a variable frame rate) and the pixel aspect
ratio (SD camcorders store 4:3 and 16:9 pictures with non-square pixels, PAL 16:15 or 64:45,
NTSC 8:9 or 32:27). Frames with non-square pixels are resampled to square pixels as they are
read, so every angle and distance downstream is measured on the true picture. Interlaced video
(camcorders' 1080i50: each frame two fields exposed 20 ms apart) is deinterlaced on read by
splitting the fields ("bob"): twice the frame rate, each field brought to full height on its own
rows, so a rocking block is sampled at 50 Hz without combing.

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

__all__ = ["VideoInfo", "probe_video", "iter_video_frames", "container_info"]


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
    field_order : {"tff", "bff"} or None
        Interlaced video: which field is exposed first (top or bottom); None for progressive.
    """

    path: str
    n_frames: int
    fps: float | None
    width_px: int
    height_px: int
    pixel_aspect: float = 1.0
    frame_times_s: np.ndarray | None = None
    field_order: str | None = None

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
        return dict(
            path=self.path,
            n_frames=self.n_frames,
            fps=self.fps,
            width_px=self.width_px,
            height_px=self.height_px,
            pixel_aspect=self.pixel_aspect,
            variable_rate=self.variable_rate,
            field_order=self.field_order,
        )


def _open_checked(path) -> Path:
    p = Path(path)
    if "%" not in str(p) and not p.exists():
        raise InputError(f"{p}: video file not found; check the path")
    return p


def _open(path):
    # FFmpeg would print its own complaints on stderr; rocklab reports one line itself.
    os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")
    import cv2

    p = _open_checked(path)
    cap = cv2.VideoCapture(str(p))
    if not cap.isOpened():
        cap.release()
        raise InputError(
            f"{p}: cannot open as a video (unknown format or corrupt file); "
            "convert it to .mkv/.mp4 or an image sequence 'dir/%05d.png'"
        )
    return cap


#: FFmpeg's AVFieldOrder: TT and TB code/show the top field first, BB and BT the bottom one.
_FIELD_ORDER = {2: "tff", 4: "tff", 3: "bff", 5: "bff"}


def container_info(path) -> tuple[np.ndarray | None, float, str | None]:
    """What the container says and OpenCV does not, read with PyAV in one pass over the packets.

    Returns
    -------
    frame_times_s : ndarray (n,) or None
        Each frame's presentation time, s, the first frame at 0.
    pixel_aspect : float
        Width / height of a stored pixel (the sample aspect ratio; 1 if none is given).
    field_order : {"tff", "bff"} or None
        Interlaced video: the stream's field order where the codec states it, else a first
        frame flagged interlaced is taken as top field first (HD camcorders; PAL DV is bottom
        first and says so); None for progressive.

    ``(None, 1.0, None)`` where PyAV is missing or cannot open the file (image sequences, exotic
    containers): the caller then uses frame / fps, square pixels and progressive frames.
    """
    if "%" in str(path):
        return None, 1.0, None
    try:
        import av
    except ImportError:
        return None, 1.0, None
    try:
        with av.open(str(path)) as c:
            s = c.streams.video[0]
            sar = s.sample_aspect_ratio or s.codec_context.sample_aspect_ratio
            tb = s.time_base
            pts, first = [], None
            for p in c.demux(s):
                if p.pts is not None and p.size:
                    pts.append(p.pts)
                if first is None and p.size:  # decode only until the first picture appears
                    first = next(iter(p.decode()), None)
            fo = int(s.codec_context.field_order or 0)
    except Exception:  # noqa: BLE001 - PyAV raises many types; rate, square pixels stay the fallback
        return None, 1.0, None
    aspect = float(sar) if sar and float(sar) > 0 else 1.0
    order = _FIELD_ORDER.get(fo, "tff" if first is not None and first.interlaced_frame else None)
    if not pts or tb is None:
        return None, aspect, order
    q = np.sort(np.asarray(pts, np.int64))
    return (q - q[0]) * float(tb), aspect, order


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
            raise InputError(f"{path}: the video has no decodable frame (empty or corrupt); check the file")
        h, w = img.shape[:2]
    finally:
        cap.release()
    # Image sequences report a nominal rate (or none); only trust real containers.
    if not np.isfinite(fps) or fps <= 0 or fps > 1e5 or "%" in str(path):
        fps = None
    times, aspect, order = container_info(path)
    if times is not None and len(times) > 1:
        # where OpenCV's nominal rate contradicts the packets (variable-rate files often report
        # the time base: 1000 fps and 681 "frames" for 24), count and rate come from the packets;
        # otherwise the header's count stays, so a cut file is still noticed (W-VIDEO-SHORT)
        rate = 1.0 / float(np.median(np.diff(times)))
        if fps is None or abs(fps - rate) > 0.01 * rate:
            fps, n = rate, len(times)
    return VideoInfo(str(path), max(n, 0), fps, _square_width(int(w), aspect), int(h), aspect, times, order)


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


#: 8-bit pixel formats whose first plane is the luma picture itself (grey needs no conversion)
_LUMA_FORMATS = frozenset(
    "yuv420p yuvj420p yuv422p yuvj422p yuv444p yuvj444p yuv411p yuvj411p yuv440p yuvj440p nv12 nv21 nv16 gray".split()
)
#: limited-range luma (16..235) stretched to 0..255, as OpenCV's YUV -> BGR -> grey path does
_STRETCH = np.clip(np.round((np.arange(256) - 16.0) * 255.0 / 219.0), 0, 255).astype(np.uint8)


def _luma(frame) -> np.ndarray:
    """The grey picture of a decoded PyAV frame: its luma plane, full range, shape (height, width)."""
    name = frame.format.name
    if name not in _LUMA_FORMATS:
        return frame.to_ndarray(format="gray")
    p = frame.planes[0]
    y = np.frombuffer(p, np.uint8).reshape(-1, p.line_size)[: frame.height, : frame.width]
    # full range where the pixel format or the frame's own tag says so (phones tag yuv420p "pc")
    if name.startswith("yuvj") or name == "gray" or int(frame.color_range or 0) == 2:
        return np.array(y)
    import cv2

    return cv2.LUT(y, _STRETCH)


class _PyAVReader:
    """``cv2.VideoCapture``'s ``read``/``release`` over PyAV's decoder, from frame ``first``.

    Pictures are BGR, or grey straight from the luma plane with ``gray`` (no colour conversion:
    a third of OpenCV's decoding time at 1080p). A start past frame 0 seeks to the key frame
    before it and decodes forward, frames being placed by their presentation times.
    """

    def __init__(self, path, first: int = 0, gray: bool = False):
        import av

        self._c = av.open(str(path))
        self._gray = gray
        # four frame threads: decoding keeps pace beside the tracker, the frames in flight hiding
        # the moments the tracker holds a core (1080p H.264 at 17 Mbit/s on 2 cores, markerless,
        # decode included, six runs of 480 frames each: 106-138 frames/s; FFmpeg's automatic
        # frame + slice threads 100-126, slices alone 86-101)
        s = self._c.streams.video[0]
        s.thread_type, s.thread_count = "FRAME", 4
        self._it = self._decode(int(first))

    def _decode(self, first: int):
        c = self._c
        s = c.streams.video[0]
        if first > 0:
            pts = np.sort([p.pts for p in c.demux(s) if p.pts is not None and p.size])
            if first >= len(pts):
                return
            c.seek(int(pts[first]), stream=s, backward=True, any_frame=False)
            for f in c.decode(s):
                if f.pts is None:  # cannot place frames by time: decode from the start instead
                    break
                if int(np.searchsorted(pts, f.pts)) >= first:
                    yield f
                    yield from c.decode(s)
                    return
            c.seek(0, stream=s)
            frames = c.decode(s)
            for _ in range(first):
                if next(frames, None) is None:
                    return
            yield from frames
            return
        yield from c.decode(s)

    def read(self):
        import av

        try:
            f = next(self._it, None)
        except av.error.FFmpegError:  # a broken packet ends the read, as in OpenCV; the frame count is checked
            f = None
        if f is None:
            return False, None
        return True, (_luma(f) if self._gray else f.to_ndarray(format="bgr24"))

    def release(self):
        self._c.close()


def _pyav_reader(path, first: int):
    """A grey PyAV reader for a video file, or None where PyAV cannot decode it (OpenCV then does)."""
    if "%" in str(path):
        return None
    try:
        r = _PyAVReader(path, first, gray=True)
    except Exception:  # noqa: BLE001 - PyAV raises many types; OpenCV's reader is the fallback
        return None
    return r


def _fields(img, order: str):
    """The two fields of an interlaced frame, in exposure order, each at full height on its own rows."""
    import cv2

    h, w = img.shape[:2]
    out = []
    for first in (True, False) if order == "tff" else (False, True):
        off = 0 if first else 1
        field = img[off::2]
        # output row y lies at field row (y - off) / 2: the field's lines keep their height
        M = np.array([[1.0, 0.0, 0.0], [0.0, 0.5, -0.5 * off]], np.float32)
        out.append(
            cv2.warpAffine(
                field, M, (w, h), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP, borderMode=cv2.BORDER_REPLICATE
            )
        )
    return out


def iter_video_frames(
    path,
    start: int = 0,
    stop: int | None = None,
    prefetch: int = 8,
    color: bool = False,
    pixel_aspect: float = 1.0,
    fields: str | None = None,
):
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
    fields : {"tff", "bff"} or None
        Deinterlace (:attr:`VideoInfo.field_order`): every frame yields its two fields in exposure
        order, indices ``2 k`` and ``2 k + 1``; ``start`` and ``stop`` count fields.

    Yields
    ------
    index : int
    gray : ndarray, shape (height, width), uint8
    image : ndarray, shape (height, width, 3), uint8, BGR
        Only with ``color``: the frame as decoded (a grey source decodes to three equal
        channels; ``gray`` itself when the reader returns one channel).
    """
    import cv2

    first = start // 2 if fields else start
    if fields:
        # OpenCV's FFmpeg reader cannot convert interlaced pictures ("Cannot convert interlaced to
        # progressive frames") and returns the previous picture again, silently: decode with PyAV
        cap = _PyAVReader(path, first, gray=not color)
    else:
        # grey frames come from PyAV's luma plane (no YUV -> BGR -> grey); colour from OpenCV
        cap = None if color else _pyav_reader(_open_checked(path), first)
        if cap is None:
            cap = _open(path)
            if first:
                cap.set(cv2.CAP_PROP_POS_FRAMES, first)

    def read():
        i = first
        try:
            while stop is None or (2 * i if fields else i) < stop:
                ok, img = cap.read()
                if not ok or img is None:
                    return
                img = _squared(img, pixel_aspect)
                if fields:
                    for k, f in enumerate(_fields(img, fields)):
                        j = 2 * i + k
                        if j >= start and (stop is None or j < stop):
                            yield (j, _to_gray(f), f) if color else (j, _to_gray(f))
                else:
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
