"""Dynamically equivalent rocking structures (DeJong & Dimitrakopoulos 2014).

Every SDOF rocking mechanism is reduced to an equivalent single block with the
fundamental parameters (p, theta_cr, lambda, eta) (paper §2, Table I). For
multi-block mechanisms the Lagrangian ``T = M(phi) phi'^2 / 2``, ``V(phi)`` and
generalised force ``Q = -B(phi) u_g''`` are linearised about the unstable
equilibrium phi_cr (Eq. 9–13):

    I_eq = M(phi_cr),  G_eq = -V''(phi_cr)/g,  B_eq = B(phi_cr),
    p_eq = sqrt(g G_eq / I_eq) (Eq. 17),  lambda = V'(0)/(g B(0)) (Eq. 10),
    lambda_lin = G_eq phi_cr / B_eq (Eq. 18),  kappa1 = phi_cr/lambda_lin (Eq. 19),
    kappa2 = phi_cr/lambda (Eq. 20),  theta_cr = phi_cr/kappa.

:class:`Mechanism` holds M, V, B as callables of phi (SI: kg m^2, J, kg m) and
evaluates these numerically; the closed forms of Table I and the rocking wall
(Eq. 21–23) are given separately and checked against it in the tests. The
four-bar linkages (asymmetric frame §5.1, arch §5.2) are in ``_mechanisms.py``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from ..._errors import InputError
from ..._errors import positive as _pos
from ...blocks import G, inertia_coefficient

__all__ = [
    "equivalent_block",
    "FundamentalParameters",
    "Mechanism",
    "block_parameters",
    "strut_parameters",
    "frame_parameters",
    "conical_shell_geometry",
    "conical_shell_parameters",
    "wall_parameters",
    "wall_mechanism",
    "free_rocking_period_eq24",
    "overturning_time_eq25",
    "sine_pulse_max_response",
    "linear_sine_pulse_response",
    "equivalence_errors",
]


def _slender(name, a):
    a = _pos(name, a)
    if a >= math.pi / 2:
        raise InputError(f"{name}={a}: slenderness angle must be in (0, pi/2) rad")
    return a


@dataclass(frozen=True)
class FundamentalParameters:
    """Equivalent-block parameters of a rocking mechanism (DeJong & Dimitrakopoulos).

    Attributes
    ----------
    p_rad_s : float
        Frequency parameter of the equivalent block, rad/s (Eq. 17).
    theta_cr_rad : float
        Critical rotation of the equivalent block phi_cr/kappa1 = lambda_lin, rad.
    lambda_ : float
        Exact uplift acceleration / g (Eq. 10).
    lambda_lin : float
        Uplift acceleration of the linearised equation / g (Eq. 18).
    eta : float
        Restitution (angular momentum, Table I); NaN where the paper gives none.
    phi_cr_rad : float
        Critical rotation of the mechanism's own coordinate, rad (Eq. 9).
    kappa1, kappa2 : float
        Scaling parameters phi_cr/lambda_lin and phi_cr/lambda (Eq. 19, 20).
    mechanism : str
        ``block``, ``strut``, ``frame``, ``wall``, ``asymmetric-frame+``/``-``, ``arch``, ...
    """

    p_rad_s: float
    theta_cr_rad: float
    lambda_: float
    lambda_lin: float
    eta: float
    phi_cr_rad: float
    kappa1: float
    kappa2: float
    mechanism: str = ""

    @property
    def theta_cr_kappa2_rad(self) -> float:
        """theta_cr with kappa2 (= lambda), rad."""
        return self.phi_cr_rad / self.kappa2

    def to_dict(self) -> dict:
        """Keys as the CLI prints them (``lambda`` rather than ``lambda_``)."""
        d = asdict(self)
        d["lambda"] = d.pop("lambda_")
        return d


def _fp(p, phi_cr, lam, lam_lin, eta, name):
    # theta_cr = phi_cr / kappa1 = lambda_lin (Eq. 17, 19)
    return FundamentalParameters(
        p_rad_s=p,
        theta_cr_rad=lam_lin,
        lambda_=lam,
        lambda_lin=lam_lin,
        eta=eta,
        phi_cr_rad=phi_cr,
        kappa1=phi_cr / lam_lin,
        kappa2=phi_cr / lam,
        mechanism=name,
    )


# -- closed forms ---------------------------------------------------------------


def equivalent_block(fp: FundamentalParameters, match: str = "uplift", alpha_I: float = 4.0 / 3.0):
    """The solid rectangular block that stands in for a mechanism in the OAS and the design check.

    Its frequency parameter is the mechanism's p (p^2 = g / (alpha_I R), so R = g / (alpha_I p^2))
    and its slenderness is chosen by ``match``:

    - ``"uplift"`` (default): tan(alpha) = lambda, the mechanism's exact uplift acceleration (Eq. 10),
      which the design check's a_p,min = g tan(alpha) then reproduces;
    - ``"kappa1"`` / ``"kappa2"``: alpha = theta_cr of Eq. 17 with kappa1 (= lambda_lin) or kappa2.

    Returns
    -------
    rocklab.Block
        Full width ``2 R sin(alpha)`` and height ``2 R cos(alpha)``, m, solid (alpha_I as given).
    """
    from ...blocks import Block

    alpha = {"uplift": math.atan(fp.lambda_), "kappa1": fp.theta_cr_rad, "kappa2": fp.theta_cr_kappa2_rad}.get(match)
    if alpha is None:
        raise InputError(f"match={match!r}: choose 'uplift', 'kappa1' or 'kappa2'")
    R = G / (inertia_coefficient(alpha_I) * fp.p_rad_s**2)
    return Block(2 * R * math.sin(alpha), 2 * R * math.cos(alpha), alpha_I=alpha_I, name=f"{fp.mechanism} equivalent")


def block_parameters(R_m: float, alpha_rad: float, alpha_I: float = 4.0 / 3.0) -> FundamentalParameters:
    """Rocking block (Table I): p = sqrt(g/(alpha_I R)), theta_cr = alpha, lambda = tan(alpha),
    lambda_lin = alpha, eta = 1 - 2 sin^2(alpha)/alpha_I (Housner)."""
    R, a, alpha_I = _pos("R_m", R_m), _slender("alpha_rad", alpha_rad), inertia_coefficient(alpha_I)
    return _fp(math.sqrt(G / (alpha_I * R)), a, math.tan(a), a, 1 - 2 * math.sin(a) ** 2 / alpha_I, "block")


def strut_parameters(R_m: float, alpha_rad: float) -> FundamentalParameters:
    """Point mass on a massless rigid strut with a rigid base (Table I): the block with
    alpha_I = 1, i.e. p = sqrt(g/R) (a pendulum), eta = 1 - 2 sin^2(alpha) = cos(2 alpha)."""
    fp = block_parameters(R_m, alpha_rad, 1.0)
    return FundamentalParameters(**{**asdict(fp), "mechanism": "strut"})


def conical_shell_geometry(H_m: float, r_m: float) -> tuple:
    """A thin uniform conical shell (a spire) rocking on its base rim: ``(R_m, alpha_rad, alpha_I)``.

    The lateral surface of height H and base radius r has its centre of mass at H/3; about the
    tangent to the base rim (the rocking axis) I_O = m (5 r^2 / 4 + H^2 / 6), so with
    R^2 = r^2 + H^2/9 and tan(alpha) = 3 r / H, alpha_I = I_O / (m R^2). DeJong & Dimitrakopoulos
    list the shell in Table I (its expressions are in the table, not in the extracted text); these
    are derived here from the surface integrals and checked by quadrature in the tests.
    """
    H, r = _pos("H_m", H_m), _pos("r_m", r_m)
    R2 = r * r + H * H / 9.0
    return math.sqrt(R2), math.atan2(3.0 * r, H), (1.25 * r * r + H * H / 6.0) / R2


def conical_shell_parameters(H_m: float, r_m: float) -> FundamentalParameters:
    """Table I's rocking conical shell: the block of :func:`conical_shell_geometry`'s R, alpha, alpha_I
    (p^2 = g / (alpha_I R), theta_cr = alpha, lambda = tan alpha, eta by angular momentum)."""
    R, a, aI = conical_shell_geometry(H_m, r_m)
    fp = block_parameters(R, a, aI)
    return FundamentalParameters(**{**asdict(fp), "mechanism": "conical-shell"})


def frame_parameters(R_m: float, alpha_rad: float, gamma: float, alpha_I: float = 4.0 / 3.0) -> FundamentalParameters:
    """Symmetric rocking frame: two equal columns (R, alpha) capped by a free beam (Table I).

    ``gamma = m_beam / m_columns`` (both columns together). From Eq. 35:
    p^2 = g (1 + 2 gamma) / (R (alpha_I + 4 gamma)) (= p_col^2 (1+2g)/(1+3g) for
    alpha_I = 4/3); theta_cr = alpha, lambda = tan(alpha) (Eq. 36-37);
    eta = (alpha_I - 2 sin^2 alpha + 4 gamma cos 2 alpha) / (alpha_I + 4 gamma)
    (angular momentum; Makris & Vassiliou 2013 for alpha_I = 4/3).
    """
    R, a, alpha_I = _pos("R_m", R_m), _slender("alpha_rad", alpha_rad), inertia_coefficient(alpha_I)
    gmm = float(gamma)
    if not (math.isfinite(gmm) and gmm >= 0):
        raise InputError(f"gamma={gamma!r}: beam/columns mass ratio must be >= 0")
    p = math.sqrt(G * (1 + 2 * gmm) / (R * (alpha_I + 4 * gmm)))
    eta = (alpha_I - 2 * math.sin(a) ** 2 + 4 * gmm * math.cos(2 * a)) / (alpha_I + 4 * gmm)
    return _fp(p, a, math.tan(a), a, eta, "frame")


def wall_parameters(R_m: float, alpha_rad: float, alpha_I: float = 4.0 / 3.0) -> FundamentalParameters:
    """Rocking (out-of-plane, two-block) wall, Eq. 21–23; R, alpha of ONE of the two blocks.

    p = sqrt(2 g/(alpha_I R)) = sqrt(2) p_block, phi_cr = alpha, lambda = 2 tan(alpha),
    lambda_lin = 2 alpha, kappa1 = 1/2, kappa2 = alpha/(2 tan alpha), theta_cr = 2 alpha.
    The paper gives no restitution for the wall: eta is NaN.
    """
    R, a, alpha_I = _pos("R_m", R_m), _slender("alpha_rad", alpha_rad), inertia_coefficient(alpha_I)
    return _fp(math.sqrt(2 * G / (alpha_I * R)), a, 2 * math.tan(a), 2 * a, float("nan"), "wall")


# -- generic mechanism ------------------------------------------------------------


@dataclass(frozen=True)
class Mechanism:
    """An SDOF rocking mechanism in its own coordinate phi >= 0 (rad).

    Attributes
    ----------
    M : callable
        Generalised mass, T = M(phi) phi'^2 / 2, kg m^2.
    V : callable
        Potential energy, J (only differences matter).
    B : callable
        Generalised force per base acceleration, Q = -B(phi) u_g'', kg m.
    phi_max : float
        Largest phi the mechanism can reach (kinematic limit), rad.
    name : str
    eta : float
        Restitution if known (else NaN).
    """

    M: Callable[[float], float]
    V: Callable[[float], float]
    B: Callable[[float], float]
    phi_max: float = math.pi / 2
    name: str = ""
    eta: float = float("nan")
    eom: Callable | None = None  # optional fast callable phi -> (M, dM/dphi, dV/dphi, B)

    def _eom(self, phi):
        if self.eom is not None:
            return self.eom(phi)
        return self.M(phi), self.dM(phi), self.dV(phi), self.B(phi)

    def dV(self, phi, h=1e-6):
        return (self.V(phi + h) - self.V(phi - h)) / (2 * h)

    def dM(self, phi, h=1e-6):
        return (self.M(phi + h) - self.M(phi - h)) / (2 * h)

    def phi_cr(self) -> float:
        """Unstable equilibrium V'(phi_cr) = 0 (Eq. 9), rad."""
        from scipy.optimize import brentq

        xs = np.linspace(1e-5, self.phi_max * (1 - 1e-6), 400)
        d = np.array([self.dV(x) for x in xs])
        k = np.flatnonzero(np.sign(d[:-1]) != np.sign(d[1:]))
        if k.size == 0:
            raise InputError(f"{self.name}: no unstable equilibrium before the kinematic limit; check the geometry")
        return brentq(self.dV, xs[k[0]], xs[k[0] + 1], xtol=1e-13)

    def parameters(self) -> FundamentalParameters:
        """Fundamental parameters by linearisation about phi_cr (Eq. 11–20)."""
        pc = self.phi_cr()
        h = 1e-4
        Geq = -(self.V(pc + h) - 2 * self.V(pc) + self.V(pc - h)) / h**2 / G
        Ieq = self.M(pc)
        Beq = self.B(pc)
        lam = self.dV(1e-7, 1e-7) / (G * self.B(0.0))
        lam_lin = Geq * pc / Beq
        return _fp(math.sqrt(G * Geq / Ieq), pc, lam, lam_lin, self.eta, self.name)

    def free_rocking_period(self, phi0: float) -> float:
        """Nonlinear free-rocking period 4 * (time from rest at phi0 to impact), s."""
        V0 = self.V(phi0)

        # substitution phi = phi0 (1 - s^2) removes the 1/sqrt singularity at phi0
        lim = math.sqrt(self.M(phi0) / (2 * self.dV(phi0) * phi0)) * 2 * phi0

        def integrand(s):
            if s < 1e-4:  # V0 - V ~ V'(phi0) phi0 s^2: use the limit, avoid round-off
                return lim
            phi = phi0 * (1 - s * s)
            return math.sqrt(self.M(phi) / (2 * (V0 - self.V(phi)))) * 2 * phi0 * s

        # the substituted integrand is smooth: fixed Gauss-Legendre, no adaptive round-off warnings
        x, w = np.polynomial.legendre.leggauss(160)
        val = 0.5 * float(sum(wi * integrand(0.5 * (xi + 1)) for xi, wi in zip(x, w)))
        return 4 * val

    def overturning_time(self, ug_over_g: float) -> float:
        """Time from rest to phi_cr under a constant base acceleration (magnitude) ug/g, s."""
        from scipy.integrate import solve_ivp

        pc = self.phi_cr()
        # the base accelerates towards -x so that phi grows (Q = -B u'' > 0 for u'' < 0)
        a = -abs(float(ug_over_g)) * G

        def f(t, y):
            phi, om = y
            M, dM, dV, B = self._eom(phi)
            return [om, (-B * a - dV - 0.5 * dM * om * om) / M]

        def hit(t, y):
            return y[0] - pc

        hit.terminal = True  # type: ignore[attr-defined]  # scipy's event protocol
        sol = solve_ivp(f, (0, 1e4), [0.0, 0.0], events=hit, rtol=1e-9, atol=1e-12)
        return float(sol.t_events[0][0]) if sol.t_events[0].size else float("inf")


