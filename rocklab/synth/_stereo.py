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

from ..tracking.stereo import DEFAULT_BOARD, charuco_board

__all__ = ["StereoCamera", "synth_stereo", "look_at", "CHARUCO"]

#: The calibration board: the one ``rocklab stereo calibrate`` expects by default.
CHARUCO = DEFAULT_BOARD


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
        return {
            "K": self.K.tolist(),
            "dist": self.dist.tolist(),
            "R": self.R.tolist(),
            "t": self.t.tolist(),
            "size": list(self.size),
        }


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


_RAYS: dict = {}


def _rays(cam: StereoCamera) -> np.ndarray:
    """Undistorted normalised ray of every pixel of ``cam``, shape (H*W, 2) (cached per camera)."""
    import cv2

    key = (id(cam), cam.size)
    if key not in _RAYS:
        W, H = cam.size
        u, v = np.meshgrid(np.arange(W, dtype=np.float32), np.arange(H, dtype=np.float32))
        pts = np.stack([u.ravel(), v.ravel()], axis=1).reshape(-1, 1, 2)
        _RAYS.clear()
        _RAYS[key] = cv2.undistortPoints(pts, cam.K, cam.dist).reshape(-1, 2)
    return _RAYS[key]


def _plane_maps(cam: StereoCamera, R_b, t_b, ppm):
    """Texture coordinates (px at ``ppm`` px/m) of the plane z=0 of the frame (R_b, t_b) under every pixel."""
    W, H = cam.size
    n = _rays(cam)
    Rcb = cam.R @ R_b
    tcb = cam.R @ t_b + cam.t
    # the ray through each pixel in the plane's frame: C + s d, and its crossing of z = 0
    C = -Rcb.T @ tcb
    d = np.column_stack([n, np.ones(len(n))]) @ Rcb  # rows: Rcb^T ray
    with np.errstate(divide="ignore", invalid="ignore"):
        s = -C[2] / d[:, 2]
    X = C[0] + s * d[:, 0]
    Y = C[1] + s * d[:, 1]
    bad = ~(s > 0)
    X[bad] = -1e6
    Y[bad] = -1e6
    return (X * ppm).reshape(H, W).astype(np.float32), (Y * ppm).reshape(H, W).astype(np.float32)


def _render_board(cam: StereoCamera, R_b, t_b, texture, ppm, noise, rng):
    """The board (plane z=0 of its own frame, texture at ``ppm`` px/m) seen by ``cam``; grey uint8."""
    import cv2

    mx, my = _plane_maps(cam, R_b, t_b, ppm)
    img = cv2.remap(texture, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=60)
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
        base = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])  # board x -> world x, y -> -z
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
        yy, xx = np.mgrid[y0 : y1 + 1, x0 : x1 + 1]
        # 4x4 supersampled coverage of the disk
        cov = np.zeros(xx.shape, np.float32)
        for dy in (-0.375, -0.125, 0.125, 0.375):
            for dx in (-0.375, -0.125, 0.125, 0.375):
                cov += (xx + dx - u0) ** 2 + (yy + dy - v0) ** 2 <= r * r
        img[y0 : y1 + 1, x0 : x1 + 1] += (peak - background) * cov / 16.0
        # sensor noise on the target and a margin round it; the flat background stays flat so the lossless
        # films stay small (a detector only ever looks at the targets' windows)
        m = int(math.ceil(r)) + 6
        ya, yb = max(int(v0) - m, 0), min(int(v0) + m + 1, H)
        xa, xb = max(int(u0) - m, 0), min(int(u0) + m + 1, W)
        img[ya:yb, xa:xb] += rng.normal(0.0, noise, (yb - ya, xb - xa)).astype(np.float32)
    return np.clip(img, 0, 255).astype(np.uint8), uv


