"""Video input: probe a file and stream grey frames (OpenCV ``VideoCapture``), optionally
with the decoded colour picture alongside.

What OpenCV does not give is read from the container with PyAV (:mod:`._container`): each
frame's presentation time (exact on a constant clock, the container's own at a variable rate, a
dropped frame a missing slot), the display rotation (phones film sideways and say so) and the
pixel aspect ratio (SD camcorders store 4:3 and 16:9 pictures with non-square pixels, PAL 16:15 or 64:45,
NTSC 8:9 or 32:27). Frames with non-square pixels are resampled to square pixels as they are
read, so every angle and distance downstream is measured on the true picture. Interlaced video
(camcorders' 1080i50: each frame two fields exposed 20 ms apart) is deinterlaced on read by
splitting the fields ("bob"): twice the frame rate, each field brought to full height on its own
rows, so a rocking block is sampled at 50 Hz without combing.

Frames are decoded with PyAV (OpenCV only where PyAV cannot open the file, e.g. image
sequences), shown as the display matrix says (turned, and mirrored), each frame indexed by its
packet: a packet that does not decode is skipped and counted, the frames after it keep their
places and times. Where the packets' times are not presentation times (an AVI numbers its
chunks in decode order, so with B-frames a frame's pts is not its place; packets without a pts
or with one pts twice) the n-th frame decoded is frame n. Decoding runs in a background thread (FFmpeg releases the GIL) so it overlaps
with detection on a second core.
"""

from __future__ import annotations

import collections
import os
import queue
import threading
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..._errors import InputError
from ._container import UPRIGHT, container_info, frame_orientation, frame_pts, luma, orient, why_unopenable
from .sequences import FrameStoreReader, frame_store

__all__ = ["VideoInfo", "probe_video", "iter_video_frames", "container_info"]


@dataclass(frozen=True)
class VideoInfo:
    """What the container says about a video.

    Attributes
    ----------
    path : str
    n_frames : int
        Frames the container holds (its packets; OpenCV's count where PyAV cannot read it).
    fps : float or None
        Frames per second: the exact rate of the container's clock, the mean rate of a
        variable-rate film (None when the container has no rate).
    width_px, height_px : int
        Size of the frames as yielded: square pixels (the stored width times ``pixel_aspect``).
    pixel_aspect : float
        Width / height of one stored pixel (the container's sample aspect ratio; 1 if it says none).
    frame_times_s : ndarray (n,) or None
        Each frame's presentation time from the container (an image folder's ``timestamps.csv``,
        a CINE's time block), s, the first frame at 0 (None when there is none: an OpenCV
        image-sequence pattern, a folder without timestamps, a Photron MRAW).
    field_order : {"tff", "bff"} or None
        Interlaced video: which field is exposed first (top or bottom); None for progressive.
    rotation_deg : int
        Display rotation applied on read (counter-clockwise, 0/90/180/270); sizes are upright.
    n_dropped : int
        Slots of the container's constant clock with no frame (frames the camera dropped).
    n_header : int
        Frame count the container's header states (0 where it states none).
    mirrored : bool
        The display matrix mirrors the picture (after ``rotation_deg``): the frames are read as
        shown, mirrored, so every angle has the sign of the mirrored picture (W-VIDEO-MIRRORED).
    """

    path: str
    n_frames: int
    fps: float | None
    width_px: int
    height_px: int
    pixel_aspect: float = 1.0
    frame_times_s: np.ndarray | None = None
    field_order: str | None = None
    rotation_deg: int = 0
    n_dropped: int = 0
    n_header: int = 0
    mirrored: bool = False

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
            rotation_deg=self.rotation_deg,
            n_dropped=self.n_dropped,
            n_header=self.n_header,
            mirrored=self.mirrored,
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
        raise InputError(f"{p}: {why_unopenable(p)}")
    return cap


