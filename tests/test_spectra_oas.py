"""Overturning curves, OAS, t_I, inclined-line fit (Ther thesis §5.1–5.3)."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rocklab import G, InputError
from rocklab.series import BaseMotion
from rocklab.models import (
    F_SINE,
    fit_inclined_line,
    free_rocking_overturns,
    load_base_motion,
    normalised_critical_impulse,
    overturning_curve,
    overturning_spectrum,
    pulse_motion,
    pulse_parameters,
    simplified_oas,
    simulate_batch,
)

FF = "records/fema-p695-far-field/SortedEQFile_{}.txt"


def _reference(acc, dt, scale, p, alpha, eta):
    """Independent event-driven solve_ivp run of the same equation; True if |theta| reaches alpha."""
    t_rec = np.arange(acc.size) * dt
    thr = math.tan(alpha)
    idx = np.flatnonzero(np.abs(scale * acc) > thr)
    i = idx[0]
    a0, a1 = scale * acc[i - 1], scale * acc[i]
    t = (i - 1 + (math.copysign(thr, a1) - a0) / (a1 - a0)) * dt
    s, y, T = -np.sign(a1), [0.0, 0.0], t_rec[-1]
    while t < T:

        def f(t, y, s=s):
            a = alpha * s - y[0]
            return [y[1], -p * p * (math.sin(a) + scale * np.interp(t, t_rec, acc) * math.cos(a))]

        def cross(t, y):
            return y[0]

        cross.terminal, cross.direction = True, -s

        def over(t, y):
            return abs(y[0]) - alpha

        over.terminal = True
        sol = solve_ivp(f, (t, T), y, events=[cross, over], rtol=1e-9, atol=1e-11, max_step=2 * dt)
        if sol.t_events[1].size:
            return True
        if sol.status == 0:
            return False
        t, om = sol.t[-1], eta * sol.y[1, -1]
        if abs(om) < 1e-7 * p:  # settled (Zeno): wait for the next uplift
            nxt = np.flatnonzero((np.abs(scale * acc) > thr) & (t_rec > t))
            if nxt.size == 0:
                return False
            t, s, y = t_rec[nxt[0]], -np.sign(acc[nxt[0]]), [0.0, 0.0]
            continue
        s, y, t = np.sign(om), [0.0, om], t + 1e-12
    return False


def test_oas_runs_match_event_driven_reference(shared_data):
    r = load_base_motion(shared_data / FF.format("120111"), units="g")
    acc = r.acc_m_s2[:1500] / G  # first 15 s hold the strong motion
    alpha = math.atan(1 / 12)
    eta = 1 - 1.5 * math.sin(alpha) ** 2
    scale = 1.342 * math.tan(alpha) / np.abs(r.acc_m_s2 / G).max()
    # p around the FF-1 boundary at a_p/a_p,min = 1.34 (reference: safe, safe, overturns)
    ps = np.array([2.21, 2.30, 2.58])
    base = BaseMotion.from_samples(r.acc_m_s2[:1500], r.dt_s)
    # the verdicts here are chaotic: p h <= 0.02 flips the middle one, 0.005 the first;
    # from 0.001 down they are converged and equal the reference
    got = simulate_batch(ps, alpha, base=base, scale=scale, eta=eta, dt_s=r.dt_s, fall_rad=alpha, max_p_dt=0.001)
    want = [_reference(acc, r.dt_s, scale, p, alpha, eta) for p in ps]
    assert list(got.overturned) == want and any(want) and not all(want)


def test_free_rocking_verdict_equals_integration():
    # random states (both pivots, inward and outward, some beyond the top): the closed-form
    # verdict must equal integrating free rocking to the end (Housner eta)
    rng = np.random.default_rng(7)
    m = 400
    alpha = np.full(m, 0.25)
    p = rng.uniform(1.0, 4.0, m)
    th = rng.uniform(-1.1, 1.1, m) * alpha
    w = rng.normal(0.0, 0.3, m) * p
    eta = 1 - 1.5 * np.sin(alpha) ** 2
    verdict = free_rocking_overturns(th, w, p, alpha, eta)
    ok = np.abs(th) < alpha  # simulate_batch starts below the top
    run = simulate_batch(
        p[ok], alpha[ok], theta0_rad=th[ok], omega0_rad_s=w[ok], eta=eta[ok], duration_s=60.0, fall_rad=alpha[ok]
    )
    assert np.array_equal(verdict[ok], run.overturned)
    assert 0.2 < verdict.mean() < 0.8  # both outcomes are exercised
    # beyond the top: outward always falls; inward falls only when too slow to climb back
    past = ~ok
    e = 0.5 * w[past] ** 2 + p[past] ** 2 * np.cos(alpha[past] - np.abs(th[past]))
    inward = th[past] * w[past] < 0
    assert np.array_equal(verdict[past][~inward], np.ones((~inward).sum(), bool))
    assert np.array_equal(verdict[past][inward] | (e[inward] >= p[past][inward] ** 2), np.ones(inward.sum(), bool))
    assert not free_rocking_overturns(0.0, 0.0, 2.0, 0.2, 1.0)  # at rest
    for bad in (dict(p_rad_s=0.0), dict(alpha_rad=2.0), dict(eta=1.5), dict(theta_rad=np.nan)):
        kw = dict(theta_rad=0.1, omega_rad_s=0.0, p_rad_s=2.0, alpha_rad=0.2, eta=0.9) | bad
        with pytest.raises(InputError, match="free_rocking_overturns"):
            free_rocking_overturns(**kw)


def test_short_pulse_impulse_tends_to_critical_impulse():
    # Eq. 17-18: as p t_p -> 0 the overturning impulse p I/a_p,min -> i_cr; H/B = 3 gives
    # i_cr = 1.013 (thesis text after Eq. 18).
    assert normalised_critical_impulse(math.atan(1 / 3)) == pytest.approx(1.013, abs=5e-4)
    c = overturning_curve("half-sine", 3, [0.005, 0.05, 0.5], np.linspace(1, 330, 120), refine=14)
    i = c.impulse_ratio
    assert i[0] == pytest.approx(c.i_cr, rel=0.005)
    assert i[0] < i[1] < i[2]  # the single-lobe impulse curve is monotonic (Fig. 34b)
    rect = overturning_curve("rectangular", 3, [0.005], np.linspace(1, 250, 100), refine=14)
    assert rect.impulse_ratio[0] == pytest.approx(c.i_cr, rel=0.005)


def test_half_sine_oas_gives_tI_near_F_tp_and_scales_with_time():
    # single lobe: transformed OAS asymptote f -> i_cr/(F t_p) (thesis §5.3.2), approached
    # from the right as a_p grows; with levels up to 10 t_I is a few % below F t_p.
    res = []
    for tp in (0.25, 0.5):
        m = pulse_motion("half-sine", tp, 1.0, dt_s=0.005, pad_s=0.1)
        o = overturning_spectrum(m, 12, levels=20, sizes=40)
        assert 0.85 < o.t_I_s / (F_SINE * tp) < 1.0
        res.append(o.t_I_s)
    # dimensional analysis: stretching the record by 2 doubles t_I
    assert res[1] / res[0] == pytest.approx(2.0, rel=2e-3)


@pytest.fixture(scope="module")
def ff_oas(shared_data):
    out = {}
    for rec in ("120111", "120112"):
        r = load_base_motion(shared_data / FF.format(rec), units="g")
        out[rec] = overturning_spectrum(r, 12)
        if rec == "120111":
            out["cont"] = overturning_spectrum(r, 12, search="contiguous")
    return out


def test_tI_of_ff41_nga_west2_file(shared_data):
    # FF-41 (1971 San Fernando, LA Hollywood Stor 090): Table 4 t_p 0.224 s, t_I 0.503 s. The
    # file here is the NGA-West2 processing, not the NGA-West1 set of the thesis: its largest
    # single-lobe impulse is a long, low lobe (8.5-9.5 s) and t_p comes out 0.293 s (+31 %),
    # so only t_I, which rests on the strong shaking, is comparable: 0.474 s (-6 %).
    r = load_base_motion(shared_data / "records/RSN68_SFERN_PEL090.AT2")
    assert pulse_parameters(r).t_p_s / 0.224 > 1.25
    assert overturning_spectrum(r, 12).t_I_s == pytest.approx(0.503, rel=0.10)


def test_tI_of_fema_pair_vs_table4(ff_oas):
    scan1, cont1, scan2 = ff_oas["120111"], ff_oas["cont"], ff_oas["120112"]
    # Table 4 (H/B = 12): FF-1 t_I = 0.266 s, FF-2 t_I = 0.360 s.
    # FF-2 with the defaults: 0.334 s (-7 %).
    assert scan2.t_I_s == pytest.approx(0.360, rel=0.10)
    # FF-1 with the defaults gives 0.336 s (+26 %): at a_p/a_p,min = 1.34 the unsafe band
    # reaches R = 1.49 m (p = 2.22 rad/s; the event-driven reference overturns there too),
    # broken by single safe grid sizes (chaotic bays) from R = 0.47 m up. A search that
    # stops at the first safe size above the smallest blocks gives 0.275 s (+3 %), close
    # to Table 4; the thesis's text ("always searching for the largest unsafe block size")
    # describes the scan, so the scan stays the default and the gap is recorded here.
    assert scan1.t_I_s == pytest.approx(0.266, rel=0.30)
    assert cont1.t_I_s == pytest.approx(0.266, rel=0.05)
    assert scan1.t_I_s > 1.1 * cont1.t_I_s
    # invariant: islands only add unsafe sizes, so the scan's f_min is never larger
    assert scan1.f_min_rad_s <= cont1.f_min_rad_s + 1e-12
    for s in (scan1, scan2):
        assert s.t_I_s == pytest.approx(s.i_cr / s.f_min_rad_s)
        assert np.nanmin(s.f_rad_s) == s.f_min_rad_s
        lv, R = s.f_min_at  # the boundary point behind t_I: f = level p(R) (Eq. 13, 19)
        assert lv * math.sqrt(G / (s.alpha_I * R)) == pytest.approx(s.f_min_rad_s, rel=1e-12)
    # the record's OAS has safe islands/bays inside the unsafe region (thesis Fig. 36a)
    rows = ["".join("X" if o else "." for o in r) for r in scan1.overturned]
    assert any("X.X" in r.strip(".") for r in rows)
    # t'_I > t_I as in every Table 4 row; the line is conservative (left of all points)
    for s in (scan1, scan2):
        assert s.t_I_prime_s > s.t_I_s and s.beta > 0
        ok = np.isfinite(s.f_rad_s)
        line = 1 / s.t_I_prime_s + s.levels[ok] / s.beta
        assert np.all(line <= s.f_rad_s[ok] * (1 + 1e-9))


def test_fit_inclined_line_recovers_a_line():
    A = np.linspace(1, 10, 30)
    f = 2.5 + A / 1.7
    f_noisy = f + np.abs(np.sin(7 * A))  # points to the right of the line only
    f_noisy[[3, 17, 25]] = f[[3, 17, 25]]  # ... touching it at three levels
    tIp, beta = fit_inclined_line(f_noisy, A)
    assert tIp == pytest.approx(1 / 2.5, rel=1e-6) and beta == pytest.approx(1.7, rel=1e-6)


def test_simplified_oas_equations():
    p = np.array([0.5, 2.0, 5.0])
    a21 = simplified_oas(p, 0.4)
    assert a21 == pytest.approx([5.0, 1.25, 1.0])  # max(1/(t_I p), 1)
    a29 = simplified_oas(p, 0.4, 0.6, 2.0, kind="eq29")
    assert a29[0] == np.inf and a29[1] == pytest.approx(1 / (0.6 * 1.5))
    a30 = simplified_oas(p, 0.4, 0.6, 2.0, kind="eq30")
    assert np.all(a30 >= np.maximum(a21, a29))


def test_oas_bad_input():
    m = BaseMotion.from_samples(np.sin(np.arange(100) * 0.1), 0.01, units="g")
    for bad in (0, -3, float("nan")):
        with pytest.raises(InputError, match="slenderness") as e:
            overturning_spectrum(m, bad)
        assert "\n" not in str(e.value)
    with pytest.raises(InputError, match="all zeros"):
        overturning_spectrum(BaseMotion.from_samples(np.zeros(50), 0.01), 12)
    with pytest.raises(InputError, match="criterion"):
        overturning_spectrum(m, 12, criterion="tilt")


def test_free_rocking_energy_verdict_equals_long_integration():
    # the exact energy verdict at the record end must agree with integrating the free rocking
    m = pulse_motion("full-sine", 0.4, 1.0, dt_s=0.005, pad_s=0.05)
    kw = dict(levels=12, level_max=6.0, sizes=30, R_max_m=10.0, refine=0)
    e = overturning_spectrum(m, 6, free="energy", **kw)
    f = overturning_spectrum(m, 6, free=60.0, **kw)
    n = overturning_spectrum(m, 6, free="none", **kw)
    assert np.array_equal(e.overturned, f.overturned)
    assert e.overturned.sum() > n.overturned.sum()  # some blocks only fall after the pulse ends


def test_full_sine_tI_in_thesis_range_for_simple_signals():
    # thesis §5.3.5: "for simple signals (Fig. 46 b-d) we obtain t_I ≈ (0.75÷0.9) t_p";
    # Fig. 46's signals are not in the text; a one-cycle sine gives 0.77 t_p here, three
    # alternating half sines 0.92 t_p, one half sine 0.59 t_p (-> F t_p = 0.64 t_p as a_p grows).
    m = pulse_motion("full-sine", 0.5, 1.0, dt_s=0.005, pad_s=0.1)
    o = overturning_spectrum(m, 12, levels=40, sizes=60)
    assert 0.75 <= o.t_I_s / 0.5 <= 0.9
