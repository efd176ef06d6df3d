"""Synthetic-session speed: rendering and writing at 1920x1080, 50 fps.

Issue 4 / synth brief: a 10 s, 50 fps, 1920x1080 session should take well
under a minute on one core. Baseline in the same process: only encoding the
same number of noisy grey frames to FFV1 + mp4v (the floor any renderer pays
for writing the two videos). Printed: render-only frames/s, full-session
frames/s, the ratio full / encode-only, and the extrapolated time of a 10 s
session. CPU time of this process is printed too (the encoder thread
overlaps with rendering on two cores).
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import cv2
import numpy as np

from rocklab.synth import synth_session
from rocklab.synth._scene import build_scene

SIZE = (1920, 1080)
FPS = 50.0
DURATION_S = 2.0
N = int(DURATION_S * FPS)


def encode_only(folder: Path) -> float:
    rng = np.random.default_rng(0)
    base = np.full(SIZE[::-1], 140, np.uint8)
    frames = [cv2.add(base, rng.normal(0, 1.0, base.shape).round().astype(np.int16), dtype=cv2.CV_8U) for _ in range(4)]
    t = time.perf_counter()
    ws = [
        cv2.VideoWriter(str(folder / "e.mkv"), cv2.VideoWriter_fourcc(*"FFV1"), FPS, SIZE, isColor=False),
        cv2.VideoWriter(str(folder / "e.mp4"), cv2.VideoWriter_fourcc(*"mp4v"), FPS, SIZE, isColor=False),
    ]
    for i in range(N):
        for w in ws:
            w.write(frames[i % 4])
    for w in ws:
        w.release()
    return time.perf_counter() - t


def render_only() -> tuple[float, float]:
    kw = dict(
        seed=0,
        blocks=1,
        table="none",
        fps=FPS,
        size=SIZE,
        targets="aruco",
        duration_s=DURATION_S,
        occlusion=None,
        rolling_shutter=False,
        block=None,
        restitution="constant",
        eta=0.75,
        theta0_rad=None,
        record=None,
        table_amplitude_m=0.045,
        table_period_s=0.6,
        table_stroke_m=0.05,
        exposure_s=None,
        noise_dn=1.0,
        distortion=True,
    )
    t = time.perf_counter()
    scene = build_scene(**kw)
    r = scene.renderer()
    setup = time.perf_counter() - t
    t = time.perf_counter()
    for i in range(N):
        r.render(i / FPS)
    return setup, time.perf_counter() - t


def main():
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        synth_session(d / "warm", seed=0, size=(160, 90), duration_s=0.2)  # numba/imports warm-up
        enc = encode_only(d)
        setup, ren = render_only()
        c0, t0 = time.process_time(), time.perf_counter()
        s = synth_session(d / "full", seed=0, size=SIZE, fps=FPS, duration_s=DURATION_S)
        full, cpu = time.perf_counter() - t0, time.process_time() - c0
    print(
        f"{N} frames {SIZE[0]}x{SIZE[1]}: encode-only {N / enc:.1f} frames/s, render-only "
        f"{N / ren:.1f} frames/s (+{setup:.1f} s scene set-up), full session {N / full:.1f} frames/s "
        f"(wall {full:.1f} s, CPU {cpu:.1f} s, mean sub-frames {s.meta['video']['mean_subframes']:.2f})"
    )
    per_frame = (full - setup) / N
    print(
        f"ratio full / encode-only: {full / enc:.2f}; extrapolated 10 s session: "
        f"{setup + 500 * per_frame:.0f} s wall here, <= {500 * cpu / N:.0f} s of CPU "
        "(CPU per frame including set-up; the wall time of one idle core)"
    )


if __name__ == "__main__":
    main()
