"""The pictures of a calibration: a film, a folder of photos or a file pattern.

A folder of calibration photos is a set of views, not a film: it needs no frame rate, and gaps in
its numbering (a blurred photo deleted) are fine; one number under two names (``left01.jpg``,
``right01.jpg``) means two cameras' photos, refused. Its pictures are taken
in the order of the numbers in their names (``left2.jpg`` before ``left10.jpg``). A pattern such as
``'calib/left*.jpg'`` (quoted, so the shell does not expand it) picks some files of a folder. A
film (video file, Photron, Phantom) is read frame by frame, every ``every``-th frame.
"""

from __future__ import annotations

import glob
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..._errors import InputError

__all__ = ["Views", "open_views", "frames_by_index", "warn_lost", "MAX_FILM_VIEWS"]

#: A film gives at most this many views by default (``every`` chosen to match): neighbouring frames
#: of a slowly moved board add little but detection time.
MAX_FILM_VIEWS = 100
_IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp")
_DIGITS = re.compile(r"(\d+)")
_LAST_NUMBER = re.compile(r"^(.*?)(\d+)(\D*)$")


def _natural(p: Path):
    return [int(t) if t.isdigit() else t.lower() for t in _DIGITS.split(p.name)]


@dataclass(frozen=True)
class Views:
    """Calibration pictures.

    Attributes
    ----------
    source : str
        The film, folder or pattern given.
    labels : tuple of str
        Each view's name: the file name, or ``frame N`` of a film.
    numbers : tuple of int or None
        The number in each file's name (None for a film, or names without one).
    files : tuple of Path or None
        The pictures (None for a film).
    every : int
        Frames of a film taken (1: all).
    """

    source: str
    labels: tuple
    numbers: tuple | None
    files: tuple | None
    every: int = 1

    @property
    def is_film(self) -> bool:
        return self.files is None

    def __len__(self) -> int:
        return len(self.labels)

    def items(self, lost: list | None = None):
        """``(label, gray)`` of each view, in order: grey 8-bit pictures (a 16-bit photo divided as its
        camera's depth asks, :func:`~rocklab.tracking.video.sequences.depth_gain`). A film's frames come
        from :func:`frames_by_index` (``lost`` as there)."""
        import cv2

        if self.is_film:
            for k, gray in enumerate(frames_by_index(self.source, lost)):
                if k % self.every == 0:
                    yield f"frame {k}", gray
            return
        for f in self.files:
            img = cv2.imread(str(f), cv2.IMREAD_ANYDEPTH | cv2.IMREAD_GRAYSCALE)
            if img is None:
                raise InputError(f"{f}: cannot decode the picture (damaged or not an image); remove it from the set")
            if img.dtype != np.uint8:
                from ..video.sequences._imageseq import depth_gain, to_8bit

                img = to_8bit(img, depth_gain(int(img.max())))
            yield f.name, img


def frames_by_index(path, lost: list | None = None):
    """Grey frames of the film at ``path``, one per slot of its container's clock.

    A frame the camera dropped or a damaged packet lost is a black picture (nothing is detected
    in it), so frame ``i`` of one camera stays frame ``i`` of the other. ``(path, n_undecoded,
    n_dropped, n_slots)`` is appended to ``lost`` at the end, for the caller to warn from its own
    thread (:func:`warn_lost`).
    """
    from ..video import iter_video_frames, probe_video

    info = probe_video(path)
    slot = np.arange(info.n_frames)
    if info.n_dropped and info.frame_times_s is not None and info.fps:
        slot = np.rint(info.frame_times_s * info.fps).astype(int)
    n = int(slot[-1]) + 1 if len(slot) else 0
    nxt, n_undecoded, blank = 0, 0, None
    for i, gray in iter_video_frames(path):
        k = int(slot[i]) if i < len(slot) else i
        blank = np.zeros_like(gray) if blank is None else blank
        for _ in range(nxt, k):
            yield blank
        n_undecoded += max(k - nxt, 0)
        yield gray
        nxt = k + 1
    if blank is not None:
        for _ in range(nxt, n):
            yield blank
        n_undecoded += max(n - nxt, 0)
    if lost is not None:
        lost.append((str(path), n_undecoded - info.n_dropped, info.n_dropped, max(n, nxt)))


