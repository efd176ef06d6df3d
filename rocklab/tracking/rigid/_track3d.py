"""Blocks and tables from 3D point tracks: rocking angle, out-of-plane motion, pivot and audit.

:func:`track_points3d` turns a :class:`~rocklab.tracking.rigid.PointSeries`
(from a C3D file, a CSV export or the stereo tracker) into the rows of
``tracks.csv`` (the 2D tracker's columns plus ``out_of_plane_rad, twist_rad,
pivot_slide_m, pivot_uplift_m``) and an :class:`~rocklab.tracking.rigid.AuditResult`
per block. The rig's axes may be yawed and offset: only the vertical is named
(``up``); the rocking direction, the pivot edges and the table's height come
from the motion itself.

The reference pose is the block upright at rest: by default the last quiet
stretch of the record (free rocking ends upright; a thread-burn release starts
tilted), or the first when the block overturned (it ends lying down). A body
named ``table`` or ``base`` is tracked too, and the blocks are then measured
relative to it, so a shake table's motion is not read as sliding.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..._diagnostics import warn
from ..._errors import InputError, where
from ._audit import AuditResult, AuditTolerances, audit_rocking
from ._pose import MIN_POINTS, BodyPoses, body_poses, kabsch, reference_shape
from ._plausible import check_rate, check_span, check_up, up_evidence
from ...series import TRACK3D_COLUMNS
from ._read_points import PointSeries
from ._rigidity import check_bodies_disjoint, check_rigid_body
from ._rocking import (
    RockingGeometry,
    axis_vector,
    find_impacts,
    fit_pivots,
    pivot_motion,
    rocking_axes,
    rotation_sigma,
    segment_ids,
    split_rotation,
)

__all__ = ["Body3D", "Track3DResult", "track_points3d", "TRACK3D_COLUMNS", "TABLE_NAMES", "parse_bodies"]

#: Body names that mean the table (tracked, and the blocks measured relative to it).
TABLE_NAMES = ("table", "base")
#: Length of the rest windows at either end of the record, s (at least 5 samples).
REST_S = 0.25
#: A rest window whose pose wanders by more than this is not at rest, rad.
QUIET_RAD = math.radians(0.2)
#: A table's rotation is averaged over this window, s: a table pitches slowly, and its per-sample
#: rotation from a few targets would add its noise to every block angle.
TABLE_SMOOTH_S = 0.2
#: Rotation between the first and last rest above which the block is taken to have overturned, rad.
OVERTURNED_RAD = math.radians(30.0)


@dataclass(frozen=True)
class Body3D:
    """One rigid body's motion, in the rocking frame found from the data.

    Attributes
    ----------
    name : str
    labels : tuple of str
        Its points.
    t_s : ndarray, shape (n,)
    theta_rad, sigma_theta_rad : ndarray, shape (n,)
        Rotation about the rocking edge (positive tips the top towards ``+e_r``) and its 1-sigma, rad.
    out_of_plane_rad, twist_rad : ndarray, shape (n,)
        Rotation about the rocking direction and about the vertical, rad.
    x_m, y_m : ndarray, shape (n,)
        The body's reference centroid along ``e_r`` and up, in the rig's origin, m.
    pivot_slide_m, pivot_across_m, pivot_uplift_m : ndarray, shape (n,)
        Displacement of the active pivot edge from its rest position along ``e_r``,
        along the rocking axis, and up, m (NaN for a table, or a side that never rocked).
    rms_m : ndarray, shape (n,)
        Pose-fit residual, m.
    status : ndarray of str, shape (n,)
        ``ok``, ``lost`` or ``degenerate``.
    geometry : RockingGeometry
    poses : BodyPoses
    rest : str
        The reference pose used: ``"first"``, ``"last"`` or ``"T0-T1 s"``.
    audit : AuditResult or None
        None for a table.
    is_table : bool
    """

    name: str
    labels: tuple
    t_s: np.ndarray
    theta_rad: np.ndarray
    sigma_theta_rad: np.ndarray
    out_of_plane_rad: np.ndarray
    twist_rad: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    pivot_slide_m: np.ndarray
    pivot_across_m: np.ndarray
    pivot_uplift_m: np.ndarray
    rms_m: np.ndarray
    status: np.ndarray
    geometry: RockingGeometry
    poses: BodyPoses
    rest: str
    audit: AuditResult | None
    is_table: bool = False

    def to_frame(self):
        """Rows of ``tracks.csv`` (:data:`TRACK3D_COLUMNS`) for this body."""
        import pandas as pd

        n = self.t_s.size
        ok = self.status == "ok"
        med = np.nanmedian(self.rms_m) if np.isfinite(self.rms_m).any() else np.nan
        quality = np.where(ok, 1.0 / (1.0 + self.rms_m / max(3.0 * med, 1e-5)) if np.isfinite(med) else 1.0, 0.0)
        return pd.DataFrame(
            {
                "frame": np.arange(n),
                "t_s": self.t_s,
                "object": self.name,
                "x_px": np.nan,
                "y_px": np.nan,
                "x_m": self.x_m,
                "y_m": self.y_m,
                "theta_rad": self.theta_rad,
                "sigma_theta_rad": self.sigma_theta_rad,
                "quality": quality,
                "status": self.status,
                "out_of_plane_rad": self.out_of_plane_rad,
                "twist_rad": self.twist_rad,
                "pivot_slide_m": self.pivot_slide_m,
                "pivot_uplift_m": self.pivot_uplift_m,
            },
            columns=list(TRACK3D_COLUMNS),
        )

    def to_dict(self) -> dict:
        """Summary numbers (SI units)."""
        ok = self.status == "ok"
        return {
            "name": self.name,
            "points": list(self.labels),
            "samples": int(self.t_s.size),
            "samples_ok": int(ok.sum()),
            "rest": self.rest,
            "is_table": self.is_table,
            "max_abs_theta_rad": float(np.nanmax(np.abs(self.theta_rad))) if ok.any() else float("nan"),
            "median_sigma_theta_rad": float(np.nanmedian(self.sigma_theta_rad)) if ok.any() else float("nan"),
            "median_rms_m": float(np.nanmedian(self.rms_m)) if ok.any() else float("nan"),
            "outliers_rejected": self.poses.n_rejected,
            "geometry": self.geometry.to_dict(),
            "audit": None if self.audit is None else self.audit.to_dict(),
        }


@dataclass(frozen=True)
class Track3DResult:
    """Every body of a 3D point record.

    Attributes
    ----------
    bodies : tuple of Body3D
    up : ndarray, shape (3,)
    source : str
    notes : tuple of str
    """

    bodies: tuple
    up: np.ndarray
    source: str
    notes: tuple = field(default=())

    def __getitem__(self, name: str) -> Body3D:
        for b in self.bodies:
            if b.name == name:
                return b
        raise KeyError(name)

    @property
    def blocks(self) -> tuple:
        """The bodies that are not the table."""
        return tuple(b for b in self.bodies if not b.is_table)

    def to_frame(self):
        """``tracks.csv``: every body's rows, bodies one after another."""
        import pandas as pd

        return pd.concat([b.to_frame() for b in self.bodies], ignore_index=True)

    def audit_dict(self) -> dict:
        """``audit.json``: the worst verdict over the blocks and every block's flags (with its name)."""
        order = {"valid": 0, "suspect": 1, "invalid": 2}
        audits = [(b.name, b.audit) for b in self.blocks if b.audit is not None]
        verdict = max((a.verdict for _, a in audits), key=order.__getitem__, default="valid")
        flags = [dict(f.to_dict(), object=name) for name, a in audits for f in a.flags]
        return {
            "verdict": verdict,
            "flags": flags,
            "source": self.source,
            "blocks": {name: a.to_dict() for name, a in audits},
        }

    def to_dict(self) -> dict:
        """Summary of every body (no per-sample arrays)."""
        return {
            "source": self.source,
            "up": self.up.tolist(),
            "notes": list(self.notes),
            "bodies": [b.to_dict() for b in self.bodies],
        }


