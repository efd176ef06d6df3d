"""Converged OAS verdicts (oas_reference) and the Taylor-per-record-interval batch integrator behind them:
against independent integrators (fine Newmark steps, the event-driven solve_ivp reference, the free
Taylor kernel), and the chaotic cells against an independent integrator's own flips."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rocklab import Block, G, InputError
from rocklab.models import oas_reference, overturning_spectrum, pulse_motion, simulate, simulate_batch
from rocklab.series import BaseMotion

B6M = Block(0.045, 0.2025, name="B6M")
GRID = dict(levels=8, sizes=12, R_max_m=20.0, R_min_m=0.05, level_max=4.0, level_offset=0.5)


@pytest.fixture(scope="module")
def shaking():
    """Two decaying sines, 4 s at dt = 5 ms: short, yet with chaotic cells on a small grid."""
    dt = 0.005
    t = np.arange(0.0, 4.0, dt)
    a = np.sin(2 * np.pi * 1.5 * t) * np.exp(-0.4 * t) + 0.4 * np.sin(2 * np.pi * 3.7 * t + 0.3) * np.exp(-0.6 * t)
    return BaseMotion.from_samples(a, dt, "g")


@pytest.fixture(scope="module")
def ref(shaking):
    return oas_reference(shaking, 5.0, **GRID)


def _fine_newmark(base, o, factor):
    """Verdicts of every cell by Newmark steps of p h <= 1e-4 (an independent integrator) at amplitude x factor."""
    i = np.repeat(np.arange(o.levels.size), o.p_rad_s.size)
    j = np.tile(np.arange(o.p_rad_s.size), o.levels.size)
    sc = factor * o.levels[i] * math.tan(o.alpha_rad) * G / base.pga_m_s2
    b = simulate_batch(
        o.p_rad_s[j], o.alpha_rad, base=base, scale=sc, eta=o.eta, dt_s=base.dt_s, fall_rad=o.alpha_rad, max_p_dt=1e-4
    )
    from rocklab.models import free_rocking_overturns

    free = (b.status == 0) & free_rocking_overturns(
        b.theta_end_rad, b.omega_end_rad_s, o.p_rad_s[j], o.alpha_rad, o.eta
    )
    return (b.overturned | free).reshape(o.overturned.shape)


def test_reference_agrees_with_fine_newmark_on_every_decided_cell(shaking, ref):
    assert ref.overturned.any() and not ref.overturned.all()
    assert not ref.unresolved.any()  # the finer Taylor check changes no verdict here
    fine = _fine_newmark(shaking, ref.oas, 1.0)
    d = ref.decided
    assert np.array_equal(fine[d], ref.overturned[d])
    # the measure has teeth: the same grid with 5 % less restitution disagrees on some decided cells
    other = overturning_spectrum(shaking, 5.0, grid="dense", eta=0.95 * ref.oas.eta, **GRID)
    assert ref.agreement(other) < 1.0


def test_chaotic_cells_flip_under_the_independent_integrator_too(shaking, ref):
    # measured: 3 chaotic cells of 96 on this grid
    assert 1 <= ref.chaotic.sum() <= 10
    assert ref.chaotic_fraction == pytest.approx(ref.chaotic.sum() / ref.chaotic.size)
    lo, mid, hi = (_fine_newmark(shaking, ref.oas, f) for f in (1 - ref.chaos_rel, 1.0, 1 + ref.chaos_rel))
    flips = (lo != mid) | (hi != mid)
    assert flips[ref.chaotic].all()


def test_reference_t_I_is_the_dense_grids_at_the_reference_runs(shaking, ref):
    o = overturning_spectrum(shaking, 5.0, grid="dense", method="taylor", **GRID)
    assert np.array_equal(o.overturned, ref.overturned)
    assert o.t_I_s == ref.oas.t_I_s and math.isfinite(o.t_I_s)


def test_taylor_batch_free_rocking_is_the_free_taylor_kernel():
    th0 = np.array([0.3, 0.8]) * B6M.alpha_rad
    b = simulate_batch(B6M.p_rad_s, B6M.alpha_rad, theta0_rad=th0, duration_s=10.0, method="taylor", max_p_dt=0.25)
    for k in range(2):
        r = simulate(B6M, float(th0[k]), duration_s=10.0, dt_s=1e-3, method="taylor")
        assert b.n_impacts[k] == r.n_impacts  # 90 impacts from 0.8 alpha (event reference: 90)
        assert b.status[k] == 1 and r.status == "rest"
    assert b.max_abs_theta_over_alpha == pytest.approx([0.3, 0.8], rel=1e-12)


def test_taylor_batch_overturning_time_matches_the_event_reference():
    base = pulse_motion("sine", 0.5, 2.0)
    blk = Block.general(0.5, math.atan(1 / 5), 4 / 3)
    sc = 2.6 * math.tan(blk.alpha_rad) * G / base.pga_m_s2
    b = simulate_batch(blk.p_rad_s, blk.alpha_rad, base=base, scale=sc, fall_rad=blk.alpha_rad, method="taylor")
    r = simulate(
        blk,
        base=base.scaled(sc),
        duration_s=float(base.t_s[-1]),
        method="event",
        restitution=float(b.eta[0]),
        fall_rad=blk.alpha_rad,
        rtol=1e-12,
        atol=1e-14,
    )
    assert r.status == "overturned" and bool(b.overturned[0])
    assert b.n_impacts[0] == r.n_impacts
    assert b.overturn_t_s[0] == pytest.approx(r.overturn_t_s, abs=1e-8)


@pytest.mark.parametrize(
    "kw, word", [({"grid": "adaptive"}, "grid="), ({"chaos_rel": 0.0}, "chaos_rel"), ({"method": "newmark"}, "method=")]
)
def test_reference_options_are_one_line_errors(shaking, kw, word):
    with pytest.raises(InputError, match=word):
        oas_reference(shaking, 5.0, levels=3, sizes=3, **kw)


def test_agreement_needs_the_same_grid_and_batch_method_is_checked(shaking, ref):
    with pytest.raises(InputError, match="another grid"):
        ref.agreement(overturning_spectrum(shaking, 5.0, levels=4, sizes=5))
    with pytest.raises(InputError, match="method"):
        simulate_batch(1.0, 0.2, theta0_rad=0.1, duration_s=1.0, method="rk4")


@pytest.mark.parametrize("eps", [1e-12, 1e-6, 1e-3])
def test_taylor_batch_grazing_uplift_comes_to_rest_like_newmark(eps):
    # two 1 g spikes scaled to tan(alpha) (1 + eps): the base barely lifts the block at each, so a
    # run sits at the uplift level without leaving the corner; it must end at rest, as Newmark's
    al = math.atan(1 / 12)
    a = np.zeros(50)
    a[10], a[30] = 1.0, -1.0
    base = BaseMotion.from_samples(a, 0.01, "g")
    p = np.array([0.5, 2.0, 8.0])
    kw = dict(base=base, scale=math.tan(al) * (1 + eps), fall_rad=al)
    tay = simulate_batch(p, al, method="taylor", **kw)
    nm = simulate_batch(p, al, dt_s=0.01, max_p_dt=1e-4, **kw)
    assert tay.status.tolist() == nm.status.tolist() == [1, 1, 1]
    assert tay.n_impacts.tolist() == nm.n_impacts.tolist() == [2, 2, 2]
    assert np.all(tay.max_abs_theta_over_alpha < 1e-10)
