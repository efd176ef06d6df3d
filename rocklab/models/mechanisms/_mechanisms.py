"""Three-block rocking mechanisms (four-bar linkages): asymmetric frame and masonry arch.

DeJong & Dimitrakopoulos 2014 §5: the mechanism is built from its rest geometry
(ground pivots, hinges, rigid bodies), its kinematics follow from the loop
closure, and :class:`rocklab.models.Mechanism` linearises it into the
equivalent block (Eq. 9–20, 38–39). SI units (m, kg, kg m^2 per unit depth for
the arch).
"""

from __future__ import annotations

import math

import numpy as np

from ..._errors import InputError
from ...blocks import G
from ..._errors import positive
from ._equivalent import Mechanism, block_parameters

__all__ = ["four_bar_mechanism", "asymmetric_frame", "arch_mechanism"]


# -- four-bar linkages (asymmetric frame §5.1, arch §5.2) ------------------------------


def _cross(u, v) -> float:
    return float(u[0] * v[1] - u[1] * v[0])


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


def _rot(v, t):
    c, s = math.cos(t), math.sin(t)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def four_bar_mechanism(A, B, C, D, bodies, name: str = "four-bar") -> Mechanism:
    """A three-block mechanism (four-bar linkage) from its rest geometry.

    Parameters
    ----------
    A, D : (2,) array_like
        Ground pivots, m (x right, y up).
    B, C : (2,) array_like
        Hinges link1/coupler and coupler/link3 at rest, m.
    bodies : sequence of three (mass_kg, (x_cm, y_cm), I_c_kg_m2)
        Rigid bodies attached to link AB, coupler BC and link CD: mass, centre of
        mass at rest (m) and moment of inertia about it.
    name : str
        Label used in errors and reports.

    Returns
    -------
    Mechanism
        The one-degree-of-freedom mechanism in the coordinate phi.

    Notes
    -----
    The coordinate phi is the clockwise rotation of AB about A (paper: phi = phi_0 - varphi);
    C follows from the loop closure on the branch of the rest configuration.
    Derivatives are central differences of the exact kinematics.
    """
    A, B0, C0, D = (np.asarray(x, float) for x in (A, B, C, D))
    l2 = float(np.linalg.norm(C0 - B0))
    l3 = float(np.linalg.norm(C0 - D))
    if min(l2, l3, float(np.linalg.norm(B0 - A))) <= 0:
        raise InputError(f"{name}: coincident hinge points; check the geometry")
    side0 = float(np.sign(_cross(D - B0, C0 - B0))) or 1.0
    ms = np.array([b[0] for b in bodies], float)
    cms = [np.asarray(b[1], float) for b in bodies]
    Ic = np.array([b[2] for b in bodies], float)
    ang_bc0 = math.atan2(*(C0 - B0)[::-1])
    ang_dc0 = math.atan2(*(C0 - D)[::-1])

    def config(phi):
        Bp = A + _rot(B0 - A, -phi)
        d = D - Bp
        dd = float(np.hypot(*d))
        if dd > l2 + l3 or dd < abs(l2 - l3):
            return None
        x = (l2 * l2 - l3 * l3 + dd * dd) / (2 * dd)
        y = math.sqrt(max(l2 * l2 - x * x, 0.0))
        e = d / dd
        n = np.array([-e[1], e[0]])
        Cp = Bp + x * e + side0 * y * n  # keep the rest configuration's branch
        # rotations from rest wrapped to (-pi, pi]: a link pointing along -x at rest (a mirrored
        # frame's beam) would otherwise jump by 2 pi between neighbouring phi
        t2 = _wrap(math.atan2(*(Cp - Bp)[::-1]) - ang_bc0)
        t3 = _wrap(math.atan2(*(Cp - D)[::-1]) - ang_dc0)
        r = [A + _rot(cms[0] - A, -phi), Bp + _rot(cms[1] - B0, t2), D + _rot(cms[2] - D, t3)]
        return np.array(r), np.array([-phi, t2, t3])

    # kinematic limit
    phi_max = math.pi / 2
    for f in np.linspace(0, math.pi / 2, 2001)[1:]:
        if config(f) is None:
            phi_max = f - math.pi / 4000
            break

    def V(phi):
        r, _ = config(phi)
        return G * float(ms @ r[:, 1])

    def _derivs(phi, h=1e-6):
        rp, tp = config(phi + h)
        rm, tm = config(phi - h)
        return (rp - rm) / (2 * h), (tp - tm) / (2 * h)

    def M(phi):
        dr, dt = _derivs(phi)
        return float(ms @ (dr**2).sum(axis=1) + Ic @ dt**2)

    def Bf(phi):
        dr, _ = _derivs(phi)
        return float(ms @ dr[:, 0])

    def eom(phi, h=1e-4):
        (rm, tm), (r0, t0), (rp, tp) = config(phi - h), config(phi), config(phi + h)
        dr, dt = (rp - rm) / (2 * h), (tp - tm) / (2 * h)
        ddr, ddt = (rp - 2 * r0 + rm) / h**2, (tp - 2 * t0 + tm) / h**2
        M_ = float(ms @ (dr**2).sum(axis=1) + Ic @ dt**2)
        dM_ = float(2 * ms @ (dr * ddr).sum(axis=1) + 2 * Ic @ (dt * ddt))
        return M_, dM_, G * float(ms @ dr[:, 1]), float(ms @ dr[:, 0])

    return Mechanism(M=M, V=V, B=Bf, phi_max=phi_max, name=name, eom=eom)


