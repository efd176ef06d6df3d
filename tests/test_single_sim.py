"""Single-block simulator: integrators agree, laws are applied, closed forms hold."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rocklab import Block, G, InputError
from rocklab.series import BaseMotion
from rocklab.models import simulate

B6M = Block(0.045, 0.2025, name="B6M")


@pytest.fixture(scope="module")
def b6m_pair():
    a = B6M.alpha_rad
    nm = simulate(B6M, 0.8 * a, duration_s=6.0, dt_s=1e-4)
    ev = simulate(B6M, 0.8 * a, duration_s=6.0, dt_s=1e-4, method="event")
    return nm, ev


def test_impact_times_newmark_vs_event(b6m_pair):
    nm, ev = b6m_pair
    assert nm.n_impacts >= 20 and ev.n_impacts >= 20
    d = np.abs(nm.impacts.t_s.to_numpy()[:20] - ev.impacts.t_s.to_numpy()[:20])
    assert d.max() <= 1e-6
    # pre-impact velocities agree too (same physics, independent integrators)
    wb = nm.impacts.omega_before_rad_s.to_numpy()[:20]
    assert np.allclose(wb, ev.impacts.omega_before_rad_s.to_numpy()[:20], rtol=1e-6)
    # first impact: quarter period of the nonlinear pendulum-like motion, alternating sides
    assert np.all(np.sign(wb[:-1]) == -np.sign(wb[1:]))


def test_every_impact_applies_housner(b6m_pair):
    for r in b6m_pair:
        imp = r.impacts
        ratio = imp.omega_after_rad_s / imp.omega_before_rad_s
        assert np.allclose(ratio, B6M.eta_H, rtol=1e-12, atol=0)
        assert np.allclose(imp.eta, B6M.eta_H)


def test_energy_constant_between_impacts_and_drops_by_eta2(b6m_pair):
    nm, _ = b6m_pair
    t, E = nm.t_s, nm.energy_J
    ti = nm.impacts.t_s.to_numpy()[:15]
    E0 = E[0]
    # thread-burn release: E(0) = m g R [cos(alpha - theta0) - cos(alpha)]
    a = B6M.alpha_rad
    assert E0 == pytest.approx(B6M.mass_kg * G * B6M.R_m * (math.cos(0.2 * a) - math.cos(a)), rel=1e-12)
    edges = np.concatenate([[0.0], ti])
    for k in range(len(ti)):
        m = (t > edges[k] + 2e-4) & (t < edges[k + 1] - 2e-4)
        seg = E[m]
        expect = E0 * B6M.eta_H ** (2 * k)
        # trapezoidal Newmark conserves energy to O((p dt)^2)
        assert np.max(np.abs(seg - expect)) <= 1e-6 * E0


def test_housner_linearised_period():
    a = B6M.alpha_rad
    p = B6M.p_rad_s
    for f in (0.3, 0.8):
        r = simulate(
            B6M, f * a, duration_s=3.0, dt_s=1e-4, restitution="constant", eta=1.0, linearized=True, stop_at_rest=False
        )
        ti = r.impacts.t_s.to_numpy()
        T = 4.0 / p * math.acosh(1.0 / (1.0 - f))
        # first impact after a quarter period, then one every half period
        assert ti[0] == pytest.approx(T / 4, abs=1e-7)
        assert np.diff(ti) == pytest.approx(np.full(len(ti) - 1, T / 2), abs=2e-7)
        ev = simulate(
            B6M,
            f * a,
            duration_s=3.0,
            dt_s=1e-3,
            restitution="constant",
            eta=1.0,
            linearized=True,
            stop_at_rest=False,
            method="event",
        )
        # the adaptive reference is closer still (Newmark drifts ~(p dt)^2/12 per unit time)
        tk = T / 4 + T / 2 * np.arange(4)
        assert ev.impacts.t_s.to_numpy()[:4] == pytest.approx(tk, abs=1e-9)


def _pulse(A_g, tp_s, dt_s, T_s):
    """Rectangular base pulse -A (to the left), samples on the step grid."""
    n = int(round(T_s / dt_s)) + 1
    acc = np.zeros(n)
    k = int(round(tp_s / dt_s))
    acc[:k] = -A_g  # last nonzero sample at tp - dt: the record ramps to 0 over [tp - dt, tp]
    return BaseMotion.from_samples(acc, dt_s, "g")


def test_rectangular_pulse_linearised_closed_form():
    blk = Block(0.2, 1.0)
    a, p = blk.alpha_rad, blk.p_rad_s
    A, tp, dt = 0.35, 0.15, 1e-4  # A > tan(alpha) = 0.2: uplift at t = 0 towards theta > 0
    base = _pulse(A, tp, dt, 3.0)
    r = simulate(
        blk,
        0.0,
        duration_s=2.5,
        dt_s=dt,
        base=base,
        linearized=True,
        restitution="constant",
        eta=1.0,
        stop_at_rest=False,
    )
    # A linear ramp over [tp - dt, tp] equals a sharp end at tp - dt/2 to O(dt^2).
    te = tp - dt / 2
    c = A - a
    during = r.t_s < tp - dt
    th_exact = c * (np.cosh(p * r.t_s[during]) - 1.0)
    # trapezoidal rate error ~ (p dt)^2 / 12 ~ 1e-8 of the exponential growth
    assert np.all(np.abs(r.theta_rad[during] - th_exact) <= 1e-7 * th_exact + 1e-12)
    psi_p = c * (math.cosh(p * te) - 1.0) - a
    w_p = c * p * math.sinh(p * te)
    assert abs(psi_p) > w_p / p  # below the overturning threshold of this pulse
    th_max = a - math.sqrt(psi_p**2 - (w_p / p) ** 2)
    t_max = te + math.atanh(-w_p / (p * psi_p)) / p
    k = int(np.argmax(r.theta_rad[r.t_s < 1.5]))
    assert r.theta_rad[k] == pytest.approx(th_max, abs=1e-6 * a)
    assert r.t_s[k] == pytest.approx(t_max, abs=2 * dt)
    assert r.status == "rocking" and not r.overturned and math.isnan(r.overturn_t_s)


def test_constant_push_overturns_at_closed_form_time():
    blk = Block(0.2, 1.0)
    a, p = blk.alpha_rad, blk.p_rad_s
    A = 0.3
    base = BaseMotion.from_samples(np.full(4001, -A), 1e-3, "g")
    for method in ("newmark", "event"):
        r = simulate(blk, 0.0, duration_s=4.0, dt_s=1e-4, base=base, linearized=True, method=method)
        t_over = math.acosh(A / (A - a)) / p  # theta = alpha when cosh(pt) = A/(A - alpha)
        # Newmark: cubic Hermite interpolation of the crossing inside the step
        assert r.overturn_t_s == pytest.approx(t_over, abs=1e-6)
        assert r.overturned and r.status == "overturned"
        assert r.fall_t_s > r.overturn_t_s


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_uplift_direction_and_threshold(sign):
    blk = Block(0.2, 1.0)  # tan(alpha) = 0.2
    dt = 1e-3
    acc = np.zeros(2001)
    acc[100:300] = sign * 0.25  # above uplift: block rotates away from the push
    base = BaseMotion.from_samples(acc, dt, "g")
    r = simulate(blk, 0.0, duration_s=2.0, dt_s=1e-4, base=base)
    moved = np.flatnonzero(np.abs(r.theta_rad) > 1e-9)
    assert r.t_s[moved[0]] == pytest.approx(0.099, abs=2e-3)  # record ramps up over [0.099, 0.1]
    # a_g > 0 (base pushed to +x) tips the block onto corner B: theta < 0
    assert np.sign(r.theta_rad[moved[0]]) == -sign
    below = simulate(blk, 0.0, duration_s=2.0, dt_s=1e-4, base=BaseMotion.from_samples(acc * 0.19 / 0.25, dt, "g"))
    assert below.status == "no_uplift" and below.max_abs_theta_rad == 0.0


def test_post_impact_patterns():
    a = B6M.alpha_rad
    still = simulate(B6M, 0.5 * a, duration_s=2.0, restitution="constant", eta=0.0)
    assert still.n_impacts == 1 and still.status == "rest"
    assert still.impacts.omega_after_rad_s.iloc[0] == 0.0
    back = simulate(B6M, 0.5 * a, duration_s=2.0, restitution="constant", eta=-0.5)
    # bouncing back: theta stays >= 0, omega flips sign at each impact
    assert back.n_impacts > 3 and np.all(back.theta_rad >= -1e-15)
    w = back.impacts
    assert np.all(w.omega_after_rad_s > 0) and np.all(w.omega_before_rad_s < 0)
    stocky = Block(0.3, 0.2)  # h/b < 1/sqrt(2): Housner eta < 0
    assert stocky.eta_H < 0
    r = simulate(stocky, 0.3 * stocky.alpha_rad, duration_s=1.0)
    assert np.all(r.theta_rad >= -1e-15) and r.impacts.eta.iloc[0] == pytest.approx(stocky.eta_H)


def test_per_impact_eta_table_applied_in_both_methods():
    a = B6M.alpha_rad
    table = [0.9, 0.8, 0.95, 0.7]
    for method in ("newmark", "event"):
        r = simulate(B6M, 0.6 * a, duration_s=3.0, restitution="per_impact", eta=table, method=method)
        ratio = (r.impacts.omega_after_rad_s / r.impacts.omega_before_rad_s).to_numpy()
        expect = np.array(table + [0.7] * (len(ratio) - 4))
        assert ratio == pytest.approx(expect, rel=1e-12)


def test_eta_function_of_velocity():
    a = B6M.alpha_rad
    r = simulate(B6M, 0.6 * a, duration_s=3.0, restitution="per_impact", omega_rad_s=[0.0, 2.0], eta=[0.6, 0.99])
    wb = np.abs(r.impacts.omega_before_rad_s.to_numpy())
    assert r.impacts.eta.to_numpy() == pytest.approx(0.6 + 0.39 * wb / 2.0, rel=1e-12)


def test_rest_and_output_fields(b6m_pair):
    nm, ev = b6m_pair
    assert nm.status == ev.status == "rest"
    # Housner free rocking: impacts accumulate geometrically, total time converges
    assert nm.t_s[-1] == pytest.approx(ev.t_s[-1], abs=2e-4)
    assert nm.theta_rad[-1] == 0.0 and nm.omega_rad_s[-1] == 0.0
    f = nm.to_frame()
    assert list(f.columns) == ["t_s", "theta_rad", "omega_rad_s", "energy_J"]
    d = nm.to_dict()
    assert d["max_abs_theta_over_alpha"] == pytest.approx(0.8)
    assert len(d["impacts"]) == nm.n_impacts


@pytest.mark.parametrize(
    "kw",
    [
        {"theta0_rad": 0.3},
        {"theta0_rad": -0.3},
        {"theta0_rad": float("nan")},
        {"dt_s": 0.0},
        {"duration_s": -1.0},
        {"restitution": "nope"},
        {"method": "rk4"},
        {"restitution": "constant", "eta": 1.5},
        {"restitution": "constant"},
        {"restitution": "modified", "k": 2.0},
        {"base": np.zeros(10)},
    ],
)
def test_bad_input_raises_one_line(kw):
    with pytest.raises(InputError) as e:
        simulate(B6M, **({"theta0_rad": 0.05} | kw))
    assert "\n" not in str(e.value)


def test_base_motion_impacts_newmark_vs_event():
    # decaying sine record: uplift, 5 impacts, then it falls
    blk = Block(0.2, 1.0)
    t = np.arange(0.0, 3.0, 0.005)
    base = BaseMotion.from_samples(0.45 * np.sin(2 * np.pi * 1.5 * t) * np.exp(-0.3 * t), 0.005, "g")
    nm = simulate(blk, 0.0, duration_s=5.0, dt_s=1e-4, base=base)
    # rtol 1e-12: the record's kinks at every sample fool DOP853's error estimate at 1e-10
    ev = simulate(blk, 0.0, duration_s=5.0, dt_s=1e-3, base=base, method="event", rtol=1e-12)
    assert nm.n_impacts == ev.n_impacts >= 5
    assert np.abs(nm.impacts.t_s - ev.impacts.t_s).max() <= 1e-6
    assert nm.overturned and ev.overturned
    assert nm.overturn_t_s == pytest.approx(ev.overturn_t_s, abs=1e-6)
    assert nm.fall_t_s == pytest.approx(ev.fall_t_s, abs=1e-5)
    # with fall_rad = alpha the run stops at the first passage of alpha
    a = simulate(blk, 0.0, duration_s=5.0, dt_s=1e-4, base=base, fall_rad=blk.alpha_rad)
    assert a.fall_t_s == pytest.approx(a.overturn_t_s, abs=1e-12) and a.t_s[-1] < nm.t_s[-1]


def test_general_body_alpha_I():
    # mass lumped at the centre of mass: alpha_I = 1, p = sqrt(g/R), eta_H = 1 - 2 sin^2(alpha)
    blk = Block.general(0.5, 0.2, alpha_I=1.0)
    r = simulate(blk, 0.5 * 0.2, duration_s=4.0, restitution="housner", linearized=True)
    T = 4.0 / math.sqrt(G / 0.5) * math.acosh(2.0)
    assert r.impacts.t_s.iloc[0] == pytest.approx(T / 4, abs=1e-7)
    assert r.impacts.eta.iloc[0] == pytest.approx(1 - 2 * math.sin(0.2) ** 2)


def test_output_decimation_and_no_stop(b6m_pair):
    nm, _ = b6m_pair
    a = B6M.alpha_rad
    dec = simulate(B6M, 0.8 * a, duration_s=6.0, dt_s=1e-4, output_dt_s=1e-2)
    k = np.arange(len(dec.t_s)) * 100
    assert np.array_equal(dec.theta_rad, nm.theta_rad[k]) and np.allclose(dec.t_s, nm.t_s[k])
    full = simulate(B6M, 0.8 * a, duration_s=6.0, dt_s=1e-4, stop_at_rest=False)
    assert len(full.t_s) == 60001 and full.status == "rest"
    after = full.t_s > nm.t_s[-1]
    assert np.all(full.theta_rad[after] == 0.0) and np.all(full.energy_J[after] == 0.0)
    with pytest.raises(InputError):
        simulate(B6M, 0.1, dt_s=1e-4, output_dt_s=0.5e-4)


def test_frame_rate_output_and_at_hermite():
    # a camera at 60 fps: 1/60 s is no multiple of dt, so samples come from RockingResult.at
    a = B6M.alpha_rad
    nm = simulate(B6M, 0.7 * a, duration_s=2.0, dt_s=1e-4, output_dt_s=1 / 60)
    ev = simulate(B6M, 0.7 * a, duration_s=2.0, dt_s=1 / 60, method="event")  # dense output
    n = min(len(nm.t_s), len(ev.t_s))
    assert n >= 100 and np.allclose(nm.t_s[:n], ev.t_s[:n], atol=1e-12)
    assert np.max(np.abs(nm.theta_rad[:n] - ev.theta_rad[:n])) < 2e-6
    assert np.median(np.abs(nm.omega_rad_s[:n] - ev.omega_rad_s[:n])) < 1e-5
    # at() reproduces the stored samples and keeps the impact velocity jump
    full = simulate(B6M, 0.7 * a, duration_s=2.0, dt_s=1e-4)
    th, w = full.at(full.t_s[100:110])
    assert np.allclose(th, full.theta_rad[100:110], rtol=0, atol=1e-15)
    ti, wb, wa = full.impacts_array[:3, 0]
    th, w = full.at([ti - 1e-9, ti + 1e-9])
    assert w == pytest.approx([wb, wa], rel=1e-4) and np.all(np.abs(th) < 1e-8)
    assert np.isnan(full.at([-1.0])[0][0])


def test_rest_then_uplift_again():
    # two short pulses, opposite directions: rock, come to rest, uplift again the other way
    blk = Block(0.2, 1.0)
    t = np.arange(0.0, 8.0, 0.002)
    a = np.where((t > 0.5) & (t < 0.8), -0.25 * np.sin(2 * np.pi * (t - 0.5) / 0.3), 0.0) + np.where(
        (t > 4.0) & (t < 4.3), 0.26 * np.sin(2 * np.pi * (t - 4.0) / 0.3), 0.0
    )
    base = BaseMotion.from_samples(a, 0.002, "g")
    law = dict(restitution="constant", eta=0.8)  # settles well before the second pulse
    nm = simulate(blk, 0.0, duration_s=8.0, dt_s=1e-4, base=base, **law)
    ev = simulate(blk, 0.0, duration_s=8.0, dt_s=1e-3, base=base, method="event", rtol=1e-12, **law)
    assert nm.status == ev.status == "rest" and nm.n_impacts == ev.n_impacts
    ti_nm, ti_ev = nm.impacts.t_s.to_numpy(), ev.impacts.t_s.to_numpy()
    second = np.flatnonzero(ti_nm > 4.0)[0]
    assert 10 < second < nm.n_impacts - 10  # the first episode ended at rest before 4 s
    for k in (0, 1, second, second + 1):
        assert ti_nm[k] == pytest.approx(ti_ev[k], abs=1e-6)
    # first uplift towards theta > 0 (a_g < 0), second towards theta < 0
    first_move = nm.theta_rad[np.flatnonzero(nm.theta_rad != 0)[0]]
    k4 = np.flatnonzero((nm.t_s > 4.0) & (nm.theta_rad != 0))[0]
    assert first_move > 0 and nm.theta_rad[k4] < 0
    assert np.all(nm.theta_rad[(nm.t_s > ti_nm[second - 1] + 1e-3) & (nm.t_s < 4.0)] == 0.0)
