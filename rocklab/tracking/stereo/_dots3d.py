"""Dot targets in two films: detection, tracking, clock offset, matching and triangulation.

1. **Detection**: bright targets on a dark background (retro-reflective dots
   under the rig's lights): a threshold halfway between the background and the
   brightest target, connected components, and an intensity-weighted centroid
   over each component's window with the background subtracted (sub-pixel).
2. **Tracking in each film**: the first frame's dots become tracks; every next
   frame's detections are assigned to the tracks' constant-velocity predictions
   (Hungarian assignment inside a gate), so no 3D is needed to follow them.
3. **Clock offset** (cameras without a shared trigger): a coarse whole-frame
   lag from cross-correlating the two films' image speed, refined to sub-frame
   by minimising the epipolar misfit of camera 2's tracks interpolated in time:
   moving targets leave their epipolar lines unless the clocks agree.
4. **Matching** of the two films' tracks along epipolar lines (Hungarian on the
   misfit over the whole film, so two dots on one epipolar line in one frame
   are told apart by the others), then **triangulation** (linear, OpenCV)
   with the reprojection error of each 3D point kept; points above the
   outlier limit are NaN.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from ..._errors import InputError, where
from ._calib import StereoRig
from ._epipolar import epi_distance, fundamental, undistorted
from ._setup import check_depth_in_front, check_film_order, check_unsynchronised

__all__ = [
    "detect_dots",
    "track_dots_2d",
    "DotTracks2D",
    "sync_offset_stereo",
    "SyncOffset",
    "match_tracks",
    "triangulate_tracks",
    "StereoPoints",
    "track_dots_stereo",
    "check_films",
]


def detect_dots(
    gray, min_area_px: int = 6, max_area_px: int = 20000, threshold: float | None = None, with_area: bool = False
):
    """Sub-pixel centres of bright dots in a grey image.

    Parameters
    ----------
    gray : ndarray, shape (H, W), uint8
    min_area_px, max_area_px : int
        Component areas accepted, px.
    threshold : float, optional
        Grey level; default halfway between the median (background) and the 99.99th percentile.

    with_area : bool
        Also return each dot's area, px (a merged pair of dots has about twice the area).

    Returns
    -------
    ndarray, shape (m, 2)
        (u, v) centres, px (and the areas, shape (m,), with ``with_area``).
    """
    import cv2

    g = np.asarray(gray)
    bg = float(np.median(g[::8, ::8]))
    # candidates on a 4x smaller picture (a 4-megapixel frame's components cost 30 ms, its quarter 1 ms);
    # each is then measured in its full-resolution window
    f = 4 if min(g.shape) >= 400 else 1
    small = cv2.resize(g, (g.shape[1] // f, g.shape[0] // f), interpolation=cv2.INTER_AREA) if f > 1 else g
    top = float(small.max()) if threshold is None else float(threshold)
    if threshold is None:
        if float(g.max()) - bg < 20:
            return (np.zeros((0, 2)), np.zeros(0)) if with_area else np.zeros((0, 2))
        threshold = bg + 0.5 * (float(g.max()) - bg)
    cand_thr = bg + 0.5 * (min(top, threshold) - bg) if f > 1 else threshold
    _, mask = cv2.threshold(small, cand_thr, 255, cv2.THRESH_BINARY)
    n, _, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
    out = []
    areas = []
    H, W = g.shape
    for k in range(1, n):
        x, y, w, h, _ = stats[k]
        x0, y0 = max(x * f - 3, 0), max(y * f - 3, 0)
        x1, y1 = min((x + w) * f + 3, W), min((y + h) * f + 3, H)
        win = g[y0:y1, x0:x1]
        m = (win > threshold).astype(np.uint8)
        nn, lab, st, _ = cv2.connectedComponentsWithStats(m, connectivity=8)
        for kk in range(1, nn):
            area = int(st[kk, cv2.CC_STAT_AREA])
            if not (min_area_px <= area <= max_area_px):
                continue
            xa, ya, wa, ha = st[kk, :4]
            xa0, ya0 = max(xa - 2, 0), max(ya - 2, 0)
            xa1, ya1 = min(xa + wa + 2, win.shape[1]), min(ya + ha + 2, win.shape[0])
            patch = win[ya0:ya1, xa0:xa1].astype(np.float64) - bg
            # only this dot's pixels and their rim (a neighbour in the same window stays out)
            own = cv2.dilate((lab[ya0:ya1, xa0:xa1] == kk).astype(np.uint8), np.ones((5, 5), np.uint8)) > 0
            patch[(patch < 0) | ~own] = 0.0
            sw = patch.sum()
            if sw <= 0:
                continue
            yy, xx = np.mgrid[y0 + ya0 : y0 + ya1, x0 + xa0 : x0 + xa1]
            out.append(((patch * xx).sum() / sw, (patch * yy).sum() / sw))
            areas.append(float(area))
    uv = np.asarray(out, float).reshape(-1, 2)
    return (uv, np.asarray(areas, float)) if with_area else uv


@dataclass(frozen=True)
class DotTracks2D:
    """Dots followed through one film.

    Attributes
    ----------
    uv_px : ndarray, shape (n_frames, n_tracks, 2)
        Image positions, px (NaN where the dot was not found).
    source : str
    """

    uv_px: np.ndarray
    source: str = ""

    @property
    def n_frames(self) -> int:
        return self.uv_px.shape[0]


def track_dots_2d(frames, source: str = "", gate_px: float = 25.0, progress=None) -> DotTracks2D:
    """Follow the first frame's dots through ``frames`` (an iterable of grey images).

    A track not found for a frame keeps its constant-velocity prediction and is
    NaN in that frame. Two dots that overlap in the image (an occlusion, or a
    target passing in front of another) make one blob of about twice the area:
    such a blob, and any detection within reach of two tracks' predictions, is
    given to neither, so tracks never swap identities through a crossing;
    detections that match no track are ignored.
    """
    from scipy.optimize import linear_sum_assignment

    rows = []
    last = vel = area = None
    blank = 0
    for i, gray in enumerate(frames):
        det, det_area = detect_dots(gray, with_area=True)
        if last is None:
            if det.shape[0] < 3:
                raise InputError(
                    f"{where(source)}first frame: {det.shape[0]} dot(s) found; need at least 3 bright "
                    "targets on a dark background in view at the start"
                )
            last, area = det, det_area
            vel = np.zeros_like(det)
            rows.append(det.copy())
            continue
        cur = np.full_like(last, np.nan)
        if not det.shape[0]:  # a frame without any dot (lost to a damaged packet): the tracks wait
            blank += 1
            rows.append(cur)
            if progress is not None:
                progress(1)
            continue
        # after blank frames the dots moved for that long: predict and search as far
        pred = last + vel * (1 + blank)
        if det.shape[0]:
            d = np.linalg.norm(pred[:, None, :] - det[None, :, :], axis=2)
            d = np.where(np.isfinite(d), d, 1e9)
            r, c = linear_sum_assignment(d)
            ok = d[r, c] < gate_px * (1 + blank)
            # a blob grown by half, or one that a second track could equally claim, is a merge: nobody's
            merged = det_area[c] > 1.5 * area[r]
            radius = np.sqrt(area[r] / np.pi)
            near = (d[:, c] < (2.0 * radius + 2.0)[None, :]).sum(axis=0) > 1
            ok &= ~merged & ~near
            cur[r[ok]] = det[c[ok]]
        seen = np.isfinite(cur).all(axis=1)
        vel = np.where(seen[:, None], (cur - last) / (1 + blank), vel)
        last = np.where(seen[:, None], cur, pred)
        blank = 0
        rows.append(cur)
        if progress is not None:
            progress(1)
    return DotTracks2D(np.stack(rows), source)


def _shift(uv, lag):
    """Tracks (n, k, 2) read ``lag`` frames later (sub-frame, linear; NaN outside)."""
    n = uv.shape[0]
    idx = np.arange(n) + lag
    i0 = np.floor(idx).astype(int)
    f = (idx - i0)[:, None, None]
    ok = (i0 >= 0) & (i0 + 1 < n)
    out = np.full_like(uv, np.nan)
    out[ok] = (1 - f[ok]) * uv[i0[ok]] + f[ok] * uv[i0[ok] + 1]
    exact = (i0 >= 0) & (i0 < n) & (np.abs(idx - i0) < 1e-12)
    out[exact] = uv[i0[exact]]
    return out


@dataclass(frozen=True)
class SyncOffset:
    """Clock offset of camera 2 against camera 1.

    Attributes
    ----------
    offset_frames : float
        Camera 2's frame ``i + offset_frames`` was exposed with camera 1's frame ``i``.
    offset_s : float
        How much later camera 2 exposes its frame ``i`` than camera 1 its frame ``i``, s
        (``-offset_frames / fps``).
    sigma_s : float
        1-sigma of the offset, s (from the curvature of the epipolar misfit).
    misfit_px : float
        RMS epipolar misfit at the offset, px.
    coarse_frames : int
        The whole-frame lag from cross-correlation.
    """

    offset_frames: float
    offset_s: float
    sigma_s: float
    misfit_px: float
    coarse_frames: int

    def to_dict(self) -> dict:
        return {
            "offset_frames": self.offset_frames,
            "offset_s": self.offset_s,
            "sigma_s": self.sigma_s,
            "misfit_px": self.misfit_px,
            "coarse_frames": self.coarse_frames,
        }


def _speed(uv):
    """Mean image speed over the tracks, px/frame (NaN-safe), shape (n,)."""
    v = np.linalg.norm(np.diff(uv, axis=0), axis=2)
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a frame without targets (lost): speed 0
        s = np.nanmean(np.where(np.isfinite(v), v, np.nan), axis=1)
    return np.nan_to_num(s)


def sync_offset_stereo(
    rig: StereoRig, tracks1: DotTracks2D, tracks2: DotTracks2D, pairs, fps: float, max_lag_frames: int = 50
) -> SyncOffset:
    """The offset of camera 2's clock against camera 1's (see the module doc, step 3).

    ``pairs`` are matched track indices ``(i1, i2)`` (see :func:`match_tracks`).
    """
    from scipy.optimize import minimize_scalar

    s1, s2 = _speed(tracks1.uv_px), _speed(tracks2.uv_px)
    n = min(s1.size, s2.size)
    a, b = s1[:n] - s1[:n].mean(), s2[:n] - s2[:n].mean()
    lags = np.arange(-max_lag_frames, max_lag_frames + 1)
    cc = [np.dot(a[max(0, -k) : n - max(0, k)], b[max(0, k) : n - max(0, -k)]) for k in lags]
    coarse = int(lags[int(np.argmax(cc))])
    i1, i2 = np.asarray(pairs, int).T
    F = fundamental(rig)
    u1 = undistorted(rig, 1, tracks1.uv_px[:, i1].reshape(-1, 2)).reshape(-1, len(i1), 2)
    u2 = undistorted(rig, 2, tracks2.uv_px[:, i2].reshape(-1, 2)).reshape(-1, len(i2), 2)
    moving = np.r_[_speed(tracks1.uv_px[:, i1]) > 0.05, False]

    def misfit(lag):
        d = epi_distance(F, u1[moving], _shift(u2, lag)[moving])
        return float(np.sqrt(np.nanmean(d**2)))

    r = minimize_scalar(misfit, bounds=(coarse - 1.5, coarse + 1.5), method="bounded", options={"xatol": 1e-4})
    lag = float(r.x)
    h = 0.05
    f0, fp, fm = misfit(lag), misfit(lag + h), misfit(lag - h)
    curv = (fp - 2 * f0 + fm) / h**2
    # misfit^2 ~ noise^2 + c (lag - lag0)^2: sigma of the minimum from the noise level and the curvature
    n_obs = max(int(np.isfinite(u1[moving]).all(axis=2).sum()), 1)
    sigma = math.sqrt(max(f0, 1e-9) / max(curv * f0, 1e-12) / n_obs) if curv > 0 else float("nan")
    return SyncOffset(lag, -lag / fps, sigma / fps, f0, coarse)


def match_tracks(rig: StereoRig, tracks1: DotTracks2D, tracks2: DotTracks2D, lag: float = 0.0, max_px: float = 2.0):
    """Pairs ``(i1, i2)`` of tracks that are one target, by the median epipolar misfit over the film.

    Returns
    -------
    pairs : ndarray, shape (k, 2) int
    misfit_px : ndarray, shape (k,)
    """
    from scipy.optimize import linear_sum_assignment

    F = fundamental(rig)
    n1, n2 = tracks1.uv_px.shape[1], tracks2.uv_px.shape[1]
    u1 = undistorted(rig, 1, tracks1.uv_px.reshape(-1, 2)).reshape(-1, n1, 2)
    u2 = undistorted(rig, 2, _shift(tracks2.uv_px, lag).reshape(-1, 2)).reshape(-1, n2, 2)
    n = min(u1.shape[0], u2.shape[0])
    step = max(1, n // 200)
    d = epi_distance(F, u1[:n:step, :, None, :], u2[:n:step, None, :, :])  # (frames, n1, n2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        cost = np.nanmedian(d, axis=0)
    cost = np.where(np.isfinite(cost), cost, 1e6)
    # still targets on one epipolar line match any of each other equally well over time; the wrong pairs
    # triangulate to phantoms far in front of or behind the scene, so depth breaks the tie
    cand = cost < max_px
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        m1 = np.nanmedian(u1[:n], axis=0)
        m2 = np.nanmedian(u2[:n], axis=0)
    ii, jj = np.nonzero(cand)
    if ii.size:
        import cv2

        P1, P2 = rig.projection_matrices()
        h = cv2.triangulatePoints(P1, P2, m1[ii].T.astype(float), m2[jj].T.astype(float))
        z = np.full(cost.shape, np.nan)
        z[ii, jj] = h[2] / h[3]
        unique = cand & (cand.sum(axis=1, keepdims=True) == 1) & (cand.sum(axis=0, keepdims=True) == 1)
        zs = z[unique] if unique.any() else z[cand]
        zs = zs[np.isfinite(zs) & (zs > 0)]
        if zs.size:
            z_ref = float(np.median(zs))
            with np.errstate(invalid="ignore", divide="ignore"):
                pen = np.where(z > 0, 10.0 * np.abs(np.log(z / z_ref)), 1e3)
            cost = np.where(cand, cost + np.nan_to_num(pen, nan=1e3), cost)
    r, c = linear_sum_assignment(cost)
    base = np.where(np.isfinite(cost), cost, 1e6)
    ok = cand[r, c]
    return np.column_stack([r[ok], c[ok]]), base[r[ok], c[ok]]


@dataclass(frozen=True)
class StereoPoints:
    """Triangulated targets.

    Attributes
    ----------
    t_s : ndarray, shape (n,)
        Camera 1's frame times, s.
    xyz_m : ndarray, shape (n, k, 3)
        Positions in camera 1's axes, m (NaN where not seen by both or rejected).
    reproj_px : ndarray, shape (n, k)
        RMS reprojection error over the two views, px.
    pairs : ndarray, shape (k, 2)
    sync : SyncOffset or None
    notes : tuple of str
    labels : tuple of str or None
        Target names when the targets carry them (ArUco corners ``M<id>c<k>``); None for dots.
    """

    t_s: np.ndarray
    xyz_m: np.ndarray
    reproj_px: np.ndarray
    pairs: np.ndarray
    sync: SyncOffset | None = None
    notes: tuple = field(default=())
    labels: tuple | None = None


def triangulate_tracks(
    rig: StereoRig,
    tracks1: DotTracks2D,
    tracks2: DotTracks2D,
    pairs,
    lag: float,
    fps: float,
    max_reproj_px: float = 1.0,
) -> StereoPoints:
    """3D positions of the matched tracks, camera 2 read at ``lag`` frames (sub-frame) after camera 1."""
    import cv2

    i1, i2 = np.asarray(pairs, int).T
    n = tracks1.n_frames
    a = undistorted(rig, 1, tracks1.uv_px[:, i1].reshape(-1, 2))
    b = undistorted(rig, 2, _shift(tracks2.uv_px[:, i2], lag)[:n].reshape(-1, 2))
    if b.shape[0] < a.shape[0]:
        b = np.vstack([b, np.full((a.shape[0] - b.shape[0], 2), np.nan)])
    P1, P2 = rig.projection_matrices()
    ok = np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1)
    X = np.full((a.shape[0], 3), np.nan)
    err = np.full(a.shape[0], np.nan)
    if ok.any():
        h = cv2.triangulatePoints(P1, P2, a[ok].T, b[ok].T)
        Xo = (h[:3] / h[3]).T
        X[ok] = Xo
        pa = P1 @ np.vstack([Xo.T, np.ones(len(Xo))])
        pb = P2 @ np.vstack([Xo.T, np.ones(len(Xo))])
        ea = np.linalg.norm(pa[:2] / pa[2] - a[ok].T, axis=0)
        eb = np.linalg.norm(pb[:2] / pb[2] - b[ok].T, axis=0)
        err[ok] = np.sqrt(0.5 * (ea**2 + eb**2))
    bad = ~(err <= max_reproj_px)
    X[bad] = np.nan
    k = len(i1)
    return StereoPoints(np.arange(n) / fps, X.reshape(n, k, 3), err.reshape(n, k), np.asarray(pairs, int))


def check_films(film1, film2, rig: StereoRig, fps: float | None = None) -> float:
    """The common frame rate of two films, or :class:`InputError` when they cannot be one test of ``rig``."""
    from ..video import probe_video

    from ..video._checks import check_mirrored

    i1, i2 = probe_video(film1), probe_video(film2)
    for info, film in ((i1, film1), (i2, film2)):
        check_mirrored(info, film)
        if (info.width_px, info.height_px) != tuple(rig.size):
            raise InputError(
                f"{where(film)}frame size {info.width_px}x{info.height_px} differs from the "
                f"calibration's {rig.size[0]}x{rig.size[1]}; calibrate with films of this camera mode"
            )
        if fps is None and info.frame_times_s is not None and info.variable_rate and not info.n_dropped:
            # frames are paired by their slot on one constant clock (a dropped frame is an empty
            # slot); a variable rate has no slots
            d = np.diff(info.frame_times_s)
            at = float(info.frame_times_s[int(np.argmax(np.abs(d - np.median(d))))])
            raise InputError(
                f"{where(film)}the camera has a variable frame rate (first irregular interval after "
                f"t = {at:.4f} s); stereo pairs the two films frame by frame at one rate: film at a "
                "fixed rate, or give --fps if the container's times are wrong"
            )
    rate1 = fps or i1.fps
    rate2 = fps or i2.fps
    if not rate1:
        raise InputError(
            f"{where(film1)}the film has no frame rate (an image folder has one only from its timestamps.csv); give --fps"
        )
    if fps is None and rate2 and abs(rate1 - rate2) > 1e-3 * rate1:
        raise InputError(
            f"{where(film2)}{rate2:.6g} frames/s but {film1} has {rate1:.6g}; the two cameras must run "
            "at one rate (give --fps if a container is wrong)"
        )
    if abs(i1.n_frames - i2.n_frames) > max(5, 0.05 * max(i1.n_frames, i2.n_frames)):
        raise InputError(
            f"{where(film2)}{i2.n_frames} frames but {film1} has {i1.n_frames}: the films must cover "
            "the same test (trim them to the same start and length)"
        )
    return float(rate1)


def track_dots_stereo(
    film1, film2, rig: StereoRig, fps: float | None = None, sync: bool = True, progress: bool = False
) -> StereoPoints:
    """Dots of two films to 3D points in camera 1's axes (the steps of the module doc).

    Parameters
    ----------
    film1, film2 : path-like
        The two cameras' films of the test.
    rig : StereoRig
    fps : float, optional
        Frame rate, Hz (default: the containers'; they must agree).
    sync : bool
        Estimate the clock offset (else the films are taken as triggered together).
    progress : bool
        A progress bar on stderr.

    Returns
    -------
    StereoPoints
    """
    from ..video import probe_video
    from ._calib import frames_by_index, warn_lost

    rate1 = check_films(film1, film2, rig, fps)
    lost: list = []
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(
            total=probe_video(film1).n_frames + probe_video(film2).n_frames,
            unit="frame",
            desc="stereo",
            file=__import__("sys").stderr,
        )
    from concurrent.futures import ThreadPoolExecutor

    # one film per thread: decoding and the detector's OpenCV calls release the GIL, so two cores work
    with ThreadPoolExecutor(max_workers=2) as ex:
        jobs = [
            ex.submit(track_dots_2d, frames_by_index(f, lost), str(f), progress=bar.update if bar else None)
            for f in (film1, film2)
        ]
        t1, t2 = (j.result() for j in jobs)
    warn_lost(lost)
    if bar:
        bar.close()
    pairs, _ = match_tracks(rig, t1, t2, 0.0, max_px=5.0)
    if len(pairs) < 3:
        raise InputError(
            f"{where(film1)}only {len(pairs)} dot(s) match along epipolar lines with {film2}; check that "
            "the calibration belongs to these cameras and both see the targets"
        )
    check_film_order(rig, t1.uv_px[:, pairs[:, 0]], t2.uv_px[:, pairs[:, 1]], film1, film2)
    so = None
    lag = 0.0
    if sync:
        so = sync_offset_stereo(rig, t1, t2, pairs, rate1)
        lag = so.offset_frames
        pairs, _ = match_tracks(rig, t1, t2, lag)
    else:
        check_unsynchronised(sync_offset_stereo(rig, t1, t2, pairs, rate1), film1, film2)
    pts = triangulate_tracks(rig, t1, t2, pairs, lag, rate1)
    check_depth_in_front(pts.xyz_m, film1, film2)
    return StereoPoints(pts.t_s, pts.xyz_m, pts.reproj_px, pts.pairs, so, pts.notes, None)