def _render_aruco_films(out, cams, sess, X1, X2, fps, size, noise, rng, paths):
    """Films of ArUco markers on the block's face and the table's plate; returns the corners' truth."""
    import cv2

    from ._files import VideoPair
    from ..tracking.rigid import kabsch
    from ._points3d import target_points

    ppm = 4000.0
    b, h = sess.block.b_m, sess.block.h_m
    depth = 0.6 * b
    body_pts, _ = target_points(sess.block, depth, side=False)
    nb = body_pts.shape[0]
    # the block's front face: x along the width, y down, origin at its top-left corner
    side = 0.6 * b
    face = np.full((int(round(h * ppm)), int(round(b * ppm))), 235, np.uint8)
    d = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50)
    face_corners = {}
    for mid, top in ((0, 0.2 * h), (1, 0.6 * h)):
        x0, y0, n = int(round(0.2 * b * ppm)), int(round(top * ppm)), int(round(side * ppm))
        face[y0 : y0 + n, x0 : x0 + n] = cv2.aruco.generateImageMarker(d, mid, n)
        face_corners[mid] = np.array([[x0, y0], [x0 + n, y0], [x0 + n, y0 + n], [x0, y0 + n]], float) / ppm
    # band-limit the textures to the pixel footprint (about ppm * 1 m / f texels per pixel): remap samples
    # them point-wise, and an unfiltered edge would land on the sample grid, biasing corners by ~0.5 px
    sig = 0.5 * ppm * 1.0 / float(cams[0].K[0, 0])
    face = cv2.GaussianBlur(face, (0, 0), sig)
    R_fb = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])  # face x, y, z -> body x, -z, y
    o_face = np.array([-b / 2, -depth / 2, h])
    # the table's plate: 6 cm tall, standing on the table in front of the block, facing the cameras
    plate = np.full((int(round(0.06 * ppm)), int(round(0.4 * ppm))), 235, np.uint8)
    plate_corners = {}
    for mid, x in ((2, 0.01), (3, 0.35)):
        x0, y0, n = int(round(x * ppm)), int(round(0.01 * ppm)), int(round(0.04 * ppm))
        plate[y0 : y0 + n, x0 : x0 + n] = cv2.aruco.generateImageMarker(d, mid, n)
        plate_corners[mid] = np.array([[x0, y0], [x0 + n, y0], [x0 + n, y0 + n], [x0, y0 + n]], float) / ppm
    plate = cv2.GaussianBlur(plate, (0, 0), sig)
    R_p = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
    o_p = np.array([-0.2, -0.12, 0.06])
    labels, corners_face = [], []
    for mid in (0, 1):
        for k in range(4):
            labels.append(f"M{mid}c{k}")
            corners_face.append(o_face + R_fb @ np.r_[face_corners[mid][k], 0.0])
    plate_world = [o_p + R_p @ np.r_[plate_corners[mid][k], 0.0] for mid in (2, 3) for k in range(4)]
    labels += [f"M{mid}c{k}" for mid in (2, 3) for k in range(4)]
    corners_face = np.asarray(corners_face)
    outs = []
    for k_cam, (cam, X) in enumerate(zip(cams, (X1, X2)), start=1):
        R, t, _ = kabsch(body_pts, X[:, :nb])
        mxp, myp = _plane_maps(cam, R_p, o_p, ppm)
        pimg = cv2.remap(plate, mxp, myp, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0)
        pmask = (
            cv2.remap(
                np.full_like(plate, 255), mxp, myp, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0
            ).astype(np.float32)
            / 255.0
        )
        vp = VideoPair(out, fps, size, mp4=False, stem=f"cam{k_cam}")
        for i in range(X.shape[0]):
            mx, my = _plane_maps(cam, R[i] @ R_fb, R[i] @ o_face + t[i], ppm)
            img = cv2.remap(face, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0)
            m = (
                cv2.remap(
                    np.full_like(face, 255), mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0
                ).astype(np.float32)
                / 255.0
            )
            frame = 30.0 * (1 - m) + img.astype(np.float32) * m
            frame = frame * (1 - pmask) + pimg.astype(np.float32) * pmask  # the plate is in front
            frame = cv2.GaussianBlur(frame, (0, 0), 0.6)
            lit = (m > 0) | (pmask > 0)
            frame[lit] += rng.normal(0.0, noise, int(lit.sum()))
            vp.write(np.clip(frame, 0, 255).astype(np.uint8))
        vp.close()
        paths[f"cam{k_cam}"] = vp.paths["mkv"]
        block_c = np.einsum("nij,pj->npi", R, corners_face) + t[:, None]
        outs.append(np.concatenate([block_c, np.broadcast_to(np.asarray(plate_world), (X.shape[0], 8, 3))], axis=1))
    return outs[0], outs[1], labels


