"""High-speed cameras' own formats as films: Photron MRAW (``.cih``/``.cihx`` + ``.mraw``) and Phantom
CINE (``.cine``), read with the optional packages ``pymraw`` and ``pycine-lite`` (``pip install
pymraw pycine-lite``; both install on Python 3.11, and rocklab works without them).

Both hold grey frames of 8, 12 or 16 bits and the camera's rate; CINE also each frame's time (its
tagged time block). They are read with the contract of :class:`._imageseq.ImageSequence` (``read(i)``
-> 8-bit frame, ``times_s``, ``fps``), so every command takes them as it takes a video file; deeper
frames are mapped to 8 bits by the same rule (:func:`._imageseq.depth_gain`: one gain for the film,
from the depth that holds its brightest sampled pixel). A colour (Bayer) CINE is refused: its raw mosaic is no grey
picture.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...._errors import InputError
from ._imageseq import depth_gain, to_8bit

__all__ = ["HIGHSPEED_SUFFIXES", "HighSpeedFilm", "open_highspeed", "frame_store"]

#: File endings read with the high-speed readers (an ``.mraw`` stands for its ``.cih``/``.cihx``).
HIGHSPEED_SUFFIXES = (".cih", ".cihx", ".mraw", ".cine")


@dataclass(frozen=True)
class HighSpeedFilm:
    """A Photron MRAW or Phantom CINE film.

    Attributes
    ----------
    path : Path
    n_frames : int
    width_px, height_px : int
    fps : float or None
        The film's frame rate, Hz: the camera's recording rate (over the MRAW's ``Save Step``
        when it kept every k-th frame).
    times_s : ndarray (n,) or None
        Each frame's time from the file, s, the first at 0 (CINE's time block; None for MRAW).
    gain : float
        Factor that maps the stored values to 8 bits.
    bits : int
        Bits per sample as stored.
    """

    path: Path
    n_frames: int
    width_px: int
    height_px: int
    fps: float | None
    times_s: np.ndarray | None
    gain: float
    bits: int
    _frame: object = None  # callable(i) -> stored frame (H, W)

    n_dropped: int = 0

    def read(self, i: int) -> np.ndarray:
        """Frame ``i`` as an 8-bit grey picture (H, W)."""
        return to_8bit(np.asarray(self._frame(i)), self.gain)


def _need(module: str, package: str, path: Path):
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise InputError(
            f"{path}: reading this format needs the package {package}; install it (pip install {package}) "
            "or export the film as an image sequence"
        ) from None


def _gain(frames, n: int) -> float:
    return depth_gain(max(int(np.max(frames(i))) for i in sorted({0, n // 2, n - 1})))


def _mraw(path: Path) -> HighSpeedFilm:
    cih = path
    if path.suffix.lower() == ".mraw":
        cih = next((c for c in (path.with_suffix(".cihx"), path.with_suffix(".cih")) if c.is_file()), None)
        if cih is None:
            raise InputError(f"{path}: no .cih/.cihx header beside the .mraw; copy it from the camera with the film")
    elif not path.with_suffix(".mraw").is_file():
        raise InputError(f"{path}: no .mraw beside the header ({path.with_suffix('.mraw').name}); copy the film too")
    pymraw = _need("pyMRAW", "pymraw", path)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # pyMRAW warns for every depth but 12 bits
            images, info = pymraw.load_video(str(cih))
    except InputError:
        raise
    except Exception as e:  # noqa: BLE001 - pyMRAW raises bare Exceptions for what it cannot read
        raise InputError(f"{cih}: not a readable Photron film ({str(e)[:80]}); check the .cih and the .mraw") from None
    if str(info.get("Color Type", "Mono")).lower() not in ("mono", "monochrome", ""):
        raise InputError(f"{cih}: a colour MRAW ({info.get('Color Type')}); export it as grey or as an image sequence")
    n, h, w = images.shape
    # a film saved with every k-th frame ("Save Step : k") runs at the recording rate over k
    step = info.get("Save Step", 1)
    step = step if isinstance(step, int) and step > 0 else 1
    fps = float(info.get("Record Rate(fps)") or 0) / step or None
    frame = images.__getitem__
    bits = int(info.get("Color Bit", 16))
    return HighSpeedFilm(path, n, int(w), int(h), fps, None, 1.0 if bits == 8 else _gain(frame, n), bits, frame)


def _cine(path: Path) -> HighSpeedFilm:
    _need("pycine", "pycine-lite", path)
    from pycine.file import read_header
    from pycine.raw import frame_reader

    try:
        header = read_header(str(path))
    except Exception as e:  # noqa: BLE001 - struct/ctypes errors on a damaged header
        raise InputError(f"{path}: not a readable Phantom CINE ({type(e).__name__}); check the file") from None
    setup, cfh, bih = header["setup"], header["cinefileheader"], header["bitmapinfoheader"]
    if int(getattr(setup, "CFA", 0)) != 0:
        raise InputError(
            f"{path}: a colour (Bayer) CINE; export it from PCC as grey (or as an image sequence) to track it"
        )
    n = int(cfh.ImageCount)

    def frame(i: int):
        return next(frame_reader(str(path), header, start_frame=i + 1, count=1))

    fps = float(setup.FrameRate or 0) or None
    times = _cine_times(np.asarray(header.get("timestamp", ()), float), n, fps, path)
    from pycine.raw import read_bpp

    bits = int(read_bpp(header))  # a packed 10-bit film is 12-bit once linearised
    return HighSpeedFilm(path, n, int(bih.biWidth), abs(int(bih.biHeight)), fps, times, _gain(frame, n), bits, frame)


def _cine_times(t: np.ndarray, n: int, fps: float | None, path: Path) -> np.ndarray | None:
    """The CINE's time block as frame times (s, the first at 0), or None where it has none or
    contradicts the rate: every interval must be positive and under 10 frame periods."""
    if len(t) != n or n < 2:
        return None
    d = np.diff(t)
    bad = np.flatnonzero(~(d > 0) | (d > 10.0 / fps if fps else False))
    if bad.size:
        from ...._diagnostics import warn

        k = int(bad[0]) + 1
        warn(
            "W-VIDEO-TIMES",
            f"{path}: the time block puts frame {k} {d[k - 1]:.6g} s after frame {k - 1} "
            f"({bad.size} such interval(s)) at {fps or 0:g} frames/s; t_s follows the rate, check frame {k}",
        )
        return None
    return t - t[0]


def open_highspeed(path) -> HighSpeedFilm:
    """Open a Photron (``.cih``, ``.cihx``, ``.mraw``) or Phantom (``.cine``) film.

    Raises
    ------
    InputError
        The reading package is not installed (naming it), a missing header or data file, a
        colour film, a file the package cannot read.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: video file not found; check the path")
    return _cine(path) if path.suffix.lower() == ".cine" else _mraw(path)


def frame_store(path):
    """The film at ``path`` as a store of frames (an image folder or a high-speed camera's file),
    or None for a video file (read by PyAV / OpenCV)."""
    from ._imageseq import open_image_sequence

    p = Path(path)
    if p.is_dir():
        return open_image_sequence(p)
    if p.suffix.lower() in HIGHSPEED_SUFFIXES:
        return open_highspeed(p)
    return None
