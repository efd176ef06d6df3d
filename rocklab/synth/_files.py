"""Writers for synthetic sessions: video containers, ``track.toml``, ``experiment.toml``.

Each file type has one writer function here so its format can change (or be
handed to the owner of the format) in one place.
"""

from __future__ import annotations

import queue
import threading
from pathlib import Path

import numpy as np

from .._errors import InputError

__all__ = ["VideoPair", "write_track_toml", "write_experiment_toml"]


#: A camcorder's H.264 bit rate at 1920x1080 (AVCHD's 17 Mbit/s), scaled by the pixel count.
CAMCORDER_BITRATE_1080P = 17_000_000


class _H264Writer:
    """``cv2.VideoWriter``-like (``write``/``release``) H.264 MP4 writer (PyAV, libx264), grey frames
    at a camcorder's bit rate for the frame size."""

    def __init__(self, path: Path, fps: float, size):
        from fractions import Fraction

        import av

        W, H = size
        if (W | H) & 1:
            raise ValueError("4:2:0 H.264 needs even frame sizes")
        self._c = av.open(str(path), "w")
        try:
            s = self._c.add_stream("libx264", rate=Fraction(float(fps)).limit_denominator(1001))
            s.width, s.height, s.pix_fmt = W, H, "yuv420p"
            s.bit_rate = int(max(2e6, CAMCORDER_BITRATE_1080P * W * H / (1920 * 1080)))
            s.options = {"preset": "veryfast"}
        except Exception:
            self._c.close()
            raise
        self._s = s

    def write(self, frame):
        import av

        for pkt in self._s.encode(av.VideoFrame.from_ndarray(np.ascontiguousarray(frame), format="gray")):
            self._c.mux(pkt)

    def release(self):
        for pkt in self._s.encode():
            self._c.mux(pkt)
        self._c.close()


class VideoPair:
    """Write the same grey frames to ``STEM.mkv`` (FFV1, lossless) and ``STEM.mp4`` (H.264 at a
    camcorder's bit rate, or OpenCV's MPEG-4 without PyAV/libx264); STEM = ``video``.

    Encoding runs in a background thread (OpenCV releases the GIL while
    encoding), overlapping with the rendering of the next frame. If this
    OpenCV build cannot write FFV1, the lossless file falls back to PNG in
    Matroska (``codec`` says which was used).
    """

    def __init__(self, folder: Path, fps: float, size, mp4: bool = True, stem: str = "video"):
        import cv2

        W, H = size
        self.codec = None
        self.paths = {}
        self.writers = []
        for fourcc in ("FFV1", "png "):
            w = cv2.VideoWriter(
                str(folder / f"{stem}.mkv"), cv2.VideoWriter_fourcc(*fourcc), float(fps), (W, H), isColor=False
            )
            if w.isOpened():
                self.codec = fourcc.strip()
                self.writers.append(w)
                self.paths["mkv"] = folder / f"{stem}.mkv"
                break
            w.release()
        if self.codec is None:
            raise RuntimeError(
                "this OpenCV build writes neither FFV1 nor PNG into .mkv; install an opencv build with FFmpeg"
            )
        self.lossy_codec = None
        if mp4:
            try:  # what a camcorder writes: H.264 at an AVCHD bit rate
                self.writers.append(_H264Writer(folder / f"{stem}.mp4", fps, (W, H)))
                self.paths["mp4"], self.lossy_codec = folder / f"{stem}.mp4", "h264"
            except Exception:  # noqa: BLE001 - no PyAV or no libx264 in its FFmpeg: OpenCV's MPEG-4
                w = cv2.VideoWriter(
                    str(folder / f"{stem}.mp4"), cv2.VideoWriter_fourcc(*"mp4v"), float(fps), (W, H), isColor=False
                )
                if w.isOpened():
                    self.writers.append(w)
                    self.paths["mp4"], self.lossy_codec = folder / f"{stem}.mp4", "mp4v"
        self._q: queue.Queue = queue.Queue(maxsize=4)
        self._err: list = []
        self._t = threading.Thread(target=self._run, daemon=True)
        self._t.start()

    def _run(self):
        while True:
            f = self._q.get()
            if f is None:
                return
            try:
                for w in self.writers:
                    w.write(f)
            except Exception as e:  # pragma: no cover - surfaced in close()
                self._err.append(e)

    def write(self, frame: np.ndarray):
        if self._err:
            raise self._err[0]
        self._q.put(frame)

    def close(self):
        self._q.put(None)
        self._t.join()
        for w in self.writers:
            w.release()
        if self._err:
            raise self._err[0]