def synth_stereo(
    out_dir,
    *,
    size=(2400, 1728),
    fps: float = 150.0,
    f_px: float = 3000.0,
    offset_s: float = 0.0027,
    n_board: int = 24,
    noise_dn: float = 2.0,
    dot_radius_m: float = 0.003,
    seed: int = 0,
    duration_s: float | None = None,
    targets: str = "dots",
    **motion,
) -> dict:
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
    targets : {"dots", "aruco"}
        Dots (retro-reflective targets), or two ArUco markers (``DICT_4X4_50`` ids 0, 1) on the
        block's front face and two (ids 2, 3) on a plate on the table's front edge; the truth
        then holds the markers' corners, labelled ``M<id>c<k>`` as the tracker labels them.
    **motion
        Passed to :func:`~rocklab.synth.synth_points3d` (``slide=``, ``jump=``, ``twist=``,
        ``double_impact=``, ``block=``, ``theta0_rad=``, ``restitution=``).

    Returns
    -------
    dict
        ``paths`` (name -> Path), ``cameras`` (two StereoCamera), ``session`` (the
        :class:`~rocklab.synth.Points3DSession` at camera 1's frame times), ``offset_s``.
    """
    from ._files import VideoPair
    from ._points3d import synth_points3d

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    cams = _cameras(tuple(size), f_px)
    paths = _calibration_films(out, cams, fps, size, f_px, n_board, noise_dn, rng)
    # the rocking film: the motion sampled finely, then read at each camera's frame times
    fine = 20
    sess = synth_points3d(
        rate_hz=fps * fine,
        noise_m=0.0,
        seed=seed,
        up="z",
        yaw_deg=0.0,
        offset_m=(0.0, 0.0, 0.0),
        side_targets=False,
        **motion,
    )
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
    if targets == "aruco":
        X1, X2, labels = _render_aruco_films(out, cams, sess, X1, X2, fps, size, noise_dn, rng, paths)
    elif targets == "dots":
        for k, (cam, X) in enumerate(zip(cams, (X1, X2)), start=1):
            vp = VideoPair(out, fps, size, mp4=False, stem=f"cam{k}")
            for i in range(t1.size):
                img, _ = _render_dots(cam, X[i], dot_radius_m, noise_dn, rng)
                vp.write(img)
            vp.close()
            paths[f"cam{k}"] = vp.paths["mkv"]
    else:
        raise ValueError(f"targets={targets!r}: must be 'dots' or 'aruco'")
    paths.update(_write_truth(out, sess, t1, X1, labels, cams, offset_s, fps))
    return {"paths": paths, "cameras": cams, "session": sess, "offset_s": offset_s, "t_s": t1, "X1": X1}


def _calibration_films(out: Path, cams, fps, size, f_px, n_board, noise_dn, rng) -> dict:
    """Film the ChArUco board in ``n_board`` poses with both cameras; returns {"calib_cam<k>": mkv path}."""
    import cv2

    from ._files import VideoPair

    board = charuco_board(CHARUCO)
    ppm = 4000.0
    bw = int(round(CHARUCO["squares"][0] * CHARUCO["square_m"] * ppm))
    bh = int(round(CHARUCO["squares"][1] * CHARUCO["square_m"] * ppm))
    texture = board.generateImage((bw, bh), marginSize=0)
    texture = (40 + texture.astype(np.float32) * (200 / 255)).astype(np.uint8)
    texture = cv2.GaussianBlur(texture, (0, 0), 0.5 * ppm * 0.9 / f_px)  # band-limited (see the markers)
    poses = _board_poses(n_board, rng)
    paths = {}
    for k, cam in enumerate(cams, start=1):
        vp = VideoPair(out, fps, size, mp4=False, stem=f"calib_cam{k}")
        for R_b, t_b in poses:
            vp.write(_render_board(cam, R_b, t_b, texture, ppm, noise_dn, rng))
        vp.close()
        paths[f"calib_cam{k}"] = vp.paths["mkv"]
    return paths


def _write_truth(out: Path, sess, t1, X1, labels, cams, offset_s, fps) -> dict:
    """Write truth.csv (motion at camera 1's frame times ``t1``, s), points_truth.csv (``X1``, m, (frames,
    points, 3)) and rig.json (cameras, clock offset, board, bodies, injected faults); returns their paths."""
    import pandas as pd

    truth = sess.truth
    tr = pd.DataFrame({c: np.interp(t1, truth["t_s"], truth[c]) for c in truth.columns})
    tr["t_s"] = t1
    truth_path = out / "truth.csv"
    tr.to_csv(truth_path, index=False, float_format="%.9g")
    pts = pd.DataFrame(
        {
            "t_s": np.repeat(t1, len(labels)),
            "point": np.tile(np.asarray(labels, dtype=object), t1.size),
            "x_m": X1[:, :, 0].ravel(),
            "y_m": X1[:, :, 1].ravel(),
            "z_m": X1[:, :, 2].ravel(),
        }
    )
    pts.to_csv(out / "points_truth.csv", index=False, float_format="%.9g")
    rig = {
        "cam1": cams[0].to_dict(),
        "cam2": cams[1].to_dict(),
        "offset_s": offset_s,
        "fps": fps,
        "charuco": CHARUCO,
        "bodies": {k: list(v) for k, v in sess.bodies.items()},
        "injected": {k: list(v) for k, v in sess.injected.items()},
    }
    (out / "rig.json").write_text(json.dumps(rig, indent=2))
    return dict(truth_csv=truth_path, points_truth_csv=out / "points_truth.csv", rig_json=out / "rig.json")
