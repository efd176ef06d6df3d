"""Time histories of rocking mechanisms and their equivalent blocks (DeJong & Dimitrakopoulos 2014)."""

import math

import numpy as np
import pandas as pd
import pytest

from rocklab import Block, G, InputError
from rocklab.series import BaseMotion
from rocklab.models import pulse_motion, simulate
from rocklab.models.mechanisms import (
    asymmetric_frame,
    block_mechanism,
    block_parameters,
    conical_shell_geometry,
    conical_shell_parameters,
    equivalent_block,
    equivalent_block_mechanism,
    free_rocking_period_eq24,
    mechanism_response,
    mechanism_time_histories,
    overturning_time_eq25,
    wall_mechanism,
)


def test_block_mechanism_matches_the_event_simulator():
    # the same block through the mechanism integrator and through simulate(method="event")
    blk = Block(0.1, 0.4)
    mech = block_mechanism(blk.R_m, blk.alpha_rad, eta=0.9)
    base = pulse_motion("sine", 0.5, 1.1 * G * math.tan(blk.alpha_rad), pad_s=3.0, dt_s=0.001)
    r = mechanism_response(mech, base, 0.9)
    ref = simulate(blk, duration_s=float(base.t_s[-1]), restitution=0.9, base=base, method="event", output_dt_s=0.001)
    t_ref = np.asarray(ref.impacts_array)[0]
    assert t_ref.size > 20
    assert np.abs(r.impacts_t_s[:20] - t_ref[:20]).max() < 1e-6  # measured 1.5e-7 s
    n = ref.theta_rad.size
    assert np.nanmax(np.abs(r.phi_rad[:n] - ref.theta_rad)) < 2e-6  # measured 3.7e-7 rad
    assert r.status == "ok" and not r.overturned


def test_linear_block_free_rocking_period_eq24():
    # released from theta0 with no base motion and eta = 1: impacts every half period of Eq. 24
    fp = block_parameters(1.0, 0.2)
    lin = equivalent_block_mechanism(fp, linear=True)
    base = BaseMotion(np.arange(0, 6.0, 0.01), np.zeros(600))
    for ratio in (0.2, 0.6):
        r = mechanism_response(lin, base, 1.0, phi0_rad=ratio * fp.theta_cr_rad, tabulate=False)
        T = float(free_rocking_period_eq24(fp.p_rad_s, ratio))
        n = r.impacts_t_s.size
        assert n >= 2
        expected = T / 4 + T / 2 * np.arange(n)
        assert np.abs(r.impacts_t_s - expected).max() < 1e-9  # measured 1.3e-11 s


def test_linear_block_overturning_time_eq25():
    # a constant base acceleration lifts the linear block, which reaches theta_cr at Eq. 25's time
    fp = block_parameters(1.0, 0.2)
    lin = equivalent_block_mechanism(fp, linear=True)
    for q in (1.5, 3.0):  # u''/(g lambda_lin)
        t = np.arange(0.0, 4.0, 0.001)
        base = BaseMotion(t, np.full(t.size, -q * fp.lambda_lin * G))
        r = mechanism_response(lin, base, 0.9, tabulate=False, t_out_s=np.linspace(0, 4.0, 400001))
        k = int(np.argmax(r.phi_rad >= fp.theta_cr_rad))
        # Eq. 25 with kappa1 takes the ratio to lambda; here lambda = lambda_lin
        t25 = float(overturning_time_eq25(fp.p_rad_s, q, fp.lambda_lin, fp.lambda_lin))
        assert r.t_s[k] == pytest.approx(t25, abs=2e-5)


