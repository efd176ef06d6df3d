"""The real films of the reviewers' kits, and their independent references (OpenCV only, no rocklab).

Used by ``benchmarks/real_films.py`` only, never by the package or CI. Each film is read from the
``fetch`` mirror of its public repository (``/work/.mirror/<owner>+<name>/repo``, override with
``$ROCKLAB_MIRRORS``) at the commit the kit used, or from ``$ROCKLAB_FILMS/<file name>``. Nothing
from these films is shipped: most of the repositories state no licence (review only).

The references are ports of the kits' scripts with the same parameters:

- review16 (``/work/scratch/review16``, session 16): ``ref_color.py`` (HSV threshold, the largest
  blob's centroid, PyAV decoding), ``ref_katie_cam.py`` (the bracket's red knob: the hand-held
  camera's shake), ``ref_arc.py`` (necros_ball: a circle fitted to the lower half of the red blob's
  outline, the sphere's centre); the katie pivot = knob + (1, 15) px read by hand on frame 0.
- ``/work/scratch/cylinder_ref/make_circle.py`` (session 18): trflorian_ball4's ball as the smallest
  circle round its green core and pale stripes, kept where its radius is within 6 % of its 11-frame
  running median (``eval_circle.py``).
- review18 (``/work/scratch/review18/reference.py``, session 18): dark bob / orange / red blobs, the
  background-median difference for sborquez_video1 (cv2.VideoCapture decoding).
- review19 (``/work/scratch/review19/reference.py``, session 19): the watch by ``HoughCircles``
  (kx_pendulum), the 2nd of the 4 right marker squares (chulminy), the yellow tape (nouyang_bounce).

The kits checked the references by hand (their READMEs list the frames and labels): juangomez
f0 (524.5, 249.5) vs (524.2, 249.1); katie's rod angle on 9 frames within 1.6 deg; sborquez_video2
6 labels within 2.0 px; sborquez_video1 3 labels within 3.4 px; adi_ball 4 within 1.2 px;
kx_pendulum 3 within 5.3 px; chulminy 2 within 0.5 px; trflorian's circle by eye on 22 frames.
"""

from __future__ import annotations

import math
import os
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np

MIRRORS = Path(os.environ.get("ROCKLAB_MIRRORS", "/work/.mirror"))
FILMS_DIR = os.environ.get("ROCKLAB_FILMS", "")


@dataclass(frozen=True)
class Film:
    """One real film as a kit ran it.

    ``boxes`` are drawn by eye on the first tracked frame (x, y, w, h px), one per object;
    ``rounding`` is the kit's way of perturbing them ("r16": review16's ``films.perturb``, clipped
    to the frame; "r18": review18/19's ``run_track.sh``); ``rule`` the kit's evaluation: "carried"
    (review16: the reference point or the first box centre carried by its translation, whichever is
    nearer), "pendulum" (review16 katie: the box centre carried by the rotation about the moving
    pivot, theta checked), "direct" (review18: the reference centroid, plain-view frames only),
    "relative" (review19: displacements from the first frame, plain-view frames only).
    """

    name: str
    repo: str
    commit: str
    path: str
    licence: str
    size: tuple[int, int]
    boxes: dict[str, tuple[int, int, int, int]]
    kind: str
    refs: tuple[str, ...]
    kit: str
    rule: str
    rounding: str
    data_set: str
    start: int = 0
    fps: float | None = None
    folder: bool = False
    hidden: tuple[tuple[int, int], ...] = ()
    occluder_x: tuple[tuple[int, int], ...] = ()
    min_area: float = 1.0
    pivot: tuple[float, float] | None = None
    notes: dict[str, str] = field(default_factory=dict)