#: Largest ratio between two lengths of one mechanism (beyond it the geometry is degenerate in floats).
MAX_LENGTH_RATIO = 1e6


def _comparable(what: str, **lengths) -> None:
    """:class:`InputError` unless the mechanism's lengths are within :data:`MAX_LENGTH_RATIO` of each other."""
    lo, hi = min(lengths, key=lambda k: lengths[k]), max(lengths, key=lambda k: lengths[k])
    if lengths[hi] > MAX_LENGTH_RATIO * lengths[lo]:
        raise InputError(
            f"{what}: {hi}={lengths[hi]:g} is more than {MAX_LENGTH_RATIO:g} times {lo}={lengths[lo]:g}; "
            "give the mechanism's lengths in one unit (m)"
        )


def asymmetric_frame(
    b_m: float, H_m: float, H1_m: float, L_m: float, h_m: float, m_AB: float, m_BC: float, m_CD: float
):
    """Asymmetric rocking frame (paper §5.1, Fig. 4) in both rocking directions.

    Geometry (half-dimensions as in Eq. 33): the left column AB is 2b wide and 2H
    high, the right column CD 2b wide and 2H_1 high standing on a step so that both
    tops are at 2H; the beam (2h deep) rests on both and spans from the left face
    of the left column to the right face of the right column; L is the distance
    between the columns' left faces. Rectangles are uniform.

    Returns
    -------
    (Mechanism, Mechanism)
        Positive (clockwise: pivots A bottom-right, B/C top-left corners, D
        bottom-right) and negative direction (the mirror image; the coordinate is
        still the left column's rotation).
    """
    b, H, H1, L, h = (
        positive(n, v) for n, v in (("b_m", b_m), ("H_m", H_m), ("H1_m", H1_m), ("L_m", L_m), ("h_m", h_m))
    )
    if L <= 2 * b:
        raise InputError(f"L_m={L}: columns overlap; the left-face distance L must exceed the width 2b")
    _comparable("asymmetric frame", b_m=b, H_m=H, H1_m=H1, L_m=L, h_m=h)
    mA, mB, mC = (positive(n, v) for n, v in (("m_AB", m_AB), ("m_BC", m_BC), ("m_CD", m_CD)))
    yD = 2 * H - 2 * H1
    wbeam = L + 2 * b
    body_ab = (mA, (b, H), mA * (4 * b * b + 4 * H * H) / 12)
    body_bc = (mB, (wbeam / 2, 2 * H + h), mB * (wbeam**2 + 4 * h * h) / 12)
    body_cd = (mC, (L + b, yD + H1), mC * (4 * b * b + 4 * H1 * H1) / 12)

    def mirror(pt):
        return (-pt[0], pt[1])

    pos = four_bar_mechanism(
        (2 * b, 0), (0, 2 * H), (L, 2 * H), (L + 2 * b, yD), [body_ab, body_bc, body_cd], name="asymmetric-frame+"
    )
    neg = four_bar_mechanism(
        mirror((0, 0)),
        mirror((2 * b, 2 * H)),
        mirror((L + 2 * b, 2 * H)),
        mirror((L, yD)),
        [(m, mirror(c), i) for m, c, i in (body_ab, body_bc, body_cd)],
        name="asymmetric-frame-",
    )
    return pos, neg


