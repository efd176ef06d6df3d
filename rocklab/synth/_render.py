"""Frame renderer for synthetic sessions: textured planar objects seen by a distorted
camera, with motion blur, optional rolling shutter, lighting gradient and sensor noise.

Each output pixel is looked up on the rocking plane through the camera's exact
inverse (``SynthCamera.plane_maps``, computed once), moved into each object's
body frame with the object's true pose at the sub-frame time, and sampled from
the object's prefiltered texture (``_render_targets``). Motion blur is the mean
of sub-frame renders spread over the exposure, with enough sub-frames that no
point moves more than ``blur_step_px`` between them. With a rolling shutter row
``v`` is exposed around ``t + (v / (H - 1) - 1/2) * readout_s``.

Only the region touched by moving objects is re-rendered per frame; static
objects are baked into the background once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ._render_targets import Texture
from ._camera import SynthCamera

__all__ = ["RenderObject", "Renderer"]


@dataclass(frozen=True)
class RenderObject:
    """An object to draw.

    Attributes
    ----------
    id : str
    texture : Texture
    pose : callable
        ``pose(t_s) -> (ox_m, oy_m, phi_rad)``, vectorised over an array of
        times: world position of the body origin and counter-clockwise angle.
    static : bool
        The pose never changes (baked into the background).
    """

    id: str
    texture: Texture
    pose: Callable
    static: bool = False


@dataclass(frozen=True)
class Occluder:
    """Something in front of ``object`` during ``[t0_s, t1_s)``.

    ``kind="patch"``: a dark patch covering the object entirely. ``kind="hand"``: a hand and
    forearm reaching down from the top of the frame over the upper part of the object (fingers
    to about 55 % of its height at full reach, in the middle 40 % of the interval) and back;
    lighter than the stone, with soft edges.
    """

    object: str
    t0_s: float
    t1_s: float
    kind: str = "patch"


def _hand_alpha(box, reach, H, W):
    """Coverage (0..1) of a hand reaching down to ``reach`` (0..1) of the object box; its region.

    Returns ``(alpha, (r0, r1, c0, c1))`` or None when the hand is out of the frame.
    """
    import cv2

    r0, r1, c0, c1 = box
    bw, bh = c1 - c0, r1 - r0
    tip = r0 + reach * 0.55 * bh  # fingertips, px from the top
    if tip <= 0:
        return None
    palm_w = 0.9 * bw
    cx = 0.5 * (c0 + c1) + 0.15 * bw
    finger_l = 0.45 * palm_w
    palm_bot = tip - finger_l
    palm_top = palm_bot - 0.9 * palm_w
    R1 = int(min(H, np.ceil(tip + 4)))
    C0 = int(max(0, np.floor(cx - 0.75 * palm_w)))
    C1 = int(min(W, np.ceil(cx + 0.75 * palm_w)))
    if R1 <= 0 or C1 <= C0:
        return None
    k = 4  # supersampling for soft edges
    canvas = np.zeros((R1 * k, (C1 - C0) * k), np.uint8)

    def P(x, y):
        return (int(round((x - C0) * k)), int(round(y * k)))

    # forearm from the top of the frame to the palm, the palm, four fingers and a thumb
    fa = 0.4 * palm_w
    cv2.fillConvexPoly(
        canvas,
        np.array(
            [
                P(cx - fa, -10),
                P(cx + fa, -10),
                P(cx + 0.45 * palm_w, palm_top + 0.3 * palm_w),
                P(cx - 0.45 * palm_w, palm_top + 0.3 * palm_w),
            ],
            np.int32,
        ),
        255,
    )
    cv2.ellipse(
        canvas,
        P(cx, 0.5 * (palm_top + palm_bot)),
        (int(0.5 * palm_w * k), int(0.5 * (palm_bot - palm_top) * k)),
        0,
        0,
        360,
        255,
        -1,
    )
    fw = palm_w / 4.4
    for i, lf in enumerate((0.85, 1.0, 0.95, 0.75)):
        x = cx - 0.5 * palm_w + fw * (0.7 + 1.0 * i)
        y1 = palm_bot + lf * finger_l - 0.5 * fw
        cv2.line(canvas, P(x, palm_bot - fw), P(x, y1), 255, max(1, int(fw * k)))
        cv2.circle(canvas, P(x, y1), int(0.5 * fw * k), 255, -1)
    tx = cx + 0.5 * palm_w
    cv2.line(
        canvas,
        P(tx, palm_bot - 0.6 * palm_w),
        P(tx + 0.25 * palm_w, palm_bot - 0.1 * palm_w),
        255,
        max(1, int(1.1 * fw * k)),
    )
    alpha = cv2.resize(canvas, (C1 - C0, R1), interpolation=cv2.INTER_AREA).astype(np.float32) / 255.0
    return alpha, (0, R1, C0, C1)


def to_world(outline: np.ndarray, ox, oy, phi):
    c, s = np.cos(phi), np.sin(phi)
    x = ox[..., None] + c[..., None] * outline[:, 0] - s[..., None] * outline[:, 1]
    y = oy[..., None] + s[..., None] * outline[:, 0] + c[..., None] * outline[:, 1]
    return np.stack([x, y], -1)


class Renderer:
    """Render grey frames (uint8, H x W) of ``objects`` at given times.

    Parameters
    ----------
    camera : SynthCamera
    objects : list of RenderObject, drawn in order (later ones in front).
    background : ndarray (H, W) float32, grey levels before lighting.
    illumination : ndarray (H, W) float32, multiplicative lighting field.
    exposure_s, readout_s : float
        Shutter open time and rolling-shutter readout (0: global shutter), s.
    noise_dn : float
        Sensor noise standard deviation, grey levels.
    flicker : float
        Relative amplitude of the exposure flicker (see :meth:`exposure_gain`); 0: none.
    rng : numpy Generator (noise draws; consumed in frame order).
    psf_px : float
        Optical blur sigma used for the texture prefilter, px (for ROI margins).
    """

    def __init__(
        self,
        camera: SynthCamera,
        objects,
        background,
        illumination,
        *,
        exposure_s,
        readout_s=0.0,
        noise_dn=1.0,
        rng,
        psf_px=0.5,
        blur_step_px=0.5,
        max_sub=32,
        occluders=(),
        plane_maps=None,
        flicker=0.0,
        flicker_seed=0,
    ):
        self.cam = camera
        self.W, self.H = camera.size
        self.X, self.Y = plane_maps if plane_maps is not None else camera.plane_maps()
        self.exposure_s, self.readout_s = float(exposure_s), float(readout_s)
        self.blur_step_px, self.max_sub = float(blur_step_px), int(max_sub)
        self.margin = int(math.ceil(4 * psf_px + 3))
        self.rng = rng
        self.illum = illumination.astype(np.float32)
        self.occluders = list(occluders)
        self.moving = [o for o in objects if not o.static]
        self.static = [o for o in objects if o.static]
        self.order = list(objects)
        bg = background.astype(np.float32).copy()
        for o in self.static:  # bake static objects once
            box = self._bbox(o, np.array([0.0]))
            if box is not None:
                r0, r1, c0, c1 = box
                ox, oy, phi = (np.asarray(v, float) for v in o.pose(np.array([0.0])))
                self._composite(
                    bg[r0:r1, c0:c1], o, (r0, r1, c0, c1), (r0, r1, c0, c1), float(ox[0]), float(oy[0]), float(phi[0])
                )
        self.bg = bg
        self.bg_u8 = np.clip(np.rint(bg * self.illum), 0, 255).astype(np.uint8)
        self.noise_bank = (
            [np.rint(rng.normal(0.0, noise_dn, (self.H + 16, self.W + 16))).astype(np.int16) for _ in range(3)]
            if noise_dn > 0
            else None
        )
        self.last_subframes = 1
        # an integer of its own from the seed (an int or a SeedSequence), not drawn from ``rng``
        self.flicker = float(flicker)
        self.flicker_seed = int(np.random.default_rng(flicker_seed).integers(2**31))
        self.flicker_phase = float(np.random.default_rng((self.flicker_seed, 7)).uniform(0, 2 * math.pi))

    def exposure_gain(self, t_s: float) -> float:
        """Brightness gain of the frame at ``t_s`` (1 without flicker).

        A camcorder's automatic exposure hunting under mains lighting: a slow swing (1.3 Hz,
        60 % of ``flicker``) plus a level that jumps every 0.6 s (40 %), deterministic per seed.
        """
        if self.flicker <= 0:
            return 1.0
        step = float(np.random.default_rng((self.flicker_seed, int(math.floor(t_s / 0.6)))).uniform(-1, 1))
        return 1.0 + self.flicker * (0.6 * math.sin(2 * math.pi * 1.3 * t_s + self.flicker_phase) + 0.4 * step)

    # ----------------------------------------------------------------- geometry
    def _span(self, t):
        half = 0.5 * (self.exposure_s + self.readout_s)
        return t - half, t + half

    def _bbox(self, o: RenderObject, ts):
        ox, oy, phi = (np.atleast_1d(np.asarray(v, float)) for v in o.pose(ts))
        pts = to_world(o.texture.outline_m, ox, oy, phi).reshape(-1, 2)
        px = self.cam.project(pts)
        m = self.margin
        c0 = max(0, int(np.floor(px[:, 0].min())) - m)
        c1 = min(self.W, int(np.ceil(px[:, 0].max())) + m + 1)
        r0 = max(0, int(np.floor(px[:, 1].min())) - m)
        r1 = min(self.H, int(np.ceil(px[:, 1].max())) + m + 1)
        if c1 <= c0 or r1 <= r0:
            return None
        return r0, r1, c0, c1

    def _n_sub(self, o: RenderObject, t) -> int:
        if self.exposure_s <= 0:
            return 1
        ts = t + self.exposure_s * np.linspace(-0.5, 0.5, 9)
        ox, oy, phi = (np.atleast_1d(np.asarray(v, float)) for v in o.pose(ts))
        px = self.cam.project(to_world(o.texture.outline_m, ox, oy, phi).reshape(-1, 2))
        px = px.reshape(len(ts), -1, 2)
        path = np.sum(np.hypot(*np.moveaxis(np.diff(px, axis=0), -1, 0)), axis=0).max()
        return int(min(self.max_sub, max(1, math.ceil(path / self.blur_step_px))))

    # ----------------------------------------------------------------- drawing
    def _composite(self, canvas, o: RenderObject, canvas_box, box, ox, oy, phi):
        """Draw ``o`` over ``canvas`` (covering ``canvas_box``) inside ``box``.

        ``ox, oy, phi`` are scalars or (rows, 1) arrays (rolling shutter).
        """
        import cv2

        R0, _, C0, _ = canvas_box
        r0, r1, c0, c1 = box
        X = self.X[r0:r1, c0:c1]
        Y = self.Y[r0:r1, c0:c1]
        c, s = np.cos(phi), np.sin(phi)
        dx = X - np.float32(ox) if np.ndim(ox) == 0 else X - np.asarray(ox, np.float32)
        dy = Y - np.float32(oy) if np.ndim(oy) == 0 else Y - np.asarray(oy, np.float32)
        c = np.float32(c) if np.ndim(c) == 0 else np.asarray(c, np.float32)
        s = np.float32(s) if np.ndim(s) == 0 else np.asarray(s, np.float32)
        tex = o.texture
        inv = np.float32(1.0 / tex.texel_m)
        mapx = (c * dx + s * dy - np.float32(tex.x0_m)) * inv
        mapy = (np.float32(tex.y0_m) - (c * dy - s * dx)) * inv
        smp = cv2.remap(tex.img, mapx, mapy, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0)
        sub = canvas[r0 - R0 : r1 - R0, c0 - C0 : c1 - C0]
        sub *= 1.0 - smp[..., 1]
        sub += smp[..., 0]

    def render(self, t_s: float) -> np.ndarray:
        """The frame centred on time ``t_s`` (s) as uint8 (H, W)."""
        import cv2

        frame = self.bg_u8.copy()
        t_lo, t_hi = self._span(t_s)
        span = np.linspace(t_lo, t_hi, 9)
        boxes = {o.id: self._bbox(o, span) for o in self.moving}
        live = [b for b in boxes.values() if b is not None]
        occ = self._occluder_boxes(t_s)
        live += [o[0] for o in occ]
        if live:
            R0, R1 = min(b[0] for b in live), max(b[1] for b in live)
            C0, C1 = min(b[2] for b in live), max(b[3] for b in live)
            n = max(self._n_sub(o, t_s) for o in self.moving)
            self.last_subframes = n
            acc = np.zeros((R1 - R0, C1 - C0), np.float32)
            rows = None
            if self.readout_s > 0:
                rows = (np.arange(R0, R1, dtype=float)[:, None] / max(1, self.H - 1) - 0.5) * self.readout_s
            for k in range(n):
                tk = t_s + ((k + 0.5) / n - 0.5) * self.exposure_s
                canvas = self.bg[R0:R1, C0:C1].copy()
                for o in self.order:
                    box = boxes.get(o.id)
                    if o.static or box is None:
                        continue
                    if rows is None:
                        ox, oy, phi = (float(np.asarray(v).ravel()[0]) for v in o.pose(np.array([tk])))
                    else:
                        rr = rows[box[0] - R0 : box[1] - R0]
                        ox, oy, phi = (np.asarray(v, float).reshape(-1, 1) for v in o.pose((tk + rr).ravel()))
                    self._composite(canvas, o, (R0, R1, C0, C1), box, ox, oy, phi)
                acc += canvas
            acc *= np.float32(1.0 / n)
            for (r0, r1, c0, c1), alpha in occ:
                region = acc[r0 - R0 : r1 - R0, c0 - C0 : c1 - C0]
                if alpha is None:
                    region[...] = 38.0  # a dark patch in front
                else:
                    # skin lighter than the stone, shaded across the hand
                    shade = 172.0 + 14.0 * np.linspace(-1.0, 1.0, c1 - c0, dtype=np.float32)[None, :]
                    region += alpha * (shade - region)
            acc *= self.illum[R0:R1, C0:C1]
            frame[R0:R1, C0:C1] = np.clip(np.rint(acc), 0, 255).astype(np.uint8)
        if self.flicker > 0:
            frame = cv2.convertScaleAbs(frame, alpha=self.exposure_gain(t_s))  # rounds and saturates
        if self.noise_bank is not None:
            k = int(self.rng.integers(len(self.noise_bank)))
            dy, dx = (int(v) for v in self.rng.integers(0, 17, 2))
            noise = self.noise_bank[k][dy : dy + self.H, dx : dx + self.W]
            frame = cv2.add(frame, noise, dtype=cv2.CV_8U)  # saturating, one pass
        return frame

    def _occluder_boxes(self, t_s):
        out = []
        for oc in self.occluders:
            obj = next((o for o in self.order if o.id == oc.object), None)
            if obj is None or not (oc.t0_s <= t_s < oc.t1_s):
                continue
            box = self._bbox(obj, np.linspace(oc.t0_s, oc.t1_s, 25))
            if box is None:
                continue
            if oc.kind == "hand":
                # in over the first 30 % of the interval, held, out over the last 30 %
                u = (t_s - oc.t0_s) / (oc.t1_s - oc.t0_s)
                reach = min(1.0, u / 0.3, (1.0 - u) / 0.3)
                reach = reach * reach * (3.0 - 2.0 * reach)
                hand = _hand_alpha(box, reach, self.H, self.W) if reach > 0 else None
                if hand is not None:
                    out.append((hand[1], hand[0]))
            else:
                r0, r1, c0, c1 = box
                out.append(((max(0, r0 - 6), min(self.H, r1 + 6), max(0, c0 - 6), min(self.W, c1 + 6)), None))
        return out
