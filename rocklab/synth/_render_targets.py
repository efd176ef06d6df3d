"""Object textures for synthetic sessions: block faces with ArUco markers, dots or plain
faces (for edge tracking), and the shake-table front face.

A texture is the object's front face painted in its *body frame* (m, ``x``
right, ``y`` up, origin at the bottom centre of a block / the top centre of the
table) on a fine grid (several texels per output pixel). Every shape is painted
with its exact area coverage per texel (rectangles and marker modules
analytically, circles by signed distance), so edges carry no aliasing bias.
The texture is then low-pass filtered with a Gaussian of ``psf_px`` output
pixels (the camera's optical + pixel-area blur): point-sampling it bilinearly at
the pixel centres is then an unbiased sub-pixel rendering. Luminance is grey
levels 0..255, stored premultiplied by coverage (alpha).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Texture", "block_texture", "table_texture", "BLACK", "WHITE"]

BLACK, WHITE = 22.0, 238.0  # printed black / white paper, grey levels


@dataclass(frozen=True)
class Texture:
    """A prefiltered RGBA-like (grey, alpha) image of an object's face.

    Attributes
    ----------
    img : ndarray (h, w, 2) float32
        Premultiplied grey (0..255) and alpha (0..1).
    x0_m, y0_m : float
        Body coordinates of the centre of texel (row 0, column 0) (top-left), m.
    texel_m : float
        Texel size, m.
    outline_m : ndarray (4, 2)
        Body-frame corners of the object's face, m (for bounding boxes).
    features : dict
        Body-frame target geometry: ``markers`` {id: (4, 2) corners, ArUco
        order TL, TR, BR, BL as printed}, ``dots`` (n, 2) centres, ``dot_diameter_m``.
    """

    img: np.ndarray
    x0_m: float
    y0_m: float
    texel_m: float
    outline_m: np.ndarray
    features: dict = field(default_factory=dict)


class _Painter:
    def __init__(self, xmin, xmax, ymin, ymax, texel_m, pad_m):
        s = texel_m
        self.s = s
        nx = int(np.ceil((xmax - xmin + 2 * pad_m) / s)) + 1
        ny = int(np.ceil((ymax - ymin + 2 * pad_m) / s)) + 1
        self.x0 = xmin - pad_m
        self.y0 = ymax + pad_m
        self.xc = self.x0 + s * np.arange(nx)  # texel centres, columns
        self.yc = self.y0 - s * np.arange(ny)  # rows, top to bottom
        self.L = np.zeros((ny, nx), np.float64)
        self.A = np.zeros((ny, nx), np.float64)

    def _cov1(self, c, a, b):
        s = self.s
        return np.clip(np.minimum(c + s / 2, b) - np.maximum(c - s / 2, a), 0, None) / s

    def _slices(self, x0, x1, y0, y1):
        s = self.s
        j0 = max(0, int(np.floor((x0 - self.x0) / s)) - 1)
        j1 = min(len(self.xc), int(np.ceil((x1 - self.x0) / s)) + 2)
        i0 = max(0, int(np.floor((self.y0 - y1) / s)) - 1)
        i1 = min(len(self.yc), int(np.ceil((self.y0 - y0) / s)) + 2)
        return slice(i0, i1), slice(j0, j1)

    def rect(self, x0, x1, y0, y1, value, opaque=False):
        """Paint an axis-aligned rectangle; ``opaque`` also adds to alpha (object outline)."""
        si, sj = self._slices(x0, x1, y0, y1)
        c = np.outer(self._cov1(self.yc[si], y0, y1), self._cov1(self.xc[sj], x0, x1))
        self._blend(si, sj, c, value, opaque)

    def grid(self, x0, y0, size, modules: np.ndarray, dark, light):
        """Paint a square of ``modules`` (n, n, 0/1 from the top-left) with exact coverage."""
        n = modules.shape[0]
        si, sj = self._slices(x0, x0 + size, y0, y0 + size)
        edges = np.linspace(0.0, size, n + 1)
        cx = np.stack([self._cov1(self.xc[sj], x0 + edges[k], x0 + edges[k + 1]) for k in range(n)], 1)
        # rows of the module image run top (y0 + size) to bottom
        cy = np.stack([self._cov1(self.yc[si], y0 + size - edges[k + 1], y0 + size - edges[k]) for k in range(n)], 1)
        vals = np.where(modules > 0, light, dark).astype(float)
        paint = cy @ vals @ cx.T
        cov = np.outer(cy.sum(1), cx.sum(1))
        self.L[si, sj] = self.L[si, sj] * (1 - cov) + paint

    def circle(self, cx, cy, r, value):
        si, sj = self._slices(cx - r, cx + r, cy - r, cy + r)
        d = np.hypot(self.xc[sj][None, :] - cx, self.yc[si][:, None] - cy)
        c = np.clip(0.5 - (d - r) / self.s, 0.0, 1.0)
        self._blend(si, sj, c, value, False)

    def _blend(self, si, sj, c, value, opaque):
        self.L[si, sj] = self.L[si, sj] * (1 - c) + value * c
        if opaque:
            self.A[si, sj] = self.A[si, sj] * (1 - c) + c

    def finish(self, psf_texels: float, outline, features) -> Texture:
        import cv2

        img = np.dstack([self.L * self.A, self.A]).astype(np.float32)
        if psf_texels > 0:
            img = cv2.GaussianBlur(img, (0, 0), psf_texels, borderType=cv2.BORDER_CONSTANT)
        return Texture(
            np.ascontiguousarray(img),
            float(self.x0),
            float(self.y0),
            float(self.s),
            np.asarray(outline, float),
            features,
        )


def _aruco_modules(dictionary: str, marker_id: int) -> np.ndarray:
    import cv2

    d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, dictionary))
    n = d.markerSize + 2
    return (cv2.aruco.generateImageMarker(d, int(marker_id), n, borderBits=1) > 127).astype(np.uint8)


def _speckle(p: _Painter, si, sj, rng, amp: float, grain_m: float):
    import cv2

    h, w = p.L[si, sj].shape
    gh, gw = max(2, int(h * p.s / grain_m)), max(2, int(w * p.s / grain_m))
    noise = rng.standard_normal((gh, gw)).astype(np.float32)
    return amp * cv2.resize(noise, (w, h), interpolation=cv2.INTER_CUBIC)


#: Photographs in rocklab/data/textures (see its PROVENANCE.md) and the width each covers, m.
PHOTOS = {"gravel": 0.25, "brick": 1.5}


def photo_texture(name: str) -> np.ndarray:
    """Grey photograph ``name`` (:data:`PHOTOS`), float32, zero mean and unit standard deviation.

    Returns
    -------
    ndarray, shape (512, 512)
    """
    from importlib.resources import files

    import cv2

    raw = (files("rocklab") / "data" / "textures" / f"{name}.png").read_bytes()
    img = cv2.imdecode(np.frombuffer(raw, np.uint8), cv2.IMREAD_GRAYSCALE).astype(np.float32)
    return (img - img.mean()) / img.std()


def _photo(p: _Painter, si, sj, rng, name: str, amp: float):
    """The photograph at its physical size over the painter's region, from a random offset (tiled)."""
    import cv2

    img = photo_texture(name)
    h, w = p.L[si, sj].shape
    pix_m = PHOTOS[name] / img.shape[1]
    ny, nx = int(np.ceil(h * p.s / pix_m)) + 2, int(np.ceil(w * p.s / pix_m)) + 2
    i0, j0 = (int(v) for v in rng.integers(0, img.shape[0], 2))
    crop = np.take(np.take(img, np.arange(i0, i0 + ny) % img.shape[0], 0), np.arange(j0, j0 + nx) % img.shape[1], 1)
    interp = cv2.INTER_AREA if p.s > pix_m else cv2.INTER_CUBIC
    return amp * cv2.resize(crop, (w, h), interpolation=interp)