def wall_mechanism(R_m: float, alpha_rad: float, mass_kg: float = 1.0, alpha_I: float = 4.0 / 3.0) -> Mechanism:
    """Nonlinear two-block wall (slider-crank, Eq. 21) as a :class:`Mechanism`.

    Derived from the geometry (bottom block pivoting on its base corner, hinge at
    mid-height, top corner sliding on a vertical restraint): T = (I_O +
    4 m R^2 sin^2(alpha - phi)) phi'^2, V = 4 m g R cos(alpha - phi),
    B = 2 m R cos(alpha - phi). Divided by 4 m g R this is Eq. 21, except that the
    extracted Eq. 21 prints the velocity term as ``-(R/g) sin^2(alpha-phi) phi'^2``;
    Lagrange gives ``-(R/g) sin(2(alpha-phi)) phi'^2`` (the sin^2 is a typesetting error).
    """
    R, a, m = _pos("R_m", R_m), _slender("alpha_rad", alpha_rad), _pos("mass_kg", mass_kg)
    IO = inertia_coefficient(alpha_I) * m * R * R
    return Mechanism(
        M=lambda f: 2 * IO + 8 * m * R * R * math.sin(a - f) ** 2,
        V=lambda f: 4 * m * G * R * math.cos(a - f),
        B=lambda f: 2 * m * R * math.cos(a - f),
        phi_max=min(2 * a + 0.5, math.pi / 2),
        name="wall",
    )


