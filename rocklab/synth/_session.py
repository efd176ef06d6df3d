"""Synthetic lab sessions: a rendered video of rocking blocks with exactly known truth.

``synth_session`` simulates the blocks with :func:`rocklab.models.simulate`,
renders them (``_render``) through a calibrated, slightly tilted, distorted
camera, and writes the session folder::

    video.mkv        FFV1 lossless, grey, fps as given
    video.mp4        mp4v lossy copy
    truth.csv        frame, t_s, object, x_m, y_m, theta_rad, vx_m_s, ax_m_s2
    track.toml       tracking config for ``rocklab track`` (schema: _config.py)
    experiment.toml  pipeline config for ``rocklab run``
    imu/<object>/    x-IMU GUI logs <object>_CalInertialAndMag.csv + _Registers.csv
    session.json     seed, parameters, blocks, true restitution, release, camera, IMU truth

Conventions (also in ``session.json["conventions"]``): world = rocking plane,
``x`` right, ``y`` up, table top at ``y = 0``; ``theta_rad`` = counter-clockwise
angle seen by the camera (the tracker's convention) = ``-theta`` of
:func:`rocklab.models.simulate` driven by the table's ``ax_m_s2``. Frame ``i``
is centred on ``t_s = i / fps``; ``x_m, y_m`` is the centre of a block's front
face and the top centre of the table's front face.
"""

from __future__ import annotations

import contextlib
import json
import math
import shutil
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._errors import InputError

__all__ = ["SynthSession", "synth_session", "load_synth_session", "TARGETS", "TABLES", "parse_size"]

TARGETS = ("aruco", "dots", "edges", "markerless")
TABLES = ("none", "sine", "record")


@dataclass(frozen=True)
class SynthSession:
    """A written synthetic session.

    Attributes
    ----------
    out_dir : Path
    video_mkv, video_mp4, truth_csv, track_toml, experiment_toml, session_json : Path
        Files in ``out_dir`` (``video_mp4`` is None when not written).
    imu : dict
        ``{object_id: folder}`` of the IMU logs.
    truth : pandas.DataFrame
        ``frame, t_s, object, x_m, y_m, theta_rad, vx_m_s, ax_m_s2`` (m, s, rad;
        ``vx_m_s``/``ax_m_s2`` only for the table, NaN for blocks).
    meta : dict
        The contents of ``session.json``.
    render_s : float
        Wall time of rendering and encoding, s (NaN when loaded from disk).
    """

    out_dir: Path
    video_mkv: Path
    video_mp4: Path | None
    truth_csv: Path
    track_toml: Path
    experiment_toml: Path
    session_json: Path
    imu: dict
    truth: object
    meta: dict = field(repr=False)
    render_s: float = float("nan")

    @property
    def fps(self) -> float:
        return float(self.meta["fps"])

    @property
    def n_frames(self) -> int:
        return int(self.meta["n_frames"])

    @property
    def camera(self):
        from ._camera import SynthCamera

        return SynthCamera.from_dict(self.meta["camera"])

    def to_frame(self):
        """The truth table (see ``truth``)."""
        return self.truth

    def to_dict(self) -> dict:
        """Paths and summary numbers, JSON-ready."""
        return {
            "out_dir": str(self.out_dir),
            "video_mkv": str(self.video_mkv),
            "video_mp4": None if self.video_mp4 is None else str(self.video_mp4),
            "truth_csv": str(self.truth_csv),
            "track_toml": str(self.track_toml),
            "experiment_toml": str(self.experiment_toml),
            "session_json": str(self.session_json),
            "imu": {k: str(v) for k, v in self.imu.items()},
            "n_frames": self.n_frames,
            "fps": self.fps,
            "size": self.meta["size_px"],
            "seed": self.meta["seed"],
            "objects": sorted(self.truth["object"].unique().tolist()),
            "render_s": self.render_s,
        }