def _marker_corners(x0, y0, size):
    # ArUco corner order as printed: top-left, top-right, bottom-right, bottom-left.
    return np.array([[x0, y0 + size], [x0 + size, y0 + size], [x0 + size, y0], [x0, y0]])


def block_texture(
    b_m,
    h_m,
    style,
    *,
    marker_ids=(),
    dictionary="DICT_4X4_50",
    marker_size_m=None,
    dot_diameter_m=None,
    texel_m,
    psf_px_m,
    rng,
    face_value=None,
    texture: str = "procedural",
) -> Texture:
    """Front face of a block ``b_m`` x ``h_m`` (m) with its targets.

    ``style``: ``"aruco"`` (markers stacked on the centre line, each on a white
    quiet zone), ``"dots"`` (four black dots on white, an asymmetric layout so
    the set has no symmetry), ``"edges"`` (plain light stone with faint speckle),
    ``"markerless"`` (granite-like stone: synthetic grains, or with
    ``texture="photo"`` the gravel photograph of :data:`PHOTOS`).
    ``psf_px_m`` is the Gaussian prefilter sigma in metres on the face.
    """
    pad = 4 * psf_px_m + 2 * texel_m
    p = _Painter(-b_m / 2, b_m / 2, 0.0, h_m, texel_m, pad)
    feats: dict = {}
    outline = np.array([[-b_m / 2, 0], [b_m / 2, 0], [b_m / 2, h_m], [-b_m / 2, h_m]])
    if style == "edges":
        p.rect(-b_m / 2, b_m / 2, 0, h_m, face_value or 212.0, opaque=True)
        si, sj = p._slices(-b_m / 2, b_m / 2, 0, h_m)
        p.L[si, sj] += _speckle(p, si, sj, rng, 6.0, 0.004)
    elif style == "markerless":
        # granite-like stone: grains at two scales over a mid-grey face, no targets at all
        p.rect(-b_m / 2, b_m / 2, 0, h_m, face_value or 150.0, opaque=True)
        si, sj = p._slices(-b_m / 2, b_m / 2, 0, h_m)
        if texture == "photo":
            p.L[si, sj] += _photo(p, si, sj, rng, "gravel", 26.0)
        else:
            p.L[si, sj] += _speckle(p, si, sj, rng, 22.0, 0.0025) + _speckle(p, si, sj, rng, 14.0, 0.01)
    elif style == "aruco":
        p.rect(-b_m / 2, b_m / 2, 0, h_m, face_value or 196.0, opaque=True)
        n = len(marker_ids)
        s = marker_size_m
        pitch = h_m / n
        feats["markers"] = {}
        for k, mid in enumerate(marker_ids):
            yc = pitch * (k + 0.5)
            q = s / 6 * 1.0  # quiet zone: one module width
            p.rect(-s / 2 - q, s / 2 + q, yc - s / 2 - q, yc + s / 2 + q, WHITE)
            p.grid(-s / 2, yc - s / 2, s, _aruco_modules(dictionary, mid), BLACK, WHITE)
            feats["markers"][int(mid)] = _marker_corners(-s / 2, yc - s / 2, s)
        feats["marker_size_m"] = s
    elif style == "dots":
        p.rect(-b_m / 2, b_m / 2, 0, h_m, WHITE, opaque=True)
        dia = dot_diameter_m or min(0.16 * b_m, 0.08 * h_m)
        dots = np.array(
            [[-0.28 * b_m, 0.15 * h_m], [0.28 * b_m, 0.15 * h_m], [-0.28 * b_m, 0.85 * h_m], [0.28 * b_m, 0.62 * h_m]]
        )
        for x, y in dots:
            p.circle(x, y, dia / 2, BLACK)
        feats["dots"] = dots
        feats["dot_diameter_m"] = dia
    else:  # pragma: no cover - validated by the caller
        raise ValueError(style)
    return p.finish(psf_px_m / texel_m, outline, feats)


