"""DLTdv (Hedrick 2008) exports: ``*xypts.csv``, ``*DLTcoefs.csv`` and ``*xyzpts.csv``.

- ``xypts``: one row per frame, columns ``ptI_camJ_X, ptI_camJ_Y`` (px, in the convention the
  coefficients were computed in), ``NaN`` where a point was not digitised;
- ``DLTcoefs``: 11 rows, one column per camera, no header: the 11-parameter DLT
  ``u = (L1 X + L2 Y + L3 Z + L4) / (L9 X + L10 Y + L11 Z + 1)``,
  ``v = (L5 X + L6 Y + L7 Z + L8) / (L9 X + L10 Y + L11 Z + 1)``;
- ``xyzpts``: columns ``ptI_X, ptI_Y, ptI_Z`` in the calibration's unit;
- ``xyzres``: column ``ptI_dltres``, DLTdv's reconstruction residual (px, see
  :func:`dlt_residual`).

A point seen by two or more cameras in a frame is reconstructed by linear least squares on
the DLT equations (as DLTdv's ``dlt_reconstruct`` does); with one camera it stays NaN. Neither
file carries a unit or a time: the calibration's unit (``units``) and the frame rate (``fps``)
are required, never assumed.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..._errors import InputError, where
from ..rigid import PointSeries

__all__ = ["read_dltdv", "dlt_reconstruct", "dlt_project", "dlt_residual", "read_dlt_coefs"]

_LENGTH_M = {"m": 1.0, "cm": 0.01, "mm": 0.001}
_XY = re.compile(r"^pt(\d+)_cam(\d+)_([XY])$")
_XYZ = re.compile(r"^pt(\d+)_([XYZ])$")


def dlt_project(coefs: np.ndarray, xyz: np.ndarray) -> np.ndarray:
    """Image coordinates of 3D points by one camera's 11 DLT coefficients.

    Parameters
    ----------
    coefs : ndarray, shape (11,)
    xyz : ndarray, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 2)
    """
    L = np.asarray(coefs, float)
    X, Y, Z = xyz[..., 0], xyz[..., 1], xyz[..., 2]
    den = L[8] * X + L[9] * Y + L[10] * Z + 1.0
    u = (L[0] * X + L[1] * Y + L[2] * Z + L[3]) / den
    v = (L[4] * X + L[5] * Y + L[6] * Z + L[7]) / den
    return np.stack([u, v], axis=-1)


def dlt_reconstruct(coefs: np.ndarray, uv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """3D points from their image coordinates in several cameras.

    Parameters
    ----------
    coefs : ndarray, shape (11, c)
        DLT coefficients, one column per camera.
    uv : ndarray, shape (n, c, 2)
        Image coordinates per sample and camera; NaN where the camera did not see the point.

    Returns
    -------
    xyz : ndarray, shape (n, 3)
        Least-squares 3D position (calibration units); NaN where fewer than two cameras saw it.
    rms_px : ndarray, shape (n,)
        RMS reprojection residual over the cameras used, px (NaN where not reconstructed).
    """
    L = np.asarray(coefs, float)
    n, c, _ = uv.shape
    xyz = np.full((n, 3), np.nan)
    rms = np.full(n, np.nan)
    seen = np.isfinite(uv).all(axis=2)
    for i in np.flatnonzero(seen.sum(axis=1) >= 2):
        cams = np.flatnonzero(seen[i])
        rows, rhs = [], []
        for j in cams:
            u, v = uv[i, j]
            Lj = L[:, j]
            rows.append([Lj[0] - u * Lj[8], Lj[1] - u * Lj[9], Lj[2] - u * Lj[10]])
            rows.append([Lj[4] - v * Lj[8], Lj[5] - v * Lj[9], Lj[6] - v * Lj[10]])
            rhs += [u - Lj[3], v - Lj[7]]
        sol = np.linalg.lstsq(np.array(rows), np.array(rhs), rcond=None)[0]
        xyz[i] = sol
        back = np.stack([dlt_project(L[:, j], sol) for j in cams])
        rms[i] = float(np.sqrt(np.mean((back - uv[i, cams]) ** 2)))
    return xyz, rms


def dlt_residual(coefs: np.ndarray, uv: np.ndarray, xyz: np.ndarray) -> np.ndarray:
    """DLTdv's residual of 3D points (its ``xyzres`` export, ``dltres``), px.

    DLTdv 6 and later report the reprojection error over the ``k`` cameras that saw the point,
    conditioned by the reconstruction's degrees of freedom: ``sqrt(sum(du^2 + dv^2) / (2k - 3))``
    (one degree of freedom with two cameras), not the plain RMS of :func:`dlt_reconstruct`.

    Parameters
    ----------
    coefs : ndarray, shape (11, c)
    uv : ndarray, shape (n, c, 2)
        Image coordinates; NaN where a camera did not see the point.
    xyz : ndarray, shape (n, 3)
        The points' 3D positions (NaN where not reconstructed).

    Returns
    -------
    ndarray, shape (n,)
        NaN where ``xyz`` is NaN.
    """
    L = np.asarray(coefs, float)
    back = np.stack([dlt_project(L[:, j], xyz) for j in range(L.shape[1])], axis=1)
    seen = np.isfinite(uv).all(axis=2)
    sq = np.where(seen[..., None], (back - uv) ** 2, 0.0).sum(axis=(1, 2))
    dof = 2 * seen.sum(axis=1) - 3
    ok = np.isfinite(xyz).all(axis=1) & (dof > 0)
    out = np.full(len(xyz), np.nan)
    out[ok] = np.sqrt(sq[ok] / dof[ok])
    return out


def read_dlt_coefs(path) -> np.ndarray:
    """DLT coefficients, shape (11, cameras), from DLTdv's / easyWand's ``*DLTcoefs.csv``."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{where(path)}not found; give the *DLTcoefs.csv of the calibration")
    try:
        L = np.loadtxt(path, delimiter=",", ndmin=2)
    except ValueError as exc:
        raise InputError(f"{where(path)}not a table of numbers ({exc}); give DLTdv's *DLTcoefs.csv") from None
    if L.shape[0] != 11 or not np.isfinite(L).all():
        raise InputError(
            f"{where(path)}{L.shape[0]} rows; DLT coefficients are 11 finite rows with one column per camera"
        )
    return L