R16 = "review16 (session 16)"
R18 = "review18 (session 18)"
R19 = "review19 (session 19)"
#: The kits' films. ``data_set``: "validation" unless a later session tuned a change on the film
#: (the CHANGELOG names its development films), then "development (what)".
FILMS = [
    Film("juangomez_pendulum", "juangomez177/Pendulum_Oscillatory_Motion", "9281de3f32438efd18d44567a9ec44d9458a9e2b",
         "pendulum.mp4", "none stated", (640, 352), {"obj": (495, 212, 61, 66)}, "red ornament on a string",
         ("color",), R16, "carried", "r16", "validation"),
    Film("katie_pendulum", "KatieButler/Non-Linear", "fab8bd78cb2aa82e49b139e37b8a477ea87a9196", "pendulum.MOV",
         "none stated", (568, 320), {"obj": (287, 205, 46, 73)}, "rigid pendulum, black disc, hand-held camera",
         ("color",), R16, "pendulum", "r16", "development (session 19: theta branch)"),
    Film("necros_ball", "necrosskull/opencv_pendulum", "92aaf6f3ad3de05701810d5dcfe781f3f84baa85", "ball.mp4",
         "MIT", (360, 640), {"obj": (63, 452, 44, 60)}, "wrapped red ball on a string", ("color", "arc"), R16,
         "carried", "r16", "validation", start=30, pivot=(306.0, 100.0)),
    Film("trflorian_ball4", "trflorian/ball-tracking-live-plot", "2c6270afbebfc0801e235f87fc8feb0c22da94c6",
         "media/ball4.mp4", "MIT", (1280, 720), {"obj": (840, 270, 110, 125)}, "green ball moved by hand",
         ("circle", "color"), R16, "carried", "r16", "development (session 19: round object's edge)", start=140),
    Film("arzafiruddin_bounce", "arzafiruddin/BouncingBall", "a7c94f599eef561848296a690cd3191e44d774cd",
         "bounceAmeen.avi", "none stated", (1920, 1080), {"obj": (934, 9, 99, 101)}, "green ball dropped, bounces",
         ("color",), R16, "carried", "r16", "development (session 19: falling smear)", start=60),
    Film("sborquez_video2", "sborquez/Pendulum-Tracking", "61a50eafec64ed3dc9355a7df587d745e6c07386",
         "videos/video2.mp4", "none stated", (480, 360), {"bob_l": (85, 246, 38, 38), "bob_r": (346, 246, 38, 38)},
         "two dark bobs, two panels", ("dark",), R18, "direct", "r18", "validation"),
    Film("izhan_ball", "IzhanAlam/Object-Tracking-With-Kalman-Filter", "d72e1e9a0838bf09c53c384a3eaff4bca80e4713",
         "ball.mp4", "none stated", (640, 480), {"ball": (272, 67, 84, 84)}, "orange ball dropped from a hand",
         ("orange",), R18, "direct", "r18", "development (session 19: plain ball's angle)", hidden=((0, 6),)),
    Film("sborquez_video1", "sborquez/Pendulum-Tracking", "61a50eafec64ed3dc9355a7df587d745e6c07386",
         "videos/video1.mp4", "none stated", (1280, 720), {"bob": (444, 578, 32, 24)}, "small blurred bob, green screen",
         ("median",), R18, "direct", "r18", "development (session 19: init's proposal)",
         occluder_x=((553, 597), (810, 840))),
    Film("adi_ball", "Adi-SRAM25/Trajectory", "6aad717ec0b7f4ba47afd817a9e0d37f75c131ee", "ball.mp4", "none stated",
         (720, 1280), {"ball": (432, 240, 53, 56)}, "small red ball thrown, bouncing", ("red",), R18, "direct", "r18",
         "development (session 19: plain ball's angle)", start=16, min_area=900),
    Film("kx_pendulum", "kXborg/Images", "da9264d7c4434ea9bfb03d1dbaa7deaf04259e79", "pendulum.mp4", "none stated",
         (1366, 576), {"watch": (573, 230, 132, 132)}, "pocket watch on a chain, panning camera", ("watch",), R19,
         "relative", "r18", "development (session 19: camera motion)"),
    Film("chulminy_img", "chulminy/Vision_Based_Vibration_Measurement", "f17044f54b90b0328411c192942f0c7748f02722",
         "img", "none (README: free for research)", (1300, 2046), {"m778": (758, 430, 46, 48)},
         "marker square on a vibrating K'nex model", ("square",), R19, "relative", "r18",
         "development (session 19: frame rate, camera motion)", fps=22.67, folder=True),
    Film("nouyang_bounce", "nouyang/howe299r", "5ec4e23a2d808272ec541df511f4cbf60bfa4cd9", "bounce.mp4", "MIT",
         (640, 360), {"finger": (45, 75, 395, 215)}, "robot finger poked, small oscillations", ("tape",), R19,
         "relative", "r18", "validation"),
]  # fmt: skip


