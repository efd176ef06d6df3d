"""Video tracking core: a streaming per-frame tracker and the file wrapper.

:func:`track_frames` works on any iterator of grey images and yields, per
frame, one :class:`Observation` per object in *plane units* (pixels about the
image centre, y up, or metres with a homography). :func:`assemble_tracks`
turns them into metres and a levelled angle once, at the end, where the scale
(median over all frames) and the level (median table angle) are known.
:func:`track_video` is the thin file wrapper.
"""

from __future__ import annotations

import collections
import math
import os
from dataclasses import dataclass, field, replace

import numpy as np

from ..._blas import one_blas_thread
from ..._diagnostics import warn
from ..._errors import InputError
from .._corrections import apply_corrections, load_corrections
from ._camera_motion import FrameSampler, check_camera
from ._checks import (
    check_cuts,
    is_cut,
    check_frames,
    check_rate,
    interpolate,
    last_seen,
    look,
    lost_status,
    region_leaves,
    ring_look,
    settle_latches,
    settle_reacquisitions,
    small_grey,
    tee,
)
from ...config import FPS_PLACEHOLDER_NOTE, TrackConfig
from ._camera_model import PlaneMap, fit_similarity
from .targets import make_detector
from .targets._observability import angle_free_objects, angle_note, warn_theta, warn_unmatched_angles
from ._plane import make_plane_map
from ._table_track import TableMotion, table_motion

__all__ = [
    "Observation",
    "ObjectTrack",
    "TrackResult",
    "track_frames",
    "assemble_tracks",
    "track_video",
    "make_plane_map",
    "TRACK_COLUMNS",
]

from ...series import TRACK_COLUMNS  # noqa: E402 - the tracks.csv layout, defined once in rocklab.series

#: Largest believable rotation between consecutive frames (rad); bigger steps are outliers.
MAX_STEP_RAD = 0.35


@dataclass(frozen=True, slots=True)
class Observation:
    """One object in one frame, in plane units (before scale and levelling).

    Attributes
    ----------
    frame : int
    object : str
    X, Y : float
        Object-frame origin in the plane (px about the image centre, y up; or m).
    theta_rad : float
        Counter-clockwise angle in the (unlevelled) plane.
    sigma_theta_rad : float
    scale : float
        Plane units per object unit (px/m for metric targets).
    rms : float
        Fit residual per coordinate, plane units.
    quality : float
        0..1: fraction of expected points found / (1 + residual / (0.2 % of the point spread)).
    status : str
        "ok" or the reason the values are NaN: "occluded" (the target's last
        window lost its contrast), "blur" (lost its fine detail but kept its
        contrast), "lost" (otherwise), "low_quality"; after assembly also
        "outlier" (an impossible jump), "latch" (on pixels another object's tracker keeps) or
        "interpolated" (when asked).
    metric : bool
        Whether ``scale`` is plane units per metre.
    plane : str
        Source of the image -> plane mapping ("image": centred pixels; "homography",
        "board", "table": metres).
    angle_dropped : bool
        The angle of this frame alone is not a measurement (NaN), the object's angle otherwise is.
    fit_theta_rad : float
        The angle the reported point was carried by, rad (the fitted pose's, also where
        ``theta_rad`` is NaN: an angle held or not reported); NaN when not fitted.
    """

    frame: int
    object: str
    X: float
    Y: float
    theta_rad: float
    sigma_theta_rad: float
    scale: float
    rms: float
    quality: float
    status: str
    metric: bool = True
    plane: str = "image"
    angle_dropped: bool = False
    fit_theta_rad: float = math.nan


def track_frames(frames, config: TrackConfig, plane_map: PlaneMap | None = None, levers: dict | None = None):
    """Track every configured object through a stream of frames.

    A frame's observations are held back while an object's angle awaits a verdict (the detector's
    ``theta_pending``: a round object whose texture, its shading taken out, tells no angle, seen on
    too few frames yet for its views to judge); if the film ends so, the held frames carry no
    angle for it, which drops its angle on every frame (:func:`_object_series`), with W-TRACK-THETA.

    Parameters
    ----------
    frames : iterable of (index, gray) or of gray images
        Grey uint8 images, shape (height, width); bare images are numbered from 0.
    config : TrackConfig
    plane_map : PlaneMap, optional
        Default: built from ``config`` and the first frame.
    levers : dict, optional
        Filled once the frames are all tracked: object id -> its disk's lever for
        :func:`assemble_tracks` (objects whose angle was found unmeasurable on the way, a round
        outline: the frames before report the point the texture's angle turned).

    Yields
    ------
    list of Observation
        One per object (config order) for each frame.
    """
    held: list = []
    det = None
    for obs, det in _observed(frames, config, plane_map, levers):
        if _pending_angles(config, det):
            held.append(obs)
            continue
        yield from held
        held = []
        yield obs
    pending = _pending_angles(config, det)
    for oid, (why, frame) in pending.items():
        warn_theta(config, oid, why, frame)
    for obs in held:
        # the angle is dropped as a whole (every frame's, the ones before the hold too), not one
        # frame's alone: a frame held after a per-frame drop must not shield the rest
        yield [
            replace(o, theta_rad=math.nan, sigma_theta_rad=math.nan, angle_dropped=False) if o.object in pending else o
            for o in obs
        ]


