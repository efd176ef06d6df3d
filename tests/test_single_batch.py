"""simulate_batch: same physics as simulate, broadcasting, sub-stepping, criteria."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rocklab import Block, InputError
from rocklab.series import BaseMotion
from rocklab.models import simulate, simulate_batch


def _sine_pulse(A_g, f_hz, dt=1e-3, T=6.0):
    t = np.arange(0.0, T, dt)
    a = np.where(t < 1.0 / f_hz, -A_g * np.sin(2 * np.pi * f_hz * t), 0.0)
    return BaseMotion.from_samples(a, dt, "g")


@pytest.fixture(scope="module")
def pulse():
    return _sine_pulse(1.0, 2.0)


def test_batch_matches_simulate_entry_by_entry(pulse):
    blocks = [Block(0.2, 1.0), Block(0.3, 1.2), Block(0.1, 0.8)]
    scales = [0.25, 0.45, 0.7]
    bat = simulate_batch(
        [b.p_rad_s for b in blocks],
        [b.alpha_rad for b in blocks],
        base=pulse,
        scale=scales,
        dt_s=1e-3,
        free_after_s=0.0,
        max_p_dt=1.0,
    )
    assert bat.overturned.shape == (3,)
    for i, (b, s) in enumerate(zip(blocks, scales)):
        r = simulate(b, 0.0, duration_s=pulse.t_s[-1], dt_s=1e-3, base=pulse.scaled(s))
        assert bat.overturned[i] == r.overturned
        assert bat.n_impacts[i] == r.n_impacts
        assert bat.max_abs_theta_over_alpha[i] == pytest.approx(r.max_abs_theta_over_alpha, rel=1e-9)
        assert (math.isnan(bat.overturn_t_s[i]) and math.isnan(r.overturn_t_s)) or bat.overturn_t_s[i] == pytest.approx(
            r.overturn_t_s, abs=1e-9
        )
    # the three cases cover the outcomes: something rocks and something falls
    assert bat.overturned.any() and not bat.overturned.all()


def test_amplitude_sweep_is_monotone_for_a_long_pulse():
    # a long constant push: uplift threshold tan(alpha) = 0.2 g; above it the block
    # accelerates away and falls (linear theory: cosh growth), below it nothing moves
    blk = Block(0.2, 1.0)
    base = BaseMotion.from_samples(np.full(3001, -1.0), 1e-3, "g")
    sc = np.array([0.1, 0.19, 0.21, 0.3, 0.6])
    bat = simulate_batch(blk.p_rad_s, blk.alpha_rad, base=base, scale=sc)
    assert list(bat.overturned) == [False, False, True, True, True]
    assert list(bat.status[:2]) == [3, 3]  # no uplift
    assert np.all(np.diff(bat.overturn_t_s[2:]) < 0)  # stronger push, earlier
    assert np.all(bat.n_impacts == 0)


def test_free_rocking_counts_housner_impacts_and_broadcasts():
    blk = Block(0.045, 0.2025)
    th0 = np.array([0.2, 0.5, 0.8]) * blk.alpha_rad
    bat = simulate_batch(blk.p_rad_s, blk.alpha_rad, theta0_rad=th0, duration_s=8.0, dt_s=1e-4)
    for i in range(3):
        r = simulate(blk, th0[i], duration_s=8.0, dt_s=1e-4)
        assert bat.n_impacts[i] == r.n_impacts
        assert bat.status[i] == 1  # rest
    assert bat.eta == pytest.approx(np.full(3, blk.eta_H))
    assert bat.max_abs_theta_over_alpha == pytest.approx([0.2, 0.5, 0.8])


def test_substepping_small_blocks():
    p = np.array([2.0, 20.0, 200.0])
    bat = simulate_batch(p, 0.2, theta0_rad=0.1, duration_s=0.01, dt_s=1e-3, max_p_dt=0.02)
    assert np.all(p * bat.dt_s <= 0.02 + 1e-15)
    assert bat.dt_s[0] == 1e-3 and bat.dt_s[2] == pytest.approx(1e-4)


def test_fall_criterion_alpha(pulse):
    blk = Block(0.2, 1.0)
    sc = np.linspace(0.2, 0.8, 13)
    at_alpha = simulate_batch(blk.p_rad_s, blk.alpha_rad, base=pulse, scale=sc, fall_rad=blk.alpha_rad)
    falls = simulate_batch(blk.p_rad_s, blk.alpha_rad, base=pulse, scale=sc)
    # passing alpha is necessary for a fall; the alpha criterion flags exactly those passing it
    assert np.all(at_alpha.overturned == np.isfinite(at_alpha.overturn_t_s))
    assert np.all(at_alpha.overturned >= falls.overturned)


@pytest.mark.parametrize(
    "kw",
    [
        {"p_rad_s": [1.0, -1.0]},
        {"theta0_rad": 0.5},
        {"alpha_rad": 2.0},
        {"scale": [1.0, 2.0, 3.0]},
        {"eta": 1.5},
        {"duration_s": None},
        {"dt_s": 0.0},
    ],
)
def test_bad_input(kw):
    args = {"p_rad_s": [3.0, 4.0], "alpha_rad": 0.2, "duration_s": 1.0} | kw
    with pytest.raises(InputError):
        simulate_batch(args.pop("p_rad_s"), args.pop("alpha_rad"), **args)