# -- closed-form responses ----------------------------------------------------------------


def free_rocking_period_eq24(p_rad_s: float, theta_over_theta_cr) -> np.ndarray:
    """Free-rocking period of the equivalent (linearised) block, Eq. 24, s:
    T = (4/p) arccosh(1 / (1 - theta/theta_cr))."""
    x = np.asarray(theta_over_theta_cr, float)
    return 4.0 / p_rad_s * np.arccosh(1.0 / (1.0 - x))


def overturning_time_eq25(
    p_rad_s: float, ug_over_g_lambda, lambda_: float, lambda_lin: float, kappa: str = "kappa1"
) -> np.ndarray:
    """Time to reach theta_cr under a constant base acceleration, Eq. 25, s.

    ``ug_over_g_lambda`` is u_g''/(g lambda). With ``kappa1`` the linear block uplifts
    at lambda_lin (Eq. 25 as printed); with ``kappa2`` at the exact lambda.
    """
    r = np.asarray(ug_over_g_lambda, float)
    q = r * (lambda_ / lambda_lin) if kappa == "kappa1" else r
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(q > 1, np.arccosh(1.0 / (q - 1.0) + 1.0) / p_rad_s, np.inf)


def sine_pulse_max_response(omega, a, eta):
    """Maximum response phi_max/phi_cr after a one-sine pulse, Eq. 41–42.

    Dimensionless groups (Eq. 40): ``omega = omega_g/p``, ``a = a_g/(g lambda)`` (> 1),
    restitution ``eta``. The pulse u_g'' = -a g lambda sin(omega p t + psi),
    sin(psi) = 1/a, starts at uplift and ends after (2 pi - psi)/omega; Eq. 41
    is the peak of the excursion after the first impact that follows it. NaN where
    D0* lies outside [0, 1] (overturning during the first excursion, D0* < 0).
    """
    w = np.asarray(omega, float)
    a = np.asarray(a, float)
    s = np.sqrt(a * a - 1.0)
    x = (2 * np.pi - np.arcsin(1.0 / a)) / w
    D0 = (w / (w * w + 1)) ** 2 * (w * w - 2 * a * a + 1 + (s + w) * a * np.exp(-x) + (s - w) * a * np.exp(x))
    with np.errstate(invalid="ignore"):
        out = 1.0 - np.sqrt(1.0 - eta**2 * (1.0 - D0))
    return np.where((D0 >= 0) & (D0 <= 1), out, np.nan), D0