def _pending_angles(config, det) -> dict:
    """Object id -> (why, frame) of the objects whose angle awaits a verdict (``theta_pending``)."""
    if det is None or not hasattr(det, "theta_pending"):
        return {}
    return {o.id: p for o in config.objects if (p := det.theta_pending(o.id)) is not None}


def _observed(frames, config: TrackConfig, plane_map: PlaneMap | None = None, levers: dict | None = None):
    """:func:`track_frames`' work, frame by frame (same parameters).

    Yields
    ------
    (list of Observation, detector)
        One observation per object (config order) for each frame, and the detector (its state
        after the frame).
    """
    det = None
    min_q = config.targets.min_quality
    boxes, sharp_ref = {}, {}
    rings, seen = {}, {}  # object -> at its last ok frame: the ring round its window; (frame, centre, speed)
    prev, steps, cuts, indices = None, [], [], []  # the whole frame's changes, cuts to another shot
    scales = {}  # object -> recent scales of complete detections
    for k, item in enumerate(frames):
        idx, gray = item if isinstance(item, tuple) else (k, item)
        if gray.ndim != 2:
            raise InputError("track_frames: frames must be grey images of shape (height, width)")
        if det is None:
            if plane_map is None:
                plane_map = make_plane_map(config, gray.shape[1], gray.shape[0], gray)
            det = make_detector(config, plane_map, gray)
            free = angle_free_objects(config, det)
        small = small_grey(gray)
        cut = False
        if prev is not None:
            steps.append(float(np.mean(np.abs(small - prev))))
            cut = is_cut(prev, small)
            if cut:
                cuts.append(idx)
        prev = small
        indices.append(idx)
        with one_blas_thread():
            dets = det.detect(gray, idx)
        for o in config.objects:  # an angle found unmeasurable on the way (a round outline, once seen)
            if o.id not in free and hasattr(det, "theta_note") and (why := det.theta_note(o.id)) is not None:
                free[o.id] = why
                warn_theta(config, o.id, why, idx)
        obs = []
        for o in config.objects:
            d = dets.get(o.id)
            if d is not None and len(d.img_pts) >= 2:
                q = plane_map.to_plane(d.img_pts)
                fixed = None
                if d.metric and plane_map.source != "image":
                    fixed = 1.0  # metres on both sides: a rigid fit
                elif len(q) < d.n_expected and scales.get(o.id):
                    fixed = float(np.median(scales[o.id]))  # partial view: keep the known scale
                f = fit_similarity(d.obj_pts, q, scale=fixed)
                if fixed is None and len(q) == d.n_expected:
                    scales.setdefault(o.id, collections.deque(maxlen=51)).append(f.scale)
                spread = math.sqrt(np.sum((q - q.mean(0)) ** 2) / len(q))
                qual = (len(q) / d.n_expected) / (
                    1.0 + f.rms / (0.002 * spread + 1e-12) if d.score is None else 1.0 / max(d.score, 1e-12)
                )
                if qual < min_q:
                    obs.append(
                        Observation(
                            idx, o.id, *(np.nan,) * 4, f.scale, f.rms, qual, "low_quality", d.metric, plane_map.source
                        )
                    )
                    continue
                th, sig = (f.theta_rad, d.combined_sigma(f.sigma_theta_rad))
                if o.id in free or getattr(d, "theta_why", None) is not None:
                    th, sig = np.nan, np.nan
                obs.append(
                    Observation(
                        idx,
                        o.id,
                        float(f.t[0]),
                        float(f.t[1]),
                        th,
                        sig,
                        f.scale,
                        f.rms,
                        qual,
                        "ok",
                        d.metric,
                        plane_map.source,
                        # an object's angle dropped as a whole is not one frame's alone
                        o.id not in free and getattr(d, "theta_why", None) is not None,
                        float(f.theta_rad),
                    )
                )
                u, v = d.img_pts[:, 0], d.img_pts[:, 1]
                box = (int(max(u.min(), 0)), int(max(v.min(), 0)), int(u.max()) + 1, int(v.max()) + 1)
                boxes[o.id] = box
                rings[o.id] = ring_look(gray, box)
                seen[o.id] = last_seen(seen.get(o.id), idx, d.img_pts.mean(axis=0))
                if o.id not in sharp_ref or k % 25 == 0:
                    sharp_ref[o.id] = look(gray, box)
            else:
                status = "lost"
                why = det.lost_reason(o.id) if hasattr(det, "lost_reason") else None
                if why is not None:
                    status = why  # the pose was fitted but does not re-explain the image
                elif o.id in boxes and not cut:  # a cut shows another scene: only "lost" is true
                    status = lost_status(gray, boxes[o.id], sharp_ref.get(o.id), rings[o.id], seen[o.id], idx)
                obs.append(Observation(idx, o.id, *(np.nan,) * 7, status, getattr(d, "metric", True), plane_map.source))
        yield obs, det
    check_cuts(steps, cuts, indices, config.source or "the film")
    warn_unmatched_angles(config, det)
    if levers is not None and hasattr(det, "disk_lever"):
        levers.update({o.id: lv for o in config.objects if (lv := det.disk_lever(o.id)) is not None})


