"""How well a region's appearance tells its angle: per object, whether it does at all (the share of
its image gradients that a turn moves); per frame, the registration's 1-sigma of the angle.

A turn about the region's centre moves each pixel along the tangent; the intensity change it
causes is the tangential component of the gradient times the radius. A shift moves every pixel
alike, so its information is the whole gradient. Their ratio,

    share = sum((r x g)^2) / sum(|r|^2 |g|^2),

is 1/2 for an isotropic texture, about 1/4 for a plain square (its corners), and 0 for a disk,
a ring or anything rotationally symmetric about the centre: there the registration's angle is
fixed by noise alone and is not a measurement.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "sigma_theta",
    "turn_share",
    "symmetry_centre",
    "theta_unobservable",
    "unshaded_turn_share",
    "angle_free_objects",
    "angle_note",
    "warn_theta",
    "warn_unmatched_angles",
    "MIN_TURN_SHARE",
    "cell_turn_info",
    "turn_information",
    "unmatched_turn_share",
    "CELL_TURN_GAP",
    "MAX_UNMATCHED_TURN",
    "MAX_UNMATCHED_ABOUT_MATCHED",
]

#: Least share of turning information for an angle to count as measured: a plain disk on a
#: plain wall gives under 1 %, a disk with its string across the region 13 %, a plain square 20 %.
MIN_TURN_SHARE = 0.05
#: Gaussian smoothing of the region before its gradients, px (sensor noise and codec blocks add
#: isotropic gradients that would otherwise lend a symmetric object an angle).
SMOOTH_PX = 1.0
#: Pixels are correlated over about a 3 x 3 neighbourhood: the covariance's σ is scaled by 3.
CORRELATION_INFLATION = 3.0
#: Cells a side over which the residual's pull on the angle is summed for its robust σ.
SANDWICH_GRID = 4
#: Largest Sobel response of a region taken as flat (grey levels per pixel, x 8).
FLAT_GRADIENT = 1e-3
#: A cell of the region (a 4 x 4 grid) whose correlation with the frame, warped back by the
#: pose, is this far under the median cell's does not match it.
CELL_TURN_GAP = 0.05
#: Share of the turning information in cells that do not match beyond which a frame's angle is
#: not a measurement: most of what tells the angle is not where the pose puts it, and the angle was
#: set by the rest (on PhysTrack's turning disc, the drawn box: the still rod's arm in a corner,
#: once the hand turning the disc and then its mark have left their cells, 63-92 % unmatched and
#: the angle 27-177 deg off with sigma 0.1 deg). Under it the cells that match hold the angle (a
#: textured block whose region shows a moving table at its foot: under 50 %, the angle right to
#: 0.05 deg).
MAX_UNMATCHED_TURN = 0.5
#: Share of the turning information about the point the matching cells turn about (the matching
#: cells' own, with the shift free, and the cells that do not match about that point) beyond which
#: a frame's angle is not a measurement either: the part the pose re-explains hardly tells the angle
#: (a round disc, whatever its place in the region) and what tells it does not match. A rendered
#: rocking block whose region's corners hold wall that leaves as it turns keeps 46-47 % of it in its
#: matching face (``tests/test_track_propose.py``, seed 8: 0.53-0.54 unmatched), the hand-held
#: pendulum's round disc before a still corner 17-27 % (review 16's box ``small80``: 0.73-0.83, the
#: angle 10-43 deg off with 0.5-2.4 deg sigma where the share about the centre was 0.45-0.48). The
#: bound lies between: two thirds, the unmatched part twice the matching part's.
MAX_UNMATCHED_ABOUT_MATCHED = 2.0 / 3.0
#: Inside a round object's disk, out to this fraction of its radius, its grey levels are split into
#: a lit sphere's shading and the texture on it; from there to :data:`RIM_OUTER` the outline, blurred
#: by the optics and the motion, whose change of contrast along it is shading as well.
RIM_INNER = 0.8
RIM_OUTER = 1.2
POINT_NOTE = 'kind = "point": a position only'
UNOBSERVABLE_NOTE = "its appearance tells no angle (W-TRACK-THETA)"


def _gradients(region):
    """(x, y, gx, gy): pixel coordinates (px, from pixel (0, 0)) and the smoothed Sobel gradients."""
    import cv2

    t = cv2.GaussianBlur(np.asarray(region, np.float32), (0, 0), SMOOTH_PX)
    h, w = t.shape
    gx = cv2.Sobel(t, cv2.CV_32F, 1, 0, ksize=3).astype(float)
    gy = cv2.Sobel(t, cv2.CV_32F, 0, 1, ksize=3).astype(float)
    x = np.broadcast_to(np.arange(w, dtype=float)[None, :], (h, w))
    y = np.broadcast_to(np.arange(h, dtype=float)[:, None], (h, w))
    return x, y, gx, gy


def symmetry_centre(region) -> np.ndarray:
    """The point about which a turn changes ``region`` (h, w) least, px from pixel (0, 0), (2,).

    The least-squares point of ``sum(((p - c) x g)^2)``: linear in ``c``, so solved in closed
    form; a disk's centre wherever it sits in the region.
    """
    return _centre_of(*_gradients(region))


def _centre_of(x, y, gx, gy) -> np.ndarray:
    # (p - c) x g = (x gy - y gx) - (cx gy - cy gx): least squares in (cx, cy)
    A = np.column_stack((gy.ravel(), -gx.ravel()))
    b = (x * gy - y * gx).ravel()
    c, *_ = np.linalg.lstsq(A, b, rcond=None)
    return c


def _share_of(x, y, gx, gy, centre) -> float:
    """:func:`turn_share` from the region's coordinates and gradients (:func:`_gradients`)."""
    if float(np.max(np.hypot(gx, gy))) < FLAT_GRADIENT:
        return float("nan")
    x, y = x - centre[0], y - centre[1]
    tangential = float(np.sum((x * gy - y * gx) ** 2))
    radial = float(np.sum((x * gx + y * gy) ** 2))
    return tangential / (tangential + radial)