def linear_sine_pulse_response(omega: float, a: float, eta: float, tau_max: float = 60.0):
    """Linearised equivalent block (Eq. 5/16, x = theta/theta_cr, tau = p t) under the
    Eq. 41 pulse, integrated with exact impacts (x = 0, x' -> eta x').

    Returns dict: ``x_end``, ``v_end`` (state at the pulse end), ``D_end`` =
    (x-1)^2 - x'^2 there, ``impact_during_pulse`` (bool), ``overturned`` (|x| >= 1),
    ``max_after`` = max|x| between the first and second impact after the pulse.
    """
    from scipy.integrate import solve_ivp

    psi = math.asin(1.0 / a)
    t_end = (2 * math.pi - psi) / omega
    state = np.array([0.0, 0.0])
    s, t = 1.0, 0.0
    out = dict(impact_during_pulse=False, overturned=False, max_after=float("nan"))
    impacts_after = 0
    peak = 0.0

    def rhs(tt, y, s):
        # Eq. 5 normalised: x'' = x - sgn(x) - u_g''/(g theta_cr), u_g'' = -a g lambda sin(.)
        u = a * math.sin(omega * tt + psi) if tt <= t_end else 0.0
        return [y[1], y[0] - s + u]

    def imp(tt, y, s):
        return y[0]

    def over(tt, y, s):
        return abs(y[0]) - 1.0

    imp.terminal = True  # type: ignore[attr-defined]  # scipy's event protocol
    over.terminal = True  # type: ignore[attr-defined]
    phase_end = True
    while t < tau_max:
        stop = t_end if (phase_end and t < t_end) else tau_max
        imp.direction = -s  # type: ignore[attr-defined]
        sol = solve_ivp(rhs, (t, stop), state, args=(s,), events=[imp, over], rtol=1e-11, atol=1e-13, max_step=0.01)
        if impacts_after == 1:
            peak = max(peak, float(np.max(np.abs(sol.y[0]))))
        t = float(sol.t[-1])
        state = sol.y[:, -1].copy()
        if sol.t_events[1].size:
            out["overturned"] = True
            break
        if sol.t_events[0].size:
            if t <= t_end:
                out["impact_during_pulse"] = True
            else:
                impacts_after += 1
                if impacts_after == 2:
                    out["max_after"] = peak
                    break
            state = np.array([0.0, eta * state[1]])
            s = math.copysign(1.0, state[1])
            t += 1e-12
            continue
        if phase_end and abs(t - t_end) < 1e-12:
            out["x_end"], out["v_end"] = float(state[0]), float(state[1])
            out["D_end"] = (state[0] - 1.0) ** 2 - state[1] ** 2
            phase_end = False
    return out