# -- masonry arch (§5.2) -----------------------------------------------------------------


def _sector(r_i, r_e, a1, a2):
    """Area, centroid and polar moment about its centroid of an annular sector (unit depth, density 1)."""
    d = a2 - a1
    area = 0.5 * d * (r_e**2 - r_i**2)
    rc = (2.0 / 3.0) * (r_e**3 - r_i**3) / (r_e**2 - r_i**2) * math.sin(d / 2) / (d / 2)
    am = 0.5 * (a1 + a2)
    cm = np.array([rc * math.cos(am), rc * math.sin(am)])
    J0 = 0.25 * d * (r_e**4 - r_i**4)
    return area, cm, J0 - area * rc * rc


def _arch_hinges(beta, t, r, u, faces, mirror=False):
    """Hinge points and the three moving bodies for hinge fractions u (0 = left springing)."""
    ri, re = r - t / 2, r + t / 2
    ang = math.pi / 2 + beta / 2 - np.asarray(u) * beta  # from the left springing clockwise
    pts = [np.array([(re if f else ri) * math.cos(a), (re if f else ri) * math.sin(a)]) for a, f in zip(ang, faces)]
    bodies = [_sector(ri, re, ang[k + 1], ang[k]) for k in range(3)]
    if mirror:  # x -> -x: the mechanism for the other direction, still a clockwise coordinate
        pts = [np.array([-q[0], q[1]]) for q in pts]
        bodies = [(m, np.array([-c[0], c[1]]), i) for m, c, i in bodies]
    return pts, bodies


def _lambda_at_rest(pts, bodies):
    """Virtual-work uplift lambda = sum m v_y / sum m v_x for a unit clockwise rotation of AB."""
    A, B, C, D = pts

    def perp(v):
        return np.array([-v[1], v[0]])

    vB = -perp(B - A)  # omega_1 = -1 (clockwise)
    M = np.column_stack([perp(C - D), -perp(C - B)])
    if abs(np.linalg.det(M)) < 1e-12:
        return float("nan")
    w3, w2 = np.linalg.solve(M, vB)
    vel = [-perp(bodies[0][1] - A), vB + w2 * perp(bodies[1][1] - B), w3 * perp(bodies[2][1] - D)]
    num = sum(b[0] * v[1] for b, v in zip(bodies, vel))
    den = sum(b[0] * v[0] for b, v in zip(bodies, vel))
    return num / den if den > 0 and num > 0 else float("nan")