def parse_bodies(specs, labels, source="", *, default_name: str = "block", min_points: int = MIN_POINTS) -> dict:
    """``{"NAME": (P1, P2, ...)}`` from ``NAME=P1,P2,...`` strings; none: one body ``default_name``
    of every point.

    Parameters
    ----------
    specs : sequence of str or None
        ``--body`` values.
    labels : sequence of str
        The point names the file has.
    source : str
        The file, for the error messages.
    default_name : str
        The one body's name when no ``specs`` are given.
    min_points : int
        The fewest points a body may have (3 for a rigid pose in 3D; 1 for a plane import, where
        a one-point body is a position only).
    """
    if not specs:
        return {default_name: tuple(labels)}
    example = ",".join(f"P{i}" for i in range(1, max(min_points, 2) + 1))
    out: dict = {}
    for s in specs:
        name, sep, pts = str(s).partition("=")
        name = name.strip()
        plist = tuple(p.strip() for p in pts.split(",") if p.strip())
        if not sep or not name or not plist:
            raise InputError(f"--body {s!r}: expected NAME={example} (a body name and its point labels)")
        if name in out:
            raise InputError(f"--body {name!r} given twice; name each body once")
        missing = [p for p in plist if p not in labels]
        if missing:
            raise InputError(
                f"{where(source)}--body {name}: point(s) {missing} not in the file (it has "
                f"{list(labels)[:12]}{' ...' if len(labels) > 12 else ''}); fix the point names"
            )
        if len(plist) < min_points:
            raise InputError(f"--body {name}: {len(plist)} point(s); a rigid pose needs at least {min_points}")
        out[name] = plist
    return out