def parse_size(text) -> tuple[int, int]:
    """``"1920x1080"`` or ``(1920, 1080)`` -> ``(1920, 1080)``; InputError otherwise."""
    try:
        if isinstance(text, str):
            w, h = text.lower().replace("×", "x").split("x")
            size = (int(w), int(h))
        else:
            size = tuple(int(v) for v in text)
    except (ValueError, TypeError):
        size = None
    if size is None or len(size) != 2 or not (64 <= size[0] <= 8192 and 64 <= size[1] <= 8192):
        raise InputError(f"size={text!r}: must be WIDTHxHEIGHT in pixels, each 64..8192 (e.g. 1920x1080)")
    return size


def _check(seed, blocks, table, fps, targets, duration_s, exposure_s, noise_dn):
    if not isinstance(seed, (int, np.integer)) or isinstance(seed, bool) or seed < 0:
        raise InputError(f"seed={seed!r}: must be a non-negative integer")
    if blocks not in (1, 2, 3):
        raise InputError(f"blocks={blocks!r}: must be 1, 2 or 3")
    if table not in TABLES:
        raise InputError(f"table={table!r}: unknown table motion; use one of {', '.join(TABLES)}")
    if targets not in TARGETS:
        raise InputError(f"targets={targets!r}: unknown target style; use one of {', '.join(TARGETS)}")
    if not (isinstance(fps, (int, float)) and math.isfinite(fps) and 1 <= fps <= 2000):
        raise InputError(f"fps={fps!r}: must be a frame rate between 1 and 2000")
    if duration_s is not None and not (math.isfinite(duration_s) and 0 < duration_s <= 120):
        raise InputError(f"duration={duration_s!r}: must be between 0 and 120 s")
    if not (isinstance(noise_dn, (int, float)) and 0 <= noise_dn <= 50):
        raise InputError(f"noise={noise_dn!r}: sensor noise must be between 0 and 50 grey levels")
    if exposure_s is not None and not (0 <= exposure_s <= 1.0 / fps):
        raise InputError(f"exposure_s={exposure_s!r}: must be between 0 and one frame (1/fps s)")


def _prepare_out(out_dir: Path, force: bool) -> Path:
    from .._outdir import check_output_dir, stage_dir

    out_dir = check_output_dir(out_dir, force=force, need_bytes=200 * 1024 * 1024)
    if out_dir.is_dir() and any(out_dir.iterdir()) and not force:
        raise InputError(
            f"--out {out_dir}: folder is not empty; choose a new --out or pass --force to "
            "replace rocklab's files in it (nothing else is deleted)"
        )
    return stage_dir(out_dir)