@dataclass(frozen=True)
class ObjectTrack:
    """One object's samples on the frame grid (metres, levelled radians).

    Attributes
    ----------
    object, kind : str
    frame : ndarray (n,) int
    t_s : ndarray (n,)
    x_m, y_m : ndarray (n,)
        Object origin in the world plane (x right, y up), m.
    theta_rad, sigma_theta_rad : ndarray (n,)
        Levelled counter-clockwise angle and its 1-σ uncertainty.
    quality : ndarray (n,)
    status : ndarray (n,) of str
    m_per_unit : float
        Metres per plane unit used for this object; NaN when no metric scale is known
        (then ``x_m, y_m`` are NaN: never a made-up scale).
    x_px, y_px : ndarray (n,)
        The object's reference point in the image (px, as in the video: u right, v down).
    theta_note : str
        Why ``theta_rad`` is NaN on every frame (kind ``"point"``, or an appearance that tells
        no angle: W-TRACK-THETA); empty when the angle is measured.
    """

    object: str
    kind: str
    frame: np.ndarray
    t_s: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    theta_rad: np.ndarray
    sigma_theta_rad: np.ndarray
    quality: np.ndarray
    status: np.ndarray
    m_per_unit: float
    x_px: np.ndarray | None = None
    y_px: np.ndarray | None = None
    theta_note: str = ""

    @property
    def ok(self) -> np.ndarray:
        return self.status == "ok"


