"""Plausibility of a 3D point record and of the vertical it was given (as for IMU logs).

A CSV states its units only in its column names, and a rig's vertical only in
``--up``: times written in ms under ``t_s``, millimetres under ``x_m`` or a wrong
or reversed ``--up`` would otherwise give confident, wrong numbers.  Checked:

- rate (``W-3D-RATE``): motion capture and stereo films run at 10 Hz - 20 kHz; a
  median step outside that is a time column not in seconds;
- size (``W-3D-SIZE``): a rigid body's targets span 2 mm - 20 m; outside, the
  coordinates are not in metres;
- up axis (``W-3D-UP``): a block rocks about a horizontal edge, so its rotation
  axis is perpendicular to the vertical, and tilting either way *raises* its
  centroid (by ``R [cos(alpha - |theta|) - cos(alpha)]``, first order in
  ``|theta|``).  Along a reversed vertical the centroid falls; along a horizontal
  axis it moves with the *sign* of theta (the sway ``~ h theta``).  The rise is
  fitted as ``p |theta| + q theta`` over the tilts between 30 % of the largest
  (at most 5 deg, below the alpha of any block with h/b < 11) and that bound.
"""

from __future__ import annotations

import math

import numpy as np

from ..._diagnostics import warn
from ..._errors import where

__all__ = []

#: Sample rates a 3D point record may have, Hz.
RATE_HZ = (10.0, 20000.0)
#: Span of a rigid body's targets, m.
SPAN_M = (2e-3, 20.0)
#: Largest angle of the rotation axis above the horizontal of ``--up``, rad.
AXIS_TILT_MAX_RAD = math.radians(20.0)
#: A sway ``|q|`` above this many rises ``|p|`` means ``--up`` is horizontal.
SWAY_RATIO = 2.0
#: Tilts used for the centroid-rise fit: at most this, rad; and the smallest largest tilt that is tested.
RISE_TILT_RAD = math.radians(5.0)
RISE_MIN_TILT_RAD = math.radians(1.0)


def check_rate(series) -> None:
    """``W-3D-RATE`` when the median sample step is outside :data:`RATE_HZ`."""
    rate = series.rate_hz
    if np.isfinite(rate) and not (RATE_HZ[0] <= rate <= RATE_HZ[1]):
        dt = 1.0 / rate
        warn(
            "W-3D-RATE",
            f"{where(series.source)}median time step {dt:.4g} s ({rate:.4g} Hz), outside the "
            f"{RATE_HZ[0]:g} Hz - {RATE_HZ[1]:g} Hz of motion capture: is t_s in seconds "
            f"(ms would give {1000 * rate:.4g} Hz)?",
        )


def check_span(source, name, ref_m) -> None:
    """``W-3D-SIZE`` when a body's targets (reference shape, (p, 3) m) span outside :data:`SPAN_M`."""
    p = ref_m[np.isfinite(ref_m).all(axis=1)]
    if len(p) < 2:
        return
    span = float(np.max(np.linalg.norm(p[:, None, :] - p[None, :, :], axis=2)))
    if not (SPAN_M[0] <= span <= SPAN_M[1]):
        warn(
            "W-3D-SIZE",
            f"{where(source)}{name}: its targets span {span:.4g} m, outside {SPAN_M[0]:g} - "
            f"{SPAN_M[1]:g} m: are the coordinates in metres (mm under x_m gives 1000x)?",
        )


def up_evidence(theta, y_m, R, up) -> dict:
    """The up-axis evidence of one block (module doc): axis tilt, rise fit ``p, q``, both sides seen."""
    from scipy.spatial.transform import Rotation

    out = {"axis_tilt_rad": float("nan"), "p": float("nan"), "q": float("nan"), "two_sided": False}
    ok = np.isfinite(R).all(axis=(1, 2))
    if ok.sum() < 3:
        return out
    rv = Rotation.from_matrix(R[ok]).as_rotvec()
    if float(np.max(np.linalg.norm(rv, axis=1))) < RISE_MIN_TILT_RAD:
        return out
    a = np.linalg.svd(rv, full_matrices=False)[2][0]
    out["axis_tilt_rad"] = float(math.asin(min(1.0, abs(float(a @ up)))))
    fin = np.isfinite(theta) & np.isfinite(y_m)
    big = float(np.max(np.abs(theta[fin]))) if fin.any() else 0.0
    if big < RISE_MIN_TILT_RAD:
        return out
    top = min(big, RISE_TILT_RAD)
    base = fin & (np.abs(theta) < 0.05 * top)
    sel = fin & (np.abs(theta) >= 0.3 * top) & (np.abs(theta) <= top)
    if base.sum() < 3 or sel.sum() < 5:
        return out
    th = theta[sel]
    rise = y_m[sel] - float(np.median(y_m[base]))
    npos, nneg = int((th > 0).sum()), int((th < 0).sum())
    out["two_sided"] = min(npos, nneg) >= 0.1 * th.size
    if out["two_sided"]:
        p, q = np.linalg.lstsq(np.c_[np.abs(th), th], rise, rcond=None)[0]
    else:  # |theta| and theta are one column: only the sign of the rise is known
        p, q = float(np.linalg.lstsq(np.abs(th)[:, None], rise, rcond=None)[0][0]), 0.0
    out["p"], out["q"] = float(p), float(q)
    return out


def check_up(source, name, ev, up_spec) -> None:
    """``W-3D-UP`` from :func:`up_evidence`."""
    why = []
    if ev["axis_tilt_rad"] > AXIS_TILT_MAX_RAD:
        why.append(
            f"its rotation axis is {math.degrees(ev['axis_tilt_rad']):.3g} deg above the horizontal "
            f"(a rocking edge is horizontal; bound {math.degrees(AXIS_TILT_MAX_RAD):.3g} deg)"
        )
    p, q = ev["p"], ev["q"]
    if np.isfinite(p):
        if ev["two_sided"] and abs(q) > SWAY_RATIO * abs(p):
            why.append(
                f"its centroid moves along --up with the sign of theta ({1e3 * q:.3g} mm/rad against a "
                f"rise of {1e3 * p:.3g} mm/rad), as along a horizontal axis"
            )
        elif p < 0:
            why.append(
                f"its centroid falls along --up when it tilts ({1e3 * p:.3g} mm/rad; a rocking block "
                "rises), so the vertical is reversed"
            )
    if why:
        warn(
            "W-3D-UP",
            f"{where(source)}{name}: --up {up_spec} is not the vertical: "
            + "; ".join(why)
            + "; give the rig's vertical axis with its sign",
        )
