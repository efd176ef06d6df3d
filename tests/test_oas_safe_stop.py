"""The Taylor record kernel's safe stop (``simulate_batch(stop_when_safe=True)``, used by the OAS): a run stops
once the rest of the record cannot bring it to alpha. Checked against the same runs to the end: every verdict
equal, no stopped run reaches alpha later, and a bound made too optimistic (the record's tail integral shrunk)
gets verdicts wrong, so the test would see a bound that is not one."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rocklab import G
from rocklab.models import simulate_batch
from rocklab.models.rocking import free_rocking_overturns
from rocklab.models.rocking._batch import _entries
from rocklab.models.rocking._newmark import run_batch
from rocklab.models.rocking._taylor_record import order_for, run_taylor_record, safe_tail
from rocklab.series import BaseMotion

ALPHA = math.atan(1 / 5)


@pytest.fixture(scope="module")
def shaking():
    """Two decaying sines, 6 s at dt = 5 ms: strong first, then a long weak tail."""
    dt = 0.005
    t = np.arange(0.0, 6.0, dt)
    a = np.sin(2 * np.pi * 1.5 * t) * np.exp(-0.6 * t) + 0.4 * np.sin(2 * np.pi * 3.7 * t + 0.3) * np.exp(-0.8 * t)
    return BaseMotion.from_samples(a, dt, "g")


def _grid(base):
    lv, R = np.meshgrid(np.linspace(1.0, 4.0, 16), np.geomspace(0.05, 20.0, 24), indexing="ij")
    p = np.sqrt(G / (4.0 / 3.0 * R.ravel()))
    return p, lv.ravel() * math.tan(ALPHA) * G / base.pga_m_s2


def _verdicts(b, p):
    """Overturned during the record or, still rocking at its end, in free rocking after it."""
    rocking = b.status == 0
    free = free_rocking_overturns(b.theta_end_rad, b.omega_end_rad_s, p, ALPHA, b.eta)
    return np.asarray(b.overturned, bool) | (rocking & free)


def test_safe_stop_keeps_every_verdict(shaking):
    p, sc = _grid(shaking)
    kw = dict(base=shaking, scale=sc, fall_rad=ALPHA, method="taylor", max_p_dt=0.25)
    full = simulate_batch(p, ALPHA, **kw)
    fast = simulate_batch(p, ALPHA, stop_when_safe=True, **kw)
    stopped = fast.status == 4
    # the stop is used (not vacuous) and saves simulated time
    assert stopped.sum() >= 30
    assert fast.t_end_s.sum() < 0.9 * full.t_end_s.sum()
    assert np.array_equal(_verdicts(full, p), _verdicts(fast, p))
    # a stopped run never reached alpha in the run to the end, and it stopped before that run ended
    assert not _verdicts(full, p)[stopped].any()
    assert np.all(full.max_abs_theta_over_alpha[stopped] < 1.0)
    assert np.all(fast.t_end_s[stopped] <= full.t_end_s[stopped] + 1e-12)
    # the runs that were not stopped are the same runs, bit for bit
    assert np.array_equal(full.overturn_t_s[~stopped], fast.overturn_t_s[~stopped], equal_nan=True)


def test_an_optimistic_bound_gets_verdicts_wrong(shaking):
    """The same kernel with the record's remaining |acc| integral shrunk 20x stops runs that go on to overturn."""
    p, sc = _grid(shaking)
    args = _entries(p, ALPHA, sc, 0.0, 0.0, 4.0 / 3.0, None, ALPHA)
    pp, al, scale, th0, w0, eta, fall = args
    acc = np.ascontiguousarray(shaking.acc_m_s2, float)
    order = order_for(pp * np.minimum(shaking.dt_s, 0.25 / pp), 1e-16)
    common = (pp, al, eta, scale, th0, w0, acc, 0.0, shaking.dt_s, float(shaking.t_s[-1]), order, 0.25, 1e-6, fall)
    tail = safe_tail(acc, shaking.dt_s)
    exact = run_taylor_record(*common, np.zeros(0))[0]
    honest = run_taylor_record(*common, tail)[0]
    optimistic = run_taylor_record(*common, tail / 20.0)[0]
    over = exact == 2
    assert np.array_equal(over, honest == 2)
    assert np.any(over & (optimistic == 4))  # would call overturning blocks safe


def test_safe_tail_bounds_the_integral():
    """Constant record: the closed form; a sign-changing one: the integral of |linear interpolation| (fine
    sampling), rounded up."""
    dt = 0.01
    c = safe_tail(np.full(101, -2.0), dt)
    assert c == pytest.approx(2.0 * dt * np.arange(100, -1, -1), rel=1e-11)
    rng = np.random.default_rng(3)
    acc = rng.normal(size=200)
    tail = safe_tail(acc, dt)
    fine = np.interp(np.linspace(0, 199, 199 * 400 + 1), np.arange(200), acc)
    step = dt / 400
    exact = np.abs(fine[:-1] + fine[1:]) * 0.5 * step  # exact where the sign holds, the crossings refined
    exact_tail = np.r_[np.cumsum(exact[::-1])[::-1][::400], 0.0]
    assert np.all(tail >= exact_tail - 1e-9)
    assert np.all(np.diff(tail) <= 0) and tail[-1] == 0.0
    assert tail == pytest.approx(exact_tail, rel=1e-6, abs=1e-9)  # exact, the zero crossings included