def turn_share(region, centre=None) -> float:
    """The share of ``region``'s gradient information that a turn moves, about ``centre``.

    Parameters
    ----------
    region : ndarray, shape (h, w)
        Grey levels.
    centre : (2,) array-like, optional
        Centre of the turn, px from pixel (0, 0); default :func:`symmetry_centre` (the least).

    Returns
    -------
    float
        0 (rotationally symmetric about the centre) to about 0.5 (isotropic texture); NaN for a
        flat region.

    Examples
    --------
    >>> import numpy as np
    >>> yy, xx = np.mgrid[-40:41, -40:41]
    >>> disk = np.where((xx - 6) ** 2 + yy**2 < 25**2, 200.0, 100.0)
    >>> round(turn_share(disk), 2)
    0.0
    >>> rng = np.random.default_rng(0)
    >>> 0.4 < turn_share(rng.random((81, 81)) * 255) < 0.6
    True
    """
    g = _gradients(region)
    return _share_of(*g, _centre_of(*g) if centre is None else centre)


def cell_turn_info(region, n_cells: int) -> np.ndarray:
    """Each cell's Gauss-Newton information on (a turn about the region's centre, a shift in x, a
    shift in y), shape (n_cells, n_cells, 3, 3): what each part of ``region`` (h, w) tells of its
    pose; summed over a set of cells, :func:`turn_information` takes the turn's part of it.

    Examples
    --------
    >>> import numpy as np
    >>> img = np.zeros((64, 64)); img[4:12, 4:12] = 255.0  # one mark, in the top-left cell
    >>> info = cell_turn_info(img, 4)
    >>> round(float(info[0, 0, 0, 0] / info[..., 0, 0].sum()), 2)
    1.0
    """
    x, y, gx, gy = _gradients(region)
    h, w = x.shape
    cols = np.stack((((x - (w - 1) / 2) * gy - (y - (h - 1) / 2) * gx), gx, gy))
    ys, xs = (np.linspace(0, k, n_cells + 1).astype(int) for k in (h, w))
    out = np.zeros((n_cells, n_cells, 3, 3))
    for i in range(n_cells):
        for j in range(n_cells):
            c = cols[:, ys[i] : ys[i + 1], xs[j] : xs[j + 1]].reshape(3, -1)
            out[i, j] = c @ c.T
    return out


