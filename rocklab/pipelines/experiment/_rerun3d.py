"""Rerun review of a 3D record (``rocklab track3d`` / ``rocklab stereo track`` with ``--rrd``).

Entity tree:

- ``3d/<body>/targets``: the body's targets in the rig's axes, every sample
  (``send_columns``, one partition per sample);
- ``3d/<block>/pivot``: the active pivot edge's path over the run (a line strip,
  static) and its position at each sample;
- ``plots/<block>/theta_deg``, ``twist_deg``, ``out_of_plane_deg``, ``slide_mm``,
  ``uplift_mm``: the decomposition, in degrees and millimetres for people;
- ``audit/<block>``: the impacts and every audit flag as text on the timeline
  (flags at warning level), so a reviewer scrubs straight to them.

The blueprint (kept apart from the data) opens a 3D view beside the plots and the flags.
"""

from __future__ import annotations

import math

import numpy as np

from ._rerun import TIMELINE, close_recording, log_series, open_recording

__all__ = ["log_track3d", "track3d_blueprint", "write_track3d_rrd"]

#: Body colours (RGB): blocks dark and saturated, the table grey.
_COLOURS = [(31, 119, 180), (214, 39, 40), (44, 160, 44), (148, 103, 189)]
_TABLE = (140, 140, 140)


def _pivot_world(b):
    """The active pivot edge's position in the body's analysis axes, (n, 3) m (NaN where unknown):
    its rest position plus the displacement the tracker measured."""
    g = b.geometry
    c = np.where((b.theta_rad >= 0)[:, None], g.pivot_pos_m[None], g.pivot_neg_m[None])
    disp = np.outer(b.pivot_slide_m, g.e_r) + np.outer(b.pivot_across_m, g.axis) + np.outer(b.pivot_uplift_m, g.up)
    return g.origin_m + c + disp


def log_track3d(rec, series, result) -> None:
    """Log a :class:`~rocklab.tracking.rigid.PointSeries` and its :class:`Track3DResult` into ``rec``."""
    import rerun as rr

    t = np.asarray(series.t_s, float)
    rec.log("3d", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    for i, b in enumerate(result.bodies):
        colour = _TABLE if b.is_table else _COLOURS[i % len(_COLOURS)]
        idx = [series.labels.index(lab) for lab in b.labels]
        xyz = series.xyz_m[:, idx]
        seen = np.isfinite(xyz).all(axis=2)
        lengths = seen.sum(axis=1)
        rec.send_columns(
            f"3d/{b.name}/targets",
            indexes=[rr.TimeColumn(TIMELINE, duration=t)],
            columns=rr.Points3D.columns(positions=xyz[seen]).partition(lengths),
        )
        rec.log(f"3d/{b.name}/targets", rr.Points3D.from_fields(colors=[colour], radii=[0.003]), static=True)
        if b.is_table:
            continue
        piv = _pivot_world(b)
        ok = np.isfinite(piv).all(axis=1)
        if ok.any():
            rec.log(f"3d/{b.name}/pivot_path", rr.LineStrips3D([piv[ok]], colors=[colour], radii=[0.0005]), static=True)
            rec.send_columns(
                f"3d/{b.name}/pivot",
                indexes=[rr.TimeColumn(TIMELINE, duration=t[ok])],
                columns=rr.Points3D.columns(positions=piv[ok]).partition(np.ones(int(ok.sum()), int)),
            )
            rec.log(f"3d/{b.name}/pivot", rr.Points3D.from_fields(colors=[(255, 127, 14)], radii=[0.004]), static=True)
        for name, values, scale in (
            ("theta_deg", b.theta_rad, 180 / math.pi),
            ("twist_deg", b.twist_rad, 180 / math.pi),
            ("out_of_plane_deg", b.out_of_plane_rad, 180 / math.pi),
            ("slide_mm", b.pivot_slide_m, 1e3),
            ("uplift_mm", b.pivot_uplift_m, 1e3),
        ):
            log_series(
                rec,
                f"plots/{b.name}/{name}",
                t,
                np.asarray(values) * scale,
                color=list(colour),
                name=f"{b.name} {name.replace('_', ' ')}",
            )
        a = b.audit
        for k, ti in enumerate(a.impacts_t_s, start=1):
            rec.set_time(TIMELINE, duration=float(ti))
            rec.log(f"audit/{b.name}", rr.TextLog(f"impact {k}", level="DEBUG"))
        for f in a.flags:
            rec.set_time(TIMELINE, duration=float(f.t_s))
            rec.log(f"audit/{b.name}", rr.TextLog(f"{b.name}: {f.describe()}", level="WARN"))
        rec.reset_time()
        rec.log(f"audit/{b.name}/verdict", rr.TextDocument(a.report()), static=True)


def track3d_blueprint(result):
    """3D view | the blocks' plots | the audit's flags."""
    import rerun.blueprint as rrb

    plots = [
        rrb.TimeSeriesView(origin=f"plots/{b.name}", name=f"{b.name}: θ, twist, out-of-plane (deg), slide, uplift (mm)")
        for b in result.blocks
    ]
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(
                rrb.Spatial3DView(origin="3d", name="targets and pivot"),
                rrb.TextLogView(origin="audit", name="impacts and audit flags"),
                row_shares=[3, 1],
            ),
            rrb.Vertical(*plots),
            column_shares=[1, 1],
        ),
        collapse_panels=True,
    )


def write_track3d_rrd(path, series, result) -> None:
    """Write the review of a 3D record to ``path`` (atomically)."""
    from ..._io import atomic_path

    with atomic_path(path) as tmp:
        rec = open_recording("rocklab_track3d", rrd_path=tmp)
        rec.send_blueprint(track3d_blueprint(result))
        log_track3d(rec, series, result)
        close_recording(rec, tmp)