def perturb(box, kind, size, rounding):
    """A box variant: "base", "shift+10" (+10 % of its size in x and y), "s120"/"s080" (scaled about its centre).

    "r16" is review16's ``films.perturb`` (rounded sizes first, clipped to the frame); "r18" is
    review18/19's ``run_track.sh`` (each side rounded at the end, not clipped).
    """
    x, y, w, h = box
    s = {"s120": 1.2, "s080": 0.8}.get(kind)
    if rounding == "r16":
        if kind == "shift+10":
            x, y = x + round(0.1 * w), y + round(0.1 * h)
        elif s:
            cx, cy = x + w / 2, y + h / 2
            w, h = round(w * s), round(h * s)
            x, y = round(cx - w / 2), round(cy - h / 2)
        W, H = size
        x0, y0 = max(0, x), max(0, y)
        return (x0, y0, min(W, x + w) - x0, min(H, y + h) - y0)
    fx, fy, fw, fh = float(x), float(y), float(w), float(h)
    if kind == "shift+10":
        fx, fy = fx + 0.1 * fw, fy + 0.1 * fh
    elif s:
        cx, cy = fx + fw / 2, fy + fh / 2
        fw, fh = fw * s, fh * s
        fx, fy = cx - fw / 2, cy - fh / 2
    return (round(fx), round(fy), round(fw), round(fh))


def git_dir(repo):
    """The mirror's git directory for ``owner/name`` (bare ``repo`` or ``repo/.git``), or None."""
    base = MIRRORS / repo.replace("/", "+") / "repo"
    for d in (base / ".git", base):
        if (d / "HEAD").exists():
            return d
    return None


def materialise(film, cache):
    """The film on disk: ``$ROCKLAB_FILMS/<name>`` if there, else taken out of its mirror into ``cache``.

    Returns the path, or None when neither the file nor the mirror is at hand.
    """
    leaf = film.name if film.folder else film.name + Path(film.path).suffix
    if FILMS_DIR and (Path(FILMS_DIR) / leaf).exists():
        return Path(FILMS_DIR) / leaf
    out = Path(cache) / leaf
    if out.exists():
        return out
    gd = git_dir(film.repo)
    if gd is None:
        return None
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(out.name + ".part")
    if film.folder:
        tmp.mkdir(exist_ok=True)
        arch = subprocess.run(
            ["git", "--git-dir", str(gd), "archive", film.commit, film.path], capture_output=True, check=True
        )
        subprocess.run(["tar", "-x", "-C", str(tmp), "--strip-components", str(film.path.count("/") + 1)],
                       input=arch.stdout, check=True)  # fmt: skip
    else:
        blob = subprocess.run(
            ["git", "--git-dir", str(gd), "show", f"{film.commit}:{film.path}"], capture_output=True, check=True
        )
        tmp.write_bytes(blob.stdout)
    tmp.rename(out)
    return out


def frames_av(path):
    """BGR frames in display order by PyAV (review16's decoder)."""
    import av

    with av.open(str(path)) as c:
        for fr in c.decode(video=0):
            yield fr.to_ndarray(format="bgr24")


def frames_cv(path):
    """BGR frames by OpenCV (review18/19's decoder); an image folder in name order."""
    p = Path(path)
    if p.is_dir():
        for f in sorted(p.glob("*.jpg")):
            yield cv2.imread(str(f))
        return
    cap = cv2.VideoCapture(str(p))
    while True:
        ok, fr = cap.read()
        if not ok:
            return
        yield fr


#: review16 ref_color.py's HSV ranges (hue ranges, S min, V min), search region, opening size
COLOR = {
    "juangomez_pendulum": dict(h=[(0, 10), (165, 180)], s=90, v=40, roi=None, open=3),
    "arzafiruddin_bounce": dict(h=[(40, 90)], s=80, v=30, roi=None, open=5),
    "katie_pendulum": dict(h=[(20, 40)], s=110, v=110, roi=(220, 150, 160, 170), open=1),
    "necros_ball": dict(h=[(0, 12), (165, 180)], s=70, v=40, roi=(0, 150, 360, 490), open=3),
    "trflorian_ball4": dict(h=[(35, 90)], s=50, v=40, roi=None, open=5),
}