@pytest.mark.parametrize("fall", ["alpha", "pi/2"])
def test_newmark_safe_stop_keeps_every_verdict(shaking, fall):
    """The Newmark batch path's safe stop (the OAS's ``method="newmark"``, the band's ``step x2``): verdicts equal
    to the runs to the end; with ``fall_rad`` pi/2 too (a block past alpha is never stopped)."""
    p, sc = _grid(shaking)
    kw = dict(base=shaking, scale=sc, fall_rad=ALPHA if fall == "alpha" else None, method="newmark", max_p_dt=0.005)
    full = simulate_batch(p, ALPHA, dt_s=shaking.dt_s, **kw)
    fast = simulate_batch(p, ALPHA, dt_s=shaking.dt_s, stop_when_safe=True, **kw)
    stopped = fast.status == 4
    assert stopped.sum() >= 30
    assert fast.t_end_s.sum() < 0.9 * full.t_end_s.sum()
    over_full = _verdicts(full, p) if fall == "alpha" else np.asarray(full.overturned, bool)
    over_fast = _verdicts(fast, p) if fall == "alpha" else np.asarray(fast.overturned, bool)
    assert np.array_equal(over_full, over_fast)
    assert over_full.sum() >= 30  # both verdicts occur
    assert not over_full[stopped].any()
    if fall == "alpha":  # (with pi/2 a block may pass alpha and come back before it is stopped)
        assert np.all(full.max_abs_theta_over_alpha[stopped] < 1.0)
    assert np.array_equal(full.overturn_t_s[~stopped], fast.overturn_t_s[~stopped], equal_nan=True)
    assert np.array_equal(full.status[~stopped], fast.status[~stopped])


def test_newmark_optimistic_bound_gets_verdicts_wrong(shaking):
    """The Newmark kernel with the tail integral shrunk 20x stops runs that go on to overturn."""
    p, sc = _grid(shaking)
    pp, al, scale, th0, w0, eta, fall = _entries(p, ALPHA, sc, 0.0, 0.0, 4.0 / 3.0, None, ALPHA)
    acc = np.ascontiguousarray(shaking.acc_m_s2, float)
    n_sub = np.maximum(1, np.ceil(pp * shaking.dt_s / 0.005 - 1e-12)).astype(np.int64)
    h = shaking.dt_s / n_sub
    n_steps = np.ceil(float(shaking.t_s[-1]) / h - 1e-9).astype(np.int64)
    common = (pp, al, th0, w0, eta, h, n_steps, acc, 0.0, shaking.dt_s, scale, 1e-6, fall, True)
    tail = safe_tail(acc, shaking.dt_s)
    exact = run_batch(*common, np.zeros(0))[4]
    honest = run_batch(*common, tail)[4]
    optimistic = run_batch(*common, tail / 20.0)[4]
    assert np.array_equal(exact == 2, honest == 2)
    assert np.any((exact == 2) & (optimistic == 4))


@pytest.mark.parametrize("method", ["taylor", "newmark"])
def test_a_block_past_alpha_is_not_stopped(method):
    """With ``fall_rad`` pi/2 a block pushed past alpha and slowed there (1 g for 0.3 s, then -0.3 g for 0.6 s,
    then still) has less excess energy than the top needs while it falls: the stop must not call it safe (the
    Taylor kernel of session 17 did: 77 of these 400 verdicts wrong)."""
    dt = 0.01
    a = np.r_[np.zeros(5), np.full(30, 1.0), np.full(60, -0.3), np.zeros(300)]
    base = BaseMotion.from_samples(a, dt, "g")
    lv, R = np.meshgrid(np.linspace(0.3, 1.5, 20), np.geomspace(0.2, 30.0, 20), indexing="ij")
    p = np.sqrt(G / (4.0 / 3.0 * R.ravel()))
    kw = dict(base=base, scale=lv.ravel(), method=method, max_p_dt=0.25 if method == "taylor" else 0.005, dt_s=dt)
    full = simulate_batch(p, 0.2, **kw)
    fast = simulate_batch(p, 0.2, stop_when_safe=True, **kw)
    passed = full.max_abs_theta_over_alpha > 1.0
    assert (passed & ~full.overturned).sum() >= 5  # past alpha and back, and past alpha and down, both occur
    assert (passed & full.overturned).sum() >= 10
    assert np.array_equal(full.overturned, fast.overturned)
    assert (fast.status == 4).sum() >= 30