def turn_information(info, cells=None) -> tuple:
    """The information on a turn left once a shift is free, and the point it turns about, of the
    cells ``cells`` (bool, shape of ``info``'s first two axes; default all) of
    :func:`cell_turn_info`'s ``info``.

    A turn about any point is a turn about the region's centre and a shift, so what a set of cells
    tells of the angle is the turn's information with the shift's part taken out (a Schur
    complement): a disk's cells tell none whatever the region's centre, a rod or an edge off the
    disk's centre does. Its least is about the point returned (template px, from the region's
    centre, (2,)): where the cells change least when turned, a disk's centre.

    Returns
    -------
    (float, ndarray)
        Information (grey level² px², as the gradients), and the point (px, x right, y down).
    """
    sel = np.ones(info.shape[:2], bool) if cells is None else np.asarray(cells, bool)
    M = info[sel].sum(axis=0) if sel.any() else np.zeros((3, 3))
    sol, *_ = np.linalg.lstsq(M[1:, 1:], M[1:, 0], rcond=None)
    return max(float(M[0, 0] - M[0, 1:] @ sol), 0.0), np.array([sol[1], -sol[0]])


def unmatched_turn_share(info, cell_cc, seen=None, covered_cc: float = -1.0) -> tuple:
    """The share of the turning information (:func:`cell_turn_info`'s ``info``) of the cells in view
    lost when the cells whose correlation with the frame warped back by the pose, ``cell_cc`` (same
    shape), falls more than :data:`CELL_TURN_GAP` under the median cell's are left out: the parts
    that tell the angle and are not re-explained by the pose as the rest of the region is (a look
    that changes as a whole, the lighting or a blur, lowers every cell instead).

    Taken twice. About the region's centre: a still background in the region's corners that holds
    most of it set the angle. And about the point the matching cells turn about
    (:func:`turn_information`, the shift free), the matching cells' own information against the
    unmatched cells' about that point: a round disc's outline the pose re-explains tells no angle
    wherever it sits in the region, so a disc before a still corner has little of its own there,
    while a block's face keeps about half (:data:`MAX_UNMATCHED_ABOUT_MATCHED`). Taken about that
    point alone, a rendered rocking block whose region holds wall in its corners lost its angle on
    102 of 140 frames (``tests/test_track_propose.py``, seed 8) under :data:`MAX_UNMATCHED_TURN`.

    ``seen``: cells inside the picture (default all); a cell out of it is neither. A frame with a
    cell under ``covered_cc`` is a covered view (the fit on the cells in view decides it): 0.

    Returns
    -------
    (float, float, ndarray)
        The share about the region's centre and the share about the matching cells' turning point
        (0 to 1 each), and that point (px from the region's centre): a disk's centre, where its
        place does not hang on the angle.
    """
    cell_cc = np.asarray(cell_cc)
    seen = np.ones(cell_cc.shape, bool) if seen is None else np.asarray(seen, bool)
    matched = seen & (cell_cc >= np.median(cell_cc) - CELL_TURN_GAP)
    _, centre = turn_information(info, matched)
    if cell_cc.min() < covered_cc:
        return 0.0, 0.0, centre
    shares = []
    # each cell's tangential energy about the region's centre, then about the matching cells' point
    for v in (np.array([1.0, 0.0, 0.0]), np.array([1.0, centre[1], -centre[0]])):
        energy = np.einsum("i,...ij,j->...", v, info, v) * seen
        total = float(energy.sum())
        shares.append(float(np.sum(energy[~matched]) / total) if total > 0 else 0.0)
    return shares[0], shares[1], centre


