"""What the container says and OpenCV does not, read with PyAV from the packets (no decoding but
the first picture): each frame's presentation time, the pixel aspect ratio, the field order and
the display matrix (a right-angle turn, possibly mirrored); and the grey picture of a decoded frame.

Frame times are the container's, never a rate rounded from them. A container stores times in
its own ticks (Matroska: 1 ms), so a constant 150 fps is stored as steps of 7, 7 and 6 ms; the
packets are then laid on the constant-rate clock that explains every one of them within half a
tick (the stream's declared rate, else one fitted to the packets), which restores the exact
times and shows a frame the camera dropped as a missing slot. Packets that fit no constant clock
(phones record at a variable rate) keep their own times, true to half a tick.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

__all__ = [
    "ContainerInfo",
    "container_info",
    "frame_clock",
    "shown_pts",
    "frame_pts",
    "frame_orientation",
    "orient",
    "UPRIGHT",
    "luma",
    "why_unopenable",
]

#: The display matrix of a picture shown as stored (see :func:`frame_orientation`).
UPRIGHT = (1, 0, 0, 1)

#: FFmpeg's AVFieldOrder: TT and TB code/show the top field first, BB and BT the bottom one.
_FIELD_ORDER = {2: "tff", 4: "tff", 3: "bff", 5: "bff"}
#: A constant clock must place at least this share of the intervals in one slot each; a file
#: whose frames skip slots more often is variable-rate, not a constant rate with dropped frames.
MIN_SINGLE_STEPS = 0.9
#: Containers whose packet times are not presentation times: AVI numbers its chunks in decode
#: order (FFmpeg's pts there is the chunk's number), so with B-frames a decoded frame's pts is
#: the number of the chunk it was coded in, not its place on screen.
_UNTIMED_FORMATS = frozenset({"avi"})


@dataclass(frozen=True)
class ContainerInfo:
    """The container's own account of a video stream.

    Attributes
    ----------
    frame_times_s : ndarray (n,) or None
        Each frame's presentation time, s, the first frame at 0, in presentation order.
    pixel_aspect : float
        Width / height of a stored pixel (the sample aspect ratio; 1 if none is given).
    field_order : {"tff", "bff"} or None
        Interlaced video: the field exposed first; None for progressive.
    rotation_deg : int
        Counter-clockwise turn that shows the stored picture upright (phones' display matrix):
        0, 90, 180 or 270 (before the mirroring, when ``mirrored``).
    rate_hz : float or None
        The constant clock the frames sit on (None: variable rate).
    n_dropped : int
        Slots of that clock with no frame (frames the camera dropped); 0 at a variable rate.
    n_header : int
        Frame count the container's header states (0 where it states none, e.g. Matroska).
    pts : ndarray (n,) of int64 or None
        The packets' presentation times in stream ticks, sorted: a decoded frame's index is its
        place here.
    timed : bool
        The packets' times are the frames' presentation times, so a decoded frame is placed by
        its pts (False: AVI, or packets without pts or with the same pts twice; the n-th frame
        decoded is frame n, its time n / rate).
    orientation : tuple of 4 int
        The first frame's display matrix as a signed permutation (:func:`frame_orientation`).
    stored_size_px : tuple (width, height) or None
        Size of the pictures as coded (before the pixel aspect and the display matrix).
    """

    frame_times_s: np.ndarray | None = None
    pixel_aspect: float = 1.0
    field_order: str | None = None
    rotation_deg: int = 0
    rate_hz: float | None = None
    n_dropped: int = 0
    n_header: int = 0
    pts: np.ndarray | None = None
    timed: bool = True
    orientation: tuple = UPRIGHT
    stored_size_px: tuple | None = None

    @property
    def shown_size_px(self) -> tuple[int, int] | None:
        """(width, height) of the pictures as read: square pixels along the stored rows, then the
        display matrix's turn (a film turned by 90 deg has its non-square pixels tall upright)."""
        if self.stored_size_px is None:
            return None
        w, h = self.stored_size_px
        w = int(round(w * self.pixel_aspect)) if abs(self.pixel_aspect - 1.0) > 1e-6 else w
        return (h, w) if self.orientation[0] == 0 else (w, h)

    @property
    def mirrored(self) -> bool:
        """Whether the display matrix mirrors the picture (its determinant is negative)."""
        a, b, c, d = self.orientation
        return a * d - b * c < 0


def frame_clock(t_s: np.ndarray, tick_s: float, rates=()) -> tuple[np.ndarray, float | None, int]:
    """Lay packet times on the constant-rate clock that explains them to half a tick.

    Parameters
    ----------
    t_s : ndarray (n,)
        Sorted packet times, s, the first at 0, each rounded to the container's tick.
    tick_s : float
        The container's tick (time base), s.
    rates : iterable of float or Fraction
        Rates the stream declares, Hz, tried first; a rate fitted to the packets is tried last.

    Returns
    -------
    times_s : ndarray (n,)
        Each frame's time: its slot over the rate (exact) where a clock fits, else ``t_s``.
    rate_hz : float or None
        The clock's rate (None: no constant clock fits, the rate is variable).
    n_dropped : int
        Empty slots between the first and the last frame.
    """
    t = np.asarray(t_s, float)
    if len(t) < 3:
        return t, (1.0 / float(t[1] - t[0]) if len(t) == 2 and t[1] > t[0] else None), 0
    tol = 0.5 * tick_s * (1 + 1e-6) + 1e-9
    d = np.diff(t)
    single = d[d <= 1.5 * np.median(d)]
    cands = [Fraction(r) if isinstance(r, Fraction) else Fraction(float(r)).limit_denominator(1001) for r in rates if r]
    if len(single) and np.mean(single) > 0:
        # the mean of the single steps: the ticks' rounding cancels along a run of frames
        r0 = 1.0 / float(np.mean(single))
        k = np.rint(t * r0)
        if np.all(np.diff(k) >= 1) and k[-1] > 0:
            r1 = 1.0 / float(np.polyfit(k, t, 1)[0])  # refined over the whole film
            # the plainest rate first: whole frames per second, NTSC's n / 1.001, then any fraction
            cands += [Fraction(round(r1)), Fraction(round(r1 * 1.001) * 1000, 1001)]
            cands += [Fraction(r1).limit_denominator(1001), Fraction(r1)]
    for r in cands:
        if not 0 < r < 1e5:
            continue
        rf = float(r)
        k = np.rint(t * rf)
        steps = np.diff(k)
        if np.all(steps >= 1) and np.mean(steps == 1) >= MIN_SINGLE_STEPS and np.all(np.abs(t - k / rf) <= tol):
            return k / rf, rf, int(k[-1]) + 1 - len(t)
    return t, None, 0


def _shown(packet) -> bool:
    """Whether a packet is a frame of the film: timed, not empty, and not cut by an edit list
    (an MP4 trimmed in a phone's editor keeps the cut frames, flagged discard; no decoder shows
    them)."""
    return packet.pts is not None and bool(packet.size) and not getattr(packet, "is_discard", False)


def shown_pts(container, stream) -> np.ndarray:
    """The presentation times (stream ticks, sorted) of the frames a film shows, from its packets."""
    return np.sort(np.asarray([p.pts for p in container.demux(stream) if _shown(p)], np.int64))


def pts_timed(format_name: str, pts, n_pictures: int) -> bool:
    """Whether packet times ``pts`` (one per picture packet that has one, ``n_pictures`` such
    packets) are presentation times a decoded frame can be placed by: not in an AVI (its pts
    number the chunks in decode order), every picture timed, no time given twice."""
    if set(str(format_name or "").split(",")) & _UNTIMED_FORMATS:
        return False
    return len(pts) == n_pictures and len(np.unique(np.asarray(pts, np.int64))) == len(pts)


def frame_pts(container, stream) -> tuple[np.ndarray, bool]:
    """The sorted packet times (stream ticks) of the frames a film shows, and whether a decoded
    frame can be placed by its pts among them (:func:`pts_timed`)."""
    pts, n = [], 0
    for p in container.demux(stream):
        if p.size and not getattr(p, "is_discard", False):
            n += 1
            if p.pts is not None:
                pts.append(p.pts)
    q = np.sort(np.asarray(pts, np.int64))
    return q, pts_timed(container.format.name, q, n)


def frame_orientation(frame) -> tuple[int, int, int, int]:
    """The frame's display matrix as a signed permutation ``(a, b, c, d)``.

    A stored pixel ``(p, q)`` (x right, y down) is shown at ``x' = a p + c q``, ``y' = b p + d q``
    (FFmpeg's convention, translation aside): a right-angle turn, possibly mirrored, as phones and
    editors write them. :data:`UPRIGHT` when the frame carries none; a matrix that is not a
    right-angle turn is taken as the nearest one.
    """
    try:
        sd = frame.side_data.get("DISPLAYMATRIX")
        if sd is None:
            return UPRIGHT
        m = np.frombuffer(bytes(sd), np.int32)[[0, 1, 3, 4]].astype(float)
    except Exception:  # noqa: BLE001 - no display matrix readable: shown as stored
        return UPRIGHT
    a, b, c, d = (int(np.sign(v)) for v in m)
    if abs(m[0]) + abs(m[3]) >= abs(m[1]) + abs(m[2]):
        return (a or 1, 0, 0, d or 1)
    return (0, b or 1, c or 1, 0)


def orient(img: np.ndarray, orientation) -> np.ndarray:
    """The stored picture ``img`` (rows, columns[, channels]) as its display matrix shows it."""
    a, b, c, d = orientation
    if (a, b, c, d) == UPRIGHT:
        return img
    if a == 0:  # the turn swaps the axes: shown row = b p, shown column = c q
        img = np.swapaxes(img, 0, 1)
        rows, cols = b, c
    else:
        rows, cols = d, a
    return np.ascontiguousarray(img[:: -1 if rows < 0 else 1, :: -1 if cols < 0 else 1])


def rotation_deg(orientation) -> int:
    """The counter-clockwise turn (0, 90, 180, 270 deg) of a display matrix (before its mirroring)."""
    a, b, c, d = orientation
    if a * d - b * c < 0:  # mirrored left-right after the turn: undo the mirror of the x' column
        a, c = -a, -c
    return {(1, 0): 0, (0, -1): 90, (-1, 0): 180, (0, 1): 270}[(a, b)]


#: 8-bit pixel formats whose first plane is the luma picture itself (grey needs no conversion)
_LUMA_FORMATS = frozenset(
    "yuv420p yuvj420p yuv422p yuvj422p yuv444p yuvj444p yuv411p yuvj411p yuv440p yuvj440p nv12 nv21 nv16 gray".split()
)
#: limited-range luma (16..235) stretched to 0..255, as OpenCV's YUV -> BGR -> grey path does
_STRETCH = np.clip(np.round((np.arange(256) - 16.0) * 255.0 / 219.0), 0, 255).astype(np.uint8)


def luma(frame) -> np.ndarray:
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


def container_info(path) -> ContainerInfo:
    """What the container says and OpenCV does not, read with PyAV in one pass over the packets.

    ``ContainerInfo()`` (no times, square pixels, progressive, upright) where PyAV is missing or
    cannot open the file (image sequences, exotic containers): the caller then uses frame / fps.
    """
    if "%" in str(path):
        return ContainerInfo()
    try:
        import av
    except ImportError:
        return ContainerInfo()
    try:
        with av.open(str(path)) as c:
            s = c.streams.video[0]
            sar = s.sample_aspect_ratio or s.codec_context.sample_aspect_ratio
            tb = s.time_base
            rates = [s.average_rate, s.guessed_rate]
            n_header = int(s.frames or 0)
            duration_s = float(c.duration) / 1e6 if c.duration else 0.0
            fmt = c.format.name
            pts, dts, n_pictures, first, broke = [], [], 0, None, False
            try:
                for p in c.demux(s):
                    if p.size and not getattr(p, "is_discard", False):
                        n_pictures += 1
                    if _shown(p):
                        pts.append(p.pts)
                        dts.append(p.pts if p.dts is None else p.dts)
                    if first is None and p.size:  # decode only until the first picture appears
                        try:
                            first = next(iter(p.decode()), None)
                        except av.error.FFmpegError:
                            pass
            except av.error.FFmpegError:  # damaged tail: the packets read so far stand
                broke = True
            fo = int(s.codec_context.field_order or 0)
    except Exception:  # noqa: BLE001 - PyAV raises many types; rate, square pixels stay the fallback
        return ContainerInfo()
    aspect = float(sar) if sar and float(sar) > 0 else 1.0
    order = _FIELD_ORDER.get(fo, "tff" if first is not None and first.interlaced_frame else None)
    ori = frame_orientation(first) if first is not None else UPRIGHT
    rot = rotation_deg(ori)
    size = (int(first.width), int(first.height)) if first is not None else None
    timed = pts_timed(fmt, pts, n_pictures)
    if not pts or tb is None or not (timed or len(pts) == n_pictures == len(set(pts))):
        # no times a frame can be placed by (raw streams, duplicated pts): counted, not timed
        return ContainerInfo(
            None, aspect, order, rot, n_header=n_header, timed=False, orientation=ori, stored_size_px=size
        )
    # an AVI's pts number its chunks: an empty chunk (a frame the camera dropped) leaves a gap
    q = np.sort(np.asarray(pts, np.int64))
    times, rate, dropped = frame_clock((q - q[0]) * float(tb), float(tb), rates)
    if not n_header and duration_s and rate:
        # Matroska and WebM count no frames but state the duration at the file's start: a file
        # cut short still claims its whole length
        n_header = int(round(duration_s * rate))
    if dropped and (broke or len(q) < n_header):
        dropped -= _cut_slots(
            times, rate, (max(dts) + min(int(a) - int(b) for a, b in zip(pts, dts)) - q[0]) * float(tb)
        )
    return ContainerInfo(times, aspect, order, rot, rate, max(dropped, 0), n_header, q, timed, ori, size)


def _cut_slots(times_s: np.ndarray, rate_hz: float | None, t_cut_s: float) -> int:
    """Empty slots of the clock after ``t_cut_s`` (the earliest time a frame coded after the last
    packet read can be shown): in a file cut short these are frames lost with its tail (the
    B-frames between the last pictures read), not frames the camera dropped."""
    if not rate_hz:
        return 0
    k = np.rint(np.asarray(times_s) * rate_hz).astype(np.int64)
    k_cut = max(int(np.ceil(t_cut_s * rate_hz - 1e-6)), 0)
    if k_cut > k[-1]:
        return 0
    return int(k[-1] - k_cut + 1 - np.count_nonzero(k >= k_cut))


def why_unopenable(p) -> str:
    """Why a file no reader opens is not a video, with the fix (one line)."""
    try:
        with open(p, "rb") as f:
            head = f.read(12)
    except OSError:
        head = b""
    if head[4:8] in (b"ftyp", b"mdat", b"wide", b"free"):
        # an MP4/MOV's index (moov) is written when the recording stops: a cut copy has none
        return (
            "an MP4/MOV file without its index (moov box), so no frame can be found: the recording "
            "or the copy was cut short; copy it again from the camera or card (a cut recording can "
            "be rebuilt with a tool such as untrunc and a good file of the same camera)"
        )
    return "cannot open as a video (unknown format or corrupt file); convert it to .mkv/.mp4 or an image sequence 'dir/%05d.png'"
