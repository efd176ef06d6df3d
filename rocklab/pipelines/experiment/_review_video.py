"""The film shown in the Rerun review: every frame, re-encoded once while the tracker decodes it.

An experiment's footage is often lossless (FFV1) or a camcorder's H.264, neither of which the
Rerun viewer plays everywhere: its native viewer decodes AV1 itself and H.264 only through a
system FFmpeg. So the frames the tracker reads anyway are encoded with PyAV into one AV1 MP4
(SVT-AV1, about 1 s between key frames for scrubbing), logged as a Rerun ``AssetVideo`` with
one ``VideoFrameReference`` per frame. Without PyAV or an AV1 encoder the review falls back to
JPEG stills of every ``decimation``-th frame and says so in the report.
"""

from __future__ import annotations

import io
import os
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

__all__ = ["ReviewVideo", "ReviewFilm"]

#: SVT-AV1 settings: preset 10 runs ~400 frames/s at 640x360 on 2 cores; CRF 40 keeps edges
#: and targets readable at ~0.1 kB per frame of synthetic footage.
AV1_OPTIONS = {"preset": "10", "crf": "40"}
#: SVT-AV1 on one logical processor: 20 threads instead of ~50 per encoder. A campaign runs one
#: encoder per worker process, and a run of the demo hung once inside SVT-AV1 (its "no frame in
#: undisplayed queue" error, then a deinit waiting forever) with the default thread pools.
SVT_PARAMS = "lp=1"


@dataclass(frozen=True)
class ReviewVideo:
    """The review's film.

    Attributes
    ----------
    kind : str
        ``"av1"`` (one MP4 in ``data``) or ``"jpeg"`` (stills in ``stills``).
    frame_index : tuple of int
        Video frame index of each encoded frame (MP4 sample order, or the stills'); the review
        places each at the tracker's time for that frame.
    fps : float
        Nominal frame rate of the source, Hz (the MP4's own rate and key-frame interval).
    data : bytes
        The MP4 (``kind == "av1"``), else empty.
    stills : tuple of bytes
        JPEG bytes per frame (``kind == "jpeg"``), else empty.
    note : str
        How the film was made, for the report (the fallback and why).
    size_px : (int, int)
        Width and height of the frames as tracked, px (the film pads odd sizes by one pixel).
    """

    kind: str
    frame_index: tuple
    fps: float
    data: bytes = b""
    stills: tuple = ()
    note: str = ""
    size_px: tuple = field(default=(0, 0))

    @property
    def n_bytes(self) -> int:
        """Size of the film in the recording, bytes."""
        return len(self.data) + sum(len(s) for s in self.stills)


def _is_grey(gray, image) -> bool:
    """True when a decoded frame ``image`` (BGR) is ``gray`` in all three channels, i.e. carries
    no colour (a grey source decodes to equal channels, which BGR→grey maps to themselves)."""
    import cv2

    if image.ndim == 2:
        return True
    s = image[::16, ::16]  # a colour picture almost always shows in the sample: skip the full check
    if not (np.array_equal(s[..., 0], s[..., 1]) and np.array_equal(s[..., 1], s[..., 2])):
        return False
    # full check in OpenCV: ~1 ms at 1080p, a quarter of numpy's strided channel compare
    return cv2.norm(image, cv2.cvtColor(gray, cv2.COLOR_GRAY2BGR), cv2.NORM_INF) == 0


