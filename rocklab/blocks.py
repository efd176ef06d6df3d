"""Block geometry and mass: the one place a rocking body is defined and validated.

All quantities are SI: metres, kilograms, seconds, radians. A :class:`Block` is
either a uniform rectangular prism (``Block(b_m, h_m, ...)``) or a general
symmetric body (``Block.general(R_m, alpha_rad, alpha_I)``) whose moment of
inertia about a rocking corner is ``I_O = alpha_I * m * R**2`` (Ther thesis
Eq. 22; ``alpha_I = 4/3`` for a uniform rectangle).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from ._errors import InputError
from ._errors import positive as _positive

__all__ = ["Block", "G", "is_lab_size", "inertia_coefficient"]

#: Standard gravity, m/s^2.
G = 9.80665


@dataclass(frozen=True)
class Block:
    """A rigid symmetric rocking block.

    Parameters
    ----------
    b_m, h_m : float
        Width and height of the frontal section, m. For a general body (see
        :meth:`general`) these are the equivalent rectangle ``b = 2 R sin(alpha)``,
        ``h = 2 R cos(alpha)``.
    depth_m : float, optional
        Out-of-plane depth, m (only used to get the mass from a density).
    mass_kg : float, optional
        Mass, kg. Defaults to ``density_kg_m3 * b * h * depth`` when a density is
        given, else to 1 kg per metre of depth (rocking kinematics do not depend on
        mass).
    density_kg_m3 : float, optional
        Density, kg/m^3, used only when ``mass_kg`` is not given.
    alpha_I : float
        Corner inertia coefficient ``I_O / (m R^2)`` (thesis Eq. 22), 4/3 for a
        uniform prism.
    name : str
        Free label (e.g. a catalogue id such as ``"B6M"``).

    Attributes (derived)
    --------------------
    alpha_rad : slenderness angle atan(b/h), rad
    R_m : half-diagonal, distance from corner to centre of mass, m
    I_O_kg_m2 : moment of inertia about a rocking corner, kg m^2
    p_rad_s : frequency parameter sqrt(m g R / I_O), rad/s
    eta_H : Housner's restitution 1 - 2 sin^2(alpha) / alpha_I
    uplift_acc_m_s2 : g tan(alpha), base acceleration that starts rocking, m/s^2
    """

    b_m: float
    h_m: float
    depth_m: float = 1.0
    mass_kg: float | None = None
    density_kg_m3: float | None = None
    alpha_I: float = 4.0 / 3.0
    name: str = ""

    def __post_init__(self):
        b = _positive("b_m (block width)", self.b_m)
        h = _positive("h_m (block height)", self.h_m)
        d = _positive("depth_m (block depth)", self.depth_m)
        object.__setattr__(self, "b_m", b)
        object.__setattr__(self, "h_m", h)
        object.__setattr__(self, "depth_m", d)
        aI = _positive("alpha_I (corner inertia coefficient)", self.alpha_I)
        if aI < 1.0:
            # I_O = I_C + m R^2 >= m R^2, so alpha_I < 1 is not a physical body.
            raise InputError(
                f"alpha_I={aI}: corner inertia coefficient I_O/(m R^2) must be >= 1 "
                "(parallel-axis theorem); 4/3 is a uniform block"
            )
        object.__setattr__(self, "alpha_I", aI)
        if self.mass_kg is not None:
            object.__setattr__(self, "mass_kg", _positive("mass_kg", self.mass_kg))
        elif self.density_kg_m3 is not None:
            rho = _positive("density_kg_m3", self.density_kg_m3)
            object.__setattr__(self, "mass_kg", rho * b * h * d)
        else:
            object.__setattr__(self, "mass_kg", 1.0 * d)

    @classmethod
    def general(
        cls, R_m: float, alpha_rad: float, alpha_I: float = 4.0 / 3.0, mass_kg: float | None = None, name: str = ""
    ) -> "Block":
        """A general symmetric body from R (m), alpha (rad) and alpha_I = I_O/(m R^2).

        Examples: ``alpha_I = 4/3`` uniform prism; ``alpha_I = 1`` mass
        concentrated at the centre of mass (e.g. a mass on top of a light pier,
        with R measured to that mass).
        """
        R = _positive("R_m (corner to centre-of-mass distance)", R_m)
        a = _positive("alpha_rad (slenderness angle)", alpha_rad)
        if a >= math.pi / 2:
            raise InputError(f"alpha_rad={alpha_rad}: slenderness angle must be in (0, pi/2) rad")
        return cls(b_m=2 * R * math.sin(a), h_m=2 * R * math.cos(a), mass_kg=mass_kg, alpha_I=alpha_I, name=name)

    # -- derived quantities -------------------------------------------------
    @property
    def alpha_rad(self) -> float:
        """Slenderness angle atan(b/h), rad."""
        return math.atan2(self.b_m, self.h_m)

    @property
    def R_m(self) -> float:
        """Half-diagonal (corner to centre of mass), m."""
        return 0.5 * math.hypot(self.b_m, self.h_m)

    @property
    def slenderness(self) -> float:
        """Aspect ratio h/b (dimensionless)."""
        return self.h_m / self.b_m

    @property
    def I_O_kg_m2(self) -> float:
        """Moment of inertia about a rocking corner, kg m^2."""
        return self.alpha_I * float(self.mass_kg or 0.0) * self.R_m**2  # mass is set in __post_init__

    @property
    def p_rad_s(self) -> float:
        """Frequency parameter p = sqrt(m g R / I_O) = sqrt(g / (alpha_I R)), rad/s."""
        return math.sqrt(G / (self.alpha_I * self.R_m))

    @property
    def eta_H(self) -> float:
        """Housner's restitution (ratio of angular velocities), 1 - 2 sin^2(alpha)/alpha_I.

        For a uniform prism this is Čeh Eq. 13, 1 - 3/2 sin^2(alpha); negative
        for h/b < 1/sqrt(2) (the block bounces back).
        """
        return 1.0 - 2.0 * math.sin(self.alpha_rad) ** 2 / self.alpha_I

    @property
    def uplift_acc_m_s2(self) -> float:
        """Base acceleration g tan(alpha) above which a block at rest uplifts, m/s^2."""
        return G * math.tan(self.alpha_rad)

    def to_dict(self) -> dict:
        """All inputs and derived quantities, SI units in the keys."""
        d = asdict(self)
        d.update(
            alpha_rad=self.alpha_rad,
            R_m=self.R_m,
            slenderness=self.slenderness,
            I_O_kg_m2=self.I_O_kg_m2,
            p_rad_s=self.p_rad_s,
            eta_H=self.eta_H,
            uplift_acc_m_s2=self.uplift_acc_m_s2,
        )
        return d


def inertia_coefficient(alpha_I, name: str = "alpha_I") -> float:
    """The corner inertia coefficient ``alpha_I = I_O / (m R^2)`` (dimensionless), validated.

    ``I_O = I_C + m R^2 >= m R^2`` (parallel-axis theorem), so ``alpha_I >= 1``; 4/3 is a
    uniform rectangular block.

    Raises
    ------
    InputError
        ``alpha_I`` is not a finite number >= 1.
    """
    try:
        v = float(alpha_I)
    except (TypeError, ValueError):
        v = math.nan
    if not (math.isfinite(v) and v >= 1.0):
        raise InputError(
            f"{name}={alpha_I!r}: corner inertia coefficient I_O/(m R^2) must be >= 1 (parallel-axis theorem); "
            "4/3 is a uniform block"
        )
    return v


def is_lab_size(b_m, h_m):
    """Whether sizes (m) describe a rocking block in metres: b, h in 1 mm - 20 m and h/b in 0.5 - 50.

    Array-valued (broadcast) for tables of blocks. Anything else is usually a unit slip (cm
    in a ``b_m`` column) or b and h swapped (warning ``W-FIT-UNITS``).
    """
    import numpy as np

    b, h = np.asarray(b_m, float), np.asarray(h_m, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        hb = h / b
    return (b >= 1e-3) & (b <= 20) & (h >= 1e-3) & (h <= 20) & (hb >= 0.5) & (hb <= 50)