def warn_lost(lost) -> None:
    """W-VIDEO-DROPPED and W-VIDEO-DAMAGED for each film of :func:`frames_by_index` that lost frames."""
    from ..._diagnostics import warn

    for path, n_bad, n_dropped, n in lost:
        if n_dropped:
            warn(
                "W-VIDEO-DROPPED",
                f"{path}: the camera dropped {n_dropped} of {n} frames (gaps in the container's clock); "
                "they count as frames without targets, so the two films stay paired frame by frame",
            )
        if n_bad > 0:
            warn(
                "W-VIDEO-DAMAGED",
                f"{path}: {n_bad} of the {n} frames the container holds did not decode (damaged "
                "packets); they count as frames without targets, so the two films stay paired frame by frame",
            )


def _pictures(source: str) -> list[Path]:
    p = Path(source)
    if p.is_dir():
        files = [f for f in p.iterdir() if f.suffix.lower() in _IMAGE_SUFFIXES and not f.name.startswith(".")]
        if not files:
            raise InputError(
                f"{p}: no pictures in the folder (PNG, JPEG, TIFF or BMP); give the calibration photos' folder"
            )
        return sorted(files, key=_natural)
    files = [Path(f) for f in glob.glob(source)]
    files = [f for f in files if f.is_file() and f.suffix.lower() in _IMAGE_SUFFIXES]
    if not files:
        raise InputError(
            f"{source}: no pictures match the pattern; give a film, a folder of photos or a pattern such as 'calib/left*.jpg'"
        )
    return sorted(files, key=_natural)


def open_views(source, every: int | None = None) -> Views:
    """The views of ``source``: a film, a folder of photos or a file pattern (see the module's doc).

    Parameters
    ----------
    source : path-like or str
    every : int or None
        A film: take every ``every``-th frame (None: as many as keep at most
        :data:`MAX_FILM_VIEWS`). Ignored for photos.

    Raises
    ------
    InputError
        Nothing at ``source``, no pictures, ``every`` < 1.
    """
    s = str(source)
    if every is not None and every < 1:
        raise InputError(f"--every {every}: take every N-th frame with N >= 1")
    p = Path(s)
    is_pattern = not p.exists() and any(ch in s for ch in "*?[")
    if p.is_dir() and not any(f.suffix.lower() in _IMAGE_SUFFIXES for f in p.iterdir()):
        pass  # a folder of another kind (a high-speed camera's) is read as a film below
    elif p.is_dir() or is_pattern:
        files = _pictures(s)
        by_kind: dict = {}
        for f in files:
            m = _LAST_NUMBER.match(f.stem)
            if m:
                by_kind.setdefault((m.group(1), m.group(3)), set()).add(int(m.group(2)))
        kinds = sorted(by_kind)
        shared = any(by_kind[a] & by_kind[b] for i, a in enumerate(kinds) for b in kinds[i + 1 :])
        if p.is_dir() and shared:
            # left01.jpg and right01.jpg (or cam1_0001 and cam2_0001) side by side: two cameras' photos,
            # which one calibration would mix
            shown = ", ".join("N".join(k) for k in kinds[:3])
            raise InputError(
                f"{p}: pictures named in {len(kinds)} ways ({shown}); one camera's photos per "
                f"calibration: give a quoted pattern such as '{p / ('*'.join(kinds[0]) + files[0].suffix)}'"
            )
        nums = [_DIGITS.findall(f.stem) for f in files]
        numbers = tuple(int(n[-1]) for n in nums) if all(nums) else None
        return Views(s, tuple(f.name for f in files), numbers, tuple(files))
    if not p.exists():
        raise InputError(
            f"{s}: not found; give a calibration film, a folder of photos or a pattern such as 'calib/left*.jpg'"
        )
    from ..video import probe_video

    n = probe_video(s).n_frames
    step = every or max(1, -(-n // MAX_FILM_VIEWS))
    return Views(s, tuple(f"frame {i}" for i in range(0, n, step)), None, None, step)
