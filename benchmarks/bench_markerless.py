"""Markerless tracking speed at 1920x1080 (issue 13 target: >= 100 frames/s on 2 cores).

Baseline in the same process on the same frames: the plain OpenCV code a user writes for a
textured region: ``goodFeaturesToTrack`` in the first frame's region, pyramidal Lucas-Kanade
from the first frame to every frame, ``estimateAffinePartial2D`` with RANSAC for the pose.
Frames are rendered in memory (a textured block rotating by up to 10 deg and translating on a
textured wall, sensor noise), so decoding is not timed; both are timed with OpenCV on 1 thread
(per core) and on all threads. Accuracy of both against the rendered angle is printed too.
Then, decoding counted: the same frames played 4 times (a 9.6 s clip) as an H.264 file at a
camcorder's 17 Mbit/s, tracked by ``track_video`` (probe, decoding thread, tracking) against the
plain script reading the file with ``cv2.VideoCapture``.

Last, the cost of verifying every pose (issue 25: at most 15 % of the markerless speed): the
same tracker on the same frames with :class:`~rocklab.tracking.video.targets._verify.PoseVerifier`
accepting every pose unchecked, 1 thread; on the rendered frames and, when it is there, on the
real pendulum film of ``../shared`` (decoded to memory first). The verified and the unverified
tracker run side by side, a frame each in turn, timed in process CPU time, a few times; the
figure is the median of those pairs' costs, with their spread (on a machine loaded by other
processes, whole runs timed one after the other moved the figure from -8 to +30 %).
"""

from __future__ import annotations

import math
import time

import cv2
import numpy as np
from threadpoolctl import threadpool_limits

from rocklab.config import TrackConfig
from rocklab.tracking import track_frames

W, H, N = 1920, 1080, 120


def render(seed=0):
    rng = np.random.default_rng(seed)
    wall = cv2.GaussianBlur((rng.random((H, W)) * 255).astype(np.uint8), (0, 0), 9)
    wall = cv2.normalize(wall, None, 90, 160, cv2.NORM_MINMAX)
    tex = cv2.GaussianBlur((rng.random((420, 240)) * 255).astype(np.uint8), (0, 0), 4)
    tex = cv2.normalize(tex, None, 30, 230, cv2.NORM_MINMAX)
    t = np.arange(N) / 50.0
    theta = np.radians(10) * np.sin(2 * np.pi * t / 1.2)
    dx = 40 * np.sin(2 * np.pi * t / 0.9)
    frames = []
    cx, cy = W / 2, H / 2
    for th, x in zip(theta, dx):
        # rotation about the block's bottom-left corner (its pivot), then the shift
        M = cv2.getRotationMatrix2D((0.0, 420.0), math.degrees(th), 1.0)
        M[:, 2] += (cx - 120 + x, cy - 210)
        f = wall.copy()
        mask = cv2.warpAffine(np.full_like(tex, 255), M, (W, H))
        blk = cv2.warpAffine(tex, M, (W, H))
        f[mask > 128] = blk[mask > 128]
        f = np.clip(f + rng.normal(0, 1.5, f.shape), 0, 255).astype(np.uint8)
        frames.append(f)
    roi = (cx - 120 + 10, cy - 210 + 10, 220, 400)
    return frames, theta, roi


def grey_frames(path) -> list:
    """Every frame of the film at ``path`` as grey uint8 images (H, W), read as a user would with
    ``cv2.VideoCapture``."""
    cap = cv2.VideoCapture(str(path))
    got = []
    while True:
        ok, img = cap.read()
        if not ok:
            break
        got.append(cv2.cvtColor(img, cv2.COLOR_BGR2GRAY))
    cap.release()
    return got


def plain_opencv(frames, roi):
    x, y, w, h = (int(v) for v in roi)
    mask = np.zeros_like(frames[0])
    mask[y : y + h, x : x + w] = 255
    p0 = cv2.goodFeaturesToTrack(frames[0], 200, 0.01, 5, mask=mask)
    out = []
    for f in frames:
        p1, st, _ = cv2.calcOpticalFlowPyrLK(frames[0], f, p0, None, winSize=(21, 21), maxLevel=3)
        ok = st.ravel() == 1
        M, _ = cv2.estimateAffinePartial2D(p0[ok], p1[ok], method=cv2.RANSAC)
        out.append(-math.atan2(M[1, 0], M[0, 0]) if M is not None else np.nan)
    return np.array(out)


def ours(frames, roi):
    cfg = TrackConfig.from_dict(
        {"targets": {"style": "markerless"}, "reference": {"level": "none"}, "objects": [{"id": "b", "roi": list(roi)}]}
    )
    obs = [o for fr in track_frames(frames, cfg) for o in fr]
    return np.array([o.theta_rad for o in obs])


def main() -> None:
    frames, theta, roi = render()
    nt = cv2.getNumThreads()
    print(
        f"baseline: plain OpenCV (goodFeaturesToTrack + LK to the first frame + estimateAffinePartial2D), "
        f"same {N} frames {W}x{H}, same process"
    )
    for threads in sorted({1, nt}):
        cv2.setNumThreads(threads)
        res = {}
        for name, fn in (("rocklab markerless", ours), ("plain OpenCV", plain_opencv)):
            fn(frames[:3], roi)  # warm-up
            # per core: OpenCV and the BLAS under NumPy both on one thread
            with threadpool_limits(threads):
                t0 = time.perf_counter()
                th = fn(frames, roi)
                dt = time.perf_counter() - t0
            err = np.degrees(th - theta)
            res[name] = N / dt
            print(
                f"  {threads} thread(s) {name:>20}: {N / dt:7.1f} frames/s, theta RMS error "
                f"{np.sqrt(np.nanmean(err**2)):.4f} deg, {np.isfinite(th).sum()}/{N} frames"
            )
    cv2.setNumThreads(nt)
    decode_included(frames, theta, roi)
    verification_cost(frames, roi)