@pytest.mark.parametrize("gamma", [0.5, 2.0])
def test_fig15_symmetric_frame_and_block_identical_dimensionless(gamma):
    # DeJong Fig. 15: a block and a symmetric frame under pulses scaled by their own p and lambda
    # respond identically in phi/phi_cr against p t (Table I: the same equation)
    pos, neg = asymmetric_frame(0.15, 1.5, 1.5, 3.0, 0.2, 1.0, 2 * gamma, 1.0)
    fpf = pos.parameters()
    blk = block_mechanism(2.0, fpf.phi_cr_rad)  # another size, same slenderness
    fpb = blk.parameters()
    out = []
    for mech, negm, fp in ((pos, neg, fpf), (blk, None, fpb)):
        w, a = 8.0, 1.5  # omega_g / p, a_g / (g lambda): rocks without overturning
        t_p = 2 * math.pi / (w * fp.p_rad_s)
        base = pulse_motion("sine", t_p, a * G * fp.lambda_, pad_s=12 / fp.p_rad_s, dt_s=t_p / 400)
        r = mechanism_response(mech, base, 0.9, negm)
        tau = np.linspace(0, 20.0, 2001)
        x = np.interp(tau, r.t_s * fp.p_rad_s, r.phi_rad / fp.phi_cr_rad)
        out.append((x, r.impacts_t_s * fp.p_rad_s))
    (x1, i1), (x2, i2) = out
    assert np.nanmax(np.abs(x1)) > 0.3  # it rocks (peak 0.446 phi_cr, 10 impacts)
    assert np.nanmax(np.abs(x1 - x2)) < 1e-5
    assert i1.size == i2.size >= 5 and np.abs(i1 - i2).max() < 1e-6  # measured 2e-7


def test_mirrored_linkage_is_smooth():
    # the negative direction of a frame is its mirror image, whose beam points along -x at rest:
    # its rotation must not jump by 2 pi between neighbouring phi (dM/dphi was 3.6e13 there)
    pos, neg = asymmetric_frame(0.15, 1.5, 1.5, 3.0, 0.2, 1.0, 1.0, 1.0)
    for m in (pos, neg):
        dM = np.array([m.eom(f)[1] for f in np.linspace(0.0, 0.01, 41)])
        assert np.abs(dM).max() < 1e-4
    assert pos.parameters().lambda_ == pytest.approx(neg.parameters().lambda_, rel=1e-6)


def test_asymmetric_frame_history_models_agree_before_divergence():
    # a strongly asymmetric frame under a pulse: the nonlinear mechanism and both equivalent blocks
    # start rocking in the same direction and their first impact times agree within 5 %
    pos, neg = asymmetric_frame(0.15, 1.5, 1.2, 3.0, 0.2, 1.0, 1.0, 1.0)
    fp = pos.parameters()
    t_p = 2 * math.pi / (8.0 * fp.p_rad_s)
    base = pulse_motion("sine", t_p, 1.5 * G * fp.lambda_, pad_s=12 / fp.p_rad_s, dt_s=t_p / 300)
    h = mechanism_time_histories(pos, base, eta=0.9, negative=neg)
    assert set(h) == {"nonlinear", "linear", "block"}
    first = {k: r.impacts_t_s[0] for k, r in h.items()}
    signs = {k: np.sign(r.phi_rad[np.flatnonzero(np.abs(r.phi_rad) > 1e-6)[0]]) for k, r in h.items()}
    assert len(set(signs.values())) == 1
    assert max(first.values()) / min(first.values()) < 1.05
    # the uplift accelerations differ by direction (asymmetric)
    lp, ln = h["nonlinear"].meta["uplift_over_g"]
    assert lp != pytest.approx(ln, rel=1e-3)
    df = h["linear"].to_frame()
    assert list(df.columns) == ["t_s", "phi_rad", "phi_dot_rad_s", "phi_over_phi_cr"]


def test_record_ending_past_critical_is_falling_not_ok():
    # a pulse that throws the block past alpha, the record ending before it falls: "falling" (it
    # was "ok" with phi = -0.293 rad > alpha = 0.2 rad at the end)
    mech = block_mechanism(1.0, 0.2, eta=0.9)
    fp = mech.parameters()
    t_p = 2 * math.pi / (5.0 * fp.p_rad_s)
    base = pulse_motion("sine", t_p, 3.0 * G * fp.lambda_, pad_s=0.05, dt_s=t_p / 200)
    r = mechanism_response(mech, base, 0.9)
    assert r.status == "falling" and "falls" in r.message
    assert abs(r.phi_rad[-1]) > fp.phi_cr_rad
    longer = pulse_motion("sine", t_p, 3.0 * G * fp.lambda_, pad_s=10.0, dt_s=t_p / 200)
    assert mechanism_response(mech, longer, 0.9).status == "overturned"