def arch_mechanism(inclusion_angle_rad: float, thickness_m: float, radius_m: float, hinges=None, grid: int = 17):
    """Rocking masonry arch as a three-block mechanism (paper §5.2, Oppenheim's mechanism).

    Parameters
    ----------
    inclusion_angle_rad : float
        Angle beta subtended by the arch (pi = semicircle), rad.
    thickness_m, radius_m : float
        Ring thickness t_a and centre-line radius r_a, m (uniform density, unit depth).
    hinges : sequence of 4 floats, optional
        Hinge positions as fractions of the arch from the left springing (A < B < C < D);
        faces alternate extrados/intrados starting at the extrados (A, C on the
        extrados), or as found by the search (which also tries the other face pattern
        and the mirror image).
        Default: the positions with the smallest uplift lambda, found on a ``grid``
        of positions and refined (a very large number of voussoirs, as in the paper).

    Returns
    -------
    (Mechanism, dict)
        The mechanism (coordinate: clockwise rotation of the left segment) and
        ``{"hinges": (u_A, u_B, u_C, u_D), "faces": ..., "lambda": ...}``.
    """
    beta = positive("inclusion_angle_rad", inclusion_angle_rad)
    t, r = positive("thickness_m", thickness_m), positive("radius_m", radius_m)
    if beta > 2 * math.pi * 0.95 or t >= r:
        raise InputError(f"arch: need inclusion angle < 1.9 pi and thickness < radius (got {beta}, {t}, {r})")
    _comparable("arch", thickness_m=t, radius_m=r)
    faces, mirror = (True, False, True, False), False
    if hinges is None:
        best: tuple[float, tuple | None] = (math.inf, None)
        g = np.linspace(0, 1, int(grid))
        for fc in ((True, False, True, False), (False, True, False, True)):
            for mir in (False, True):
                # A in the left half, D in the right half, segments >= 2 grid steps: the
                # global mechanism of the paper's Fig. 9, not local snaps near a springing
                for ia in range(g.size // 2):
                    for ib in range(ia + 2, g.size):
                        for ic in range(ib + 2, g.size):
                            for id_ in range(max(ic + 2, g.size // 2 + 1), g.size):
                                trial = (g[ia], g[ib], g[ic], g[id_])
                                lam = _lambda_at_rest(*_arch_hinges(beta, t, r, trial, fc, mir))
                                if lam < best[0]:
                                    best, faces, mirror = (lam, trial), fc, mir
        if best[1] is None:
            raise InputError("arch: no admissible four-hinge mechanism found; check the geometry")
        ua = np.array(best[1])
        step = 1.0 / (grid - 1)
        for _ in range(4):  # local refinement of the hinge positions
            step /= 3
            cand = ua
            lam0 = best[0]
            for k in range(4):
                for sgn in (-1, 1):
                    v = ua.copy()
                    v[k] = min(1.0, max(0.0, v[k] + sgn * step))
                    if np.all(np.diff(v) > 0):
                        lam = _lambda_at_rest(*_arch_hinges(beta, t, r, v, faces, mirror))
                        if lam < lam0:
                            lam0, cand = lam, v
            ua = cand
            best = (lam0, tuple(ua))
        hinges = best[1]
    u = tuple(float(x) for x in hinges)
    if len(u) != 4 or not all(0 <= a < b_ for a, b_ in zip(u, u[1:])) or u[-1] > 1:
        raise InputError(f"hinges={hinges!r}: need 4 increasing fractions in [0, 1]")
    pts, bodies = _arch_hinges(beta, t, r, u, faces, mirror)
    mech = four_bar_mechanism(pts[0], pts[1], pts[2], pts[3], [(b[0], tuple(b[1]), b[2]) for b in bodies], name="arch")
    return mech, {
        "hinges": u,
        "faces": ["extrados" if f else "intrados" for f in faces],
        "mirrored": mirror,
        "lambda": _lambda_at_rest(pts, bodies),
    }


# -- single-body mechanisms of Table I -------------------------------------------------


def block_mechanism(
    R_m: float, alpha_rad: float, alpha_I: float = 4.0 / 3.0, eta: float | None = None, name: str = "block"
) -> Mechanism:
    """A rocking block (or any structure of Table I) as a :class:`Mechanism`, per unit mass.

    M = alpha_I R^2, V = g R cos(alpha - phi), B = R cos(alpha - phi): Lagrange gives Eq. 2,
    phi'' = -p^2 (sin(alpha - phi) + u_g''/g cos(alpha - phi)) with p^2 = g / (alpha_I R). The
    strut is ``alpha_I = 1``; the symmetric frame of mass ratio gamma is the block with
    ``alpha_I = (4/3 + 4 gamma) / (1 + 2 gamma)`` (the same p, alpha and lambda, Eq. 35-37).

    Parameters
    ----------
    R_m : float
        Pivot-to-centre-of-mass distance, m.
    alpha_rad : float
        Slenderness angle, rad.
    alpha_I : float
        I_O / (m R^2).
    eta : float, optional
        Restitution; default Housner's 1 - 2 sin^2(alpha) / alpha_I (angular momentum, Table I).
    """
    fp = block_parameters(R_m, alpha_rad, alpha_I)
    R, a, aI = float(R_m), float(alpha_rad), float(alpha_I)
    return Mechanism(
        M=lambda f: aI * R * R,
        V=lambda f: G * R * math.cos(a - f),
        B=lambda f: R * math.cos(a - f),
        phi_max=math.pi / 2,
        name=name,
        eta=fp.eta if eta is None else float(eta),
        eom=lambda f: (aI * R * R, 0.0, G * R * math.sin(a - f), R * math.cos(a - f)),
    )
