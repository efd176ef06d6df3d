"""Impact times of free rocking from the energy integral: an exact reference with no time steps.

Between impacts a free-rocking block conserves energy (Housner 1963; Čeh et al. 2018 Eq. 1 with
no base motion), so the time from theta = 0 up to the turning point tm and back is
2 int_0^tm dtheta / sqrt(2 p^2 (cos(alpha - tm) - cos(alpha - theta))), and after impact k the
angular velocity eta^k omega_1 sets the next tm. Quadpack integrates the 1/sqrt singularity at tm
with its algebraic weight, so the times are good to about 1e-14 relative: the integrators are
measured against it (``benchmarks/bench_single.py``, ``tests/test_single_taylor.py``).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import quad

__all__ = ["free_rocking_impact_times"]


def free_rocking_impact_times(block, theta0_rad: float, eta: float, n: int) -> np.ndarray:
    """Times of the first ``n`` impacts of ``block`` released at rest from ``theta0_rad``.

    Parameters
    ----------
    block : Block
        Its ``alpha_rad`` (rad) and ``p_rad_s`` (rad/s) are used.
    theta0_rad : float
        Release angle, 0 < theta0_rad < alpha_rad (rad).
    eta : float
        Restitution of the angular velocity at each impact (constant).
    n : int
        Number of impacts.

    Returns
    -------
    ndarray, shape (n,)
        Impact times from the release (s).
    """
    a, p = block.alpha_rad, block.p_rad_s

    def quarter(tm):
        def smooth(th):  # the integrand times sqrt(tm - theta); quadpack weighs the 1/sqrt
            x = 0.5 * (tm - th)
            r = 2.0 if x == 0.0 else 2.0 * x / math.sin(x)
            return math.sqrt(r / (4 * p * p * math.sin(a - 0.5 * (th + tm))))

        return quad(smooth, 0.0, tm, weight="alg", wvar=(0.0, -0.5), epsabs=0, epsrel=1.2e-14, limit=200)[0]

    w1 = math.sqrt(2 * p * p * (math.cos(a - theta0_rad) - math.cos(a)))
    t = [quarter(theta0_rad)]
    for k in range(1, n):
        w = w1 * eta**k
        t.append(t[-1] + 2 * quarter(a - math.acos(math.cos(a) + w * w / (2 * p * p))))
    return np.array(t)
