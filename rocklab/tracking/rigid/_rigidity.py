"""Which points move as one rigid body: the set-up checks made before any pose is trusted.

A body's pose is a least-squares fit of its points' rest shape, so a point that belongs to
another body (a table marker listed with the block's, a marker named in two bodies) does not
stop the fit: it bends the pose a little at every sample, and the audit then reports the
bend as sliding, uplift or twist of the block. These checks name the set-up error first.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..._errors import InputError, where

__all__ = ["rigid_groups", "check_rigid_body", "check_bodies_disjoint", "stray_points"]

#: A point whose distances to a body's other points spread by more than this many times the
#: body's typical spread (and by more than :data:`STRAY_FLOOR_M`) is not on that body.
STRAY_FACTOR = 10.0
#: Distance spreads below this are accepted whatever the body's noise, m (soft marker bases,
#: skin of a concrete block: a fraction of a millimetre).
STRAY_FLOOR_M = 2e-3


def _distance_spread(xyz) -> np.ndarray:
    """(p, p) 5th-95th percentile spread of every pairwise distance over the record, m (NaN: never seen together)."""
    step = max(1, xyz.shape[0] // 2000)
    sub = xyz[::step]
    d = np.linalg.norm(sub[:, :, None, :] - sub[:, None, :, :], axis=3)  # (m, p, p)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # pairs never seen together stay NaN
        lo, hi = np.nanpercentile(d, [5, 95], axis=0)
    return hi - lo


def rigid_groups(xyz, labels, tol_m: float = 1e-3) -> list:
    """Groups of points whose mutual distances stay within ``tol_m`` (5th-95th percentile) over the record.

    Parameters
    ----------
    xyz : ndarray, shape (n, p, 3)
        Positions, m.
    labels : sequence of str, length p
    tol_m : float
        Largest spread of a pairwise distance that still links two points, m.

    Returns
    -------
    list of tuple of str
        Connected groups, largest first (single points left out).
    """
    from scipy.sparse.csgraph import connected_components

    p = xyz.shape[1]
    spread = _distance_spread(xyz)
    link = np.isfinite(spread) & (spread < tol_m)
    np.fill_diagonal(link, False)
    _, comp = connected_components(link, directed=False)
    groups = [tuple(labels[i] for i in range(p) if comp[i] == c) for c in np.unique(comp)]
    return sorted((g for g in groups if len(g) > 1), key=len, reverse=True)


def stray_points(xyz, labels) -> list[tuple[str, float, float]]:
    """Points that do not keep their distances to the rest of their body.

    Parameters
    ----------
    xyz : ndarray, shape (n, p, 3)
        One body's points, m.
    labels : sequence of str, length p

    Returns
    -------
    list of (label, spread_m, typical_m)
        Each stray point, the median spread of its distances to the body's other points, m, and
        the body's typical (median) spread, m. Empty when every point keeps its distances.
    """
    spread = _distance_spread(np.asarray(xyz, float))
    np.fill_diagonal(spread, np.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        per_point = np.nanmedian(spread, axis=1)
        typical = float(np.nanmedian(per_point))
    if not np.isfinite(typical):
        return []
    limit = max(STRAY_FLOOR_M, STRAY_FACTOR * typical)
    return [(labels[i], float(v), typical) for i, v in enumerate(per_point) if np.isfinite(v) and v > limit]


def check_bodies_disjoint(bodies: dict, source="") -> None:
    """:class:`InputError` when one point is listed in two bodies (a marker sits on one body).

    Parameters
    ----------
    bodies : dict
        ``{name: (label, ...)}``.
    source : str
        The file read (for the message).
    """
    owner: dict = {}
    for name, labels in bodies.items():
        for lab in labels:
            if lab in owner:
                raise InputError(
                    f"{where(source)}point {lab!r} is listed in body {owner[lab]!r} and in body {name!r}; "
                    "a marker sits on one body: remove it from one --body list"
                )
            owner[lab] = name


def check_rigid_body(name, labels, xyz, poses, source) -> None:
    """:class:`InputError` when a body's points do not move as one rigid body.

    Two tests: a pose residual far above the body's own at rest (several groups, with the
    ``--body`` lists that would separate them), then a point whose distances to the others
    spread far more than theirs (a static or foreign point in a moving body, named in the
    message: it bends the fit too little for the first test).

    Parameters
    ----------
    name : str
        The body's name.
    labels : sequence of str, length p
    xyz : ndarray, shape (n, p, 3)
        The body's points, m.
    poses : BodyPoses
        Their rigid fit (``rms_m``: residual per sample, m).
    source : str
        The file read (for the message).
    """
    rms = poses.rms_m
    if not np.isfinite(rms).any():
        return
    rest_rms = float(np.nanmedian(rms[: max(5, rms.size // 20)]))
    with np.errstate(all="ignore"):
        run_rms = float(np.nanpercentile(rms, 95))
    typical = float(np.nanmin([rest_rms, np.nanmedian(rms)]))
    if not (np.isfinite(run_rms) and run_rms > max(10.0 * typical, 1e-3)):
        _check_stray(name, labels, xyz, source)
        return
    groups = rigid_groups(xyz, list(labels))
    names: list[str] = []
    for g in groups[:4]:
        cen = np.nanmean(xyz[:, [list(labels).index(lab) for lab in g]], axis=1)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            still = float(np.nanmax(np.nanpercentile(cen, 95, axis=0) - np.nanpercentile(cen, 5, axis=0))) < 2e-3
        names.append("table" if still and "table" not in names else f"block{len(names) + 1}")
    hint = " ".join(f"--body {n}={','.join(g)}" for n, g in zip(names, groups))
    raise InputError(
        f"{where(source)}the points of body {name!r} do not move as one rigid body (pose residual "
        f"{run_rms * 1e3:.4g} mm at the 95th percentile, {typical * 1e3:.4g} mm typical): some belong "
        f"to another body; list each body's points, e.g. {hint or '--body NAME=P1,P2,P3'}"
    )


def _check_stray(name, labels, xyz, source) -> None:
    """:class:`InputError` naming the points of a body that are not on it (:func:`stray_points`);
    when more than half stray the body list is not a mistake of one point, and the audit decides."""
    stray = stray_points(xyz, list(labels))
    if stray and len(stray) <= len(labels) // 2:
        keep = [lab for lab in labels if lab not in {s[0] for s in stray}]
        desc = ", ".join(f"{lab} ({v * 1e3:.4g} mm)" for lab, v, _ in stray)
        raise InputError(
            f"{where(source)}body {name!r}: point(s) {desc} do not keep their distances to the body's other "
            f"points (those spread by {stray[0][2] * 1e3:.4g} mm): a point of another body, the table's if it "
            f"stays still; remove it, e.g. --body {name}={','.join(keep)}"
        )