class ReviewFilm:
    """``track_video``'s ``on_frame(index, gray, image)`` callback that builds a :class:`ReviewVideo`.

    Parameters
    ----------
    fps : float
        Frame rate of the source, Hz.
    decimation : int
        JPEG fallback only: keep every n-th frame.
    codec : str
        PyAV encoder name; ``"jpeg"`` forces the fallback.
    """

    def __init__(self, fps: float, decimation: int = 1, codec: str = "libsvtav1"):
        self.fps = float(fps)
        self.decimation = max(int(decimation), 1)
        self.codec = codec
        self._container = None
        self._stream = None
        self._buf = None
        self._time_base = Fraction(1, 1)
        self._index: list[int] = []
        self._stills: list[bytes] = []
        self._grey: bool | None = None
        self._size = (0, 0)
        self.note = ""
        self.kind = None

    def _open(self, h: int, w: int) -> None:
        if self.codec == "jpeg":
            self.kind, self.note = "jpeg", "JPEG stills (asked for)"
            return
        try:
            import av
        except ImportError:
            self.kind, self.note = "jpeg", "JPEG stills: PyAV (av) is not installed, so no video asset"
            return
        os.environ.setdefault("SVT_LOG", "1")  # SVT-AV1 prints its banner on stderr unless told
        try:
            self._buf = io.BytesIO()
            self._container = av.open(self._buf, mode="w", format="mp4")
            rate = Fraction(self.fps).limit_denominator(1001)
            self._time_base = 1 / rate
            s = self._container.add_stream(self.codec, rate=rate)
            # 4:2:0 needs even sizes: the frame is padded by one pixel where needed
            s.width, s.height = w + (w & 1), h + (h & 1)
            s.pix_fmt = "yuv420p"
            opts = dict(AV1_OPTIONS, g=str(max(int(round(self.fps)), 1)))
            if self.codec == "libsvtav1":
                opts["svtav1-params"] = SVT_PARAMS
            s.options = opts
            self._stream = s
            self.kind = "av1"
            self.note = f"AV1 video asset ({self.codec}), every frame"
        except Exception as e:  # noqa: BLE001 - any codec trouble means the JPEG fallback
            self._container = self._stream = None
            self.kind, self.note = "jpeg", f"JPEG stills: the {self.codec} encoder failed ({e})"

    def __call__(self, i: int, gray: np.ndarray, image: np.ndarray) -> None:
        import cv2

        if self.kind is None:
            self._open(*gray.shape[:2])
            self._size = (int(gray.shape[1]), int(gray.shape[0]))
        if self._grey is None:
            self._grey = _is_grey(gray, image)
        pic = gray if self._grey else image
        if self.kind == "av1":
            import av

            h, w = pic.shape[:2]
            if (h | w) & 1:
                pic = cv2.copyMakeBorder(pic, 0, h & 1, 0, w & 1, cv2.BORDER_REPLICATE)
            fmt = "gray" if pic.ndim == 2 else "bgr24"
            frame = av.VideoFrame.from_ndarray(np.ascontiguousarray(pic), format=fmt)
            # explicit presentation times: the encoder orders its frames by them
            frame.pts, frame.time_base = len(self._index), self._time_base
            try:
                for pkt in self._stream.encode(frame):
                    self._container.mux(pkt)
                self._index.append(int(i))
                return
            except Exception as e:  # noqa: BLE001 - a mid-film failure: the stills take over
                self._abandon(f"JPEG stills: the {self.codec} encoder failed at frame {i} ({e})")
        if i % self.decimation == 0:
            ok, buf = cv2.imencode(".jpg", pic, [cv2.IMWRITE_JPEG_QUALITY, 80])
            if ok:
                self._index.append(int(i))
                self._stills.append(buf.tobytes())

    def _abandon(self, note: str) -> None:
        # end the stream before the encoder is freed: SVT-AV1 freed without its end-of-stream
        # can wait forever in its deinit
        for end in (lambda: list(self._stream.encode()), self._container.close):
            try:
                end()
            except Exception:  # noqa: BLE001 - the film is abandoned either way
                pass
        self._container = self._stream = None
        self._index, self.kind, self.note = [], "jpeg", note

    def finish(self) -> ReviewVideo | None:
        """Flush the encoder; the film, or None when no frame was seen."""
        if self.kind is None:
            return None
        if self.kind == "av1":
            try:
                for pkt in self._stream.encode():
                    self._container.mux(pkt)
                self._container.close()
            except Exception as e:  # noqa: BLE001
                self._abandon(f"JPEG stills: the {self.codec} encoder failed at the end ({e})")
                return ReviewVideo("jpeg", (), self.fps, note=self.note, size_px=self._size)
            return ReviewVideo(
                "av1", tuple(self._index), self.fps, data=self._buf.getvalue(), note=self.note, size_px=self._size
            )
        note = self.note + (f", every {self.decimation}th frame" if self.decimation > 1 else "")
        return ReviewVideo(
            "jpeg", tuple(self._index), self.fps, stills=tuple(self._stills), note=note, size_px=self._size
        )
