"""Image sequences as films: a folder of numbered PNG / JPEG / TIFF / BMP frames.

High-speed cameras (and their software's "save as images") write one file per frame, often 16-bit
(a 12-bit sensor in 16-bit words). A folder is read as a film with the same contract as a video
file (:func:`rocklab.tracking.probe_video`, :func:`rocklab.tracking.iter_video_frames`): a size, a
frame count, a rate and each frame's time.

- **Order**: the number in each file name (its last run of digits: ``frame_00017.png``), sorted as
  numbers; every name has the same text around it. A gap in the numbering is an error (a frame
  lost when copying), unless each frame's time is given.
- **Time**: ``timestamps.csv`` in the folder, a header naming ``t_s`` (seconds; times of the
  frames in order) and optionally ``file`` (then every image must be listed); otherwise a rate
  given by the caller (``--fps``, ``[video] fps``). Without either the folder has no rate, and the
  tracker asks for one.
- **Depth**: frames are decoded with OpenCV (PNG, JPEG, TIFF and BMP at 8 or 16 bits; no further
  dependency) and 16-bit frames are mapped to 8 bits with one gain for the whole sequence
  (:func:`depth_gain`): the values a camera of 10, 12, 14 or 16 bits writes, divided by 4, 16, 64 or
  256, the depth being the least that holds the brightest pixel of the first, middle and last
  frames (a 12-bit camera's 0..4095 becomes 0..255: the trackers' whole range, never the low byte,
  whose truncation would wrap the picture's brightness).
- **Size**: every frame must have the first frame's size (read from the headers with Pillow,
  matplotlib's own imaging library, without decoding).
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...._errors import InputError

__all__ = [
    "ImageSequence",
    "FrameStoreReader",
    "open_image_sequence",
    "depth_gain",
    "IMAGE_SUFFIXES",
    "TIMESTAMPS_FILE",
    "to_8bit",
]

#: File endings read as frames (case-insensitive); every other file in the folder is ignored.
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp")
#: The file in the folder that gives each frame's time (header ``t_s``, optionally ``file``).
TIMESTAMPS_FILE = "timestamps.csv"
_NUMBERED = re.compile(r"^(.*?)(\d+)(\D*)$")


@dataclass(frozen=True)
class ImageSequence:
    """A folder of frames, ordered and timed.

    Attributes
    ----------
    folder : Path
    files : tuple of Path
        The frames in order.
    width_px, height_px : int
    times_s : ndarray (n,) or None
        Each frame's time from ``timestamps.csv``, s, the first at 0 (None: none given).
    gain : float
        Factor that maps the stored values to 8 bits (1 for 8-bit frames).
    bits : int
        Bits per sample as stored (8 or 16).
    """

    folder: Path
    files: tuple
    width_px: int
    height_px: int
    times_s: np.ndarray | None
    gain: float
    bits: int

    @property
    def n_frames(self) -> int:
        return len(self.files)

    @property
    def fps(self) -> float | None:
        """The mean rate of ``times_s``, Hz (None without times)."""
        t = self.times_s
        if t is None or len(t) < 2 or not t[-1] > t[0]:
            return None
        return (len(t) - 1) / float(t[-1] - t[0])

    @property
    def n_dropped(self) -> int:
        """Frames missing from the timestamps' clock (an interval of k > 1.5 median steps: k - 1)."""
        t = self.times_s
        if t is None or len(t) < 3:
            return 0
        d = np.diff(t)
        med = float(np.median(d))
        big = d[d > 1.5 * med]
        return int(np.sum(np.rint(big / med) - 1)) if med > 0 else 0

    def read(self, i: int) -> np.ndarray:
        """Frame ``i`` as 8-bit BGR (H, W, 3) or grey (H, W), as stored (no colour conversion)."""
        import cv2

        f = self.files[i]
        img = cv2.imread(str(f), cv2.IMREAD_UNCHANGED)
        if img is None:
            raise InputError(f"{f}: cannot decode the image (damaged or not an image); replace the frame")
        if img.shape[:2] != (self.height_px, self.width_px):
            raise InputError(
                f"{f}: {img.shape[1]}x{img.shape[0]} px, the sequence's first frame is "
                f"{self.width_px}x{self.height_px}; every frame must have the same size (remove or re-export it)"
            )
        if img.ndim == 3 and img.shape[2] == 4:
            img = img[:, :, :3]  # the alpha channel is no part of the picture
        return to_8bit(img, self.gain)