def probe_video(path) -> VideoInfo:
    """Open ``path`` and read its frame count, rate, size, pixel aspect and frame times.

    ``path`` is a video file, a folder of numbered frames or a high-speed camera's file (see
    :func:`iter_video_frames`); a folder's rate and times come from its ``timestamps.csv``.

    Raises
    ------
    InputError
        Missing/unreadable file, or a video without a single decodable frame.
    """
    import cv2

    store = frame_store(_open_checked(path))
    if store is not None:  # an image folder or a high-speed camera's file: its own size, rate and times
        s = store
        return VideoInfo(str(path), s.n_frames, s.fps, s.width_px, s.height_px, 1.0, s.times_s, n_dropped=s.n_dropped)
    ci = container_info(path)
    n, fps, size = 0, 0.0, None
    try:  # OpenCV: count and rate where the packets have no times; image sequences
        cap = _open(path)
    except InputError:
        if ci.stored_size_px is None:
            raise
        cap = None  # PyAV decodes what this OpenCV cannot (its FFmpeg may lack a decoder: AV1)
    if cap is not None:
        try:
            n, fps = int(cap.get(cv2.CAP_PROP_FRAME_COUNT) or 0), float(cap.get(cv2.CAP_PROP_FPS) or 0.0)
            ok, img = cap.read()
            size = (img.shape[1], img.shape[0]) if ok and img is not None else None  # turned by OpenCV
        finally:
            cap.release()
    if size is None and ci.stored_size_px is None:
        raise InputError(f"{path}: the video has no decodable frame (empty or corrupt); check the file")
    # Image sequences report a nominal rate (or none); only trust real containers.
    if not np.isfinite(fps) or fps <= 0 or fps > 1e5 or "%" in str(path):
        fps = None
    times = ci.frame_times_s
    if times is not None and len(times) > 1 and not float(times[-1]) > float(times[0]):
        # a muxer that wrote no times (every frame at 0): the frames are counted, not timed; the
        # rate is the option's or OpenCV's, and without either the tracker asks for --fps
        n, times = len(times), None
    if times is not None and len(times) > 1:
        # count and rate from the packets: OpenCV's are estimates (a Matroska film's duration x a
        # rate rounded from its 1 ms ticks; a variable-rate phone film reports its time base)
        n = len(times)
        fps = ci.rate_hz or (n - 1) / float(times[-1] - times[0])
    w, h = ci.shown_size_px or (_square_width(size[0], ci.pixel_aspect), size[1])
    return VideoInfo(
        str(path),
        max(n, 0),
        fps,
        int(w),
        int(h),
        ci.pixel_aspect,
        times,
        ci.field_order,
        ci.rotation_deg,
        ci.n_dropped,
        ci.n_header,
        ci.mirrored,
    )


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


class _PyAVReader:
    """``cv2.VideoCapture``'s ``read``/``release`` over PyAV's decoder, from frame ``first``.

    Pictures are BGR, or grey straight from the luma plane with ``gray`` (no colour conversion:
    a third of OpenCV's decoding time at 1080p), as stored: ``orientation`` is the last frame's
    display matrix (:func:`._container.orient` shows it upright, after the pixels are made square).
    Every frame is placed by its presentation time among the packets' where these are
    presentation times (:func:`._container.pts_timed`; else the n-th frame decoded is frame n):
    ``index`` is the last frame's place, so a packet that fails to decode (counted in
    ``n_broken``) leaves a gap instead of shifting the frames after it, and so does every frame
    predicted from it up to the next key frame. A start past frame 0
    seeks to the key frame before it and decodes forward.
    """

    def __init__(self, path, first: int = 0, gray: bool = False):
        import av

        self._c = av.open(str(path))
        self._gray = gray
        self.n_broken = 0
        self.orientation = UPRIGHT
        # the first and the last place lost to damage, until a key frame after it
        self._tainted, self._damage_end = None, -1
        self.index = int(first) - 1
        # four frame threads: decoding keeps pace beside the tracker, the frames in flight hiding
        # the moments the tracker holds a core (1080p H.264 at 17 Mbit/s on 2 cores, markerless,
        # decode included, six runs of 480 frames each: 106-138 frames/s; FFmpeg's automatic
        # frame + slice threads 100-126, slices alone 86-101)
        s = self._c.streams.video[0]
        self._pts, self._timed = frame_pts(self._c, s)
        self._c.seek(0, stream=s)
        s.thread_type, s.thread_count = "FRAME", 4
        self._it = self._decode(int(first))

    def _frames(self):
        """Decoded frames from the current position on, packet by packet: a broken packet is
        counted and skipped (FFmpeg's decoder resumes at the next one it can read)."""
        import av

        s = self._c.streams.video[0]
        packets = self._c.demux(s)
        recent = collections.deque(maxlen=s.thread_count + 2)  # the packets in flight
        while True:
            try:
                p = next(packets)
            except StopIteration:
                return
            except av.error.FFmpegError:  # the container itself breaks off: what was read stands
                self.n_broken += 1
                return
            try:
                frames = p.decode()
            except av.error.FFmpegError:
                self.n_broken += 1
                if not self._timed:  # no frame can be placed by its time: the loss is counted
                    continue
                # the damage may begin inside a packet before, which decoded without complaint
                # (concealed); with frame threads the error surfaces a few packets late
                at = [int(np.searchsorted(self._pts, q)) for q in (p.pts, *recent) if q is not None]
                if at:
                    self._tainted = min(at + ([self._tainted] if self._tainted is not None else []))
                    self._damage_end = max(at[0], self._damage_end)
                continue
            if p.size:
                recent.append(p.pts)
            for f in frames:
                if self._tainted is not None and f.pts is not None:
                    at = int(np.searchsorted(self._pts, f.pts))
                    if f.key_frame and at > self._damage_end:  # a fresh start after the damage
                        self._tainted = None
                    elif at >= self._tainted:
                        # predicted from a picture lost to the damage: FFmpeg conceals it without
                        # a flag (a marker 10 deg off), so it is dropped until the next key frame
                        self.n_broken += 1
                        continue
                yield f

    def _decode(self, first: int):
        c = self._c
        s = c.streams.video[0]
        pts = self._pts
        if first > 0 and not self._timed:  # frames found by counting them from the start
            yield from self._counted(first)
            return
        if first > 0:
            if first >= len(pts):
                return
            c.seek(int(pts[first]), stream=s, backward=True, any_frame=False)
            frames = self._frames()
            for f in frames:
                if f.pts is None:  # cannot place frames by time: decode from the start instead
                    break
                if int(np.searchsorted(pts, f.pts)) >= first:
                    yield f
                    yield from frames
                    return
            yield from self._counted(first)
            return
        yield from self._frames()

    def _counted(self, first: int):
        """The frames from the ``first``-th decoded on, decoding from the start."""
        s = self._c.streams.video[0]
        self._c.seek(0, stream=s)
        frames = self._frames()
        self.index = -1
        for _ in range(first):
            if next(frames, None) is None:
                return
            self.index += 1
        yield from frames

    def _place(self, f) -> int:
        """The frame's index: its packet's place by presentation time, else the next one."""
        nxt = self.index + 1
        if not self._timed or f.pts is None or not len(self._pts):
            return nxt
        k = int(np.searchsorted(self._pts, f.pts))
        return k if k >= nxt and k < len(self._pts) and self._pts[k] == f.pts else nxt

    def read(self):
        f = next(self._it, None)
        if f is None:
            return False, None
        self.index = self._place(f)
        self.orientation = frame_orientation(f)
        return True, (luma(f) if self._gray else f.to_ndarray(format="bgr24"))

    def release(self):
        self._c.close()