@dataclass(frozen=True)
class TrackResult:
    """Tracks of every object of one video.

    Attributes
    ----------
    tracks : tuple of ObjectTrack
    fps : float
    level_rad : float
        Camera roll removed from every angle (rad, counter-clockwise).
    level_source : str
        Where it came from (``"table table"``, ``"rest of block_1"``, ``"line"``, ``"value"``,
        ``"plane (...)"``, ``"none"``).
    level_sigma_rad : float
        Its 1-σ uncertainty, rad (NaN when unknown).
    n_frames : int
    width_px, height_px : int
    source : str or None
    config : TrackConfig
    plane : str
        Where the image -> plane mapping came from: "image" (centred pixels times the
        measured scale; compare positions as displacements), "homography", "board" or
        "table" (metres in that plane).
    camera_drift_px : float
        The background's largest shift from the first frame tracked, px at a frame corner
        (:func:`~rocklab.tracking.video._camera_motion.check_camera`); NaN when not measured (an
        object found by its markers has no region to leave out of the background).
    camera_moves : bool
        ``W-VIDEO-CAMERA`` was raised: positions include the camera's motion (status suspect).
    """

    tracks: tuple
    fps: float
    level_rad: float
    n_frames: int
    width_px: int
    height_px: int
    source: str | None
    config: TrackConfig = field(repr=False)
    plane: str = "image"
    plane_map: PlaneMap | None = field(default=None, repr=False, compare=False)
    level_source: str = "none"
    level_sigma_rad: float = math.nan
    corrections: tuple = ()  # manual corrections applied (dicts: rocklab.tracking._corrections)
    camera_drift_px: float = 0.0  # the background's largest shift from the first frame, px
    camera_moves: bool = False  # W-VIDEO-CAMERA: positions include the camera's motion

    def __getitem__(self, oid: str) -> ObjectTrack:
        for t in self.tracks:
            if t.object == oid:
                return t
        raise KeyError(oid)

    @property
    def objects(self) -> tuple:
        return tuple(t.object for t in self.tracks)

    def to_frame(self):
        """Long table with :data:`TRACK_COLUMNS` (the ``tracks.csv`` layout)."""
        import pandas as pd

        parts = [
            pd.DataFrame(
                {
                    "frame": t.frame,
                    "t_s": t.t_s,
                    "object": t.object,
                    "x_px": t.x_px if t.x_px is not None else np.full(t.frame.size, np.nan),
                    "y_px": t.y_px if t.y_px is not None else np.full(t.frame.size, np.nan),
                    "x_m": t.x_m,
                    "y_m": t.y_m,
                    "theta_rad": t.theta_rad,
                    "sigma_theta_rad": t.sigma_theta_rad,
                    "quality": t.quality,
                    "status": t.status,
                }
            )
            for t in self.tracks
        ]
        df = pd.concat(parts, ignore_index=True)
        return df.sort_values(["frame", "object"], kind="stable").reset_index(drop=True)

    def table_motion(
        self, object: str | None = None, window_s: float | None = None, polyorder: int | None = None
    ) -> TableMotion:
        """Table displacement/velocity/acceleration (x, m; SG derivatives; window from the noise)."""
        if object is None:
            tab = self.config.table
            if tab is None:
                raise InputError("no object of kind 'table' in the tracking config; name one")
            object = tab.id
        tr = self[object]
        m = self.config.motion
        return table_motion(
            tr.t_s,
            tr.x_m,
            window_s if window_s is not None else m.sg_window_s,
            polyorder if polyorder is not None else m.sg_polyorder,
            object,
        )

    def to_pixels(self, object: str, frame: int, points_m) -> np.ndarray:
        """Image pixels of points fixed to a tracked object, at one frame.

        Inverts what :func:`assemble_tracks` did (levelling, scale, homography or
        centring, lens distortion), so overlays land on the image.

        Parameters
        ----------
        object : str
        frame : int
            Frame index.
        points_m : array_like (k, 2)
            Points in the object's frame, m (x right, y up when upright).

        Returns
        -------
        ndarray (k, 2)
            Pixel coordinates (u right, v down); NaN when the object is not tracked there.
        """
        tr = self[object]
        pts = np.asarray(points_m, float).reshape(-1, 2)
        hit = np.flatnonzero(tr.frame == int(frame))
        if not hit.size or self.plane_map is None or not np.isfinite(tr.theta_rad[hit[0]]):
            return np.full(pts.shape, np.nan)
        i = hit[0]
        c, s = math.cos(tr.theta_rad[i]), math.sin(tr.theta_rad[i])
        x = tr.x_m[i] + c * pts[:, 0] - s * pts[:, 1]
        y = tr.y_m[i] + s * pts[:, 0] + c * pts[:, 1]
        cl, sl = math.cos(self.level_rad), math.sin(self.level_rad)
        X = (cl * x - sl * y) / tr.m_per_unit
        Y = (sl * x + cl * y) / tr.m_per_unit
        return self.plane_map.to_image(np.column_stack((X, Y)))

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        per = {}
        for t in self.tracks:
            st, cnt = np.unique(t.status, return_counts=True)
            per[t.object] = {
                "kind": t.kind,
                "n_ok": int(np.sum(t.ok)),
                "m_per_unit": t.m_per_unit,
                "status_counts": {str(a): int(b) for a, b in zip(st, cnt)},
                "median_sigma_theta_rad": float(np.nanmedian(t.sigma_theta_rad))
                if np.any(np.isfinite(t.sigma_theta_rad))
                else np.nan,
                "theta_note": t.theta_note,
            }
        return {
            "source": self.source,
            "fps": self.fps,
            "n_frames": self.n_frames,
            "width_px": self.width_px,
            "height_px": self.height_px,
            "plane": self.plane,
            "level_rad": self.level_rad,
            "level_source": self.level_source,
            "level_sigma_rad": self.level_sigma_rad,
            "objects": per,
            "corrections": list(self.corrections),
            "camera_drift_px": self.camera_drift_px,
            "status": "suspect" if self.camera_moves else "ok",
        }