def to_8bit(img: np.ndarray, gain: float) -> np.ndarray:
    """``img`` times ``gain``, rounded and saturated to uint8 (an 8-bit image with gain 1 as is)."""
    if img.dtype == np.uint8 and gain == 1.0:
        return img
    return np.clip(np.rint(img.astype(np.float32) * np.float32(gain)), 0, 255).astype(np.uint8)


def depth_gain(peak: int) -> float:
    """The gain that maps a camera's values to 8 bits: ``2 ** (8 - bits)`` for the least depth of 8,
    10, 12, 14 or 16 bits that holds ``peak`` (the brightest value seen)."""
    bits = next((b for b in (8, 10, 12, 14) if peak < 2**b), 16)
    return 2.0 ** (8 - bits)


def _frames(folder: Path) -> list[Path]:
    imgs = [f for f in folder.iterdir() if f.suffix.lower() in IMAGE_SUFFIXES and not f.name.startswith(".")]
    if not imgs:
        raise InputError(
            f"{folder}: no frames in the folder (PNG, JPEG, TIFF or BMP files); give a folder of numbered "
            "images or a video file"
        )
    kinds = sorted({f.suffix.lower().replace(".jpeg", ".jpg").replace(".tiff", ".tif") for f in imgs})
    if len(kinds) > 1:
        raise InputError(
            f"{folder}: frames of several kinds ({', '.join(kinds)}); a sequence is one kind of file: "
            "move the others out of the folder"
        )
    return imgs


def _ordered(folder: Path, imgs: list[Path], timed_by_file: bool) -> list[Path]:
    parts = {}
    for f in imgs:
        m = _NUMBERED.match(f.stem)
        if m is None:
            raise InputError(f"{f}: no frame number in the name; frames are named like frame_00001.png")
        parts[f] = (m.group(1), int(m.group(2)), m.group(3))
    patterns = sorted({(a, c) for a, _, c in parts.values()})
    if len(patterns) > 1:
        shown = ", ".join(f"{a}N{c}" for a, c in patterns[:3])
        raise InputError(
            f"{folder}: frames named in {len(patterns)} ways ({shown}); one sequence per folder: move the others out"
        )
    ordered = sorted(imgs, key=lambda f: parts[f][1])
    nums = np.array([parts[f][1] for f in ordered])
    if len(nums) > 1 and np.any(np.diff(nums) == 0):
        k = int(np.flatnonzero(np.diff(nums) == 0)[0])
        raise InputError(f"{ordered[k]} and {ordered[k + 1].name}: the same frame number; remove one")
    if not timed_by_file and len(nums) > 1 and np.any(np.diff(nums) != 1):
        k = int(np.flatnonzero(np.diff(nums) != 1)[0])
        lost = int(np.sum(np.diff(nums) - 1))
        raise InputError(
            f"{folder}: the frame numbers jump from {nums[k]} ({ordered[k].name}) to {nums[k + 1]} ({lost} frame(s) "
            f"missing); restore the missing frames, or give each frame's time in {TIMESTAMPS_FILE} (columns file,t_s)"
        )
    return ordered


def _timestamps(folder: Path):
    """``(times_s, files or None)`` from the folder's timestamps file, or ``(None, None)``."""
    p = folder / TIMESTAMPS_FILE
    if not p.is_file():
        return None, None
    import pandas as pd

    try:
        df = pd.read_csv(p, comment="#", skipinitialspace=True)
    except Exception as e:  # noqa: BLE001 - pandas raises many types; one line says which file
        raise InputError(f"{p}: not a readable CSV ({type(e).__name__}); give a header t_s (and file)") from None
    df.columns = [str(c).strip() for c in df.columns]
    if "t_s" not in df.columns:
        raise InputError(
            f"{p}, line 1: no column t_s; the header names each frame's time in seconds, t_s (and optionally file)"
        )
    t = pd.to_numeric(df["t_s"], errors="coerce").to_numpy(float)
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise InputError(f"{p}, line {int(bad[0]) + 2}: t_s is not a number; give every frame's time in seconds")
    if len(t) > 1 and np.any(np.diff(t) <= 0):
        k = int(np.flatnonzero(np.diff(t) <= 0)[0])
        raise InputError(f"{p}, line {k + 3}: t_s does not increase; the frames' times must increase")
    files = [str(v).strip() for v in df["file"]] if "file" in df.columns else None
    return t - (t[0] if len(t) else 0.0), files