def _pyav_reader(path, first: int, gray: bool = True):
    """A PyAV reader for a video file, or None where PyAV cannot decode it (OpenCV then does)."""
    if "%" in str(path):
        return None
    try:
        return _PyAVReader(path, first, gray=gray)
    except Exception:  # noqa: BLE001 - PyAV raises many types; OpenCV's reader is the fallback
        return None


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
        A video file, a folder of numbered frames (:mod:`.sequences`), a Photron ``.cih``/``.mraw``
        or Phantom ``.cine`` (:mod:`.sequences`), or an OpenCV image-sequence pattern (``dir/%05d.png``).
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
        The frame's place in the container (a packet that did not decode leaves a gap).
    gray : ndarray, shape (height, width), uint8
    image : ndarray, shape (height, width, 3), uint8, BGR
        Only with ``color``: the frame as decoded (a grey source decodes to three equal
        channels; ``gray`` itself when the reader returns one channel).
    """
    first = start // 2 if fields else start
    cap = _capture(path, first, fields, color)

    def read():
        i = first
        try:
            while stop is None or (2 * i if fields else i) < stop:
                ok, img = cap.read()
                if not ok or img is None:
                    return
                i = getattr(cap, "index", i)  # PyAV places each frame by its time
                if stop is not None and (2 * i if fields else i) >= stop:
                    return
                # pixels made square and fields split on the stored rows, then the display matrix
                img = _squared(img, pixel_aspect)
                turn = getattr(cap, "orientation", UPRIGHT)
                if fields:
                    for k, f in enumerate(_fields(img, fields)):
                        f = orient(f, turn)
                        j = 2 * i + k
                        if j >= start and (stop is None or j < stop):
                            yield (j, _to_gray(f), f) if color else (j, _to_gray(f))
                else:
                    img = orient(img, turn)
                    yield (i, _to_gray(img), img) if color else (i, _to_gray(img))
                i += 1
        finally:
            cap.release()

    if prefetch <= 0:
        yield from read()
        return

    yield from _prefetched(read, prefetch)


def _capture(path, first: int, fields, color: bool):
    """A reader of ``path`` placed on frame ``first``: PyAV, a frame store, or OpenCV's as a last resort."""
    import cv2

    if fields:
        # OpenCV's FFmpeg reader cannot convert interlaced pictures ("Cannot convert interlaced to
        # progressive frames") and returns the previous picture again, silently: decode with PyAV
        cap = _PyAVReader(path, first, gray=not color)
    elif (store := frame_store(_open_checked(path))) is not None:
        cap = FrameStoreReader(store, first, gray=not color)
    else:
        # PyAV for every film it opens (grey from the luma plane: no YUV -> BGR -> grey), so grey
        # and colour frames are the same frames, upright and at the same indices
        cap = _pyav_reader(_open_checked(path), first, gray=not color)
        if cap is None:
            cap = _open(path)
            if first:
                cap.set(cv2.CAP_PROP_POS_FRAMES, first)
    return cap


def _prefetched(read, prefetch: int):
    """Yield the items of the generator ``read()``, decoded up to ``prefetch`` ahead in a background thread.

    An InputError raised while reading is raised here, in the consumer; stopping early stops the thread
    and releases the reader.
    """

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
        except InputError as e:  # a frame that cannot be read (a folder's): raised by the consumer
            put(e)
        finally:
            put(done)

    th = threading.Thread(target=worker, daemon=True, name="rocklab-video")
    th.start()
    try:
        while True:
            item = q.get()
            if item is done:
                break
            if isinstance(item, InputError):
                raise item
            yield item
    finally:
        stop_flag.set()
        th.join(timeout=2.0)
