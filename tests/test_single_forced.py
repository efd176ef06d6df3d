"""The lean loops under a base record (rocklab.models.rocking._newmark_lean, the rest scan) solve the general loop's steps.

``simulate`` runs rocking steps under a record in a lean fixed-point loop with
Taylor-shifted sin/cos and u(t) stepped along each record interval, and skips
steps at rest below the uplift level in a short scan. The kernel's ``lean=False``
takes every step in the general Newton loop, the reference here: both must be
the same trapezoidal solution up to rounding, amplified by the dynamics no more
than any rounding-level change (measured against a 1e-15 change of the scale).
"""

from __future__ import annotations

import numpy as np
import pytest

from rocklab import Block
from rocklab.series import BaseMotion
from rocklab.models import bundled_record


def _compare(fast, gen, th_tol=1e-10):
    assert fast.status == gen.status
    assert fast.n_impacts == gen.n_impacts
    assert len(fast.t_s) == len(gen.t_s)
    # the lean loops really ran: histories are not bitwise those of the general loop
    assert np.any(fast.theta_rad != gen.theta_rad)
    assert np.max(np.abs(fast.theta_rad - gen.theta_rad)) <= th_tol
    E = np.max(np.abs(gen.energy_J))
    assert np.max(np.abs(fast.energy_J - gen.energy_J)) <= th_tol * 10 * E
    ti_f, wb = fast.impacts_array[0], gen.impacts_array[1]
    dt_imp = np.abs(ti_f - gen.impacts_array[0])
    # an impact time moves by (angle difference) / |omega-|: 1e-9 s for every impact that is not
    # a near-rest touch-down, and the angle-equivalent bound for all
    assert np.all(dt_imp[np.abs(wb) >= 0.05] <= 1e-9)
    assert np.all(dt_imp * np.abs(wb) <= th_tol)
    assert np.allclose(fast.impacts_array[1], wb, rtol=1e-7, atol=1e-9)
    assert fast.max_abs_theta_rad == pytest.approx(gen.max_abs_theta_rad, abs=th_tol)


@pytest.fixture(scope="module")
def elcentro():
    return bundled_record("elcentro")


@pytest.mark.parametrize(
    "blk, scale, T, extra",
    [
        (Block(0.2, 1.0), 1.0, 20.0, {"output_dt_s": 7e-4}),  # 98 impacts, rests, rocks again
        (Block(0.3, 1.5), 1.2, 12.0, {"fall_rad": "alpha"}),  # overturns (|theta| >= alpha) at 9.1 s
        (Block(0.045, 0.2025), 1.0, 5.0, {}),  # B6M: falls over (pi/2) at 2.8 s
    ],
)
def test_forced_loop_equals_general_loop_elcentro(simulate_loop, elcentro, blk, scale, T, extra):
    if extra.get("fall_rad") == "alpha":
        extra = dict(extra, fall_rad=blk.alpha_rad)
    kw = dict(theta0_rad=0.0, base=elcentro.scaled(scale), duration_s=T, dt_s=1e-4, **extra)
    fast, gen = simulate_loop(True, blk, **kw), simulate_loop(False, blk, **kw)
    assert fast.n_impacts >= 3
    _compare(fast, gen)
    if "fall_rad" in extra:
        assert fast.status == "overturned"
        assert abs(fast.overturn_t_s - gen.overturn_t_s) <= 1e-9


def test_difference_is_rounding_amplified_by_the_dynamics(simulate_loop, elcentro):
    # under a record a rocking response amplifies any rounding-level change: the lean loop may
    # differ from the general loop by no more than a 1e-15 relative change of the record does
    blk, kw = Block(0.5, 3.0), dict(theta0_rad=0.0, duration_s=20.0, dt_s=5e-4, stop_at_rest=False)
    fast = simulate_loop(True, blk, base=elcentro.scaled(1.5), **kw)
    gen = simulate_loop(False, blk, base=elcentro.scaled(1.5), **kw)
    pert = simulate_loop(False, blk, base=elcentro.scaled(1.5 * (1 + 1e-15)), **kw)
    assert fast.n_impacts == gen.n_impacts == pert.n_impacts >= 20
    d_fast = np.max(np.abs(fast.theta_rad - gen.theta_rad))
    d_pert = np.max(np.abs(pert.theta_rad - gen.theta_rad))
    assert 0.0 < d_fast <= 10.0 * d_pert + 1e-13


def test_coarse_record_late_start_and_free_tail(simulate_loop):
    # record samples every 0.02 s (200 steps per interval, u(t) stepped along each straight
    # segment), starting at 0.3 s: free rocking before it, then the record, then free rocking
    dt_rec = 0.02
    t = np.arange(60) * dt_rec
    a = 2.0 * np.sin(2 * np.pi * t / 0.45) * np.exp(-t / 0.8)
    a[-1] = 0.0
    rec = BaseMotion.from_samples(a, dt_rec, "m/s2", t0_s=0.3, name="coarse")
    blk = Block(0.15, 0.9)
    kw = dict(theta0_rad=0.3 * blk.alpha_rad, base=rec, duration_s=4.0, dt_s=1e-4, stop_at_rest=False)
    fast, gen = simulate_loop(True, blk, **kw), simulate_loop(False, blk, **kw)
    assert fast.n_impacts >= 5
    _compare(fast, gen)