def assemble_tracks(
    observations,
    config: TrackConfig,
    fps: float,
    width_px: int,
    height_px: int,
    plane_map: PlaneMap | None = None,
    source=None,
    frame_times_s=None,
    levers: dict | None = None,
) -> TrackResult:
    """Convert per-frame observations (plane units) into a :class:`TrackResult` (m, levelled rad).

    Parameters
    ----------
    observations : iterable of list of Observation
        As yielded by :func:`track_frames`.
    fps : float
        Frame rate; ``t_s = frame / fps`` unless ``frame_times_s`` is given.
    frame_times_s : ndarray, optional
        Each frame's own time from the container, s (indexed by frame number).
    levers : dict, optional
        As filled by :func:`track_frames` (read once ``observations`` are consumed).
    """
    rows = [o for frame_obs in observations for o in frame_obs]
    if not rows:
        raise InputError(f"{source or 'video'}: no frames to track; check the file or the frame range")
    plane = plane_map.source if plane_map is not None else rows[0].plane
    metric_plane = plane != "image"
    by = {o.id: [r for r in rows if r.object == o.id] for o in config.objects}
    frames = np.array(sorted({r.frame for r in rows}), int)
    pos = {f: i for i, f in enumerate(frames)}
    n = len(frames)
    raw = {
        o.id: _object_series(by[o.id], pos, n, _shift_warning(config, o.id, frames), (levers or {}).get(o.id))
        for o in config.objects
    }
    unseen = [o.id for o in config.objects if not np.any(raw[o.id][1] == "ok")]
    if len(unseen) == len(config.objects) or (unseen and n > 1):
        o = unseen[0]
        raise InputError(
            f"{config.source or 'config'}: object {o!r} is never seen in "
            f"{source or 'the video'}; check its markers/dots/roi and the dictionary"
        )
    pm_px = plane_map
    if pm_px is None and plane == "image":  # observations in centred pixels: invert that
        pm_px = PlaneMap(width_px, height_px, config.video.camera_matrix, config.video.dist_coeffs)
    # before the scale and the level: a latched tracker's frames are another object's
    settle_reacquisitions(raw, config, pm_px, frames, source or "the video", width_px, height_px)
    settle_latches(raw, config, pm_px, frames, source or "the video")
    m_per = _metres_per_unit(config, raw, metric_plane)
    from ._level import level_from_reference, world_angle

    level, level_src, level_sig = level_from_reference(config, raw, fps, metric_plane, pm_px)
    c, s = math.cos(-level), math.sin(-level)
    t_all = frame_times(frames, frame_times_s, fps, source)
    tracks = []
    for o in config.objects:
        a, st, _ = raw[o.id]
        x = (c * a["X"] - s * a["Y"]) * m_per[o.id]
        y = (s * a["X"] + c * a["Y"]) * m_per[o.id]
        th = world_angle(o, config, a["th"], a["sig"], fps, level, level_src, config.source or "config")
        sig = a["sig"].copy()
        q = np.where(st == "ok", a["q"], np.nan)
        if pm_px is not None:
            uv = pm_px.to_image(np.column_stack((a["X"], a["Y"])))
            u, v = uv[:, 0].copy(), uv[:, 1].copy()
        else:
            u = v = np.full(n, np.nan)
        if config.motion.interpolate_max_gap_frames:
            interpolate([x, y, th, u, v], st, config.motion.interpolate_max_gap_frames)
        t_s = t_all
        tracks.append(
            ObjectTrack(
                o.id,
                o.kind,
                frames.copy(),
                t_s,
                x,
                y,
                th,
                sig,
                q,
                st.astype(str),
                m_per[o.id],
                u,
                v,
                angle_note(o, st, th),
            )
        )
    return TrackResult(
        tuple(tracks),
        float(fps),
        level,
        n,
        int(width_px),
        int(height_px),
        None if source is None else str(source),
        config,
        plane,
        plane_map,
        level_src,
        level_sig,
    )


def _step_kept(th0: float, th1: float, th2: float) -> bool:
    """Whether an angle that stepped from ``th0`` to ``th1`` (rad) stays stepped at ``th2``, the next
    measured angle: nearer ``th1`` than ``th0`` (a misfit frame alone comes back)."""
    return abs(math.remainder(th2 - th1, 2 * math.pi)) < abs(math.remainder(th2 - th0, 2 * math.pi))


def _object_series(rows, pos, n, on_shift=None, lever=None):
    """One object's observations laid on the frames (``pos``: frame -> row of ``n``).

    Returns ({"X", "Y", "th", "sig", "scale", "q", "fit_th"}: arrays (n,), NaN where not measured; statuses (n,);
    whether a measured frame is in metres). An angle step no rocking block makes marks an outlier;
    when the angles after it go on from the step (:func:`_step_kept`), every angle from that frame on
    is NaN and ``on_shift(index, ok frames from there)`` is called. An angle found unmeasurable on
    the way drops every frame's; with the object's disk ``lever`` (:meth:`MarkerlessTracker.disk_lever`,
    :func:`track_frames`) the frames whose angle was measured report the point the disk's centre
    carries without turning (:func:`_upright`), as the frames after do.
    """
    a = {k: np.full(n, np.nan) for k in ("X", "Y", "th", "sig", "scale", "q", "fit_th")}
    st = np.full(n, "lost", dtype=object)
    metric = False  # metres only where a measured frame says so: a lost frame's flag is a default
    dropped = np.zeros(n, bool)  # frames whose angle alone is not a measurement
    for r in rows:
        i = pos[r.frame]
        a["X"][i], a["Y"][i], a["th"][i], a["sig"][i] = r.X, r.Y, r.theta_rad, r.sigma_theta_rad
        a["scale"][i], a["q"][i], a["fit_th"][i] = r.scale, r.quality, r.fit_theta_rad
        st[i] = r.status
        dropped[i] = r.angle_dropped
        metric = metric or (r.status == "ok" and r.metric)
    th = a["th"]
    okk = np.flatnonzero(st == "ok")
    if np.isnan(th[okk[~dropped[okk]]]).any():  # found unmeasurable on the way: no frame's angle is measured
        if lever is not None:
            d_pose, d_first, th0, at, measured = lever
            seen = {pos[f]: c for f, c in measured.items() if f in pos}
            _upright(a, dropped, d_pose, d_first, th0, pos.get(at, n) if at is not None else n, seen)
        th[:], a["sig"][:] = np.nan, np.nan
    # An angle step no rocking block makes between frames is a misdetection, not motion.
    shift = None
    for j0, j1, j2 in zip(okk[:-1], okk[1:], list(okk[2:]) + [None]):
        if j1 - j0 == 1 and abs(math.remainder(th[j1] - th[j0], 2 * math.pi)) > MAX_STEP_RAD:
            back = st[j0] != "ok"  # the step back from a lone misfit frame
            st[j1] = "outlier"
            # the frames after it: the next whose angle was measured (frames between may have none)
            later = okk[(okk >= (j2 if j2 is not None else n)) & np.isfinite(th[okk])]
            if shift is None and not back and len(later) and _step_kept(th[j0], th[j1], th[later[0]]):
                shift = j1
    if shift is not None:
        # the frames after the step go on from it: one side of it is not the object's angle, and
        # which the track cannot tell (a registration that settled a turn off); no angle from there
        a["th"][shift:], a["sig"][shift:] = np.nan, np.nan
        if on_shift is not None:
            on_shift(shift, int(np.sum(st[shift:] == "ok")))
    bad = st != "ok"
    for k in ("X", "Y", "th", "sig"):
        a[k][bad] = np.nan
    return a, st, metric