def synth_session(
    out_dir,
    seed: int = 0,
    blocks: int = 1,
    table: str = "none",
    fps: float = 50.0,
    size=(1920, 1080),
    targets: str = "aruco",
    duration_s: float | None = None,
    occlusion=None,
    rolling_shutter: bool = False,
    *,
    block=None,
    restitution: str = "constant",
    eta: float | None = 0.75,
    theta0_rad=None,
    record=None,
    table_amplitude_m: float | None = None,
    table_period_s: float = 0.6,
    table_stroke_m: float = 0.05,
    exposure_s: float | None = None,
    noise_dn: float = 1.0,
    distortion: bool = True,
    imu: bool = True,
    imu_rate_hz: float = 256.0,
    mp4: bool = True,
    calibrated: bool = True,
    layout: str | None = None,
    force: bool = False,
    progress: bool = False,
    flicker: float = 0.0,
    texture: str = "procedural",
    column_cut_m: float = 0.0,
    column_impacts: int = 1,
    video: bool = True,
) -> SynthSession:
    """Render a synthetic lab session into ``out_dir`` (see the module doc for the layout).

    Parameters
    ----------
    out_dir : path
        New (or empty) folder; written atomically (rendered into a temporary sibling folder, then renamed).
        ``force=True`` replaces a non-empty one.
    seed : int
        Everything random (camera pose and lens, release times, textures, noise, IMU errors) derives from it:
        same seed, identical files.
    blocks : {1, 2, 3}
        One block, or two or three blocks: a stacked column (thesis §4.3: three 0.1 x 0.2 m granite blocks,
        ``rocklab.models.simulate_column``) when the column model is available, else independent blocks side by
        side (``layout`` forces one: ``"column"`` or ``"side"``).
    table : {"none", "sine", "record"}
        ``none``: free rocking after a thread-burn release from ``theta0_rad`` at a known time; ``sine``: blocks
        at rest on a table doing one smooth sine cycle (``table_period_s``, ``table_amplitude_m``, default 45 mm
        as thesis Fig. 31, 20 mm for the column which overturns at 45 mm); ``record``: ``record`` (path of an
        .AT2/CSV record or a BaseMotion; default the bundled El Centro 1940) scaled and high-passed to the table
        stroke ``table_stroke_m``.
    fps : float
        Frame rate, Hz.
    size : (W, H) or "WxH"
        Frame size, px. The framing scales with it (a 0.2 m block fills a third of the frame height).
    targets : {"aruco", "dots", "edges", "markerless"}
        Two ArUco markers (DICT_4X4_50) per block and two on the table; four black dots per block and three on
        the table; or plain light blocks on a dark background.
    duration_s : float, optional
        Video length, s (default: until the blocks are at rest plus 0.6 s, at most 12 s).
    occlusion : (t0_s, t1_s) or dict, optional
        A dark patch hides ``block_1`` (or ``{"object", "t0_s", "t1_s"}``) during [t0, t1).
    rolling_shutter : bool
        Rows are read out over 80 % of the frame period (top first).
    block : Block or list of Block, optional
        Block geometry (default 0.1 m x 0.2 m x 0.3 m granite, the thesis §4.3 column element).
    restitution, eta :
        Impact law for :func:`rocklab.models.simulate` (default constant eta = 0.75: a 0.1 x 0.2 m block
        survives the sine pulse).
    theta0_rad : float or sequence, optional
        Initial counter-clockwise tilt(s) for free rocking (default ±0.5 alpha). A column: one angle tilts it as
        one body, one per level gives each block's own angle (thesis §4.2: ``[0, -0.153]``, the upper block
        alone tilted).
    column_cut_m, column_impacts : float, int
        A column's cut edge at every joint (m) and impacts per closing (the true model, written to
        ``experiment.toml``'s ``[column]``).
    video : bool
        Render the film (``video.mkv``/``.mp4``, ``track.toml``). False: only the IMU logs, the truth and an
        ``experiment.toml`` that measures every block with its IMU (needs ``imu``).
    exposure_s : float, optional
        Shutter time, s (default half a frame period); motion blur integrates over it.
    noise_dn : float
        Sensor noise, grey levels (sigma).
    flicker : float
        Exposure flicker, relative amplitude (0 to 0.5): a camcorder's automatic exposure hunting under mains
        light (``Renderer.exposure_gain``); the frames' brightness follows it.
    texture : {"procedural", "photo"}
        Surfaces from synthetic noise, or from photographs (CC0, shipped in ``rocklab/data/textures``): the wall
        is a brick wall and a markerless block's face is gravel-like stone.
    imu : bool
        Write IMU logs (one per block and one on the table), x-IMU GUI format, from 0.5..1.5 s before the video to
        1 s after the blocks and table are still (as a lab logs; >= 0.5 s after the video, the blocks simulated up
        to 30 s past it), ``session.json["conventions"]["imu_end_s"]``; ``truth.csv`` covers the video frames.

    Returns
    -------
    SynthSession

    Raises
    ------
    InputError
        Bad parameter values, non-empty ``out_dir`` without ``force``, an unreadable record.
    """
    from ._scene import SCENE_OPTIONS

    size = parse_size(size)
    fps = float(fps) if isinstance(fps, (int, float, np.number)) and not isinstance(fps, bool) else fps
    _check(seed, blocks, table, fps, targets, duration_s, exposure_s, noise_dn)
    _check_look(flicker, texture, video, imu)
    seed = int(seed)
    # the scene's options (build_scene's parameters) go on as given: size parsed, fps a float, seed an int
    scene_options = {name: value for name, value in locals().items() if name in SCENE_OPTIONS}
    files = dict(imu=imu, imu_rate_hz=imu_rate_hz, calibrated=calibrated, video=video)
    render_s = _render_session(scene_options, float(flicker), files, Path(out_dir), force, mp4, progress)
    return load_synth_session(Path(out_dir), render_s=render_s)


