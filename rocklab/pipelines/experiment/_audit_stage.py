"""The assumption audit of one experiment, from whichever source measured it.

- a video source or a plane ``tracks.csv``: θ only, so the impacts (double
  impacts). :func:`rocklab.tracking.rigid.audit_plane_track` can read sliding
  and uplift off a plane track, but one camera's θ and position disagree with
  rigid rocking by millimetres on small, distant blocks, which would be false
  alarms;
- a ``tracks.csv`` from ``rocklab track3d`` (it has the pivot columns): its
  sliding, uplift, twist and out-of-plane rotation;
- an IMU: θ only, so the impacts.

The result is the ``audit`` object of ``report.json``; a verdict other than
``valid`` raises ``W-AUDIT`` (the experiment becomes ``suspect``).
"""

from __future__ import annotations

import numpy as np

__all__ = ["audit_experiment", "fit_exclusions"]


def _from_tracks_csv(rows):
    """``rows``: one object's :class:`rocklab.series.Tracks`."""
    from ...tracking.rigid import audit_rocking

    t, th = rows.theta()
    cols = rows.frame.columns
    sig = float(np.nanmedian(rows.column("sigma_theta_rad"))) if "sigma_theta_rad" in cols else None
    if rows.is_3d:
        return audit_rocking(
            t,
            th,
            slide_m=rows.column("pivot_slide_m"),
            uplift_m=rows.column("pivot_uplift_m"),
            twist_rad=rows.column("twist_rad"),
            out_of_plane_rad=rows.column("out_of_plane_rad"),
            sigma_theta_rad=sig,
            source="3d",
        )
    return _theta_only(
        t,
        th,
        sig,
        "2d",
        "a plane track: sliding, uplift, twist and out-of-plane rotation not checked (use 3D points, rocklab track3d)",
    )


def _theta_only(t, th, sig, source, why):
    from dataclasses import replace

    from ...tracking.rigid import audit_rocking

    res = audit_rocking(t, th, sigma_theta_rad=sig, source=source)
    return replace(res, notes=res.notes + (why,))


def _from_video(cfg, tr, measured):
    b = {o: tr[o] for o in tr.objects}.get(cfg.video.object)
    t, th = (b.t_s, b.theta_rad) if b is not None else measured["video"]
    sig = float(np.nanmedian(b.sigma_theta_rad)) if b is not None and np.isfinite(b.sigma_theta_rad).any() else None
    # one camera's theta and position disagree with rigid rocking by several mm on small, distant blocks even
    # without any slide, so sliding/uplift from a plane track would raise false alarms: impacts only here
    return _theta_only(
        t,
        th,
        sig,
        "2d",
        "one camera: sliding, uplift, twist and out-of-plane rotation not checked (use 3D points, rocklab track3d)",
    )


def audit_experiment(cfg, measured: dict, tr, track_rows=None):
    """The assumption audit (:class:`rocklab.tracking.rigid.AuditResult`) of the experiment's
    primary source: ``report.json``'s ``audit``.

    ``tr`` is the video's TrackResult and ``track_rows`` the tracked CSV's rows (when those are sources).
    """
    from ..._diagnostics import warn

    if cfg.primary == "video" and tr is not None:
        res = _from_video(cfg, tr, measured)
    elif cfg.primary == "track":
        res = _from_tracks_csv(track_rows)
    else:
        t, th = measured[cfg.primary]
        res = _theta_only(t, th, None, "imu", "an IMU: sliding, uplift and twist not checked")
    if res.verdict != "valid":
        kinds = ", ".join(sorted({f.kind for f in res.flags}))
        warn(
            "W-AUDIT",
            f"{cfg.name}: assumption audit {res.verdict} ({kinds}; impacts "
            f"{', '.join(map(str, res.excluded_impacts)) or 'none'}); their per-impact eta "
            "are not trustworthy",
        )
    return res


def fit_exclusions(audit, per_impact, max_dt_s: float = 0.02) -> tuple:
    """The fit's impacts that the audit flagged, with the reasons.

    Parameters
    ----------
    audit : rocklab.tracking.rigid.AuditResult or None
        :func:`audit_experiment`'s result.
    per_impact : pandas.DataFrame or None
        The fit's per-impact table (``impact, t_s, ...``).
    max_dt_s : float
        An audit impact and a fit impact closer than this are the same impact, s.

    Returns
    -------
    tuple of ExcludedImpact
        In the order of the fit's impacts.
    """
    from ._stages import ExcludedImpact

    if audit is None or not audit.flags or per_impact is None or len(per_impact) == 0:
        return ()
    times = np.asarray(audit.impacts_t_s, float)
    fit_t = per_impact["t_s"].to_numpy(float)
    out: dict = {}
    for f in audit.flags:
        k = f.impact
        if k is None or not 1 <= k <= times.size:
            continue
        j = int(np.argmin(np.abs(fit_t - times[k - 1])))
        if abs(fit_t[j] - times[k - 1]) > max_dt_s:
            continue
        row = per_impact.iloc[j]
        e = out.setdefault(
            int(row["impact"]),
            {
                "impact": int(row["impact"]),
                "t_s": float(row["t_s"]),
                "eta": float(row.get("eta_peaks", np.nan)),
                "reasons": [],
            },
        )
        e["reasons"].append(f"{f.kind} ({f.detail}): {f.value:.4g} against {f.tolerance:.4g} (SI)")
    return tuple(ExcludedImpact(**out[k]) for k in sorted(out))