#: Rows apart at most for two frames whose disk edge was measured to place the frames between
#: (:func:`_upright`).
SEEN_GAP_ROWS = 10


def _upright(a, held, d_pose, d_first, th0, upto, seen=None) -> None:
    """Move, in place, each frame of ``a`` (:func:`_object_series`'s arrays) before row ``upto``
    (the frames after report the point upright already) to the point its disk's centre carries
    without turning: ``(X, Y) + s R(th) d - R(th0) d_first``, ``th`` the angle the point was
    carried by (``fit_th``), ``th0`` the first angle, rad; ``d`` the disk's centre in the object's
    frame (plane units) where the first frame shows it (``d_first``), or where the poses put it
    (``d_pose``) on the frames whose angle was ``held`` (bool (n,)), not measured: a held pose
    places the disk's centre where it does not lie in the first frame. ``seen``: row -> the disk's
    centre (2,) plane units where its edge showed it on that frame: the frame reports it less
    ``R(th0) d_first`` instead (the poses' place for the disk is the texture's); a frame between two
    such rows at most :data:`SEEN_GAP_ROWS` apart is moved by their misplacement of the disk
    interpolated (it changes only where a keyframe is cut)."""
    m = np.isfinite(a["fit_th"]) & np.isfinite(a["X"]) & (np.arange(len(a["X"])) < upto)
    th, sc = a["fit_th"][m], np.where(np.isfinite(a["scale"][m]), a["scale"][m], 1.0)
    d = np.where(held[m][:, None], np.asarray(d_pose, float), np.asarray(d_first, float))
    c, s, c0, s0 = np.cos(th), np.sin(th), math.cos(th0), math.sin(th0)
    off0 = np.array([c0 * d_first[0] - s0 * d_first[1], s0 * d_first[0] + c0 * d_first[1]])
    a["X"][m] += sc * (c * d[:, 0] - s * d[:, 1]) - off0[0]
    a["Y"][m] += sc * (s * d[:, 0] + c * d[:, 1]) - off0[1]
    rows = np.array(sorted(i for i in (seen or {}) if m[i]), int)
    if not len(rows):
        return
    miss = np.array([seen[i] - off0 for i in rows]) - np.column_stack((a["X"][rows], a["Y"][rows]))
    gap = np.diff(rows)
    for j in np.flatnonzero(m):
        k = int(np.searchsorted(rows, j))
        if k < len(rows) and rows[k] == j:
            step = miss[k]
        elif 0 < k < len(rows) and gap[k - 1] <= SEEN_GAP_ROWS:
            w = (j - rows[k - 1]) / gap[k - 1]
            step = (1.0 - w) * miss[k - 1] + w * miss[k]
        else:
            continue
        a["X"][j] += step[0]
        a["Y"][j] += step[1]


def _shift_warning(config, oid: str, frames):
    """The ``on_shift`` of :func:`_object_series` for object ``oid``: W-TRACK-THETA naming the frame."""

    def said(i: int, n_ok: int) -> None:
        warn(
            "W-TRACK-THETA",
            f"{config.source or 'config'}: object {oid!r}: its angle steps by more than "
            f"{math.degrees(MAX_STEP_RAD):.0f} deg between frames {frames[i] - 1} and {frames[i]} and the "
            f"frames after go on from the step: the angle on one side of it is not the object's (a "
            f"registration that settled a turn off); theta_rad is NaN from frame {frames[i]} on ({n_ok} ok "
            "frames), x and y are tracked; draw the region round the object alone, or round a part that "
            "shows the turn",
        )

    return said