def write_track_toml(path: Path, *, style, camera, objects, marker_size_m, dot_diameter_m, calibrated=True) -> str:
    """``track.toml`` through the tracker's own schema (:class:`rocklab.config.TrackConfig`).

    No frame rate: the film's container has each frame's time, and a rate written here would
    re-time any other film the config is reused on.

    ``calibrated``: write the camera matrix, distortion and plane homography
    (else the tracker works from the marker size / dot layout alone).
    ``objects``: list of dicts with ``id, kind`` and ``markers`` +
    ``marker_positions_m`` / ``dots`` / ``roi`` + ``size_m`` + ``theta0_rad``.
    Validated by parsing it back with :func:`rocklab.config.load_track_config`.
    """
    from .._io import write_text_atomic
    from ..config import TrackConfig, load_track_config

    d = {"video": {}, "targets": {"style": style}, "reference": {"level": "table"}, "objects": []}
    if calibrated:
        # A calibrated lab: lens model plus the plane homography (undistorted px -> m), so
        # tracked positions are absolute in the session's world frame and perspective does
        # not bias angles.
        d["video"]["camera_matrix"] = camera.K.tolist()
        d["video"]["dist_coeffs"] = camera.dist.tolist()
        d["reference"]["homography"] = camera.plane_homography().tolist()
    if style == "aruco":
        d["targets"].update(dictionary="DICT_4X4_50", marker_size_m=float(marker_size_m))
    elif style == "dots":
        d["targets"].update(dot_diameter_m=float(dot_diameter_m), dot_color="dark")
    for o in objects:
        e = {"id": o["id"], "kind": o["kind"]}
        for k in ("markers", "marker_positions_m", "marker_size_m", "dots", "roi", "size_m", "theta0_rad"):
            if o.get(k) is not None:
                v = o[k]
                e[k] = v.tolist() if isinstance(v, np.ndarray) else v
        d["objects"].append(e)
    text = TrackConfig.from_dict(d).to_toml(
        header=(
            "Tracking config written by 'rocklab synth' (schema: docs/track-toml.md).",
            "Object origins: block = centre of its front face, table = top centre of its front face.",
        )
    )
    write_text_atomic(path, text, stamp=False)  # an input of `rocklab run`, not an output
    load_track_config(path)  # round-trip check: the tracker can read what we wrote
    return text


def write_experiment_toml(path: Path, *, name, block, table_kind, imu_objects, column=None, video=True) -> str:
    """``experiment.toml`` for ``rocklab run``, through its schema (:class:`rocklab.config.ExperimentConfig`).

    ``block``: dict with ``id, b_m, h_m, mass_kg`` of the block the run fits;
    ``imu_objects``: object ids that have ``imu/<id>/`` logs; ``column``: a stacked column's
    ``objects`` (ids bottom to top), ``blocks`` (dicts with ``b_m, h_m, mass_kg``, written per
    level when they differ), ``cut_m`` and ``impacts`` (or None); ``video``: whether the session
    has a film (without one, every level is measured by its IMU).
    """
    from .._io import write_text_atomic
    from ..config import ExperimentConfig, SourceImu, SourceTable, SourceVideo

    path = Path(path)
    folder = path.parent
    bid = block["id"]
    col: dict = {}
    if column is not None:
        col = {"columns": tuple(column["objects"]), "column_cut_m": float(column["cut_m"])}
        col["column_impacts"] = int(column["impacts"])
        per = {k: tuple(float(b[k]) for b in column["blocks"]) for k in ("b_m", "h_m", "mass_kg")}
        if any(len(set(v)) > 1 for v in per.values()):
            col.update({f"column_{k}": v for k, v in per.items()})
        if not video:
            # the synthetic IMUs' y axis points away from the camera: -y turns counter-clockwise positive
            col.update(column_imus=tuple(folder / "imu" / o for o in column["objects"]), column_imu_axis="-y")
    if not video and table_kind != "none":
        raise InputError(
            "video=False with a moving table: the table IMU's clock can only be put on the blocks' through "
            "a film; render the video or use table='none'"
        )
    cfg = ExperimentConfig(
        path=path,
        name=name,
        b_m=float(block["b_m"]),
        h_m=float(block["h_m"]),
        mass_kg=float(block["mass_kg"]),
        block_id=None,
        primary="video" if video else "imu",
        video=SourceVideo(path=folder / "video.mkv", track_config=folder / "track.toml", object=bid) if video else None,
        imu=SourceImu(path=folder / "imu" / bid, axis="y")
        if bid in imu_objects and (video or column is None)
        else None,
        table=SourceTable() if table_kind == "none" else SourceTable(source="video", object="table"),
        truth=folder / "truth.csv",
        **col,
    )
    text = cfg.to_toml(header=("Experiment config written by 'rocklab synth' (schema: docs/experiment-toml.md).",))
    write_text_atomic(path, text, stamp=False)  # an input of `rocklab run`, not an output
    return text