def equivalence_errors(mech: Mechanism, ratios=(0.1, 0.3, 0.5, 0.7, 0.9), accs=(1.2, 1.5, 2.0, 3.0)):
    """Errors of the equivalent-block approximation of one mechanism (paper Fig. 3, 6–8).

    Returns dict with ``period_ratio`` (T_eq24 / T_nonlinear at phi/phi_cr = ``ratios``) and
    ``t_ratio_kappa1``, ``t_ratio_kappa2`` (t_eq25 / t_nonlinear under a constant base
    acceleration u/(g lambda) = ``accs``), plus the parameters used.
    """
    fp = mech.parameters()
    ratios = np.asarray(ratios, float)
    accs = np.asarray(accs, float)
    T = np.array(
        [free_rocking_period_eq24(fp.p_rad_s, x) / mech.free_rocking_period(x * fp.phi_cr_rad) for x in ratios]
    )
    tn = np.array([mech.overturning_time(r * fp.lambda_) for r in accs])
    t1 = overturning_time_eq25(fp.p_rad_s, accs, fp.lambda_, fp.lambda_lin, "kappa1") / tn
    t2 = overturning_time_eq25(fp.p_rad_s, accs, fp.lambda_, fp.lambda_lin, "kappa2") / tn
    return dict(parameters=fp, ratios=ratios, accs=accs, period_ratio=T, t_ratio_kappa1=t1, t_ratio_kappa2=t2)