#: Times the rendered frames are played in the file: 480 frames, a 9.6 s clip (a free-rocking
#: test's length), so that opening and probing the file weigh as they do on real footage.
REPEAT = 4


def decode_included(frames, theta, roi) -> None:
    """The same frames as a camcorder's file (H.264, 17 Mbit/s): decoding counted, all threads."""
    import tempfile
    from pathlib import Path

    import av

    from rocklab.tracking import track_video

    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "film.mp4"
        with av.open(str(path), "w") as c:
            s = c.add_stream("libx264", rate=50)
            s.width, s.height, s.pix_fmt, s.bit_rate = W, H, "yuv420p", 17_000_000
            for f in frames * REPEAT:
                for pkt in s.encode(av.VideoFrame.from_ndarray(f, format="gray")):
                    c.mux(pkt)
            for pkt in s.encode():
                c.mux(pkt)
        cfg = TrackConfig.from_dict(
            {
                "targets": {"style": "markerless"},
                "reference": {"level": "none", "m_per_px": 1e-3},
                "objects": [{"id": "b", "roi": list(roi)}],
            }
        )

        def plain(p):
            return plain_opencv(grey_frames(p), roi)

        theta = np.tile(theta, REPEAT)
        print(
            f"decode included: the {N} frames played {REPEAT} times ({N * REPEAT} frames, "
            f"{N * REPEAT / 50:.1f} s) as H.264 1080p at 17 Mbit/s, {cv2.getNumThreads()} threads"
        )
        for name, fn in (
            ("rocklab track_video", lambda p: track_video(p, cfg)["b"].theta_rad),
            ("plain OpenCV", plain),
        ):
            t0 = time.perf_counter()
            th = np.asarray(fn(path))
            dt = time.perf_counter() - t0
            err = np.degrees(th - theta[: th.size])
            print(f"  {name:>20}: {th.size / dt:7.1f} frames/s, theta RMS error {np.sqrt(np.nanmean(err**2)):.4f} deg")


def _lockstep(frames, roi):
    """Process CPU time (s) of the markerless tracker over ``frames`` with pose verification and
    with every pose accepted unchecked: both trackers run side by side, one frame each in turn
    (which goes first alternates), so that a change of the machine's load between frames hits
    both alike."""
    from unittest import mock

    from rocklab.tracking.video.targets import _verify

    cfg = TrackConfig.from_dict(
        {"targets": {"style": "markerless"}, "reference": {"level": "none"}, "objects": [{"id": "b", "roi": list(roi)}]}
    )
    unchecked = [False]
    verify, confirm = _verify.PoseVerifier.verify, _verify.PoseVerifier.confirm

    def verify_or_not(self, *a, **k):
        return None if unchecked[0] else verify(self, *a, **k)

    def confirm_or_not(self, *a, **k):
        return None if unchecked[0] else confirm(self, *a, **k)

    runs = {False: track_frames(frames, cfg), True: track_frames(frames, cfg)}
    cpu = {False: 0.0, True: 0.0}
    with (
        mock.patch.object(_verify.PoseVerifier, "verify", verify_or_not),
        mock.patch.object(_verify.PoseVerifier, "confirm", confirm_or_not),
    ):
        for i in range(len(frames) + 1):  # one step more: what the tracker does after the last frame
            for off in (False, True) if i % 2 == 0 else (True, False):
                unchecked[0] = off
                t0 = time.process_time()
                next(runs[off], None)
                cpu[off] += time.process_time() - t0
    return cpu[False], cpu[True]


def verification_cost(frames, roi, pairs: int = 5) -> None:
    """Cost of pose verification, same process, same frames, 1 thread, ``pairs`` times: the
    verified and the unverified tracker run in lockstep, frame by frame (:func:`_lockstep`), timed
    in process CPU time (what other processes on a loaded machine change least); each pair's cost
    is ``1 - t_unverified / t_verified``, the share of the verified run's time that verification
    takes, and the figure is their median and spread.
    """
    from pathlib import Path

    films = [("rendered 1920x1080", frames, roi)]
    real = Path(__file__).resolve().parents[2] / "shared" / "data" / "video" / "pendulum_film2_vga.mp4"
    if real.exists():
        got = grey_frames(real)
        films.append((f"real pendulum film {got[0].shape[1]}x{got[0].shape[0]}", got, (310, 66, 70, 74)))
    else:
        print(f"  (real film not found at {real}: rendered frames only)")
    print(
        "verification cost: the same tracker with every pose accepted unchecked, 1 thread, "
        f"{pairs} pairs run frame by frame in lockstep, process CPU time; median of the pairs' costs [min-max]"
    )
    cv2.setNumThreads(1)
    for name, fr, r in films:
        costs, times = [], {"verified": [], "unverified": []}
        with threadpool_limits(1):
            ours(fr[:3], r)  # warm-up
            for _ in range(pairs):
                tv, tu = _lockstep(fr, r)
                times["verified"].append(tv)
                times["unverified"].append(tu)
                costs.append(100 * (1 - tu / tv))
        n = len(fr)
        v, u = n / np.median(times["verified"]), n / np.median(times["unverified"])
        print(
            f"  {name} ({n} frames): verified {v:7.1f} frames/s, unverified {u:7.1f} frames/s (medians), "
            f"verification costs {np.median(costs):.1f} % of the speed "
            f"[{min(costs):.1f}-{max(costs):.1f}; pairs: {', '.join(f'{c:.1f}' for c in costs)}]"
        )


def _nullcontext():
    from contextlib import nullcontext

    return nullcontext()


if __name__ == "__main__":
    main()