def table_texture(
    width_m,
    thick_m,
    style,
    *,
    marker_ids=(),
    dictionary="DICT_4X4_50",
    marker_size_m=None,
    dot_diameter_m=None,
    texel_m,
    psf_px_m,
    rng,
) -> Texture:
    """Front face of the table top (body frame: origin at the top centre, y up).

    Markers (or dots) sit near both ends so the tracker can level from the
    table line; for ``edges`` the face is a plain mid-grey slab.
    """
    pad = 4 * psf_px_m + 2 * texel_m
    p = _Painter(-width_m / 2, width_m / 2, -thick_m, 0.0, texel_m, pad)
    outline = np.array([[-width_m / 2, -thick_m], [width_m / 2, -thick_m], [width_m / 2, 0], [-width_m / 2, 0]])
    feats: dict = {}
    p.rect(-width_m / 2, width_m / 2, -thick_m, 0, 96.0, opaque=True)
    si, sj = p._slices(-width_m / 2, width_m / 2, -thick_m, 0)
    # a markerless steel slab needs visible grain to be followed; the others keep a faint one
    p.L[si, sj] += (
        _speckle(p, si, sj, rng, 16.0, 0.004) if style == "markerless" else _speckle(p, si, sj, rng, 3.0, 0.006)
    )
    xs = (-0.4 * width_m, 0.4 * width_m)
    yc = -thick_m / 2
    if style == "aruco":
        s = marker_size_m
        feats["markers"] = {}
        for x, mid in zip(xs, marker_ids):
            q = s / 6
            p.rect(x - s / 2 - q, x + s / 2 + q, yc - s / 2 - q, yc + s / 2 + q, WHITE)
            p.grid(x - s / 2, yc - s / 2, s, _aruco_modules(dictionary, mid), BLACK, WHITE)
            feats["markers"][int(mid)] = _marker_corners(x - s / 2, yc - s / 2, s)
        feats["marker_size_m"] = s
    elif style == "dots":
        # Same printed dot size as on the blocks (trackers filter by one size), on white labels.
        dia = dot_diameter_m or 0.3 * thick_m
        dots = np.array([[xs[0], yc], [0.0, yc], [xs[1], yc]])
        for x, y in dots:
            p.rect(x - 1.2 * dia, x + 1.2 * dia, y - 1.2 * dia, y + 1.2 * dia, WHITE)
            p.circle(x, y, dia / 2, BLACK)
        feats["dots"] = dots
        feats["dot_diameter_m"] = dia
    return p.finish(psf_px_m / texel_m, outline, feats)
