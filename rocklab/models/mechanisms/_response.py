"""Time histories of rocking mechanisms under base motion (DeJong & Dimitrakopoulos 2014, Eq. 6, 8, 16).

A mechanism rocks in two directions, each a :class:`~rocklab.models.mechanisms.Mechanism` in its
own coordinate phi >= 0 (a symmetric mechanism uses the same one twice). The signed rotation is
phi > 0 in the positive direction and -phi in the negative one. Between impacts Lagrange's
equation (Eq. 8)

    M(phi) phi'' + M'(phi) phi'^2 / 2 + V'(phi) = -B(phi) s u_g''

holds, with s = +1 in the positive direction and -1 in the negative one (the negative mechanism
is the mirror image, so the base pushes it the other way). At phi = 0 the pivots change and the
angular velocity is multiplied by the restitution eta (Eq. 6). From rest, the mechanism uplifts
in the direction whose uplift acceleration lambda (Eq. 10) the base exceeds.

The equivalent block of each direction (Eq. 14-17: theta = phi / kappa) is itself written as a
mechanism, so one integrator serves the three models the paper compares (Fig. 14):

* ``nonlinear``: the mechanism's own equation (Eq. 8);
* ``linear``: the linearised equivalent block, theta'' = p^2 (theta - theta_cr - u_g''/g) (Eq. 16);
* ``block``: the nonlinear rocking block with the same p and alpha = theta_cr (Eq. 3).

Each is integrated with scipy's DOP853 between events (impact, overturning) at tolerances that
put an impact time within 1e-9 s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..._errors import InputError
from ...blocks import G
from ._equivalent import FundamentalParameters, Mechanism

__all__ = ["MechanismResponse", "mechanism_response", "equivalent_block_mechanism", "mechanism_time_histories"]

#: The mechanism is at rest when its rate after an impact is below this, rad/s (it rises by less
#: than 1e-18 rad: the impacts of a settling mechanism converge geometrically, Zeno-like).
REST_VELOCITY_RAD_S = 1e-9
#: Integrator tolerances (per record interval): the linear block's impacts stay within 1e-10 s of
#: Eq. 24 over 12 half periods (at 1e-10 the restarts at every interval cost 5e-8 s per impact).
RTOL, ATOL = 1e-12, 1e-14
#: A mechanism overturns this far short of its kinematic limit, rad (a linkage's equation needs
#: configurations on both sides of phi for its finite differences).
KINEMATIC_MARGIN_RAD = 1e-3
#: Points of the spline table of a mechanism's equation of motion (see ``tabulate``).
TABLE_POINTS = 2049


@dataclass(frozen=True)
class MechanismResponse:
    """Response of one model of a rocking mechanism to a base motion.

    Attributes
    ----------
    t_s : ndarray, shape (n,)
        Output times, s (the base motion's grid unless another was asked for).
    phi_rad : ndarray, shape (n,)
        Signed rotation in the mechanism's coordinate, rad (> 0 positive direction); for the
        equivalent blocks kappa * theta, so all models compare on one axis. NaN after overturning.
    phi_dot_rad_s : ndarray, shape (n,)
        Its rate, rad/s.
    phi_cr_rad : tuple of float
        Critical rotation of the positive and negative directions, rad.
    impacts_t_s : ndarray
        Impact times (phi = 0 with a change of direction), s.
    overturned : bool
        True when |phi| reached the overturning limit: 1e-3 rad short of the mechanism's
        kinematic limit ``phi_max`` (at most pi/2: lying on its side); for an equivalent block
        theta = pi/2, so every model falls at the same rotation.
    t_overturn_s : float
        Time of overturning, s (NaN if it did not overturn).
    model : str
        ``nonlinear``, ``linear`` or ``block``.
    eta : float
        Restitution used at every impact.
    name : str
        Mechanism label.
    status, message : str
        ``ok``; ``overturned`` (the history ends there); ``falling`` (the record ends with the
        mechanism past its critical rotation and opening: it falls without more base motion).
    """

    t_s: np.ndarray
    phi_rad: np.ndarray
    phi_dot_rad_s: np.ndarray
    phi_cr_rad: tuple
    impacts_t_s: np.ndarray
    overturned: bool
    t_overturn_s: float
    model: str
    eta: float
    name: str = ""
    status: str = "ok"
    message: str = ""
    meta: dict = field(default_factory=dict, compare=False)

    @property
    def peak_ratio(self) -> float:
        """Largest |phi| / phi_cr of the direction it occurred in (>= 1 when it overturned)."""
        if self.overturned:
            return float("inf")
        pos = np.nanmax(np.clip(self.phi_rad, 0, None)) / self.phi_cr_rad[0]
        neg = np.nanmax(np.clip(-self.phi_rad, 0, None)) / self.phi_cr_rad[1]
        return float(max(pos, neg))

    def to_frame(self):
        """Table with ``t_s``, ``phi_rad``, ``phi_dot_rad_s`` and ``phi_over_phi_cr`` (signed)."""
        import pandas as pd

        cr = np.where(self.phi_rad >= 0, self.phi_cr_rad[0], self.phi_cr_rad[1])
        return pd.DataFrame(
            {
                "t_s": self.t_s,
                "phi_rad": self.phi_rad,
                "phi_dot_rad_s": self.phi_dot_rad_s,
                "phi_over_phi_cr": self.phi_rad / cr,
            }
        )

    def to_dict(self) -> dict:
        """Scalars only (the arrays are in :meth:`to_frame`)."""
        return {
            "model": self.model,
            "name": self.name,
            "eta": self.eta,
            "phi_cr_rad": list(self.phi_cr_rad),
            "n_impacts": int(self.impacts_t_s.size),
            "impacts_t_s": [float(t) for t in self.impacts_t_s],
            "overturned": bool(self.overturned),
            "t_overturn_s": None if not self.overturned else float(self.t_overturn_s),
            "peak_ratio": None if self.overturned else self.peak_ratio,
            "status": self.status,
            "message": self.message,
        }


def _uplift(mech: Mechanism) -> float:
    """Uplift acceleration / g of one direction (Eq. 10)."""
    return mech.dV(1e-7, 1e-7) / (G * mech.B(0.0))


def _falls(mech: Mechanism, phi: float, om: float) -> bool:
    """Whether a free mechanism at (phi, om) (its own coordinate, om > 0 opening) overturns.

    V has its maximum at phi_cr: opening, it falls when its energy passes that barrier; closing
    from beyond phi_cr, when it has too little energy to come back over it.
    """
    pc = mech.phi_cr()
    e = 0.5 * mech.M(phi) * om * om + mech.V(phi) - mech.V(pc)
    return (phi > pc or e > 0) if om > 0 else (phi > pc and e < 0)


def _tabulated(mech: Mechanism, phi_hi: float, n: int = TABLE_POINTS):
    """The mechanism's (M, M', V', B) as cubic splines on [0, phi_hi]: a linkage's equation costs
    about 0.1 ms per evaluation (its kinematics by finite differences), the spline a few us."""
    from scipy.interpolate import CubicSpline

    x = np.linspace(0.0, phi_hi, n)
    sp = CubicSpline(x, np.array([mech._eom(float(v)) for v in x]), axis=0)
    return lambda phi: sp(phi)


def _flight(eom, y, t, t_end, tb, ab, side, phi_hi):
    """Integrate one excursion record interval by record interval (the base is linear inside one,
    so the right-hand side is smooth there and DOP853 keeps its order).

    Returns ``(t, y, event, pieces)``: the time and state where it stopped, ``"impact"``,
    ``"over"`` or ``None`` (end of the record), and the dense solutions for the output grid.
    """
    from scipy.integrate import solve_ivp

    def impact(tt, yy):
        return yy[0]

    def over(tt, yy):
        return yy[0] - phi_hi

    impact.terminal, impact.direction = True, -1  # scipy's event protocol
    over.terminal, over.direction = True, 1
    k = max(int(np.searchsorted(tb, t, side="right")) - 1, 0)
    pieces = []
    while t < t_end:
        t1 = float(tb[min(k + 1, tb.size - 1)])
        if t1 <= t:
            k += 1
            continue
        a0, da = side * ab[k], side * (ab[k + 1] - ab[k]) / (tb[k + 1] - tb[k])
        tk = float(tb[k])

        def rhs(tt, yy, a0=a0, da=da, tk=tk):
            phi, om = yy
            # a Runge-Kutta stage may probe just past the overturning limit, where a linkage has
            # no configuration: the force there is held at the limit's (the event cuts the step)
            M, dM, dV, B = eom(min(max(phi, 0.0), phi_hi))
            return [om, (-B * (a0 + da * (tt - tk)) - dV - 0.5 * dM * om * om) / M]

        sol = solve_ivp(
            rhs, (t, t1), y, method="DOP853", events=[impact, over], dense_output=True, rtol=RTOL, atol=ATOL
        )
        pieces.append((t, float(sol.t[-1]), sol.sol))
        t, y = float(sol.t[-1]), sol.y[:, -1]
        if sol.t_events[1].size:
            return t, y, "over", pieces
        if sol.t_events[0].size:
            return t, sol.y_events[0][0], "impact", pieces
        k += 1
    return t, y, None, pieces


def mechanism_response(
    positive: Mechanism,
    base,
    eta: float,
    negative: Mechanism | None = None,
    phi0_rad: float = 0.0,
    phi_limit_rad: tuple | None = None,
    scale: tuple = (1.0, 1.0),
    t_out_s=None,
    model: str = "nonlinear",
    tabulate: bool = True,
) -> MechanismResponse:
    """Integrate a two-direction rocking mechanism under a base motion.

    Parameters
    ----------
    positive : Mechanism
        The mechanism rocking in the positive direction (its coordinate phi >= 0).
    base : BaseMotion
        Horizontal base acceleration, m/s^2 (positive towards +x), on a uniform grid.
    eta : float
        Restitution at every impact, 0 < eta <= 1 (Eq. 6).
    negative : Mechanism, optional
        The negative direction (the mirror image); the positive one again when omitted (a
        symmetric mechanism).
    phi0_rad : float
        Signed rotation released from rest at the start of the base motion, rad (in the
        mechanism's own coordinate; divided by ``scale`` for an equivalent block).
    phi_limit_rad : (float, float), optional
        Overturning limits of each direction in the integrated coordinate, rad; default each
        mechanism's kinematic limit ``phi_max``.
    scale : (float, float)
        The reported rotation is ``scale`` times the integrated one (kappa for an equivalent
        block, 1 for the mechanism).
    t_out_s : array_like, optional
        Output times, s; default the base motion's grid.
    model : str
        Label stored in the result.
    tabulate : bool
        Evaluate the equation of motion from cubic splines through 2049 points of each
        direction (relative error ~1e-13 for a smooth mechanism); False calls the mechanism's own
        functions (the closed-form equivalent blocks do).

    Returns
    -------
    MechanismResponse
    """
    eta = float(eta)
    if not (0.0 < eta <= 1.0):
        raise InputError(f"eta={eta!r}: a restitution must be in (0, 1]; give the coefficient of Eq. 6")
    mechs, kappa, limit, lam, eoms = _directions(positive, negative, scale, phi_limit_rad, tabulate)
    tb = np.asarray(base.t_s, float)
    ab = np.asarray(base.acc_m_s2, float)
    t_out = tb if t_out_s is None else np.asarray(t_out_s, float)
    phi_out = np.full(t_out.size, np.nan)
    om_out = np.full(t_out.size, np.nan)
    t, t_end = float(tb[0]), float(tb[-1])
    side = 1 if phi0_rad >= 0 else -1
    y = np.array([abs(phi0_rad) / kappa[side], 0.0])
    resting = y[0] == 0.0
    impacts: list[float] = []
    overturned, t_over = False, float("nan")

    def fill(lo, hi, values):
        i0, i1 = np.searchsorted(t_out, [lo, hi], side="left")
        i1 = i1 + 1 if i1 < t_out.size and t_out[i1] == hi else i1
        if i1 > i0:
            phi_out[i0:i1], om_out[i0:i1] = values(t_out[i0:i1])

    while t < t_end:
        if resting:
            # at rest until the base exceeds one direction's uplift acceleration (Eq. 10)
            lift = _next_uplift(tb, ab, t, lam)
            if lift is None:
                fill(t, t_end, lambda tt: (np.zeros_like(tt), np.zeros_like(tt)))
                break
            t_next, side = lift
            fill(t, t_next, lambda tt: (np.zeros_like(tt), np.zeros_like(tt)))
            t, y, resting = t_next, np.array([0.0, 0.0]), False
        if y[0] <= 0.0:
            y = np.array([0.0, max(float(y[1]), 0.0)])
        t0 = t
        t, y, event, pieces = _flight(eoms[side], y, t, t_end, tb, ab, side, limit[side])
        for lo, hi, sol in pieces:
            fill(lo, hi, lambda tt, sol=sol, k=side * kappa[side]: tuple(k * sol(tt)))
        if event == "over":
            overturned, t_over = True, t
            phi_out[t_out > t_over] = np.nan
            om_out[t_out > t_over] = np.nan
            break
        if event == "impact":
            impacts.append(t)
            v = abs(float(y[1])) * kappa[side] * eta  # the mechanism's rate after impact
            side = -side
            if v <= REST_VELOCITY_RAD_S or t <= t0:
                resting = True
                y = np.array([0.0, 0.0])
            else:
                y = np.array([0.0, v / kappa[side]])
            continue
        break
    phi_cr = tuple(float(mechs[s].phi_cr() * kappa[s]) for s in (1, -1))
    end = (t_over if overturned else None, t_end, resting)
    status, msg = _end_status(mechs[side], kappa[side], phi_cr[0 if side == 1 else 1], y, end)
    return MechanismResponse(
        t_s=t_out,
        phi_rad=phi_out,
        phi_dot_rad_s=om_out,
        phi_cr_rad=phi_cr,
        impacts_t_s=np.asarray(impacts, float),
        overturned=overturned,
        t_overturn_s=t_over,
        model=model,
        eta=eta,
        name=positive.name,
        status=status,
        message=msg,
        meta={"uplift_over_g": (lam[1], lam[-1])},
    )


def _directions(positive, negative, scale, phi_limit_rad, tabulate):
    """Per direction (1, -1): mechanism, scale, overturning limit rad, uplift acceleration / g, equation of motion."""
    mechs = {1: positive, -1: negative if negative is not None else positive}
    kappa = {1: float(scale[0]), -1: float(scale[1])}
    limit = {
        s: float(phi_limit_rad[0 if s == 1 else 1])
        if phi_limit_rad is not None
        else float(mechs[s].phi_max) - KINEMATIC_MARGIN_RAD
        for s in (1, -1)
    }
    lam = {s: _uplift(mechs[s]) for s in (1, -1)}
    eoms = {s: (_tabulated(mechs[s], limit[s]) if tabulate else mechs[s]._eom) for s in (1, -1)}
    return mechs, kappa, limit, lam, eoms


def _next_uplift(tb, ab, t, lam):
    """(time s, direction) at which the base, from ``t`` on, first exceeds a direction's uplift
    acceleration ``lam[side] g`` (Eq. 10); None if it never does."""
    k0 = int(np.searchsorted(tb, t, side="left"))
    up_pos = -ab[k0:] > lam[1] * G
    up_neg = ab[k0:] > lam[-1] * G
    hit = np.flatnonzero(up_pos | up_neg)
    if hit.size == 0:
        return None
    side = 1 if up_pos[hit[0]] else -1
    j = k0 + int(hit[0])
    t_next = float(tb[j])
    if j > k0:  # the crossing of the uplift level, between samples (the base is piecewise linear)
        lev = -side * lam[side] * G
        a0, a1 = ab[j - 1], ab[j]
        if a1 != a0:
            t_next = float(tb[j - 1] + (tb[j] - tb[j - 1]) * np.clip((lev - a0) / (a1 - a0), 0.0, 1.0))
    return max(t_next, t), side


def _end_status(mech, kappa, phi_cr, y, end):
    """(status, message) at the end of a run, ``end`` = (overturning time s or None, record's end s, at rest?).

    ``falling``: the state y = (phi rad, rate rad/s) at the record's end carries the mechanism past its
    critical rotation ``phi_cr`` (rad, reported).
    """
    t_over, t_end, resting = end
    if t_over is not None:
        return "overturned", f"overturned at {t_over:.4g} s"
    if resting or not _falls(mech, float(y[0]), float(y[1])):
        return "ok", ""
    return "falling", (
        f"the record ends at {t_end:.4g} s with the mechanism at {kappa * y[0]:.4g} rad, "
        f"moving at {kappa * y[1]:.4g} rad/s: without more base motion it passes or stays past "
        f"its critical rotation ({phi_cr:.4g} rad) and falls; give a longer record "
        "(pad it with zeros) to see the outcome"
    )


def equivalent_block_mechanism(fp: FundamentalParameters, linear: bool, kappa: str = "kappa1") -> Mechanism:
    """The equivalent block of one rocking direction as a :class:`Mechanism` in theta (rad).

    Parameters
    ----------
    fp : FundamentalParameters
        The direction's parameters (``Mechanism.parameters()``).
    linear : bool
        True: Eq. 16, theta'' = p^2 (theta - theta_cr - u_g''/g) (M = 1/p^2, V' = theta_cr - theta,
        B = 1/g). False: the nonlinear block of Eq. 3 with alpha = theta_cr (M = 1/p^2,
        V = cos(alpha - theta), B = cos(alpha - theta)/g).
    kappa : {"kappa1", "kappa2"}
        Scaling of Eq. 19 (theta_cr = lambda_lin) or Eq. 20 (theta_cr = lambda).
    """
    if kappa not in ("kappa1", "kappa2"):
        raise InputError(f"kappa={kappa!r}: choose 'kappa1' (Eq. 19) or 'kappa2' (Eq. 20)")
    th = fp.theta_cr_rad if kappa == "kappa1" else fp.theta_cr_kappa2_rad
    p2 = fp.p_rad_s**2
    if linear:
        return Mechanism(
            M=lambda f: 1.0 / p2,
            V=lambda f: th * f - 0.5 * f * f,
            B=lambda f: 1.0 / G,
            phi_max=math.pi / 2,
            name=f"{fp.mechanism} linear block",
            eom=lambda f: (1.0 / p2, 0.0, th - f, 1.0 / G),
        )
    return Mechanism(
        M=lambda f: 1.0 / p2,
        V=lambda f: math.cos(th - f),
        B=lambda f: math.cos(th - f) / G,
        phi_max=math.pi / 2,
        name=f"{fp.mechanism} block",
        eom=lambda f: (1.0 / p2, 0.0, math.sin(th - f), math.cos(th - f) / G),
    )


def mechanism_time_histories(
    mechanism: Mechanism,
    base,
    eta: float | None = None,
    negative: Mechanism | None = None,
    phi0_rad: float = 0.0,
    kappa: str = "kappa1",
    models=("nonlinear", "linear", "block"),
) -> dict:
    """A mechanism and its equivalent blocks under one base motion (paper Fig. 14).

    Parameters
    ----------
    mechanism : Mechanism
        Positive direction (e.g. ``asymmetric_frame(...)[0]``, ``wall_mechanism(...)``).
    base : BaseMotion
        Base acceleration, m/s^2.
    eta : float, optional
        Restitution; default the mechanism's own ``eta`` (an error when it has none: the paper
        treats eta as a free parameter, Eq. 6).
    negative : Mechanism, optional
        Negative direction (mirror image); default the positive one.
    phi0_rad : float
        Signed initial rotation of the mechanism, rad.
    kappa : {"kappa1", "kappa2"}
        Scaling of the equivalent blocks (Eq. 19 / 20).
    models : sequence of str
        Which of ``nonlinear``, ``linear``, ``block`` to integrate.

    Returns
    -------
    dict
        ``{model: MechanismResponse}``; every response reports rotations in the mechanism's
        coordinate phi (equivalent blocks: phi = kappa theta, Eq. 14).
    """
    if eta is None:
        eta = mechanism.eta
    if eta is None or not math.isfinite(eta):
        raise InputError(
            f"{mechanism.name or 'mechanism'}: no restitution known; give eta (0 < eta <= 1), e.g. "
            "from angular momentum or a test (DeJong & Dimitrakopoulos treat it as a free parameter)"
        )
    bad = [m for m in models if m not in ("nonlinear", "linear", "block")]
    if bad:
        raise InputError(f"models={bad}: choose from 'nonlinear', 'linear', 'block'")
    neg = negative if negative is not None else mechanism
    out = {}
    if "nonlinear" in models:
        out["nonlinear"] = mechanism_response(mechanism, base, eta, neg, phi0_rad, model="nonlinear")
    fps = (mechanism.parameters(), neg.parameters())
    k = tuple(fp.kappa1 if kappa == "kappa1" else fp.kappa2 for fp in fps)
    for name, lin in (("linear", True), ("block", False)):
        if name not in models:
            continue
        mp, mn = (equivalent_block_mechanism(fp, lin, kappa) for fp in fps)
        out[name] = mechanism_response(mp, base, eta, mn, phi0_rad, scale=k, model=name, tabulate=False)
    return out
