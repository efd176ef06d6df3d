"""A two-camera (stereo) lab session with exact truth: a ChArUco calibration film and a rocking block.

What GOM Pontos-style rigs record (Čeh et al. 2018, §4.3): two synchronised
high-speed cameras looking at dot targets on the block and the table. Here:

- two pinhole cameras with radial distortion (OpenCV's model), converging on
  the block from about 1 m, with a baseline of 0.3 m;
- ``calib_cam1.mkv`` / ``calib_cam2.mkv``: a ChArUco board held in a series of
  poses, seen by both (the board is still in each pose, so no sync is needed);
- ``cam1.mkv`` / ``cam2.mkv``: bright dots (retro-reflective targets on a dark
  background, as the rigs see them) on the block's front face and on the table,
  moving with a simulated free-rocking motion (optionally with the slide, jump,
  twist or bounce of :func:`~rocklab.synth.synth_points3d`); camera 2 runs
  ``offset_s`` later than camera 1 (no shared trigger);
- ``truth.csv`` (the rocking truth), ``points_truth.csv`` (every dot's world
  position at camera 1's frame times) and ``rig.json`` (both cameras' exact
  intrinsics, distortion and poses; the world frame has z up, the table top
  at z = 0, the block's rest base centre at the origin).

Dots are drawn as anti-aliased disks centred on each dot centre's exact
projection (with distortion), so the projected centre is the truth for the
detector.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["StereoCamera", "synth_stereo", "look_at", "CHARUCO"]

#: The calibration board: squares x rows, square and marker side (m), ArUco dictionary.
CHARUCO = {"squares": (9, 6), "square_m": 0.03, "marker_m": 0.022, "dictionary": "DICT_5X5_100"}


@dataclass(frozen=True)
class StereoCamera:
    """A pinhole camera with OpenCV radial-tangential distortion.

    Attributes
    ----------
    K : ndarray, shape (3, 3)
        Intrinsics, px.
    dist : ndarray, shape (5,)
        ``k1, k2, p1, p2, k3``.
    R : ndarray, shape (3, 3)
        World to camera rotation (``x_cam = R x_world + t``).
    t : ndarray, shape (3,)
        m.
    size : tuple of int
        (width, height), px.
    """

    K: np.ndarray
    dist: np.ndarray
    R: np.ndarray
    t: np.ndarray
    size: tuple

    def project(self, X) -> np.ndarray:
        """Pixel positions of world points ``X`` (m, shape (n, 3)), shape (n, 2)."""
        import cv2

        X = np.asarray(X, float).reshape(-1, 3)
        rvec, _ = cv2.Rodrigues(self.R)
        uv, _ = cv2.projectPoints(X, rvec, self.t, self.K, self.dist)
        return uv.reshape(-1, 2)

    def depth(self, X) -> np.ndarray:
        """Distance along the optical axis, m."""
        return (np.asarray(X, float).reshape(-1, 3) @ self.R.T + self.t)[:, 2]

    def to_dict(self) -> dict:
        return {"K": self.K.tolist(), "dist": self.dist.tolist(), "R": self.R.tolist(), "t": self.t.tolist(),
                "size": list(self.size)}


def look_at(eye, target, up=(0.0, 0.0, 1.0)):
    """World-to-camera ``(R, t)`` for a camera at ``eye`` looking at ``target`` (image y down)."""
    eye, target, up = (np.asarray(v, float) for v in (eye, target, up))
    z = target - eye
    z /= np.linalg.norm(z)
    x = np.cross(z, up)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    R = np.stack([x, y, z])
    return R, -R @ eye


def _cameras(size, f_px):
    W, H = size
    K = np.array([[f_px, 0.0, W / 2 - 3.5], [0.0, f_px, H / 2 + 2.5], [0.0, 0.0, 1.0]])
    K2 = K.copy()
    K2[0, 0] *= 1.004
    K2[1, 1] *= 1.004
    K2[0, 2] += 6.0
    target = (0.0, 0.0, 0.2)
    c1 = StereoCamera(K, np.array([-0.06, 0.02, 0.0, 0.0, 0.0]), *look_at((-0.15, -0.98, 0.38), target), size)
    c2 = StereoCamera(K2, np.array([-0.05, 0.015, 0.0, 0.0, 0.0]), *look_at((0.15, -0.98, 0.38), target), size)
    return c1, c2


def _board():
    import cv2

    d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, CHARUCO["dictionary"]))
    return cv2.aruco.CharucoBoard(CHARUCO["squares"], CHARUCO["square_m"], CHARUCO["marker_m"], d)


def _render_board(cam: StereoCamera, R_b, t_b, texture, ppm, noise, rng):
    """The board (plane z=0 of its own frame, texture at ``ppm`` px/m) seen by ``cam``; grey uint8."""
    import cv2

    W, H = cam.size
    # every output pixel -> undistorted normalised ray -> board plane -> texture pixel
    u, v = np.meshgrid(np.arange(W, dtype=np.float32), np.arange(H, dtype=np.float32))
    pts = np.stack([u.ravel(), v.ravel()], axis=1).reshape(-1, 1, 2)
    n = cv2.undistortPoints(pts, cam.K, cam.dist).reshape(-1, 2)
    # camera frame of the board: x_cam = Rc (R_b X + t_b) + tc
    Rcb = cam.R @ R_b
    tcb = cam.R @ t_b + cam.t
    rays = np.column_stack([n, np.ones(len(n))])
    # solve for X (board plane, z=0): Rcb[:, :2] @ [X, Y] + tcb = s * ray
    A = np.zeros((len(n), 3, 3))
    A[:, :, 0] = Rcb[:, 0]
    A[:, :, 1] = Rcb[:, 1]
    A[:, :, 2] = -rays
    sol = np.linalg.solve(A, -np.broadcast_to(tcb, (len(n), 3))[..., None])[..., 0]
    mx = (sol[:, 0] * ppm).reshape(H, W).astype(np.float32)
    my = (sol[:, 1] * ppm).reshape(H, W).astype(np.float32)
    img = cv2.remap(texture, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT,
                    borderValue=60)
    img = cv2.GaussianBlur(img, (0, 0), 0.7).astype(np.float32)
    img += rng.normal(0.0, noise, img.shape)
    return np.clip(img, 0, 255).astype(np.uint8)


def _board_poses(n, rng):
    """Board poses (R, t) in world: in front of the block, tilted up to 35 deg, spread over the view."""
    from scipy.spatial.transform import Rotation

    out = []
    w, h = CHARUCO["squares"][0] * CHARUCO["square_m"], CHARUCO["squares"][1] * CHARUCO["square_m"]
    for i in range(n):
        # face the cameras (board normal towards -y), then tilt
        base = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])      # board x -> world x, y -> -z
        tilt = Rotation.from_euler("xyz", rng.uniform([-35, -35, -15], [35, 35, 15]), degrees=True).as_matrix()
        R = tilt @ base
        centre = np.array([rng.uniform(-0.22, 0.22), rng.uniform(-0.3, 0.1), rng.uniform(-0.02, 0.42)])
        t = centre - R @ np.array([w / 2, h / 2, 0.0])
        out.append((R, t))
    return out


def _render_dots(cam: StereoCamera, X, radius_m, noise, rng, background=18.0, peak=235.0):
    """Bright anti-aliased disks at the projections of world points ``X`` (NaN rows skipped)."""
    W, H = cam.size
    img = np.full((H, W), background, np.float32)
    ok = np.isfinite(X).all(axis=1)
    uv = np.full((len(X), 2), np.nan)
    if ok.any():
        uv[ok] = cam.project(X[ok])
        z = cam.depth(X[ok])
    for (u0, v0), zz in zip(uv[ok], z if ok.any() else []):
        r = cam.K[0, 0] * radius_m / zz
        x0, x1 = int(math.floor(u0 - r - 2)), int(math.ceil(u0 + r + 2))
        y0, y1 = int(math.floor(v0 - r - 2)), int(math.ceil(v0 + r + 2))
        if x1 < 0 or y1 < 0 or x0 >= W or y0 >= H:
            continue
        x0, y0, x1, y1 = max(x0, 0), max(y0, 0), min(x1, W - 1), min(y1, H - 1)
        yy, xx = np.mgrid[y0:y1 + 1, x0:x1 + 1]
        # 4x4 supersampled coverage of the disk
        cov = np.zeros(xx.shape, np.float32)
        for dy in (-0.375, -0.125, 0.125, 0.375):
            for dx in (-0.375, -0.125, 0.125, 0.375):
                cov += ((xx + dx - u0) ** 2 + (yy + dy - v0) ** 2 <= r * r)
        img[y0:y1 + 1, x0:x1 + 1] += (peak - background) * cov / 16.0
        # sensor noise on the target and a margin round it; the flat background stays flat so the lossless
        # films stay small (a detector only ever looks at the targets' windows)
        m = int(math.ceil(r)) + 6
        ya, yb = max(int(v0) - m, 0), min(int(v0) + m + 1, H)
        xa, xb = max(int(u0) - m, 0), min(int(u0) + m + 1, W)
        img[ya:yb, xa:xb] += rng.normal(0.0, noise, (yb - ya, xb - xa)).astype(np.float32)
    return np.clip(img, 0, 255).astype(np.uint8), uv


def synth_stereo(out_dir, *, size=(2400, 1728), fps: float = 150.0, f_px: float = 3000.0, offset_s: float = 0.0027,
                 n_board: int = 24, noise_dn: float = 2.0, dot_radius_m: float = 0.003, seed: int = 0,
                 duration_s: float | None = None, **motion) -> dict:
    """Render a stereo session (see the module doc) into ``out_dir``; returns the paths and the truth.

    Parameters
    ----------
    out_dir : path-like
        A new or empty folder.
    size : (int, int)
        Frame size (width, height), px (default 2400 x 1728, Čeh's GOM rig).
    fps : float
        Frame rate of both cameras, Hz.
    f_px : float
        Focal length, px.
    offset_s : float
        Camera 2's clock runs this much later, s.
    n_board : int
        Calibration poses.
    noise_dn, dot_radius_m : float
        Image noise (1-sigma, grey levels) and target radius (m).
    duration_s : float, optional
        Cut the rocking film after this long, s.
    **motion
        Passed to :func:`~rocklab.synth.synth_points3d` (``slide=``, ``jump=``, ``twist=``,
        ``double_impact=``, ``block=``, ``theta0_rad=``, ``restitution=``).

    Returns
    -------
    dict
        ``paths`` (name -> Path), ``cameras`` (two StereoCamera), ``session`` (the
        :class:`~rocklab.synth.Points3DSession` at camera 1's frame times), ``offset_s``.
    """
    import pandas as pd

    from ..tracking._synth_files import VideoPair
    from ._points3d import synth_points3d

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    cams = _cameras(tuple(size), f_px)
    # the calibration film
    board = _board()
    ppm = 4000.0
    bw = int(round(CHARUCO["squares"][0] * CHARUCO["square_m"] * ppm))
    bh = int(round(CHARUCO["squares"][1] * CHARUCO["square_m"] * ppm))
    texture = board.generateImage((bw, bh), marginSize=0)
    texture = (40 + texture.astype(np.float32) * (200 / 255)).astype(np.uint8)
    poses = _board_poses(n_board, rng)
    paths = {}
    for k, cam in enumerate(cams, start=1):
        vp = VideoPair(out, fps, size, mp4=False, stem=f"calib_cam{k}")
        for R_b, t_b in poses:
            vp.write(_render_board(cam, R_b, t_b, texture, ppm, noise_dn, rng))
        vp.close()
        paths[f"calib_cam{k}"] = vp.paths["mkv"]
    # the rocking film: the motion sampled finely, then read at each camera's frame times
    fine = 20
    sess = synth_points3d(rate_hz=fps * fine, noise_m=0.0, seed=seed, up="z", yaw_deg=0.0,
                          offset_m=(0.0, 0.0, 0.0), side_targets=False, **motion)
    t_fine = sess.series.t_s
    labels = sess.series.labels
    t_end = t_fine[-1] if duration_s is None else min(t_fine[-1], float(duration_s))
    t1 = np.arange(0.0, t_end - offset_s - 1e-9, 1.0 / fps)

    def at(times):
        X = np.empty((times.size, len(labels), 3))
        for j in range(3):
            for p in range(len(labels)):
                X[:, p, j] = np.interp(times, t_fine, sess.series.xyz_m[:, p, j])
        return X

    X1, X2 = at(t1), at(t1 + offset_s)
    for k, (cam, X) in enumerate(zip(cams, (X1, X2)), start=1):
        vp = VideoPair(out, fps, size, mp4=False, stem=f"cam{k}")
        for i in range(t1.size):
            img, _ = _render_dots(cam, X[i], dot_radius_m, noise_dn, rng)
            vp.write(img)
        vp.close()
        paths[f"cam{k}"] = vp.paths["mkv"]
    truth = sess.truth
    tr = pd.DataFrame({c: np.interp(t1, truth["t_s"], truth[c]) for c in truth.columns})
    tr["t_s"] = t1
    truth_path = out / "truth.csv"
    tr.to_csv(truth_path, index=False, float_format="%.9g")
    pts = pd.DataFrame({"t_s": np.repeat(t1, len(labels)), "point": np.tile(labels, t1.size),
                        "x_m": X1[:, :, 0].ravel(), "y_m": X1[:, :, 1].ravel(), "z_m": X1[:, :, 2].ravel()})
    pts.to_csv(out / "points_truth.csv", index=False, float_format="%.9g")
    rig = {"cam1": cams[0].to_dict(), "cam2": cams[1].to_dict(), "offset_s": offset_s, "fps": fps,
           "charuco": CHARUCO, "bodies": {k: list(v) for k, v in sess.bodies.items()},
           "injected": {k: list(v) for k, v in sess.injected.items()}}
    (out / "rig.json").write_text(json.dumps(rig, indent=2))
    paths.update(truth_csv=truth_path, points_truth_csv=out / "points_truth.csv", rig_json=out / "rig.json")
    return {"paths": paths, "cameras": cams, "session": sess, "offset_s": offset_s, "t_s": t1, "X1": X1}