def _header_size(f: Path):
    """(width, height, bits) from the file's header (Pillow reads no pixels for this); None where
    Pillow cannot say (then the frame's size is checked when it is read)."""
    try:
        from PIL import Image

        with Image.open(f) as im:
            bits = 16 if im.mode.startswith("I;16") or im.mode in ("I", "F") else 8
            return im.size[0], im.size[1], bits
    except Exception:  # noqa: BLE001 - Pillow raises many types; OpenCV decides when reading
        return None


def open_image_sequence(folder) -> ImageSequence:
    """Open a folder of frames as a film (see the module's doc for the rules).

    A command opens its film several times (probe, first frame, frames): the folder is listed
    and its headers read once while neither it nor its ``timestamps.csv`` changes.

    Raises
    ------
    InputError
        No frames, frames of several kinds or names, a gap in the numbering without timestamps,
        frames of different sizes, a timestamps file that does not fit the frames.
    """
    folder = Path(folder)
    stamp = [folder.stat().st_mtime_ns]
    ts = folder / TIMESTAMPS_FILE
    stamp.append(ts.stat().st_mtime_ns if ts.is_file() else 0)
    return _open_cached(str(folder.resolve()), *stamp)


@functools.lru_cache(maxsize=4)
def _open_cached(folder: str, *_stamp) -> ImageSequence:
    folder = Path(folder)
    imgs = _frames(folder)
    times, listed = _timestamps(folder)
    if listed is not None:
        by_name = {f.name: f for f in imgs}
        miss = [n for n in listed if n not in by_name]
        if miss:
            raise InputError(f"{folder / TIMESTAMPS_FILE}: lists {miss[0]}, which is not in the folder; fix the list")
        unlisted = sorted(set(by_name) - set(listed))
        if unlisted:
            raise InputError(
                f"{folder / TIMESTAMPS_FILE}: has no time for {unlisted[0]} ({len(unlisted)} frame(s) unlisted); "
                "list every frame or move it out of the folder"
            )
        order = _ordered(folder, imgs, True)
        pos = {n: k for k, n in enumerate(listed)}
        if [pos[f.name] for f in order] != sorted(pos[f.name] for f in order):
            raise InputError(f"{folder / TIMESTAMPS_FILE}: the frames' times are not in the order of their numbers")
        times = np.array([times[pos[f.name]] for f in order])
    else:
        order = _ordered(folder, imgs, False)
        if times is not None and len(times) != len(order):
            raise InputError(
                f"{folder / TIMESTAMPS_FILE}: {len(times)} times for {len(order)} frames; give one t_s per frame "
                "(or a file column naming each)"
            )
    import cv2

    first = cv2.imread(str(order[0]), cv2.IMREAD_UNCHANGED)
    if first is None:
        raise InputError(f"{order[0]}: cannot decode the image (damaged or not an image); replace the frame")
    h, w = first.shape[:2]
    for f in order[1:]:
        hs = _header_size(f)
        if hs is not None and hs[:2] != (w, h):
            raise InputError(
                f"{f}: {hs[0]}x{hs[1]} px, the sequence's first frame ({order[0].name}) is {w}x{h}; every frame "
                "must have the same size (remove or re-export it)"
            )
    if first.dtype == np.uint8:
        gain, bits = 1.0, 8
    elif first.dtype == np.uint16:
        peaks = [int(first.max())]
        for f in {order[len(order) // 2], order[-1]}:
            img = cv2.imread(str(f), cv2.IMREAD_UNCHANGED)
            if img is not None:
                peaks.append(int(img.max()))
        gain, bits = depth_gain(max(peaks)), 16
    else:
        raise InputError(
            f"{order[0]}: {first.dtype} pixels; frames must be 8- or 16-bit integers (convert the sequence)"
        )
    return ImageSequence(folder, tuple(order), int(w), int(h), times, gain, bits)


class FrameStoreReader:
    """``cv2.VideoCapture``'s ``read``/``release`` over an :class:`ImageSequence` (or any store of frames
    with ``n_frames`` and ``read(i)``: :class:`._highspeed.HighSpeedFilm`), from frame ``first``.

    ``index`` is the last frame's place; pictures are 8-bit, grey with ``gray`` (else BGR).
    """

    def __init__(self, seq: ImageSequence, first: int = 0, gray: bool = True):
        self._seq, self._gray = seq, gray
        self.index = int(first) - 1

    def read(self):
        import cv2

        i = self.index + 1
        if i >= self._seq.n_frames:
            return False, None
        img = self._seq.read(i)
        self.index = i
        if self._gray and img.ndim == 3:
            img = cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
        elif not self._gray and img.ndim == 2:
            img = cv2.cvtColor(img, cv2.COLOR_GRAY2BGR)
        return True, img

    def release(self):
        pass