def test_equivalent_block_round_trip_and_mechanisms():
    blk = Block(0.3, 1.5)
    eq = equivalent_block(block_parameters(blk.R_m, blk.alpha_rad), match="kappa1")
    assert (eq.b_m, eq.h_m) == pytest.approx((0.3, 1.5), rel=1e-12)
    pos, _ = asymmetric_frame(0.15, 1.5, 1.2, 3.0, 0.2, 1.0, 1.0, 1.0)
    fp = pos.parameters()
    eq = equivalent_block(fp)  # same p, and the exact uplift the design check uses (g tan alpha)
    assert eq.p_rad_s == pytest.approx(fp.p_rad_s, rel=1e-12)
    assert eq.uplift_acc_m_s2 == pytest.approx(G * fp.lambda_, rel=1e-12)
    assert equivalent_block(fp, "kappa2").alpha_rad == pytest.approx(fp.theta_cr_kappa2_rad, rel=1e-12)


def test_conical_shell_inertia_by_quadrature():
    # a thin uniform conical shell rocking on its base rim: centroid, R and I_O from the surface itself
    H, r = 10.0, 2.0
    z = (np.arange(4000) + 0.5) / 4000 * H
    ph = (np.arange(720) + 0.5) / 720 * 2 * np.pi
    Z, P = np.meshgrid(z, ph, indexing="ij")
    rho = r * (1 - Z / H)
    w = rho  # surface element ~ rho dz dphi (the slant factor is constant)
    x = rho * np.cos(P)
    zc = (w * Z).sum() / w.sum()
    I_O = (w * ((x - r) ** 2 + Z**2)).sum() / w.sum()  # per unit mass, about the rim tangent at (r, 0, 0)
    R, a, aI = conical_shell_geometry(H, r)
    assert zc == pytest.approx(H / 3, rel=1e-6)
    assert R == pytest.approx(math.hypot(r, zc), rel=1e-6)
    assert aI * R * R == pytest.approx(I_O, rel=1e-5)
    fp = conical_shell_parameters(H, r)
    assert fp.lambda_ == pytest.approx(3 * r / H) and fp.p_rad_s == pytest.approx(math.sqrt(G / (aI * R)))


def test_bad_inputs():
    base = pulse_motion("sine", 0.5, 5.0)
    with pytest.raises(InputError, match="no restitution"):
        mechanism_time_histories(wall_mechanism(1.0, 0.1), base)
    with pytest.raises(InputError, match="restitution must be"):
        mechanism_response(block_mechanism(1.0, 0.2), base, 1.5)
    with pytest.raises(InputError, match="kappa"):
        equivalent_block_mechanism(block_parameters(1.0, 0.2), True, kappa="k3")


def test_cli_equivalent_time_history(run_cli, tmp_path):
    rec = tmp_path / "pulse.csv"
    base = pulse_motion("sine", 1.0, 0.4 * G, pad_s=4.0, dt_s=0.005)
    pd.DataFrame({"t_s": base.t_s, "acc_m_s2": base.acc_m_s2}).to_csv(rec, index=False)
    rc, out, err = run_cli("equivalent", "wall", "--R", "1", "--alpha", "0.12", "--base-motion", rec)
    assert rc == 2 and "no restitution known" in err
    csv = tmp_path / "h.csv"
    args = ("equivalent", "wall", "--R", "1", "--alpha", "0.12", "--eta", "0.85", "--base-motion", rec, "-o", csv)
    rc, out, err = run_cli(*args)
    assert rc == 0, err
    df = pd.read_csv(csv)
    assert list(df.columns) == ["t_s", "phi_nonlinear_rad", "phi_linear_rad", "phi_block_rad"]
    assert np.nanmax(np.abs(df["phi_nonlinear_rad"])) > 0.01  # 0.4 g > lambda = 2 tan(0.12) = 0.24
    assert "impacts" in out
    rc, out, err = run_cli("equivalent", "wall", "--R", "1", "--alpha", "0.12", "--eta", "0.8")
    assert rc == 2 and "--base-motion" in err
    rc, out, err = run_cli("equivalent", "wall", "--R", "1", "--alpha", "0.12")
    assert rc == 0 and "eta = none (give --eta)" in out and "nan" not in out
    rc, out, err = run_cli(
        "equivalent", "cone", "--H", "10", "--base-radius", "2", "--pulse", "half-sine,0.8g,0.5", "--json"
    )
    assert rc == 0, err
    import json

    d = json.loads(out)
    assert d["lambda"] == pytest.approx(0.6) and d["equivalent_block"]["b_m"] > 0
    # the cone is Table I's block: its nonlinear history and its nonlinear equivalent block agree
    h = d["time_history"]["models"]
    assert h["nonlinear"]["n_impacts"] == h["block"]["n_impacts"]
