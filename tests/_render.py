"""Tiny deterministic renderer for tracking tests (the full one is ``rocklab synth``).

A scene is a list of planar objects, each a texture (grey uint8, drawn in its
own frame at ``tex_px_per_m``) with a known pose per frame. World: x right,
y up, metres; the camera maps world -> image by a scale ``px_per_m``, an
optional roll, and centring on the image centre. Textures are pre-blurred and
sampled bilinearly with an anti-aliased alpha, then the frame gets a blur and
sensor noise.
"""

from __future__ import annotations

import cv2
import numpy as np

TEX = 2000.0  # texture px per m (even marker sides and mm positions land on whole texels)


def marker_texture(ids, positions_m, size_m, face_m, face_grey=200, dictionary="DICT_4X4_50", origin_m=(0.0, 0.0)):
    """Grey face (w, h m) with ArUco markers centred at ``positions_m`` (object frame, y up).

    Returns ``(texture, origin_px)`` where ``origin_px`` is the texture pixel of the object origin.
    ``origin_m`` is the object-frame position of the face's lower-left corner.
    """
    d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, dictionary))
    w, h = face_m
    tex = np.full((int(round(h * TEX)), int(round(w * TEX))), face_grey, np.uint8)
    ox, oy = _origin(tex, origin_m)
    for i, (cx, cy) in zip(ids, positions_m):
        s = int(round(size_m * TEX))
        q = int(round(size_m * 0.125 * TEX))  # white quiet zone
        img = cv2.aruco.generateImageMarker(d, int(i), s)
        # marker texels u0..u0+s-1 span [u0 - 0.5, u0 + s - 0.5]: centred on the requested point
        u0 = ox + 0.5 + cx * TEX - s / 2
        v0 = oy + 0.5 - cy * TEX - s / 2
        assert abs(u0 - round(u0)) < 1e-6 and abs(v0 - round(v0)) < 1e-6, "off-texel marker"
        u0, v0 = int(round(u0)), int(round(v0))
        tex[v0 - q : v0 + s + q, u0 - q : u0 + s + q] = 255
        tex[v0 : v0 + s, u0 : u0 + s] = img
    return tex, (ox, oy)


