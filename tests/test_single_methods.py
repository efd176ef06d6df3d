"""simulate's integrators behind one contract: the METHODS registry, Integrator instances, KernelResult."""

from __future__ import annotations

import numpy as np
import pytest

from rocklab import Block, InputError
from rocklab.models import simulate
from rocklab.models.rocking import METHODS, Integrator, KernelResult, Newmark, Taylor

B6M = Block(0.045, 0.2025, name="B6M")


def test_every_registered_method_runs_and_an_unknown_one_lists_them():
    th0 = 0.6 * B6M.alpha_rad
    first = {}
    for name in METHODS:
        r = simulate(B6M, th0, duration_s=1.5, method=name.upper())
        assert r.method == name
        first[name] = r.impacts_array[0, 0]
    # the same first impact whichever integrator: the registry really dispatches to three of them
    assert len(first) == 3
    assert max(first.values()) - min(first.values()) <= 1e-6
    with pytest.raises(InputError) as e:
        simulate(B6M, th0, duration_s=1.0, method="rk45")
    assert all(repr(k) in str(e.value) for k in METHODS)
    with pytest.raises(InputError, match="unknown integrator"):
        simulate(B6M, th0, duration_s=1.0, method=None)


def test_an_instance_carries_its_options():
    kw = dict(duration_s=2.0, dt_s=1e-4)
    lean = simulate(B6M, 0.7 * B6M.alpha_rad, **kw)
    general = simulate(B6M, 0.7 * B6M.alpha_rad, method=Newmark(lean=False), **kw)
    assert general.method == "newmark" and general.n_impacts == lean.n_impacts >= 8
    # the same trapezoidal solution, but not bitwise: the general loop really ran
    assert np.max(np.abs(general.theta_rad - lean.theta_rad)) <= 1e-9
    assert np.any(general.theta_rad != lean.theta_rad)


class _TaylorOnSteps(Taylor):
    """Taylor's kernel on the dt grid only: simulate must resample its output itself."""

    name = "taylor_steps"
    any_output_grid = False

    def run(self, problem):
        out = super().run(problem._replace(resample_dt_s=None))
        assert isinstance(out, KernelResult)
        return out


def test_output_grid_contract():
    # a camera frame interval that is not a whole number of steps: an integrator that samples any
    # grid does it itself, any other is resampled from its steps (Hermite); both give the same motion
    kw = dict(duration_s=1.0, dt_s=1e-4, output_dt_s=1 / 240)
    direct = simulate(B6M, 0.5 * B6M.alpha_rad, method="taylor", **kw)
    steps = simulate(B6M, 0.5 * B6M.alpha_rad, method=_TaylorOnSteps(), **kw)
    assert isinstance(_TaylorOnSteps(), Integrator) and steps.method == "taylor_steps"
    assert np.allclose(np.diff(steps.t_s), 1 / 240) and len(steps.t_s) == len(direct.t_s)
    assert np.max(np.abs(steps.theta_rad - direct.theta_rad)) <= 1e-8
    assert np.any(steps.theta_rad != direct.theta_rad)  # really resampled, not the direct samples
    assert steps.n_impacts == direct.n_impacts >= 3


@pytest.mark.parametrize("eps", [0.0, 1e-12, 1e-6])
def test_event_method_ends_when_the_base_only_touches_the_uplift_level(eps):
    # a record scaled to a_p/a_p,min = 1 (eps = 0: the peak above g tan(alpha) by the least float) lifts
    # the block at an instant and drops it back at once; method='event' restarted that phase forever.
    # Reference: the Newmark kernel (rest, theta ~ 0); the event method's impacts all at the two spikes
    import math
    import signal

    from rocklab import G
    from rocklab.series import BaseMotion

    alpha = math.atan(1 / 12)
    blk = Block.general(0.2, alpha, 4.0 / 3.0)
    a = np.zeros(50)
    a[10], a[30] = 1.0, -1.0
    x = math.tan(blk.alpha_rad) * (1.0 + eps)
    while True:  # the least scale whose samples exceed tan(alpha) once divided by g, as the kernels test it
        base = BaseMotion.from_samples(a * x, 0.01, "g")
        if np.max(np.abs(base.acc_m_s2 / G)) > math.tan(blk.alpha_rad):
            break
        x = np.nextafter(x, 2.0)

    def stop(*_):
        raise TimeoutError("simulate(method='event') did not end within 20 s")

    old = signal.signal(signal.SIGALRM, stop)
    signal.alarm(20)
    try:
        ev = simulate(blk, base=base, duration_s=0.5, method="event", fall_rad=alpha)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    nm = simulate(blk, base=base, duration_s=0.5, dt_s=1e-4, fall_rad=alpha)
    assert ev.status == nm.status == "rest"
    assert nm.n_impacts == 2 and ev.max_abs_theta_rad < 1e-10 and nm.max_abs_theta_rad < 1e-10
    t_imp = ev.impacts["t_s"].to_numpy()
    near = np.abs(t_imp[:, None] - np.array([0.1, 0.3])[None, :]) < 1e-6
    assert near.any(axis=1).all() and near.any(axis=0).all()  # at the spikes only, and at both