def theta_unobservable(region):
    """Why the angle of the object in ``region`` (h, w) cannot be measured and its centre of
    symmetry (px from pixel (0, 0), (2,)); ``(None, None)`` when the angle can be measured."""
    g = _gradients(region)
    c = _centre_of(*g)
    share = _share_of(*g, c)
    if not share >= MIN_TURN_SHARE:
        return (
            f"its appearance barely changes when it turns (turning share of its gradients "
            f"{100 * share:.3g} %, under {100 * MIN_TURN_SHARE:.3g} %: symmetric or textureless)"
        ), c
    return None, None


def _sphere_shading_basis(u, v):
    """The nine real spherical harmonics up to second order of a sphere's normal seen at ``(u, v)``
    (image offsets from its centre over its radius): the shading of a convex Lambertian object under
    any distant lighting lies within 1-2 % of their span (Basri & Jacobs 2003, IEEE PAMI 25(2);
    Ramamoorthi & Hanrahan 2001, JOSA A 18(10)), and it stays with the light, not with the object."""
    z = np.sqrt(np.clip(1.0 - u * u - v * v, 0.0, None))
    return [np.ones_like(u), u, v, z, u * v, u * z, v * z, u * u - v * v, 3.0 * z * z - 1.0]


def unshaded_turn_share(region, centre, radius: float) -> float:
    """The share of ``region``'s gradient information that a turn about a round object's disk
    (``centre``, px from pixel (0, 0), (2,); ``radius``, px) moves, once the disk's shading is taken
    out: :func:`turn_share` about the disk's centre with the tangential part of the gradients of the
    disk's interior (to :data:`RIM_INNER` of the radius) taken from the grey levels less their
    least-squares fit by a lit sphere's shading (:func:`_sphere_shading_basis`), and none from its
    blurred outline (:data:`RIM_INNER` to :data:`RIM_OUTER`). A plain ball's dark and lit sides turn
    no gradient with the ball: what is left is its marks, and what lies off the disk (a string).

    Returns
    -------
    float
        0 to about 0.5; NaN for a flat region or a disk with too few pixels inside.

    Examples
    --------
    >>> import numpy as np
    >>> yy, xx = np.mgrid[0:81, 0:81].astype(float)
    >>> u, v = (xx - 40) / 30, (yy - 40) / 30
    >>> lit = np.clip(0.6 * np.sqrt(np.clip(1 - u * u - v * v, 0, None)) - 0.8 * u, 0, None)
    >>> ball = np.where(u * u + v * v < 1, 40 + 180 * lit, 150.0)  # lit from the left
    >>> round(turn_share(ball, (40, 40)), 3), round(unshaded_turn_share(ball, (40, 40), 30.0), 3)
    (0.042, 0.001)
    >>> ball[36:44, 22:58] -= 60.0  # a dark band across it
    >>> round(unshaded_turn_share(ball, (40, 40), 30.0), 3)
    0.02
    """
    x, y, gx, gy = _gradients(region)
    if float(np.max(np.hypot(gx, gy))) < FLAT_GRADIENT:
        return float("nan")
    dx, dy = x - float(centre[0]), y - float(centre[1])
    r = np.hypot(dx, dy)
    inside = r < RIM_INNER * radius
    basis = _sphere_shading_basis(dx / radius, dy / radius)
    if int(inside.sum()) < 4 * len(basis):
        return float("nan")
    t = np.asarray(region, float)
    coef, *_ = np.linalg.lstsq(np.stack([b[inside] for b in basis], 1), t[inside], rcond=None)
    shading = sum(c * b for c, b in zip(coef, basis))
    _, _, sx, sy = _gradients(shading)
    tangential = np.where(inside, dx * (gy - sy) - dy * (gx - sx), dx * gy - dy * gx) ** 2
    tangential[(r >= RIM_INNER * radius) & (r <= RIM_OUTER * radius)] = 0.0
    total = float(np.sum((dx * gy - dy * gx) ** 2 + (dx * gx + dy * gy) ** 2))
    return float(tangential.sum() / total)