def _check_look(flicker, texture, video=True, imu=True):
    """The frames' exposure flicker and surface textures are among the known ones; a session
    without a film has IMUs."""
    if not video and not imu:
        raise InputError("video=False needs imu=True: a session without a film is measured by its IMUs")
    if not (isinstance(flicker, (int, float)) and not isinstance(flicker, bool) and 0 <= flicker <= 0.5):
        raise InputError(f"flicker={flicker!r}: exposure flicker must be a relative amplitude from 0 to 0.5")
    if texture not in ("procedural", "photo"):
        raise InputError(f"texture={texture!r}: use 'procedural' (synthetic noise) or 'photo' (photographs)")


def _render_session(scene_options, flicker, files, out_dir: Path, force: bool, mp4: bool, progress: bool) -> float:
    """Build the scene, render it and write its files into a staged folder published as ``out_dir``.

    Returns the rendering time, s. Nothing is left behind when any step fails.
    """
    from ._scene import build_scene

    tmp = _prepare_out(out_dir, force)
    t_start = time.perf_counter()
    try:
        scene = build_scene(**scene_options)
        scene.flicker = flicker
        if files["video"]:
            _render_video(scene, tmp, mp4, progress)
        meta = scene.write_files(tmp, **files)
        meta["flicker"] = flicker
        meta["texture"] = scene_options["texture"]
        render_s = time.perf_counter() - t_start
        meta["render_s"] = render_s
        from .._io import write_json_atomic

        write_json_atomic(tmp / "session.json", meta)
        from .._outdir import publish_dir

        publish_dir(tmp, out_dir, command="synth")
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return render_s


def _render_video(scene, folder: Path, mp4: bool, progress: bool):
    from ._files import VideoPair

    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover
        tqdm = None
    renderer = scene.renderer()
    writer = VideoPair(folder, scene.fps, scene.size, mp4=mp4)
    bar = (
        tqdm(total=scene.n_frames, desc="synth", unit="frame", file=sys.stderr, disable=not progress)
        if tqdm
        else contextlib.nullcontext()
    )
    subframes = []
    try:
        for i in range(scene.n_frames):
            writer.write(renderer.render(i / scene.fps))
            subframes.append(renderer.last_subframes)
            if tqdm:
                bar.update(1)
    finally:
        writer.close()
        if tqdm:
            bar.close()
    scene.video_info = {
        "lossless_codec": writer.codec,
        "lossless_file": "video.mkv",
        "lossy_file": "video.mp4" if "mp4" in writer.paths else None,
        "lossy_codec": writer.lossy_codec,
        "color": "grey (one channel; readers return BGR with equal channels)",
        "max_subframes": int(max(subframes, default=1)),
        # brightness gain of each frame (exposure flicker; all 1 without it)
        "exposure_gain": [round(renderer.exposure_gain(i / scene.fps), 6) for i in range(scene.n_frames)]
        if scene.flicker > 0
        else None,
        "mean_subframes": float(np.mean(subframes)) if subframes else 1.0,
    }


def load_synth_session(out_dir, render_s: float = float("nan")) -> SynthSession:
    """Open a session folder written by :func:`synth_session` (reads session.json and truth.csv)."""
    import pandas as pd

    out_dir = Path(out_dir)
    sj = out_dir / "session.json"
    if not sj.is_file():
        raise InputError(f"{out_dir}: no session.json; not a synthetic session folder")
    meta = json.loads(sj.read_text(encoding="utf-8"))
    truth = pd.read_csv(out_dir / "truth.csv")
    mp4 = out_dir / "video.mp4"
    return SynthSession(
        out_dir,
        out_dir / "video.mkv",
        mp4 if mp4.is_file() else None,
        out_dir / "truth.csv",
        out_dir / "track.toml",
        out_dir / "experiment.toml",
        sj,
        {k: out_dir / "imu" / k for k in meta.get("imu", {})},
        truth,
        meta,
        render_s,
    )