def dots_texture(dots_m, diameter_m, face_m, origin_m=(0.0, 0.0), face_grey=210, dot_grey=30):
    w, h = face_m
    scale = 4
    big = np.full((int(round(h * TEX)) * scale, int(round(w * TEX)) * scale), face_grey, np.uint8)
    ox, oy = _origin(big[::scale, ::scale], origin_m)
    for cx, cy in dots_m:
        c = ((ox + cx * TEX) * scale + (scale - 1) / 2, (oy - cy * TEX) * scale + (scale - 1) / 2)
        cv2.circle(
            big,
            (int(round(c[0] * 16)), int(round(c[1] * 16))),
            int(round(diameter_m / 2 * TEX * scale * 16)),
            int(dot_grey),
            -1,
            cv2.LINE_AA,
            4,
        )
    tex = cv2.resize(big, (big.shape[1] // scale, big.shape[0] // scale), interpolation=cv2.INTER_AREA)
    return tex, (ox, oy)


def plain_texture(face_m, grey=220, origin_m=(0.0, 0.0)):
    w, h = face_m
    tex = np.full((int(round(h * TEX)), int(round(w * TEX))), grey, np.uint8)
    return tex, _origin(tex, origin_m)


def _origin(tex, origin_m):
    # Texture pixel i spans [i - 0.5, i + 0.5]: the face's lower-left corner is (-0.5, H - 0.5).
    return -0.5 - origin_m[0] * TEX, tex.shape[0] - 0.5 + origin_m[1] * TEX


def _rot(ax, ay, az):
    cx, sx, cy, sy, cz, sz = np.cos(ax), np.sin(ax), np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


class Scene:
    """``tilt_rad = (about x, about y)``: a pinhole camera at 1 m looking at the plane with
    that pitch/yaw (``K`` in :attr:`K`); 0 gives a fronto-parallel view."""

    def __init__(
        self,
        width=640,
        height=400,
        px_per_m=1500.0,
        roll_rad=0.0,
        noise=2.0,
        blur=0.6,
        seed=0,
        background=(90, 140),
        tilt_rad=(0.0, 0.0),
    ):
        self.W, self.H, self.k, self.roll = width, height, px_per_m, roll_rad
        self.noise, self.blur = noise, blur
        self.rng = np.random.default_rng(seed)
        yy, xx = np.mgrid[0:height, 0:width]
        lo, hi = background
        self.bg = (lo + (hi - lo) * xx / width).astype(np.float32)
        self.objects = []
        cx, cy = (width - 1) / 2, (height - 1) / 2
        self.K = np.array([[px_per_m, 0, cx], [0, px_per_m, cy], [0, 0, 1.0]])
        # world (x right, y up, z to the camera) -> camera (x right, y down, z forward)
        R = _rot(tilt_rad[0], tilt_rad[1], 0.0) @ np.diag([1.0, -1.0, -1.0]) @ _rot(0, 0, roll_rad)
        t = np.array([0.0, 0.0, 1.0])
        t = t - R @ np.zeros(3)
        self.G = self.K @ np.column_stack((R[:, 0], R[:, 1], t))  # plane (x, y, 1) -> image

    def add(self, tex, origin_px):
        # band-limit the texture (0.8 image px) so the bilinear warp does not alias edges
        t = cv2.GaussianBlur(tex.astype(np.float32), (0, 0), 0.8 * TEX / self.k)
        self.objects.append((t, origin_px))

    def world_to_image(self, xy):
        xy = np.atleast_2d(np.asarray(xy, float))
        h = np.column_stack((xy, np.ones(len(xy)))) @ self.G.T
        return h[:, :2] / h[:, 2:3]

    def render(self, poses):
        """``poses``: per object ``(x_m, y_m, theta_rad)`` of its origin. Returns uint8 (H, W)."""
        img = self.bg.copy()
        for (tex, (ox, oy)), (x, y, th) in zip(self.objects, poses):
            # texture px -> object m: P = ((u-ox)/TEX, (oy-v)/TEX); world = R(th) P + (x, y);
            # image = G world.
            c, s = np.cos(th), np.sin(th)
            L = np.array([[c, -s], [s, c]]) @ np.diag([1 / TEX, -1 / TEX])
            T = np.eye(3)
            T[:2, :2] = L
            T[:2, 2] = np.array([x, y]) - L @ np.array([ox, oy])
            M = self.G @ T
            warped = cv2.warpPerspective(
                tex, M, (self.W, self.H), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0
            )
            alpha = cv2.warpPerspective(
                np.ones_like(tex),
                M,
                (self.W, self.H),
                flags=cv2.INTER_LINEAR,
                borderMode=cv2.BORDER_CONSTANT,
                borderValue=0,
            )
            img = img * (1 - alpha) + warped
        if self.blur:
            img = cv2.GaussianBlur(img, (0, 0), self.blur)
        img += self.rng.normal(0, self.noise, img.shape).astype(np.float32)
        return np.clip(np.rint(img), 0, 255).astype(np.uint8)


def write_video(path, frames, fps):
    """FFV1 .mkv (lossless) of grey frames."""
    h, w = frames[0].shape
    vw = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"FFV1"), fps, (w, h), True)
    assert vw.isOpened()
    for f in frames:
        vw.write(cv2.cvtColor(f, cv2.COLOR_GRAY2BGR))
    vw.release()


def checker_texture(squares_x, squares_y, square_m, margin_m=0.01):
    """Checkerboard (white margin) whose first inner corner (top-left) is the object origin."""
    w = squares_x * square_m + 2 * margin_m
    h = squares_y * square_m + 2 * margin_m
    tex = np.full((int(round(h * TEX)), int(round(w * TEX))), 255, np.uint8)
    s = int(round(square_m * TEX))
    m = int(round(margin_m * TEX))
    for j in range(squares_y):
        for i in range(squares_x):
            if (i + j) % 2 == 0:
                tex[m + j * s : m + (j + 1) * s, m + i * s : m + (i + 1) * s] = 20
    ox, oy = _origin(tex, (0.0, 0.0))
    # first inner corner: one square in from the top-left board corner
    return tex, (m + s - 0.5, m + s - 0.5)


def realistic_session(path, size=(1920, 1080), seed=3, duration_s=2.4):
    """Issue 13's realistic render with ``rocklab synth``: photographed stone and bricks, H.264 at
    a camcorder's bit rate, exposure flicker 0.12, half-frame motion blur, no markers anywhere, a
    block rocking on a table driven by a 45 mm / 0.6 s sine pulse. Returns the session."""
    from rocklab.synth import synth_session

    return synth_session(
        path,
        seed=seed,
        size=size,
        duration_s=duration_s,
        imu=False,
        targets="markerless",
        table="sine",
        flicker=0.12,
        texture="photo",
    )