def _metres_per_unit(config, raw, metric_plane) -> dict:
    """Metres per plane unit per object (objects may sit at different depths); NaN, with a coded
    warning, where no metric scale is known."""
    m_per = {}
    fallback = config.reference.m_per_px
    if fallback is None and not metric_plane:
        metric_scales = [
            1.0 / np.nanmedian(raw[o.id][0]["scale"][raw[o.id][1] == "ok"]) for o in config.objects if raw[o.id][2]
        ]
        fallback = float(np.median(metric_scales)) if metric_scales else None
    for o in config.objects:
        a, st, metric = raw[o.id]
        if metric_plane:
            m_per[o.id] = 1.0
        elif metric and config.reference.m_per_px is None:
            m_per[o.id] = 1.0 / float(np.nanmedian(a["scale"][st == "ok"]))
        elif fallback is not None:
            m_per[o.id] = float(fallback)
        else:  # no metric scale anywhere: positions stay in pixels, never a made-up metre
            m_per[o.id] = math.nan
            warn(
                "W-TRACK-NOSCALE",
                f"{config.source or 'config'}: no metric scale for object {o.id!r}: x_m, y_m "
                "left empty (x_px, y_px and theta_rad are measured); give "
                "targets.marker_size_m, objects.size_m or reference.m_per_px",
            )
    return m_per


def no_rate_error(path, config: TrackConfig) -> InputError:
    """The one-line error for a film with no frame rate of its own and none given (``track``,
    ``track preview``).

    Parameters
    ----------
    path : path-like
        The film (an image folder without timestamps.csv).
    config : TrackConfig
        Its config; when its file keeps an older ``track init``'s placeholder note above
        ``fps = 50``, the message says that value is not read as the rate.
    """
    where = config.source or "the config"
    placeholder = False
    if config.source is not None and os.path.isfile(config.source):
        with open(config.source, encoding="utf-8", errors="replace") as f:
            placeholder = FPS_PLACEHOLDER_NOTE in f.read()
    told = (
        f"; {where} has 'fps = 50' under the note '{FPS_PLACEHOLDER_NOTE}' (an older 'rocklab track init''s "
        "guess, not read as the rate): pass --fps N, or set [video] fps to the rate and delete that note"
        if placeholder
        else f"; pass --fps N (or set [video] fps in {where})"
    )
    return InputError(
        f"{path}: the film has no frame rate (an image folder has one only from its timestamps.csv){told}"
    )


