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

TEX = 1500.0  # texture px per m


def marker_texture(ids, positions_m, size_m, face_m, face_grey=200, dictionary="DICT_4X4_50",
                   origin_m=(0.0, 0.0)):
    """Grey face (w, h m) with ArUco markers centred at ``positions_m`` (object frame, y up).

    Returns ``(texture, origin_px)`` where ``origin_px`` is the texture pixel of the object origin.
    ``origin_m`` is the object-frame position of the face's lower-left corner.
    """
    d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, dictionary))
    w, h = face_m
    tex = np.full((int(round(h * TEX)), int(round(w * TEX))), face_grey, np.uint8)
    ox, oy = _origin(tex, origin_m)
    for i, (cx, cy) in zip(ids, positions_m):
        quiet = 1.25
        s = int(round(size_m * TEX))
        sq = int(round(size_m * quiet * TEX))
        img = cv2.aruco.generateImageMarker(d, int(i), s)
        pad = np.full((sq, sq), 255, np.uint8)
        o = (sq - s) // 2
        pad[o:o + s, o:o + s] = img
        u0 = int(round(ox + 0.5 + cx * TEX - sq / 2))
        v0 = int(round(oy + 0.5 - cy * TEX - sq / 2))
        tex[v0:v0 + sq, u0:u0 + sq] = pad
    return tex, (ox, oy)


def dots_texture(dots_m, diameter_m, face_m, origin_m=(0.0, 0.0), face_grey=210, dot_grey=30):
    w, h = face_m
    scale = 4
    big = np.full((int(round(h * TEX)) * scale, int(round(w * TEX)) * scale), face_grey, np.uint8)
    ox, oy = _origin(big[::scale, ::scale], origin_m)
    for cx, cy in dots_m:
        c = ((ox + cx * TEX) * scale + (scale - 1) / 2, (oy - cy * TEX) * scale + (scale - 1) / 2)
        cv2.circle(big, (int(round(c[0] * 16)), int(round(c[1] * 16))),
                   int(round(diameter_m / 2 * TEX * scale * 16)), int(dot_grey), -1, cv2.LINE_AA, 4)
    tex = cv2.resize(big, (big.shape[1] // scale, big.shape[0] // scale), interpolation=cv2.INTER_AREA)
    return tex, (ox, oy)


def plain_texture(face_m, grey=220, origin_m=(0.0, 0.0)):
    w, h = face_m
    tex = np.full((int(round(h * TEX)), int(round(w * TEX))), grey, np.uint8)
    return tex, _origin(tex, origin_m)


def _origin(tex, origin_m):
    # Texture pixel i spans [i - 0.5, i + 0.5]: the face's lower-left corner is (-0.5, H - 0.5).
    return -0.5 - origin_m[0] * TEX, tex.shape[0] - 0.5 + origin_m[1] * TEX


class Scene:
    def __init__(self, width=640, height=400, px_per_m=1500.0, roll_rad=0.0, noise=2.0,
                 blur=0.6, seed=0, background=(90, 140)):
        self.W, self.H, self.k, self.roll = width, height, px_per_m, roll_rad
        self.noise, self.blur = noise, blur
        self.rng = np.random.default_rng(seed)
        yy, xx = np.mgrid[0:height, 0:width]
        lo, hi = background
        self.bg = (lo + (hi - lo) * xx / width).astype(np.float32)
        self.objects = []

    def add(self, tex, origin_px):
        t = cv2.GaussianBlur(tex.astype(np.float32), (0, 0), 0.5 * TEX / self.k)
        self.objects.append((t, origin_px))

    def world_to_image(self, xy):
        xy = np.atleast_2d(xy)
        c, s = np.cos(self.roll), np.sin(self.roll)
        X = c * xy[:, 0] - s * xy[:, 1]
        Y = s * xy[:, 0] + c * xy[:, 1]
        return np.c_[(self.W - 1) / 2 + self.k * X, (self.H - 1) / 2 - self.k * Y]

    def render(self, poses):
        """``poses``: per object ``(x_m, y_m, theta_rad)`` of its origin. Returns uint8 (H, W)."""
        img = self.bg.copy()
        for (tex, (ox, oy)), (x, y, th) in zip(self.objects, poses):
            # texture px -> object m: P = ((u-ox)/TEX, (oy-v)/TEX); world = R(th) P + (x, y);
            # image = camera(world). Compose the affine texture px -> image px.
            c, s = np.cos(th + self.roll), np.sin(th + self.roll)
            k = self.k / TEX
            A = np.array([[k * c, k * s], [-k * s, k * c]])
            # image of object origin:
            o_img = self.world_to_image([x, y])[0]
            b = o_img - A @ np.array([ox, oy])
            M = np.c_[A, b].astype(np.float64)
            warped = cv2.warpAffine(tex, M, (self.W, self.H), flags=cv2.INTER_LINEAR,
                                    borderMode=cv2.BORDER_CONSTANT, borderValue=0)
            alpha = cv2.warpAffine(np.ones_like(tex), M, (self.W, self.H), flags=cv2.INTER_LINEAR,
                                   borderMode=cv2.BORDER_CONSTANT, borderValue=0)
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
