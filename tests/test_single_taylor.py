"""simulate(method="taylor"): free rocking by Taylor series between exact impacts, against the
event-driven reference (solve_ivp DOP853 at rtol 1e-13) and the Newmark kernel."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rocklab import Block
from rocklab._errors import InputError
from rocklab.models import bundled_record, simulate

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