def track_video(
    path, config: TrackConfig, fps: float | None = None, progress: bool = False, on_frame=None
) -> TrackResult:
    """Track a video file.

    Parameters
    ----------
    path : path-like
        Video file (any container OpenCV reads) or image-sequence pattern.
    config : TrackConfig
    fps : float, optional
        Overrides ``config.video.fps`` and the container's rate.
    progress : bool
        tqdm progress bar on stderr.
    on_frame : callable(index, gray, image), optional
        Called with every decoded frame before it is tracked, so a caller can use the
        frames (e.g. log them) without decoding the video twice: ``gray`` uint8 (H, W)
        as tracked, ``image`` the decoded picture, uint8 (H, W, 3) BGR (see
        :func:`~rocklab.tracking.iter_video_frames` with ``color=True``).

    Raises
    ------
    InputError
        Unreadable/empty video, no frame rate, unknown marker id, an object never seen.

    Examples
    --------
    A rendered session (ArUco markers, 1 s at 50 fps) tracked with the config it came with:

    >>> import pathlib, tempfile
    >>> import numpy as np, pandas as pd
    >>> from rocklab.synth import synth_session
    >>> from rocklab.config import load_track_config
    >>> from rocklab.tracking import track_video
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> s = synth_session(d / "s", seed=1, size=(480, 270), duration_s=1.0, imu=False, mp4=False)
    >>> res = track_video(d / "s" / "video.mkv", load_track_config(d / "s" / "track.toml"))
    >>> b = res["block_1"]
    >>> truth = pd.read_csv(d / "s" / "truth.csv").query("object == 'block_1'").sort_values("frame")
    >>> err_deg = np.degrees(np.asarray(b.theta_rad) - truth.theta_rad.to_numpy())
    >>> float((b.status == "ok").mean()), bool(np.sqrt(np.mean(err_deg**2)) < 0.1)
    (1.0, True)
    """
    from ._video import iter_video_frames, probe_video

    info = probe_video(path)
    _check_regions(config, info, path)
    fields = info.field_order
    given = fps or config.video.fps
    rate = given or info.fps
    # the container's own frame times, unless the user overrides the rate (a clock known wrong)
    times = None if given else info.frame_times_s
    if given and info.frame_times_s is not None and info.fps and abs(given - info.fps) > 1e-3 * info.fps:
        check_rate(given, info, path, "the given fps" if fps else f"{config.source or 'config'}: [video] fps")
    n_expected = info.n_frames
    if fields is not None:  # deinterlaced: two fields per frame, half a frame apart
        if rate is not None and not given:
            rate = 2.0 * rate
        if times is not None:
            half = 0.5 / info.fps if info.fps else 0.5 * float(np.median(np.diff(times)))
            times = np.column_stack((times, times + half)).ravel()
        n_expected = 2 * info.n_frames
    if rate is None:
        raise no_rate_error(path, config)
    v = config.video
    fixes = load_corrections(v.corrections, [o.id for o in config.objects]) if v.corrections else ()  # errors first
    start, stop = v.start_frame, v.stop_frame
    ref_frame = config.reference.board.frame if config.reference.board is not None else start
    first = None
    for _, g in iter_video_frames(
        path, ref_frame, ref_frame + 1, prefetch=0, pixel_aspect=info.pixel_aspect, fields=fields
    ):
        first = g
    if first is None:
        raise InputError(
            f"{path}: frame {ref_frame} is past the end of the video "
            f"({info.n_frames} frames); check start_frame / reference.board.frame"
        )
    pm = make_plane_map(config, info.width_px, info.height_px, first)
    frames = iter_video_frames(
        path, start, stop, color=on_frame is not None, pixel_aspect=info.pixel_aspect, fields=fields
    )
    if on_frame is not None:
        frames = tee(frames, on_frame)
    if progress:
        from tqdm import tqdm

        total = (min(stop, n_expected) if stop else n_expected) - start
        frames = tqdm(frames, total=total if total > 0 else None, unit="frame", desc="track", leave=False)
    expected = (min(stop, n_expected) if stop else n_expected) - start
    sampler = FrameSampler(expected)
    levers: dict = {}
    obs = track_frames(sampler.wrap(frames), config, pm, levers)
    res = assemble_tracks(
        obs, config, rate, info.width_px, info.height_px, pm, path, frame_times_s=times, levers=levers
    )
    check_frames(res, expected, path, info, config)
    boxes = [o.roi for o in config.objects if getattr(o, "roi", None) is not None]
    if config.table is not None and getattr(config.table, "roi", None) is not None:
        boxes.append(config.table.roi)  # a shake table moves: no background
    if len(boxes) >= len(config.objects):
        drift, moves = check_camera(sampler.frames, boxes, path, info.width_px)
    else:  # an object without a region (markers) would move as the background does: not measured
        drift, moves = math.nan, False
    res = replace(res, camera_drift_px=drift, camera_moves=moves)
    return apply_corrections(res, fixes) if fixes else res  # the config's hand fixes


def frame_times(frames: np.ndarray, frame_times_s, fps: float, source=None) -> np.ndarray:
    """Each frame's time, s: the container's own (``frame_times_s``, indexed by frame number),
    else ``frames / fps``.

    A frame numbered past the container's times (a reader and a container that disagree on the
    count) is timed at ``fps`` after the last known time, with W-VIDEO-COUNT: a warning, never an
    index error.
    """
    frames = np.asarray(frames, int)
    if frame_times_s is None:
        return frames / float(fps)
    t = np.asarray(frame_times_s, float)
    over = frames >= len(t)
    if not np.any(over):
        return t[frames]
    last = float(t[-1]) if len(t) else -1.0 / float(fps)
    out = np.where(over, last + (frames - (len(t) - 1)) / float(fps), t[np.minimum(frames, max(len(t) - 1, 0))])
    warn(
        "W-VIDEO-COUNT",
        f"{source or 'video'}: {int(np.sum(over))} frame(s) read past the {len(t)} the container's times "
        f"cover (frame {int(frames[over][0])} on); they are timed at {float(fps):.6g} frames/s after "
        "the last known time; check the film (convert it to .mkv/.mp4 with ffmpeg) or give --fps",
    )
    return out


def _check_regions(config, info, path) -> None:
    """Every object's ``roi`` lies in the frames (a region past the edge tracks nothing real: it
    was refused by ``track init`` but not when written by hand)."""
    W, H = info.width_px, info.height_px
    for o in config.objects:
        # half a pixel of slack: continuous coordinates, pixel centres at integers
        if o.roi is not None and region_leaves(o.roi, W, H, tol_px=0.5):
            raise InputError(
                f"{config.source or 'track.toml'}: object {o.id!r} roi {[float(x) for x in o.roi]} leaves the {W}x{H} "
                f"frames of {os.path.basename(str(path))}; give a region inside them (read it off 'rocklab track init')"
            )
