"""The free-rocking fast loop (rocklab.models.rocking._newmark_lean) solves the same Newmark step as the general loop.

Free rocking runs between impacts in a lean loop (fixed-point update with a
Taylor-shifted sin/cos); the general Newton loop (the kernel's ``lean=False``) is
the reference here: both must give the same trapezoidal solution to rounding:
impact times, histories, energy. A base record of zeros over the whole run
(ug = 0: the same lean loop compiled with its base terms) must give the free
loop's numbers.
"""

from __future__ import annotations

import numpy as np
import pytest

from rocklab import Block
from rocklab.series import BaseMotion
from rocklab.models import simulate

B6M = Block(0.045, 0.2025, name="B6M")


def _zeros(T_s, dt_s=1e-3):
    return BaseMotion.from_samples(np.zeros(int(T_s / dt_s) + 2), dt_s, "m/s2", name="zeros")


# coarse steps (p dt up to 0.017, W-SIM-DT) on purpose: the two loops must agree even there
@pytest.mark.filterwarnings("ignore::rocklab._diagnostics.RocklabWarning")
@pytest.mark.parametrize(
    "dt_s, f, law",
    [
        (1e-4, 0.8, {}),  # the benchmark case: one step shifts < 2e-4 rad
        (2e-3, 0.95, {}),  # larger increments: the longer Taylor forms
        (1e-4, 0.5, {"restitution": "constant", "eta": -0.6}),  # bounce back onto the same corner
    ],
)
def test_fast_loop_equals_general_loop(simulate_loop, dt_s, f, law):
    T = 3.0
    kw = dict(duration_s=T, dt_s=dt_s, **law)
    fast = simulate(B6M, f * B6M.alpha_rad, **kw)
    gen = simulate_loop(False, B6M, f * B6M.alpha_rad, **kw)
    zeros = simulate(B6M, f * B6M.alpha_rad, base=_zeros(T + 0.1), **kw)
    assert zeros.n_impacts == fast.n_impacts
    assert np.max(np.abs(zeros.impacts_array[0] - fast.impacts_array[0])) <= 1e-9
    assert fast.n_impacts == gen.n_impacts >= 3
    assert fast.status == gen.status
    assert np.max(np.abs(fast.impacts_array[0] - gen.impacts_array[0])) <= 1e-9
    assert np.allclose(fast.impacts_array[1], gen.impacts_array[1], rtol=1e-8, atol=0)
    n = min(len(fast.t_s), len(gen.t_s))
    assert abs(len(fast.t_s) - len(gen.t_s)) <= 1
    assert np.max(np.abs(fast.theta_rad[:n] - gen.theta_rad[:n])) <= 1e-9
    E0 = fast.energy_J[0]
    assert np.max(np.abs(fast.energy_J[:n] - gen.energy_J[:n])) <= 1e-9 * E0
    # between impacts the trapezoidal rule keeps the energy of the undamped step to
    # O((p dt)^2): the fast loop's carried sin/cos must not drift (re-anchored every 1024 steps)
    first = fast.t_s < fast.impacts_array[0, 0] - 2 * dt_s
    assert np.max(np.abs(fast.energy_J[first] - E0)) <= 1e-5 * E0
    assert fast.max_abs_theta_rad == pytest.approx(gen.max_abs_theta_rad, abs=1e-12)


def test_free_tail_after_a_record_equals_padded_record():
    # a pulse that uplifts the block, then free rocking: past the record's end the fast
    # loop takes over; the same pulse padded with zeros keeps the general loop throughout
    blk = Block(0.2, 1.0)
    dt = 5e-3
    t = np.arange(121) * dt  # 0 ... 0.6 s; ends on a zero sample, so both records give the same ug(t)
    a = 2.5 * np.sin(2 * np.pi * t / 0.6)
    a[-1] = 0.0
    short = BaseMotion.from_samples(a, dt, "m/s2", name="pulse")
    padded = BaseMotion.from_samples(np.concatenate([a, np.zeros(int(4.0 / dt))]), dt, "m/s2", name="padded")
    kw = dict(duration_s=4.0, dt_s=1e-4, stop_at_rest=False)
    r1 = simulate(blk, 0.0, base=short, **kw)
    r2 = simulate(blk, 0.0, base=padded, **kw)
    assert r1.n_impacts == r2.n_impacts >= 5
    assert r1.status == r2.status == "rocking"
    assert np.max(np.abs(r1.impacts_array[0] - r2.impacts_array[0])) <= 1e-9
    assert np.max(np.abs(r1.theta_rad - r2.theta_rad)) <= 1e-9


@pytest.mark.parametrize(
    "blk, f, dt_s, law",
    [
        (B6M, 0.8, 1e-4, {}),
        (B6M, 0.95, 2e-3, {}),  # longer Taylor forms and the fixed-point iteration
        (B6M, 0.5, 1e-4, {"restitution": "constant", "eta": -0.6}),
        (Block(0.5, 3.0), 0.5, 1e-4, {"restitution": "constant", "eta": 1.0}),  # rocks through the record
    ],
)
@pytest.mark.filterwarnings("ignore::rocklab._diagnostics.RocklabWarning")
def test_zero_record_gives_the_free_loop_numbers(simulate_loop, blk, f, dt_s, law):
    # free and forced rocking share one loop body; with u = 0 its base terms vanish exactly
    T = 3.0
    kw = dict(duration_s=T, dt_s=dt_s, **law)
    free = simulate(blk, f * blk.alpha_rad, **kw)
    zeros = simulate(blk, f * blk.alpha_rad, base=_zeros(T + 0.1), **kw)
    gen = simulate_loop(False, blk, f * blk.alpha_rad, base=_zeros(T + 0.1), **kw)
    assert zeros.status == free.status and zeros.n_impacts == free.n_impacts >= 3
    assert len(zeros.t_s) == len(free.t_s)
    assert np.max(np.abs(zeros.theta_rad - free.theta_rad)) <= 1e-12
    assert np.max(np.abs(zeros.omega_rad_s - free.omega_rad_s)) <= 1e-12
    assert np.max(np.abs(zeros.impacts_array - free.impacts_array)) <= 1e-12
    # the lean loop ran under the record: the general loop's rounding differs
    assert np.any(zeros.theta_rad != gen.theta_rad)
