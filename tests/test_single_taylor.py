"""simulate(method="taylor"): free rocking by Taylor series between exact impacts, against the
event-driven reference (solve_ivp DOP853 at rtol 1e-13) and the Newmark kernel."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rocklab import Block
from rocklab._errors import InputError
from rocklab.models import bundled_record, simulate
from rocklab.models.rocking import free_rocking_impact_times

B6M = Block(0.045, 0.2025, name="B6M")


@pytest.fixture(scope="module")
def b6m_runs():
    th0 = 0.8 * B6M.alpha_rad
    kw = dict(duration_s=10.0, dt_s=1e-4)
    return (
        simulate(B6M, th0, method="taylor", **kw),
        simulate(B6M, th0, method="event", rtol=1e-13, **kw),
        simulate(B6M, th0, **kw),
    )


def test_taylor_matches_the_tight_event_reference(b6m_runs):
    tay, ref, nm = b6m_runs
    assert tay.status == ref.status == "rest" and tay.n_impacts == ref.n_impacts == 90
    ti, tr, tn = (r.impacts.t_s.to_numpy() for r in (tay, ref, nm))
    # measured 3.5e-11 s (the Newmark kernel at dt = 1e-4 s: 2.2e-7 s)
    assert np.abs(ti - tr).max() < 1e-9
    assert np.abs(tn - tr).max() > 100 * np.abs(ti - tr).max()
    wi, wr = tay.impacts.omega_before_rad_s.to_numpy(), ref.impacts.omega_before_rad_s.to_numpy()
    assert np.abs(wi - wr).max() < 1e-8
    n = min(tay.t_s.size, ref.t_s.size)
    assert np.array_equal(tay.t_s[:n], ref.t_s[:n])
    assert np.abs(tay.theta_rad[:n] - ref.theta_rad[:n]).max() < 1e-9  # measured 3e-12 rad
    assert tay.max_abs_theta_rad == pytest.approx(0.8 * B6M.alpha_rad, rel=1e-12)


def test_taylor_energy_is_the_invariant_between_impacts(b6m_runs):
    tay, ref, _ = b6m_runs
    # the output energy is constant between impacts and equals the state's own energy
    a, p2 = B6M.alpha_rad, B6M.p_rad_s**2
    th, w = tay.theta_rad, tay.omega_rad_s
    e_state = B6M.I_O_kg_m2 * (0.5 * w**2 + p2 * (np.cos(a - np.abs(th)) - math.cos(a)))
    moving = tay.energy_J > 0
    assert np.abs(e_state[moving] - tay.energy_J[moving]).max() < 1e-10 * tay.energy_J[0]
    # each impact keeps eta^2 of the energy (Housner's eta)
    imp = tay.impacts
    ratio = (imp.omega_after_rad_s / imp.omega_before_rad_s).to_numpy()
    assert ratio == pytest.approx(B6M.eta_H, rel=1e-12)


def test_taylor_overturning_and_laws():
    a = B6M.alpha_rad
    p = B6M.p_rad_s
    # released upright with more than the energy to pass alpha: it falls; time vs the reference
    w0 = 1.05 * math.sqrt(2 * p**2 * (1 - math.cos(a)))
    tay = simulate(B6M, 0.0, w0, duration_s=3.0, method="taylor", fall_rad=a)
    ref = simulate(B6M, 0.0, w0, duration_s=3.0, method="event", rtol=1e-13, fall_rad=a)
    assert tay.status == ref.status == "overturned"
    assert tay.fall_t_s == pytest.approx(ref.fall_t_s, abs=1e-9)
    assert tay.overturn_t_s == pytest.approx(ref.overturn_t_s, abs=1e-9)
    # a per-impact table of restitution coefficients is applied in order
    etas = [0.9, 0.8, 0.95]
    r = simulate(B6M, 0.5 * a, duration_s=2.0, method="taylor", restitution="per_impact", eta=etas)
    assert r.impacts.eta.to_numpy()[:3] == pytest.approx(etas)
    # a camera-rate grid is evaluated directly, not resampled
    cam = simulate(B6M, 0.5 * a, duration_s=1.0, method="taylor", output_dt_s=1 / 240)
    ref = simulate(B6M, 0.5 * a, duration_s=1.0, method="event", rtol=1e-13, output_dt_s=1 / 240)
    n = min(cam.t_s.size, ref.t_s.size)
    assert np.diff(cam.t_s) == pytest.approx(1 / 240) and np.abs(cam.theta_rad[:n] - ref.theta_rad[:n]).max() < 1e-8


def test_taylor_refuses_what_it_does_not_integrate():
    with pytest.raises(InputError, match="free rocking"):
        simulate(B6M, 0.0, duration_s=1.0, method="taylor", base=bundled_record("elcentro"))
    with pytest.raises(InputError, match="linearized"):
        simulate(B6M, 0.1, duration_s=1.0, method="taylor", linearized=True)
    with pytest.raises(InputError, match="taylor"):
        simulate(B6M, 0.1, duration_s=1.0, method="rk4")


def test_block_output_equals_the_per_sample_series():
    # the output grid is evaluated in blocks of re-expanded low-degree polynomials; against one
    # order-12 evaluation per sample (the previous path) on the same series: equal to the rounding
    # (measured <= 2.5e-16 of alpha and of p alpha), for p dt from 1e-4 up to the blocks' bound
    from rocklab.models.rocking._taylor import ORDER, _coefficients, _recurrence_factors
    from rocklab.models.rocking._taylor_dense import block_scratch, blocks_fit, dense_blocks, dense_samples

    n = ORDER

    def both(p, alpha, dt, th_f, w_f, s):
        inv, q = _recurrence_factors(p * p, n)
        a, S, C, jc = (np.zeros(n + 1) for _ in range(4))
        _coefficients(a, S, C, jc, th_f * alpha, w_f * p * alpha, s, p * p, alpha, n, inv, q)
        t = 0.123456789
        k0, k1 = int(t / dt) + 1, int((t + 0.2 / p) / dt) + 1  # one full step of p h = 0.2
        one, blk = ([np.zeros(k1 + 40) for _ in range(3)] for _ in range(2))
        dense_samples(a, n, *one, k0, k1, dt, t, 1.5)
        dense_blocks(a, n, *blk, k0, k1, dt, t, 1.5, *block_scratch(n, dt))
        assert np.array_equal(one[2], blk[2])
        return np.abs(one[0] - blk[0]).max() / alpha, np.abs(one[1] - blk[1]).max() / (p * alpha)

    states = ((0.9, 0.0, 1.0), (0.0, 1.0, 1.0), (-0.5, -0.7, -1.0), (0.01, -0.05, 1.0))
    for p, alpha, dt in ((8.42, 0.218, 1e-4), (20.0, 0.3, 5e-5), (17.0, 0.1, 1e-4), (8.42, 0.218, 2.29e-4)):
        assert blocks_fit(p, dt)
        for st in states:
            e_th, e_w = both(p, alpha, dt, *st)
            assert e_th < 1e-15 and e_w < 1e-15
    # perturbed: blocks ten times wider than the bound lose accuracy (the bound is what keeps it)
    assert not blocks_fit(8.42, 2.29e-3)
    assert max(both(8.42, 0.218, 2.29e-3, *st)[1] for st in states) > 1e-12


def test_block_output_run_equals_the_per_sample_run():
    # whole runs: the 1e-4 s grid (blocks) against a 2.5e-3 s grid (too coarse for blocks:
    # one order-12 evaluation per sample) at their common times
    th0 = 0.8 * B6M.alpha_rad
    fine = simulate(B6M, th0, method="taylor", duration_s=4.0, dt_s=1e-4)
    coarse = simulate(B6M, th0, method="taylor", duration_s=4.0, dt_s=2.5e-3)
    assert np.array_equal(fine.impacts_array, coarse.impacts_array)
    n = coarse.t_s.size - 1  # the last sample of a run at rest is the rest sample
    assert np.abs(fine.t_s[: 25 * n : 25] - coarse.t_s[:n]).max() < 1e-15
    assert np.abs(fine.theta_rad[: 25 * n : 25] - coarse.theta_rad[:n]).max() < 1e-15  # measured 6e-17 rad
    assert np.abs(fine.omega_rad_s[: 25 * n : 25] - coarse.omega_rad_s[:n]).max() < 1e-14  # 1.6e-15 rad/s


def test_taylor_impact_times_match_the_energy_quadrature(b6m_runs):
    # an independent reference without time steps: 90 impact times from the energy integral.
    # Measured: Taylor 2.4e-12 s; DOP853 with events at rtol 1e-13 3.4e-11 to 4.7e-11 s at any
    # rtol from 1e-11 to 3e-14 (its impact location, not its step, limits it)
    tay, ref, _ = b6m_runs
    t_q = free_rocking_impact_times(B6M, 0.8 * B6M.alpha_rad, B6M.eta_H, 90)
    err_tay = np.abs(tay.impacts.t_s.to_numpy() - t_q).max()
    assert err_tay < 1e-11
    # perturbed: the same quadrature with eta off by 1e-9 (relative) is far outside that bound
    t_p = free_rocking_impact_times(B6M, 0.8 * B6M.alpha_rad, B6M.eta_H * (1 + 1e-9), 90)
    assert np.abs(tay.impacts.t_s.to_numpy() - t_p).max() > 10 * err_tay