def _color_mask(im, p):
    hsv = cv2.cvtColor(im, cv2.COLOR_BGR2HSV)
    m = np.zeros(im.shape[:2], np.uint8)
    for lo, hi in p["h"]:
        m |= cv2.inRange(hsv, (lo, p["s"], p["v"]), (hi, 255, 255))
    if p["roi"]:
        x, y, w, h = p["roi"]
        mm = np.zeros_like(m)
        mm[y : y + h, x : x + w] = m[y : y + h, x : x + w]
        m = mm
    if p["open"] > 1:
        m = cv2.morphologyEx(m, cv2.MORPH_OPEN, np.ones((p["open"], p["open"]), np.uint8))
    return m


def _circle_fit(pts):
    x, y = pts[:, 0].astype(float), pts[:, 1].astype(float)
    c = np.linalg.lstsq(np.column_stack((x, y, np.ones_like(x))), x**2 + y**2, rcond=None)[0]
    cx, cy = c[0] / 2, c[1] / 2
    return cx, cy, float(np.sqrt(c[2] + cx**2 + cy**2))


def ref_color(film, path, arc=False):
    """review16 ``ref_color.py`` (or, ``arc``, ``ref_arc.py``): per frame (x, y) of the largest blob, NaN if none."""
    p = COLOR[film.name]
    rows = []
    for im in frames_av(path):
        n, lab, st, cen = cv2.connectedComponentsWithStats(_color_mask(im, p))
        if n < 2:
            rows.append((np.nan, np.nan))
            continue
        i = 1 + int(np.argmax(st[1:, cv2.CC_STAT_AREA]))
        if not arc:
            rows.append((cen[i][0], cen[i][1]))
            continue
        cs, _ = cv2.findContours((lab == i).astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
        c = max(cs, key=cv2.contourArea)[:, 0, :].astype(float)
        rows.append(_circle_fit(c[c[:, 1] >= cen[i][1]])[:2])  # the lower half: the wrap never covers it
    return np.array(rows, float)


def ref_katie_knob(path):
    """review16 ``ref_katie_cam.py``: the bracket's red knob (x, y) per frame, the hand-held camera's shake."""
    rows = []
    for im in frames_av(path):
        hsv = cv2.cvtColor(im[0:80, 300:380], cv2.COLOR_BGR2HSV)
        m = cv2.inRange(hsv, (0, 120, 80), (10, 255, 255)) | cv2.inRange(hsv, (170, 120, 80), (180, 255, 255))
        n, lab, st, cen = cv2.connectedComponentsWithStats(m)
        i = 1 + int(np.argmax(st[1:, cv2.CC_STAT_AREA]))
        rows.append((cen[i][0] + 300, cen[i][1]))
    return np.array(rows, float)


def ref_trflorian_circle(path):
    """cylinder_ref ``make_circle.py`` + ``eval_circle.py``'s radius filter: (x, y) per frame, NaN where not kept."""
    out = []
    for f, img in enumerate(frames_cv(path)):
        if f < 140:
            out.append((np.nan, np.nan, np.nan))
            continue
        hsv = cv2.cvtColor(img, cv2.COLOR_BGR2HSV)
        g = cv2.inRange(hsv, (35, 50, 40), (90, 255, 255))
        pale = cv2.inRange(hsv, (30, 20, 120), (95, 255, 255))
        n, lab, st, _ = cv2.connectedComponentsWithStats(cv2.morphologyEx(g, cv2.MORPH_OPEN, np.ones((5, 5), np.uint8)))
        if n < 2:
            out.append((np.nan, np.nan, np.nan))
            continue
        core = lab == 1 + int(np.argmax(st[1:, 4]))
        both = cv2.morphologyEx((core | (pale > 0)).astype(np.uint8), cv2.MORPH_OPEN, np.ones((3, 3), np.uint8))
        _, lab2, _, _ = cv2.connectedComponentsWithStats(both)
        blob = (lab2 == int(np.bincount(lab2[core]).argmax())).astype(np.uint8)
        cnt = max(cv2.findContours(blob, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)[0], key=len)
        (x, y), r = cv2.minEnclosingCircle(cnt)
        out.append((round(x, 2), round(y, 2), round(r, 2)))  # the kit's circle.csv keeps 2 decimals
    a = np.array(out, float)
    r = a[:, 2]
    with np.errstate(all="ignore"):
        med = np.array([np.nanmedian(r[max(i - 5, 0) : i + 6]) if np.isfinite(r[max(i - 5, 0) : i + 6]).any() else np.nan
                        for i in range(len(r))])  # fmt: skip
        good = np.abs(r - med) <= 0.06 * med
    a[~good, :2] = np.nan
    return a[:, :2]


def _largest(mask, min_area, max_area=10**9, round_only=False):
    # review18's: the largest component of min_area..max_area; round_only: bbox aspect 0.6..1.6, fill >= 0.6
    n, _, st, cen = cv2.connectedComponentsWithStats(mask)
    best = None
    for i in range(1, n):
        a, w, h = st[i, cv2.CC_STAT_AREA], st[i, cv2.CC_STAT_WIDTH], st[i, cv2.CC_STAT_HEIGHT]
        if a < min_area or a > max_area:
            continue
        if round_only and not (0.6 <= w / h <= 1.6 and a >= 0.6 * w * h):
            continue
        if best is None or a > st[best, cv2.CC_STAT_AREA]:
            best = i
    if best is None:
        return (np.nan, np.nan, 0, -1, -1, -1, -1)
    return (cen[best][0], cen[best][1], int(st[best, cv2.CC_STAT_AREA]), *(int(v) for v in st[best, :4]))


def ref_review18(film, path):
    """review18 ``reference.py``: {object: array (n, 7) of x, y, area, bx, by, bw, bh} (area 0: not found)."""
    out: dict[str, list] = {o: [] for o in film.boxes}
    frames = list(frames_cv(path))
    ell = cv2.getStructuringElement
    if film.name == "sborquez_video1":
        bg = np.median(np.stack(frames[::3]).astype(np.int16), axis=0).astype(np.int16)
    for fr in frames:
        hsv = cv2.cvtColor(fr, cv2.COLOR_BGR2HSV)
        if film.name == "sborquez_video2":
            m = (hsv[..., 2] < 110).astype(np.uint8) * 255
            m[:150] = 0
            m[322:] = 0  # the black letterbox starts at y 324
            m = cv2.morphologyEx(m, cv2.MORPH_OPEN, ell(cv2.MORPH_ELLIPSE, (5, 5)))
            for name, x0, x1 in (("bob_l", 16, 247), ("bob_r", 253, 469)):  # black borders x<14, 249-250, >470
                mm = np.zeros_like(m)
                mm[:, x0:x1] = m[:, x0:x1]
                out[name].append(_largest(mm, 400, 1800, round_only=True))
        elif film.name == "izhan_ball":
            m = cv2.morphologyEx(
                cv2.inRange(hsv, (3, 150, 150), (22, 255, 255)), cv2.MORPH_OPEN, ell(cv2.MORPH_ELLIPSE, (7, 7))
            )
            out["ball"].append(_largest(m, 400))
        elif film.name == "sborquez_video1":
            m = (np.abs(fr.astype(np.int16) - bg).sum(axis=2) > 40).astype(np.uint8) * 255
            m[:480] = 0
            m[612:] = 0
            m[:, :130] = 0
            m[:, 815:] = 0  # the operator's hand moves at x >= 815
            out["bob"].append(_largest(cv2.morphologyEx(m, cv2.MORPH_OPEN, ell(cv2.MORPH_ELLIPSE, (3, 3))), 25, 700))
        else:  # adi_ball
            m = cv2.inRange(hsv, (0, 70, 40), (12, 255, 255)) | cv2.inRange(hsv, (165, 70, 40), (180, 255, 255))
            m[1000:] = 0  # the dark tile band and floor
            m[:200, 680:] = 0  # a red thing in the top right corner (not the ball)
            out["ball"].append(_largest(cv2.morphologyEx(m, cv2.MORPH_OPEN, ell(cv2.MORPH_ELLIPSE, (5, 5))), 150, 6000))
    return {k: np.array(v, float) for k, v in out.items()}


def _watch(frames):
    rows, prev = [], (639.5, 296.5)
    for fr in frames:
        g = cv2.medianBlur(cv2.cvtColor(fr, cv2.COLOR_BGR2GRAY), 5)
        c = cv2.HoughCircles(g, cv2.HOUGH_GRADIENT, dp=1, minDist=3, param1=80, param2=25, minRadius=50, maxRadius=80)
        if c is None:
            rows.append((np.nan, np.nan, 0, np.nan, np.nan, np.nan, np.nan))
            continue
        c = c[0]
        d = np.hypot(c[:, 0] - prev[0], c[:, 1] - prev[1])
        k = int(np.argmin(d))
        if d[k] > 120:
            rows.append((np.nan, np.nan, 0, np.nan, np.nan, np.nan, np.nan))
            continue
        near = c[np.hypot(c[:, 0] - c[k, 0], c[:, 1] - c[k, 1]) < 25]  # the blurred rim's spread of circles
        x, y, r = np.median(near, axis=0)
        prev = (x, y)
        rows.append((x, y, np.pi * r * r, x - r, y - r, 2 * r, 2 * r))
    return rows


def _squares(frames):
    rows = []
    for fr in frames:
        g = cv2.cvtColor(fr, cv2.COLOR_BGR2GRAY)[380:560]
        n, lab, st, _ = cv2.connectedComponentsWithStats((g > 100).astype(np.uint8))
        sq = []
        for j in range(1, n):
            bx, by, bw, bh, a = st[j]
            if 1200 <= a <= 3500 and 40 <= bw <= 60 and 40 <= bh <= 60:
                blob = (lab[by : by + bh, bx : bx + bw] == j).astype(np.uint8)
                cs, _ = cv2.findContours(blob, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
                filled = np.zeros_like(blob)
                cv2.drawContours(filled, cs, -1, 1, -1)
                M = cv2.moments(filled, True)
                sq.append((M["m10"] / M["m00"] + bx, M["m01"] / M["m00"] + by + 380, M["m00"], bx, by + 380, bw, bh))
        sq.sort()
        rows.append(sq[1] if len(sq) == 4 else (np.nan, np.nan, 0, np.nan, np.nan, np.nan, np.nan))
    return rows


def _tape(frames):
    rows = []
    for fr in frames:
        m = cv2.inRange(cv2.cvtColor(fr, cv2.COLOR_BGR2HSV), (22, 60, 120), (40, 255, 255))
        n, _, st, cen = cv2.connectedComponentsWithStats(cv2.morphologyEx(m, cv2.MORPH_OPEN, np.ones((3, 3), np.uint8)))
        j = 1 + int(np.argmax(st[1:, 4]))
        bx, by, bw, bh, a = st[j]
        rows.append((cen[j, 0], cen[j, 1], a, bx, by, bw, bh))
    return rows


def ref_review19(film, path):
    """review19 ``reference.py``: {object: array (n, 7) of x, y, area, bx, by, bw, bh} (area 0: not found)."""
    fn = {"kx_pendulum": _watch, "chulminy_img": _squares, "nouyang_bounce": _tape}[film.name]
    return {next(iter(film.boxes)): np.array(fn(frames_cv(path)), float)}


def references(film, path):
    """Every reference of ``film``: {label: {object: array (n, >= 2), x, y first}} and extras (katie's knob)."""
    if film.kit == R18:
        return {"centroid": ref_review18(film, path)}
    if film.kit == R19:
        return {film.refs[0]: ref_review19(film, path)}
    obj = next(iter(film.boxes))
    out = {}
    for label in film.refs:
        if label == "color":
            out["colour centroid"] = {obj: ref_color(film, path)}
        elif label == "arc":
            out["sphere (lower arc)"] = {obj: ref_color(film, path, arc=True)}
        elif label == "circle":
            out["enclosing circle"] = {obj: ref_trflorian_circle(path)}
    if film.rule == "pendulum":
        out["colour centroid"]["knob"] = ref_katie_knob(path)
    return out


def rot(a):
    """2x2 rotation matrix by ``a`` rad."""
    return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