def angle_free_objects(config, detector) -> dict:
    """The objects of ``config`` whose angle is not reported, with the reason: kind ``"point"``,
    and blocks whose detector finds their appearance tells no angle (warning W-TRACK-THETA).

    Returns
    -------
    dict
        object id -> reason (one line).
    """
    out = {}
    for o in config.objects:
        why = detector.theta_note(o.id) if hasattr(detector, "theta_note") else None
        if o.kind == "point":
            out[o.id] = POINT_NOTE
        elif why is not None:
            out[o.id] = why
            warn_theta(config, o.id, why)
    return out


def warn_theta(config, oid, why, frame=None):
    """W-TRACK-THETA for object ``oid`` (``frame``: the frame it was found at, when not the first)."""
    from ...._diagnostics import warn

    at = "" if frame is None else f" (found at frame {frame}; theta_rad is dropped on every frame)"
    warn(
        "W-TRACK-THETA",
        f"{config.source or 'config'}: object {oid!r}: theta cannot be measured: {why}{at}; "
        'theta_rad is NaN, x and y are tracked; set kind = "point" to track a position only, '
        "or draw the region round a part that shows the turn (an edge, a mark)",
    )


def warn_unmatched_angles(config, detector) -> None:
    """W-TRACK-THETA for each object whose angle was dropped on some frames because the parts of
    its region that tell the angle did not match the pose (:func:`unmatched_turn_share`). Not for
    an object whose angle awaits the shading verdict at the film's end: its angle is dropped on
    every frame, and that warning says why."""
    from ...._diagnostics import warn

    if detector is None or not hasattr(detector, "theta_unmatched"):
        return
    pending = getattr(detector, "theta_pending", lambda oid: None)
    for o in config.objects:
        n, k = detector.theta_unmatched(o.id)
        if k and pending(o.id) is None:
            warn(
                "W-TRACK-THETA",
                f"{config.source or 'config'}: object {o.id!r}: theta not measured on {k} of {n} frames "
                f"tracked: there, the parts of its region in view that hold over {100 * MAX_UNMATCHED_TURN:.0f} "
                f"% of its turning information (over {100 * MAX_UNMATCHED_ABOUT_MATCHED:.0f} % about the point the "
                "rest turns about) do not match the fitted pose as the rest of the region does "
                f"(their correlation more than {CELL_TURN_GAP:g} under the median cell's), or it was "
                "registered on a keyframe cut from such a frame, or its inscribed disc turned best "
                "elsewhere, or the fit went on from such a frame off the last angle measured; "
                "theta_rad is NaN on those frames, "
                "x and y are tracked; draw the region round the object alone (no background or "
                "other object in its corners)",
            )


def angle_note(obj, status, theta_rad) -> str:
    """Why an assembled track's angle is NaN on every frame it has: kind ``"point"``, or an
    appearance that tells none (frames ``ok`` with no angle); ``""`` when the angle is measured.

    Parameters
    ----------
    obj : ObjectConfig
    status : ndarray (n,) of str
    theta_rad : ndarray (n,)
    """
    if obj.kind == "point":
        return POINT_NOTE
    ok = np.asarray(status) == "ok"
    if ok.any() and not np.any(np.isfinite(np.asarray(theta_rad, float)[ok])):
        return UNOBSERVABLE_NOTE
    return ""


