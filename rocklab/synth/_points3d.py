"""A motion-capture session of a free-rocking block, with exact truth.

:func:`synth_points3d` simulates a thread-burn release with the single-block
model, places dot targets on the block (front face and one side, so the set is
not planar) and on the table, moves them with the simulated rocking, and
expresses them in a rig whose axes are yawed and offset from the block's, with
the vertical on any named axis. Deliberate departures from planar rocking can
be injected at a chosen impact: a slide of the block along the table, a jump
(a parabolic flight), a twist about the vertical, or a double impact (a short
bounce back onto the edge just left). The truth table holds every quantity the
3D tracker and the audit measure.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..blocks import Block
from ..tracking.rigid import PointSeries
from ..tracking.rigid._rocking import axis_vector

__all__ = ["Points3DSession", "synth_points3d", "G_M_S2"]

G_M_S2 = 9.81


@dataclass(frozen=True)
class Points3DSession:
    """A simulated 3D point record and its truth.

    Attributes
    ----------
    series : PointSeries
        Target positions in the rig's axes, m, with noise.
    truth : pandas.DataFrame
        Per sample: ``t_s, theta_rad, twist_rad, out_of_plane_rad, slide_m, uplift_m, table_x_m``
        (slide and uplift of the block's base, m; ``theta > 0`` tips the top towards the rig's ``e_r``).
    impacts_t_s : ndarray
        Impact times of the simulated motion (after the injected events), s.
    block : Block
    bodies : dict
        ``{"block": labels, "table": labels}`` (the ``--body`` split).
    e_r, axis, up : ndarray, shape (3,)
        The block's rocking direction, rocking axis and the vertical in rig axes.
    injected : dict
        What was injected: ``{"slide": (impact, m), "jump": (impact, m), ...}``.
    """

    series: PointSeries
    truth: object
    impacts_t_s: np.ndarray
    block: Block
    bodies: dict
    e_r: np.ndarray
    axis: np.ndarray
    up: np.ndarray
    injected: dict

    def write(self, folder, c3d: bool = True) -> dict:
        """Write ``points.csv``, ``points.c3d`` (optional) and ``truth.csv`` into ``folder``; returns the paths."""
        from .._io import write_frame_atomic
        from ..tracking.rigid import write_c3d, write_points_csv

        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        paths = {
            "points_csv": write_points_csv(self.series, folder / "points.csv"),
            "truth_csv": write_frame_atomic(folder / "truth.csv", self.truth, float_format="%.9g"),
        }
        if c3d:
            paths["points_c3d"] = write_c3d(self.series, folder / "points.c3d")
        return paths


def target_points(block: Block, depth_m: float, side: bool = True):
    """Block targets in block axes (x along the width, y along the depth, z up; origin at the base centre)."""
    b, h, d = block.b_m, block.h_m, depth_m
    pts = []
    for zf in (0.2, 0.45, 0.7, 0.92):
        for xf in (-0.3, 0.3):
            pts.append((xf * b, -d / 2, zf * h))  # front face, two columns of dots
    if side:
        pts += [(b / 2, 0.15 * d, 0.35 * h), (b / 2, -0.2 * d, 0.8 * h)]  # one side face
    labels = [f"B{i + 1}" for i in range(len(pts))]
    return np.asarray(pts), labels


def _rig(up: str, yaw_rad: float) -> np.ndarray:
    """Rotation from block/world axes (z up) to rig axes (``up`` names the rig's vertical)."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    yaw = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    u = axis_vector(up)
    k = int(np.argmax(np.abs(u)))
    # cyclic permutations (proper rotations) taking world z to rig axis k; a half-turn about x flips it
    perm = np.roll(np.eye(3), k + 1, axis=0)
    if u[k] < 0:
        perm = perm @ np.diag([1.0, -1.0, -1.0])
    return perm @ yaw


def _bounce(t, theta, t_k, tau_s, amp_rad):
    """``theta`` with a bounce of ``tau_s`` back onto the old side at impact ``t_k``, the rest delayed by ``tau_s``."""
    old = np.interp(t_k - 1e-3, t, theta)
    out = np.interp(t - tau_s, t, theta)
    out[t < t_k] = theta[t < t_k]
    w = (t >= t_k) & (t < t_k + tau_s)
    out[w] = math.copysign(amp_rad, old) * np.sin(math.pi * (t[w] - t_k) / tau_s)
    return out


def synth_points3d(
    block: Block | None = None,
    theta0_rad: float | None = None,
    restitution="housner",
    rate_hz: float = 150.0,
    hold_s: float = 0.3,
    tail_s: float = 0.6,
    noise_m: float = 5e-5,
    seed: int = 0,
    up: str = "z",
    yaw_deg: float = 27.0,
    offset_m=(0.42, -0.31, 0.05),
    slide: tuple | None = None,
    jump: tuple | None = None,
    twist: tuple | None = None,
    double_impact: int | None = None,
    depth_m: float | None = None,
    table: bool = True,
    side_targets: bool = True,
) -> Points3DSession:
    """Simulate a motion-capture record of a free-rocking block (thread-burn release).

    Parameters
    ----------
    block : Block, optional
        Default: b = 0.1 m, h = 0.4 m (a 40 cm granite-like specimen).
    theta0_rad : float, optional
        Release angle, rad (default 0.6 alpha).
    restitution : str, float or Restitution
        Passed to :func:`rocklab.models.simulate`.
    rate_hz : float
        Sample rate, Hz (default 150, Čeh's GOM rig).
    hold_s, tail_s : float
        Time held at ``theta0`` before the release, and at rest after the motion, s.
    noise_m : float
        1-sigma of the per-coordinate position noise, m (default 0.05 mm).
    seed : int
    up : str
        The rig's vertical axis (``x``, ``y``, ``z`` with an optional sign).
    yaw_deg : float
        Rotation of the rig about the vertical against the block's rocking direction, deg.
    offset_m : tuple of 3 floats
        The block base centre's position in rig axes, m.
    slide, jump, twist : (impact, value), optional
        At that impact (1-based): slide the block along its rocking direction by
        ``value`` m; lift it into a parabolic flight of height ``value`` m; turn it
        about the vertical by ``value`` rad (it stays turned).
    double_impact : int, optional
        At that impact the block bounces back for 25 ms (0.3 deg) before rocking on.
    depth_m : float, optional
        Out-of-plane depth of the block, m (default 0.6 b).
    table : bool
        Also four targets on the (still) table, body ``table``.
    side_targets : bool
        Two of the block's targets on its side face (off: all on the front face,
        as two cameras in front see them).

    Returns
    -------
    Points3DSession
    """
    import pandas as pd

    from ..models import simulate

    block = block or Block(b_m=0.1, h_m=0.4, name="synth3d")
    depth = depth_m if depth_m is not None else 0.6 * block.b_m
    th0 = 0.6 * block.alpha_rad if theta0_rad is None else float(theta0_rad)
    dt = 1.0 / rate_hz
    res = simulate(block, theta0_rad=th0, duration_s=30.0, restitution=restitution, output_dt_s=dt)
    motion_t = res.t_s
    t = np.arange(0.0, hold_s + motion_t[-1] + tail_s, dt)
    tm = t - hold_s
    theta = np.where(tm < 0, th0, np.interp(tm, motion_t, res.theta_rad, right=0.0))
    impacts = hold_s + np.asarray(res.impacts["t_s"], float)
    theta, impacts, (slide_x, uplift, psi), injected = _inject(t, theta, impacts, double_impact, slide, jump, twist)
    body, labels = target_points(block, depth, side_targets)
    n = t.size
    half = block.b_m / 2.0
    world = _block_points(body, half, theta, psi, slide_x, uplift)
    all_labels = list(labels)
    if table:
        tpts = np.array(
            [[-2.5 * half, -depth, 0.0], [2.5 * half, -depth, 0.0], [2.5 * half, depth, 0.0], [-2.5 * half, depth, 0.0]]
        )
        world = np.concatenate([world, np.broadcast_to(tpts, (n, 4, 3))], axis=1)
        all_labels += [f"T{i + 1}" for i in range(4)]
    Q = _rig(up, math.radians(yaw_deg))
    rig = np.einsum("ij,npj->npi", Q, world) + np.asarray(offset_m, float)
    rng = np.random.default_rng(seed)
    rig = rig + rng.normal(0.0, noise_m, rig.shape)
    series = PointSeries(t, tuple(all_labels), rig, f"synth3d(seed={seed})")
    # theta about the rocking axis from the truth's body frame: the tracker's e_r is +-Q x; keep its sign rule
    e_r = Q @ np.array([1.0, 0.0, 0.0])
    axis = Q @ np.array([0.0, 1.0, 0.0])
    truth = pd.DataFrame(
        {
            "t_s": t,
            "theta_rad": theta,
            "twist_rad": psi,
            "out_of_plane_rad": np.zeros(n),
            "slide_m": slide_x,
            "uplift_m": uplift,
            "table_x_m": np.zeros(n),
        }
    )
    bodies = {"block": tuple(labels)}
    if table:
        bodies["table"] = tuple(all_labels[len(labels) :])
    return Points3DSession(series, truth, impacts, block, bodies, e_r, axis, Q @ np.array([0.0, 0.0, 1.0]), injected)


def _inject(t, theta, impacts, double_impact, slide, jump, twist):
    """The faults asked for, injected at their impacts (1-based) into the rocking history ``theta`` (rad).

    Returns (theta rad, impact times s, (slide m, uplift m, twist rad) each like ``t``, {fault: (impact, value)}).
    """
    injected = {}

    def at(k, what):
        if not 1 <= int(k) <= impacts.size:
            raise ValueError(f"{what} at impact {k}: the motion has {impacts.size} impacts")
        return float(impacts[int(k) - 1])

    if double_impact is not None:
        t_k = at(double_impact, "double_impact")
        tau = 0.025
        theta = _bounce(t, theta, t_k, tau, math.radians(0.3))
        later = impacts > t_k
        impacts = np.sort(np.r_[impacts[~later], t_k, t_k + tau, impacts[later] + tau])
        injected["double_impact"] = (int(double_impact), tau)
    slide_x = np.zeros_like(t)
    uplift = np.zeros_like(t)
    psi = np.zeros_like(t)
    if slide is not None:
        t_k = at(slide[0], "slide")
        slide_x[t >= t_k] = float(slide[1])
        injected["slide"] = (int(slide[0]), float(slide[1]))
    if jump is not None:
        t_k = at(jump[0], "jump")
        h = float(jump[1])
        tau = 2.0 * math.sqrt(2.0 * h / G_M_S2)
        u = (t - t_k) / tau
        w = (u >= 0) & (u <= 1)
        uplift[w] = 4.0 * h * u[w] * (1.0 - u[w])
        injected["jump"] = (int(jump[0]), h)
    if twist is not None:
        t_k = at(twist[0], "twist")
        psi[t >= t_k] = float(twist[1])
        injected["twist"] = (int(twist[0]), float(twist[1]))
    return theta, impacts, (slide_x, uplift, psi), injected


def _block_points(body, half, theta, psi, slide_x, uplift):
    """World positions (n, points, 3) m of the body points (points, 3) of a block rocking by ``theta`` about its
    edges at ±``half`` m, turned by ``psi`` rad about the vertical, slid by ``slide_x`` m, lifted by ``uplift`` m."""
    n = theta.size
    c, s = np.cos(theta), np.sin(theta)
    px = np.where(theta >= 0, half, -half)  # the edge it turns about
    q = body[None, :, :] - np.stack([px, np.zeros(n), np.zeros(n)], axis=1)[:, None, :]
    x = c[:, None] * q[..., 0] + s[:, None] * q[..., 2] + px[:, None]
    z = -s[:, None] * q[..., 0] + c[:, None] * q[..., 2]
    y = q[..., 1]
    cp, sp = np.cos(psi)[:, None], np.sin(psi)[:, None]
    xw = cp * x - sp * y + slide_x[:, None]
    yw = sp * x + cp * y
    zw = z + uplift[:, None]
    return np.stack([xw, yw, zw], axis=2)