def _columns(path, pattern, what):
    import pandas as pd

    try:
        df = pd.read_csv(path, na_values=["NaN", "nan"], skipinitialspace=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise InputError(f"{where(path)}not a CSV table ({str(exc).splitlines()[0]}); give DLTdv's {what}") from None
    df.columns = [str(c).strip() for c in df.columns]
    bad = [c for c in df.columns if not pattern.match(c)]
    if bad or df.empty:
        raise InputError(
            f"{where(path, 1)}column {bad[0] if bad else '(none)'!r} is not a DLTdv {what} column "
            f"(pt1_cam1_X... or pt1_X...); export the {what} from DLTdv again"
        )
    vals = df.apply(pd.to_numeric, errors="coerce")
    wrong = np.argwhere(vals.isna().to_numpy() & df.notna().to_numpy())
    if wrong.size:
        r, c = wrong[0]
        raise InputError(
            f"{where(path, int(r) + 2, df.columns[c])}not a number ({df.iat[r, c]!r}); NaN marks a missing point"
        )
    return df.columns, vals.to_numpy(float)


def _time_and_scale(fps, units, path):
    if fps is None or not np.isfinite(fps) or fps <= 0:
        raise InputError(f"{where(path)}DLTdv files carry no time; give the cameras' frame rate with --fps (Hz)")
    if units not in _LENGTH_M:
        raise InputError(
            f"{where(path)}DLT coordinates carry no unit; give --units m, cm or mm (the unit of the "
            "calibration frame or wand length)"
        )
    return float(fps), _LENGTH_M[units]


def read_dltdv(path, coefs=None, fps: float | None = None, units: str | None = None):
    """Read DLTdv points as a :class:`rocklab.tracking.rigid.PointSeries` (metres, seconds).

    Parameters
    ----------
    path : str or Path
        ``*xyzpts.csv`` (3D, read as is) or ``*xypts.csv`` (2D per camera; needs ``coefs``).
    coefs : str or Path, optional
        ``*DLTcoefs.csv`` with one column per camera of the xypts file.
    fps : float
        Frame rate, Hz: row ``k`` is at ``t_s = k / fps``.
    units : {"m", "cm", "mm"}
        Unit of the calibration (of the coefficients' and the xyzpts' coordinates).

    Returns
    -------
    series : PointSeries
        Points ``pt1``, ``pt2``... in m.
    info : dict
        ``{"cameras": c, "reconstructed": True/False, "median_rms_px": ..., "median_dltres_px": ...}``:
        the median over reconstructed samples of the plain reprojection RMS and of DLTdv's own
        residual (:func:`dlt_residual`, what its ``xyzres`` holds); None for an ``xyzpts`` file.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{where(path)}not found; give DLTdv's *xypts.csv or *xyzpts.csv")
    rate, scale = _time_and_scale(fps, units, path)
    with open(path, encoding="utf-8", errors="replace") as fh:
        first = fh.readline()
    if "_cam" in first:
        return _from_xypts(path, coefs, rate, scale, units)
    cols, vals = _columns(path, _XYZ, "xyzpts")
    pts = sorted({int(_XYZ.match(c).group(1)) for c in cols})
    xyz = np.full((vals.shape[0], len(pts), 3), np.nan)
    for k, c in enumerate(cols):
        i, ax = _XYZ.match(c).groups()
        xyz[:, pts.index(int(i)), "XYZ".index(ax)] = vals[:, k]
    t = np.arange(vals.shape[0]) / rate
    notes = [f"rows at {rate:g} Hz"] + ([f"coordinates converted from {units} to m"] if scale != 1.0 else [])
    series = PointSeries(t, tuple(f"pt{i}" for i in pts), xyz * scale, str(path), tuple(notes))
    return series, {"cameras": None, "reconstructed": False, "median_rms_px": None, "median_dltres_px": None}


def _from_xypts(path, coefs, rate, scale, units):
    if coefs is None:
        raise InputError(f"{where(path)}2D points need the cameras' DLT coefficients; give --coefs *DLTcoefs.csv")
    L = read_dlt_coefs(coefs)
    cols, vals = _columns(path, _XY, "xypts")
    keys = [_XY.match(c).groups() for c in cols]
    pts = sorted({int(k[0]) for k in keys})
    cams = sorted({int(k[1]) for k in keys})
    if max(cams) > L.shape[1]:
        raise InputError(
            f"{where(coefs)}{L.shape[1]} camera column(s), but {path.name} has camera {max(cams)}; "
            "give the coefficients of this calibration"
        )
    uv = np.full((vals.shape[0], len(pts), L.shape[1], 2), np.nan)
    for k, (i, j, ax) in enumerate(keys):
        uv[:, pts.index(int(i)), int(j) - 1, "XY".index(ax)] = vals[:, k]
    xyz = np.full((vals.shape[0], len(pts), 3), np.nan)
    rms = np.full((vals.shape[0], len(pts)), np.nan)
    res = np.full((vals.shape[0], len(pts)), np.nan)
    for p in range(len(pts)):
        xyz[:, p], rms[:, p] = dlt_reconstruct(L, uv[:, p])
        res[:, p] = dlt_residual(L, uv[:, p], xyz[:, p])
    t = np.arange(vals.shape[0]) / rate
    notes = [f"rows at {rate:g} Hz", f"3D from {L.shape[1]} cameras by the DLT coefficients of {Path(coefs).name}"]
    if scale != 1.0:
        notes.append(f"coordinates converted from {units} to m")
    any_ = bool(np.isfinite(rms).any())
    series = PointSeries(t, tuple(f"pt{i}" for i in pts), xyz * scale, str(path), tuple(notes))
    return series, {
        "cameras": int(L.shape[1]),
        "reconstructed": True,
        "median_rms_px": float(np.nanmedian(rms)) if any_ else None,
        "median_dltres_px": float(np.nanmedian(res)) if any_ else None,
    }