def sigma_theta(tmpl, warped, mask=None, tmpl_normalised=None) -> float:
    """Gauss-Newton 1-sigma of a registration's angle, rad: ``σ² (JᵀJ)⁻¹`` with σ the intensity
    residual, inflated by :data:`CORRELATION_INFLATION` because neighbouring pixels are not
    independent (optics, codec, the registration's smoothing); at least the cluster-robust σ
    from how the residual pulls the angle cell by cell (:func:`_cell_robust_sigma`).

    Parameters
    ----------
    tmpl : ndarray, shape (h, w), float32
        The template.
    warped : ndarray, shape (h, w), float32
        The frame warped back onto the template's grid by the registered pose.
    mask : ndarray, shape (h, w), optional
        Pixels still in view (1) when part of the object is covered; both residual and
        gradients are taken on those only.
    tmpl_normalised : ndarray, optional
        ``tmpl`` at zero mean and unit variance, when the caller keeps it (no mask only).

    Returns
    -------
    float
        rad; ``inf`` when the angle is not determined.
    """
    import math

    import cv2

    h, w = tmpl.shape
    # the registration matches up to gain and offset: compare zero-mean, unit-variance patches
    if mask is None:
        a = tmpl_normalised if tmpl_normalised is not None else (tmpl - tmpl.mean()) / (tmpl.std() + 1e-9)
        b = warped - float(warped.mean())
        b /= math.sqrt(float(np.dot(b.ravel(), b.ravel())) / b.size) + 1e-9
    else:
        a = (tmpl - tmpl[mask].mean()) / (tmpl[mask].std() + 1e-9)
        b = (warped - warped[mask].mean()) / (warped[mask].std() + 1e-9)
    r = a - b
    gx = cv2.Sobel(b, cv2.CV_32F, 1, 0, ksize=3) / 8.0
    gy = cv2.Sobel(b, cv2.CV_32F, 0, 1, ksize=3) / 8.0
    if mask is not None:  # covered pixels contribute neither residual nor gradient
        r, gx, gy = r * mask, gx * mask, gy * mask
    # every 2nd pixel each way: JᵀJ of the full grid is 4 times the subsample's to well under
    # a percent on any textured region, at a quarter of the cost
    k = 2 if min(h, w) >= 32 else 1
    n_used = r[::k, ::k].size if mask is None else int(mask[::k, ::k].sum())
    gx, gy, r = gx[::k, ::k], gy[::k, ::k], r[::k, ::k]
    xc = (np.arange(0, w, k, dtype=np.float32) - w / 2)[None, :]
    yc = (np.arange(0, h, k, dtype=np.float32) - h / 2)[:, None]
    cols = [(-yc * gx + xc * gy).ravel(), np.ascontiguousarray(gx).ravel(), np.ascontiguousarray(gy).ravel()]
    # JᵀJ from the six distinct dot products (float64 sums of float32 columns)
    JTJ = np.empty((3, 3))
    for i in range(3):
        for j in range(i, 3):
            JTJ[i, j] = JTJ[j, i] = float(np.dot(cols[i].astype(float), cols[j].astype(float)))
    JTJ *= k * k
    rr = r.ravel().astype(float)
    s2 = float(np.dot(rr, rr)) / max(n_used - 3, 1)
    try:
        inv = np.linalg.inv(JTJ)
    except np.linalg.LinAlgError:
        return math.inf
    gn = CORRELATION_INFLATION * math.sqrt(max(s2 * inv[0, 0], 0.0))
    return max(gn, _cell_robust_sigma(cols, rr, r.shape, inv, k))


def _cell_robust_sigma(cols, rr, shape, inv, k) -> float:
    """The angle's 1-sigma, rad, from how the residual pulls on it cell by cell (a cluster-robust
    sandwich over a :data:`SANDWICH_GRID` grid): about the Gauss-Newton σ where the residual is
    noise, larger where parts of the region pull the angle different ways and the fit is their
    balance (a still background in the region against the object's own edge)."""
    import math

    g = SANDWICH_GRID
    score = (np.stack(cols).astype(float) * rr[None, :]).reshape(3, *shape)
    ys, xs = (np.linspace(0, n, g + 1).astype(int)[:-1] for n in shape)
    per_cell = np.add.reduceat(np.add.reduceat(score, ys, axis=1), xs, axis=2).reshape(3, -1) * (k * k)
    B = per_cell @ per_cell.T * (g * g / (g * g - 1))
    return math.sqrt(max(float((inv @ B @ inv)[0, 0]), 0.0))
