"""Real films, checked against an independent reference: frames ok, frames ok but wrong, boxes.

For each real film: the markerless tracker (``track_video``) from a box drawn round the ball and
from boxes perturbed round it (each side +-20 %, the centre +-10 %, seeded), against a script
that knows nothing of the tracker (``tests/_blob.py``'s ``silhouette_track``: the ball's whole
silhouette against the film's temporal median, in colour, and the smallest circle round it;
checked against frames labelled by hand, see its module). ``--blue`` uses the older reference
(the ball's blue half by an HSV threshold, 2.5-3.9 px off five of the nine hand labels). Printed per film and box: frames, frames ok, frames ok but wrong (the tracked point
more than 1 % of the frame width off the reference, after the median offset), the status counts,
the swing period from x_px against the reference's, and whether the ball's angle was flagged
unmeasurable (W-TRACK-THETA) or how many ok frames report one.

Development film (tune on it): ``../shared/data/video/pendulum_film2_vga.mp4``.
Validation films (never tuned on): the other take of the same scene at four resolutions,
``film1_{vga,sd,hd,fhd}.mp4`` of the public repository bartekpacia/pendulum (no licence stated,
so not shipped: put them in ``$ROCKLAB_FILMS``, default ``/tmp/verify-films``; skipped when absent).

TrackLab's ``pendulumDrag.mp4`` (AGPL-3.0, not shipped; in ``$ROCKLAB_FILMS`` too) is checked
against a bright blob on its black cloth instead (``tests/_blob.py``'s ``bright_blob_track``).

Run: ``python benchmarks/real_inputs.py [n_boxes [part of a file name]] [--blue]``.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from _blob import (  # noqa: E402
    blob_track,
    bright_blob_track,
    perturbed_boxes,
    silhouette_track,
    swing_period_s,
    wrong_ok,
)

from rocklab._diagnostics import collecting  # noqa: E402
from rocklab.config import TrackConfig
from rocklab.tracking import track_video
from rocklab.tracking.video._video import probe_video  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
FILMS_DIR = Path(os.environ.get("ROCKLAB_FILMS", "/tmp/verify-films"))
#: (set, path, box drawn round the ball in the first frame, x, y, w, h px)
FILMS = [
    ("development", ROOT.parent / "shared" / "data" / "video" / "pendulum_film2_vga.mp4", (310, 66, 70, 74)),
    *[
        ("validation", FILMS_DIR / f"film1_{r}.mp4", tuple(round(v * s) for v in (650, 290, 205, 220)))
        for r, s in (("vga", 310 / 1080), ("sd", 480 / 1080), ("hd", 720 / 1080), ("fhd", 1.0))
    ],
]
#: Films whose object is not the blue ball: (set, path, box, the object's centre in the first frame
#: for :func:`bright_blob_track`). TrackLab's pendulumDrag.mp4 (github.com/OpenPhysics/TrackLab,
#: AGPL-3.0, not shipped): a bob hanging still for a second, then shot into a fast swing.
BRIGHT_FILMS = [("validation", FILMS_DIR / "pendulumDrag.mp4", (313, 316, 20, 18), (323.0, 325.0))]


def run(path, box, ref, ref_scale):
    cfg = TrackConfig.from_dict(
        {
            "targets": {"style": "markerless"},
            "reference": {"level": "none"},
            "objects": [{"id": "ball", "roi": list(box)}],
        }
    )
    t0 = time.perf_counter()
    with collecting():
        res = track_video(path, cfg)
    dt = time.perf_counter() - t0
    tr = res["ball"]
    r = ref * ref_scale
    wrong, _ = wrong_ok(tr.x_px, tr.y_px, tr.ok, r, res.width_px)
    st, cnt = np.unique(tr.status, return_counts=True)
    x = np.where(tr.ok, tr.x_px, np.nan)
    try:
        T = swing_period_s(tr.t_s, x)
    except Exception:  # a track too broken to fit is reported as such
        T = np.nan
    # a ball's angle is not measurable (W-TRACK-THETA): finite angles on ok frames are reported as such
    theta = "flagged" if tr.theta_note else f"{int(np.isfinite(tr.theta_rad[tr.ok]).sum())} ok frames with an angle"
    return len(tr.status), int(tr.ok.sum()), int(wrong.sum()), dict(zip(st.tolist(), cnt.tolist())), T, dt, theta


def main(n_boxes=5, only="", blue=False):
    for kind, path, box, *start in FILMS + BRIGHT_FILMS:
        if only not in path.name:
            continue
        if not path.exists():
            print(f"{kind:11s} {path.name}: absent, skipped")
            continue
        info = probe_video(path)
        ref, fps, w_cv = blob_track(path)
        if start:  # not the blue ball: the bright blob against the film's median
            ref = bright_blob_track(path, start[0])
        elif not blue:  # large films are reduced to about 640 px for the median
            ref = silhouette_track(path, scale=min(1.0, 640.0 / w_cv))[0]
        scale = np.array([info.width_px / w_cv, 1.0])  # non-square pixels: the tracker resamples
        T_ref = swing_period_s(np.arange(len(ref)) / fps, ref[:, 0])
        print(f"{kind} {path.name} ({info.width_px}x{info.height_px}): reference period {T_ref:.5f} s")
        periods = []
        for i, b in enumerate([box, *perturbed_boxes(box, n_boxes, seed=1)]):
            n, ok, bad, st, T, dt, theta = run(path, b, ref, scale)
            periods.append(T)
            print(
                f"  box {i:2d} {b}: frames {n}, ok {ok} ({100 * ok / n:.2f} %), ok but wrong {bad}, "
                f"period {T:.5f} s ({1e2 * (T / T_ref - 1):+.3f} %), theta {theta}, {n / dt:.0f} frames/s, {st}"
            )
        p = np.array(periods)
        print(f"  period spread over boxes: {1e2 * (np.nanmax(p) - np.nanmin(p)) / np.nanmedian(p):.4f} %")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--blue"]
    main(int(args[0]) if args else 5, args[1] if len(args) > 1 else "", "--blue" in sys.argv)