def _rest_windows(t):
    """Sample indices of the first and last :data:`REST_S` of the record (at least 5 samples each)."""
    n = t.size
    m = max(5, int(np.searchsorted(t, t[0] + REST_S)))
    m = min(m, max(n // 3, 1))
    return np.arange(m), np.arange(n - m, n)


def _quiet(xyz, ref, frames) -> bool:
    """Whether the body holds still over ``frames`` (its rotation wanders less than :data:`QUIET_RAD`)."""
    from scipy.spatial.transform import Rotation

    rot, _, _ = kabsch(ref, xyz[frames])
    ok = np.isfinite(rot).all(axis=(1, 2))
    if ok.sum() < 2:
        return False
    return float(np.max(Rotation.from_matrix(rot[ok]).magnitude())) < QUIET_RAD


def _choose_rest(t, xyz, rest, name, source):
    """(reference shape, description of the rest used, notes)."""
    from scipy.spatial.transform import Rotation

    notes = []
    first, last = _rest_windows(t)
    if isinstance(rest, tuple):
        t0, t1 = rest
        frames = np.flatnonzero((t >= t0) & (t <= t1))
        if frames.size < 1:
            raise InputError(
                f"--rest {t0:g},{t1:g}: no samples in that time range (the record spans "
                f"{t[0]:.4g}-{t[-1]:.4g} s); give a range inside it"
            )
        ref = reference_shape(xyz, frames)
        return ref, f"{t0:.4g}-{t1:.4g} s", notes
    ref_first = reference_shape(xyz, first)
    ref_last = reference_shape(xyz, last)
    if rest == "first":
        return ref_first, "first", notes
    if rest == "last":
        return ref_last, "last", notes
    q_first, q_last = _quiet(xyz, ref_first, first), _quiet(xyz, ref_last, last)
    rot, _, _ = kabsch(ref_first, ref_last)
    angle = float(Rotation.from_matrix(rot).magnitude()) if np.isfinite(rot).all() else float("nan")
    if q_last and not (np.isfinite(angle) and angle > OVERTURNED_RAD):
        return ref_last, "last", notes
    if q_first:
        if np.isfinite(angle) and angle > OVERTURNED_RAD:
            notes.append(
                f"{name}: ends {math.degrees(angle):.4g} deg from where it started (overturned): "
                "the first rest is the reference"
            )
            return ref_first, "first", notes
        warn(
            "W-3D-REST",
            f"{where(source)}{name} is not at rest at the end of the record; theta is measured "
            "from the first samples, which carry the release tilt if the block was held tilted "
            "(give --rest T0,T1 for an upright rest)",
        )
        return ref_first, "first", notes
    warn(
        "W-3D-REST",
        f"{where(source)}{name} is at rest neither at the start nor at the end of the record; "
        "theta is measured from the last samples (give --rest T0,T1 for an upright rest)",
    )
    return ref_last, "last", notes


def _smooth_rotations(R, t_s, window_s: float) -> np.ndarray:
    """Rotations averaged over a moving window of ``window_s`` (rotation vectors, NaN rows kept NaN)."""
    from scipy.ndimage import uniform_filter1d
    from scipy.spatial.transform import Rotation

    ok = np.isfinite(R).all(axis=(1, 2))
    if ok.sum() < 3:
        return R
    dt = float(np.median(np.diff(t_s)))
    w = max(1, int(round(window_s / dt)) | 1)
    rv = np.full((R.shape[0], 3), np.nan)
    rv[ok] = Rotation.from_matrix(R[ok]).as_rotvec()
    idx = np.arange(R.shape[0])
    filled = np.column_stack([np.interp(idx, idx[ok], rv[ok, j]) for j in range(3)])
    sm = uniform_filter1d(filled, size=w, axis=0, mode="nearest")
    out = np.full_like(R, np.nan)
    out[ok] = Rotation.from_rotvec(sm[ok]).as_matrix()
    return out


def _in_frame(R_T, t_T, xyz):
    """Points expressed in the table's rest frame: ``R_T^T (x - t_T)`` per sample (NaN where the table is lost)."""
    return np.einsum("nji,npj->npi", R_T, xyz - t_T[:, None, :])


def _fit_body(name, labels, t, xyz, rest, source):
    """``(reference shape, rest used, notes, BodyPoses)`` of one body: its rest, then its pose in every sample."""
    ref, rest_used, notes = _choose_rest(t, xyz, rest, name, source)
    if (~np.isfinite(ref).all(axis=1)).sum() > len(labels) - MIN_POINTS:
        raise InputError(
            f"{where(source)}body {name!r}: fewer than {MIN_POINTS} of its points are placed at rest; "
            "give --rest T0,T1 where the points are seen, or fix the --body list"
        )
    poses = body_poses(xyz, ref)
    check_rigid_body(name, labels, xyz, poses, source)
    return ref, rest_used, notes, poses


def _body(name, labels, t, up, tolerances, fitted, is_table=False, axes=None):
    """:class:`Body3D` from a body's :func:`_fit_body` result (``axes``: the rocking axes to use)."""
    ref, rest_used, notes, poses = fitted
    notes = list(notes)
    R, tr = poses.R, poses.t_m
    if axes is None:
        axis, e_r, max_rot = rocking_axes(R, up)
        if max_rot < math.radians(0.1) and not is_table:
            notes.append(
                f"{name}: turns by at most {math.degrees(max_rot):.4g} deg; the rocking direction is "
                "the rig's first horizontal axis"
            )
    else:
        axis, e_r = axes
    theta, oop, twist = split_rotation(R, e_r, axis, up)
    sigma = rotation_sigma(poses.rms_m, poses.n_points, ref, axis)
    # the pivot section: the middle of the targets' extent along the edge, where a twist about the
    # block's vertical centre line moves the edge least along e_r
    origin = np.nanmean(ref, axis=0)
    along = ref @ axis
    origin = origin + axis * (0.5 * (np.nanmax(along) + np.nanmin(along)) - origin @ axis)
    centre = np.einsum("nij,j->ni", R, origin) + tr
    x_m, y_m = centre @ e_r, centre @ up
    n = t.size
    slide = np.full(n, np.nan)
    across = np.full(n, np.nan)
    uplift = np.full(n, np.nan)
    c_pos = c_neg = np.full(3, np.nan)
    audit = None
    if not is_table:
        sig_med = float(np.nanmedian(sigma)) if np.isfinite(sigma).any() else 0.0
        hyst = max(5.0 * sig_med, math.radians(0.05))
        impacts = find_impacts(t, theta, hyst)
        seg = segment_ids(t, impacts)
        min_theta = max(math.radians(0.3), 10.0 * sig_med)
        c_pos, c_neg = fit_pivots(R, tr, theta, seg, origin, min_theta, axis)
        ok = np.isfinite(theta)
        if np.isfinite(c_pos).all() or np.isfinite(c_neg).all():
            disp = np.full((n, 3), np.nan)
            disp[ok] = pivot_motion(
                R[ok],
                tr[ok],
                theta[ok],
                origin,
                np.where(np.isfinite(c_pos), c_pos, np.nan),
                np.where(np.isfinite(c_neg), c_neg, np.nan),
            )
            slide, across, uplift = disp @ e_r, disp @ axis, disp @ up
        for side, c in (("positive", c_pos), ("negative", c_neg)):
            if not np.isfinite(c).all():
                notes.append(
                    f"{name}: never rocked beyond {math.degrees(min_theta):.4g} deg on the {side} side; "
                    "its pivot is unknown and the pivot columns are empty there"
                )
        audit = audit_rocking(
            t,
            theta,
            slide_m=slide,
            uplift_m=uplift,
            twist_rad=twist,
            out_of_plane_rad=oop,
            sigma_theta_rad=sig_med,
            tolerances=tolerances,
            source="3d",
        )
    width = float((c_pos - c_neg) @ e_r) if np.isfinite(c_pos).all() and np.isfinite(c_neg).all() else float("nan")
    gap = float((c_pos - c_neg) @ up) if np.isfinite(width) else float("nan")
    geo = RockingGeometry(up, axis, e_r, origin, c_pos, c_neg, width, gap)
    body = Body3D(
        name,
        tuple(labels),
        t,
        theta,
        sigma,
        oop,
        twist,
        x_m,
        y_m,
        slide,
        across,
        uplift,
        poses.rms_m,
        poses.status,
        geo,
        poses,
        rest_used,
        audit,
        is_table,
    )
    return body, notes


def track_points3d(
    series: PointSeries,
    bodies: dict | None = None,
    up: str = "z",
    rest="auto",
    tolerances: AuditTolerances | None = None,
) -> Track3DResult:
    """Rocking motion of every body in a 3D point record.

    Parameters
    ----------
    series : PointSeries
        Positions, m (see :func:`~rocklab.tracking.rigid.read_points`).
    bodies : dict, optional
        ``{name: (point labels)}``; default: every point is one block named ``block``.
        A body named ``table`` or ``base`` is the table (see the module doc).
    up : str
        The rig's vertical axis: ``x``, ``y`` or ``z`` with an optional sign (default ``z``).
    rest : {"auto", "first", "last"} or (t0_s, t1_s)
        Which samples show the block upright at rest (see the module doc).
    tolerances : AuditTolerances, optional

    Returns
    -------
    Track3DResult
    """
    try:
        u = axis_vector(up)
    except ValueError:
        raise InputError(f"--up {up!r}: must be x, y or z with an optional sign (the rig's vertical axis)") from None
    if rest not in ("auto", "first", "last") and not isinstance(rest, tuple):
        raise InputError(f"--rest {rest!r}: must be auto, first, last or T0,T1 (seconds)")
    if series.t_s.size < 10:
        raise InputError(f"{where(series.source)}{series.t_s.size} samples; a rocking record needs at least 10")
    bodies = bodies or parse_bodies(None, series.labels)
    check_bodies_disjoint(bodies, series.source)
    tables = [n for n in bodies if n.lower() in TABLE_NAMES]
    if len(tables) > 1:
        raise InputError(f"--body: two tables {tables}; name one body table")
    if len(tables) == len(bodies):
        raise InputError(f"--body: only a table ({tables[0]}); name the block's points too")
    notes = list(series.notes)
    out = []
    frame_xyz = None
    table_rest = "first" if rest == "auto" else rest
    if tables:
        name = tables[0]
        sel = series.select(bodies[name])
        table_fit = _fit_body(name, sel.labels, series.t_s, sel.xyz_m, table_rest, series.source)
        notes += table_fit[2]
        poses = table_fit[3]
        R_s = _smooth_rotations(poses.R, series.t_s, TABLE_SMOOTH_S)
        # the translation that goes with the averaged rotation, about the table targets' centroid
        c_ref = np.nanmean(poses.ref_m, axis=0)
        t_s = poses.t_m + np.einsum("nij,j->ni", poses.R - R_s, c_ref)
        frame_xyz = (R_s, t_s)
    blocks = []
    for name, labels in bodies.items():
        if name in tables:
            continue
        sel = series.select(labels)
        xyz = sel.xyz_m if frame_xyz is None else _in_frame(*frame_xyz, sel.xyz_m)
        b, bnotes = _body(
            name,
            sel.labels,
            series.t_s,
            u,
            tolerances,
            _fit_body(name, sel.labels, series.t_s, xyz, rest, series.source),
        )
        notes += bnotes
        blocks.append(b)
    if tables:
        # the table's angles in the first block's rocking frame, so its x_m is the shake direction
        geo = blocks[0].geometry
        tb, _ = _body(
            tables[0],
            tuple(bodies[tables[0]]),
            series.t_s,
            u,
            tolerances,
            table_fit,
            is_table=True,
            axes=(geo.axis, geo.e_r),
        )
        out.append(tb)
    out += blocks
    check_rate(series)
    for b in out:
        check_span(series.source, b.name, b.poses.ref_m)
        if not b.is_table:
            check_up(series.source, b.name, up_evidence(b.theta_rad, b.y_m, b.poses.R, u), up)
    for b in out:
        lost = int((b.status != "ok").sum())
        if lost > 0.01 * b.t_s.size:
            warn(
                "W-3D-LOST",
                f"{where(series.source)}{b.name}: no pose in {lost} of {b.t_s.size} samples "
                f"({100.0 * lost / b.t_s.size:.4g} %): fewer than {MIN_POINTS} of its points seen",
            )
    for b in blocks:
        if b.audit is not None and b.audit.verdict != "valid":
            worst = ", ".join(sorted({f.kind for f in b.audit.flags}))
            warn(
                "W-AUDIT",
                f"{where(series.source)}{b.name}: assumption audit {b.audit.verdict} ({worst}; "
                f"impacts {', '.join(map(str, b.audit.excluded_impacts)) or 'none'}); see audit.json",
            )
    return Track3DResult(tuple(out), u, series.source, tuple(notes))
