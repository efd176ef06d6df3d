"""A stacked column of blocks for synthetic sessions (``rocklab.models`` column API).

The column simulator gives joint rotations (clockwise positive, joint ``j``
under block ``j``, joint 0 on the table) on a uniform grid; here they become
the pose of every block: block ``j`` sits on the top centre of block ``j - 1``
and turns about the left (counter-clockwise) or right (clockwise) end of the
joint's pivot line, ``half_width_m[j]`` from the centre. Angles here are
counter-clockwise (``truth.csv``'s convention), the negative of the column
simulator's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["column_api", "ColumnMotion", "ColumnBlockView"]


def column_api():
    """``(Column, simulate_column)`` when ``rocklab.models`` has them, else None."""
    try:
        from ..models import Column, simulate_column
    except ImportError:
        return None
    return Column, simulate_column


@dataclass(frozen=True)
class ColumnMotion:
    """Joint rotations of a column over time and the table it stands on.

    Attributes
    ----------
    b_m, h_m : ndarray (n,)
        Block widths and heights, bottom to top, m.
    half_width_m : ndarray (n,)
        Pivot offset of each joint from its centre, m.
    x0_m : float
        World x of the column's base centre with the table at u = 0, m.
    t_s : ndarray (m,)
        Time grid, s (video time).
    psi_rad : ndarray (m, n)
        Counter-clockwise joint rotations (block j relative to block j - 1), rad.
    """

    b_m: np.ndarray
    h_m: np.ndarray
    half_width_m: np.ndarray
    x0_m: float
    t_s: np.ndarray
    psi_rad: np.ndarray
    table: object
    release_s: float | None = None

    @property
    def n(self) -> int:
        return len(self.b_m)

    def joint(self, j: int, t):
        return np.interp(np.asarray(t, float), self.t_s, self.psi_rad[:, j])

    def pose(self, j: int, t):
        """Bottom-centre position ``(ox, oy)`` m and counter-clockwise angle of block ``j``."""
        t = np.asarray(t, float)
        jx = self.x0_m + self.table.u(t)
        jy = np.zeros_like(jx)
        ang = np.zeros_like(jx)
        for k in range(j + 1):
            if k > 0:  # joint k sits on the top centre of block k - 1
                jx = jx - self.h_m[k - 1] * np.sin(ang)
                jy = jy + self.h_m[k - 1] * np.cos(ang)
            psi = self.joint(k, t)
            px = -np.where(psi >= 0, 1.0, -1.0) * self.half_width_m[k]  # pivot in the joint frame
            qx = px - np.cos(psi) * px  # q = p - R(psi) p
            qy = -np.sin(psi) * px
            c, s = np.cos(ang), np.sin(ang)
            jx, jy = jx + c * qx - s * qy, jy + s * qx + c * qy
            ang = ang + psi
        return jx, jy, ang


@dataclass(frozen=True)
class ColumnBlockView:
    """One block of a :class:`ColumnMotion` with the interface of ``BlockMotion``."""

    id: str
    column: ColumnMotion
    index: int

    @property
    def b_m(self) -> float:
        return float(self.column.b_m[self.index])

    @property
    def h_m(self) -> float:
        return float(self.column.h_m[self.index])

    @property
    def table(self):
        return self.column.table

    @property
    def release_s(self):
        return self.column.release_s

    @property
    def t_s(self) -> np.ndarray:
        return self.column.t_s

    @property
    def phi_rad(self) -> np.ndarray:
        """Absolute counter-clockwise angle on the grid, rad."""
        return np.cumsum(self.column.psi_rad[:, : self.index + 1], axis=1)[:, -1]

    def phi(self, t):
        return self.pose(t)[2]

    def pose(self, t):
        return self.column.pose(self.index, t)

    def centre(self, t):
        ox, oy, phi = self.pose(t)
        r = self.h_m / 2
        return ox - r * np.sin(phi), oy + r * np.cos(phi)
