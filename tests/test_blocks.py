import math

import pytest

from rocklab import Block, G, InputError


def test_ceh_table1_housner_restitution():
    # Čeh Table 1: B1N (0.03 x 0.135) and B2N (0.03 x 0.045)
    b1 = Block(0.03, 0.135)
    b2 = Block(0.03, 0.045)
    assert b1.alpha_rad == pytest.approx(0.2187, abs=5e-5)
    assert b1.R_m == pytest.approx(0.0691, abs=5e-5)
    assert b1.eta_H == pytest.approx(0.9294, abs=5e-5)
    assert b2.alpha_rad == pytest.approx(0.5880, abs=5e-5)
    assert b2.eta_H == pytest.approx(0.5385, abs=5e-5)


def test_prism_frequency_parameter_closed_form():
    b = Block(0.045, 0.2025, mass_kg=1.0896)
    assert b.p_rad_s == pytest.approx(math.sqrt(3 * G / (4 * b.R_m)), rel=1e-12)
    # p = sqrt(m g R / I_O) with I_O = 4/3 m R^2
    assert b.p_rad_s == pytest.approx(math.sqrt(b.mass_kg * G * b.R_m / b.I_O_kg_m2), rel=1e-12)
    assert b.uplift_acc_m_s2 == pytest.approx(G * 0.045 / 0.2025, rel=1e-12)


def test_general_body_point_mass():
    # all mass at the centre of mass: I_O = m R^2 -> p = sqrt(g/R), eta = 1 - 2 sin^2 alpha
    b = Block.general(R_m=2.0, alpha_rad=0.1, alpha_I=1.0)
    assert b.p_rad_s == pytest.approx(math.sqrt(G / 2.0))
    assert b.eta_H == pytest.approx(1 - 2 * math.sin(0.1) ** 2)
    assert b.alpha_rad == pytest.approx(0.1)


def test_mass_from_density():
    b = Block(0.1, 0.2, depth_m=0.05, density_kg_m3=2700)
    assert b.mass_kg == pytest.approx(2700 * 0.1 * 0.2 * 0.05)


def test_stocky_block_bounces_back():
    assert Block(0.1, 0.05).eta_H < 0  # h/b < 1/sqrt(2)
    assert Block(0.1, 0.0707).eta_H < 0 < Block(0.1, 0.0708).eta_H


@pytest.mark.parametrize(
    "kw",
    [
        dict(b_m=0, h_m=1),
        dict(b_m=-0.1, h_m=1),
        dict(b_m=0.1, h_m=float("nan")),
        dict(b_m=0.1, h_m=1, mass_kg=-1),
        dict(b_m=0.1, h_m=1, alpha_I=0.5),
    ],
)
def test_invalid_geometry(kw):
    with pytest.raises(InputError) as e:
        Block(**kw)
    assert "\n" not in str(e.value)
