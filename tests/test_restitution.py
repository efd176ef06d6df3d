"""Restitution laws: paper values, identities between laws, limits."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rocklab import Block, InputError
from rocklab.models import RESTITUTION_LAWS, Restitution, make_restitution
from rocklab.models import eta_axes, eta_bumps, eta_housner, eta_modified


def test_ceh_table1_housner():
    # Čeh Table 1: B1N (0.03 x 0.135) and B2N (0.03 x 0.045)
    assert make_restitution("housner", Block(0.03, 0.135)).eta == pytest.approx(0.9294, abs=5e-5)
    assert make_restitution("housner", Block(0.03, 0.045)).eta == pytest.approx(0.5385, abs=5e-5)


@pytest.mark.parametrize("hb", [0.8, 1.5, 4.5, 10.0])
def test_modified_k1_is_housner_and_k0_is_lossless(hb):
    b = Block(0.1, 0.1 * hb)
    assert make_restitution("modified", b, k=1.0).eta == pytest.approx(b.eta_H, rel=1e-14)
    assert make_restitution("modified", b, k=0.0).eta == 1.0
    # Čeh Eq. 14 literally (uniform prism)
    s2 = math.sin(b.alpha_rad) ** 2
    k = 0.7
    assert eta_modified(b.alpha_rad, k) == pytest.approx((4 - 3 * s2 * (1 + k * k)) / (4 - 3 * s2 * (1 - k * k)))


def test_thesis_B8_two_interface_single_block_is_housner():
    # thesis App. B, Eq. B7-B8 with half sizes h, b: Theta1/Theta0 = (1 - (b/h)^2/2) / (1 + (b/h)^2)
    for h, b in [(0.1, 0.02), (0.5, 0.25), (0.2, 0.19)]:
        th0 = 4 / 3 * (h * h + b * b)
        th1 = 4 / 3 * (h * h - 0.5 * b * b)
        blk = Block(2 * b, 2 * h)
        assert th1 / th0 == pytest.approx(blk.eta_H, rel=1e-13)
        assert th1 / th0 == pytest.approx((1 - 0.5 * (b / h) ** 2) / (1 + (b / h) ** 2), rel=1e-13)
        # thesis Eq. 1 as printed: (2h^2 - b^2) / (2h^2 + 2b^2)
        assert eta_housner(blk.alpha_rad) == pytest.approx((2 * h * h - b * b) / (2 * h * h + 2 * b * b))


def test_thesis_A3_A4_axes_and_cut_corner():
    h, b, b2 = 0.3, 0.06, 0.05  # half sizes, m (thesis notation)
    blk = Block(2 * b, 2 * h)
    mu = lambda x1, x2: (2 * h * h + 0.5 * b * b + 1.5 * x1 * x2) / (2 * h * h + 0.5 * b * b + 1.5 * x2 * x2)
    assert eta_axes(blk, -b, b) == pytest.approx(blk.eta_H, rel=1e-13)  # "Eqs. (1) and (A3) identical"
    assert eta_axes(blk, -0.01, 0.04) == pytest.approx(mu(-0.01, 0.04), rel=1e-13)
    r = make_restitution("cut_corner", blk, b2_m=b2)
    assert r.eta == pytest.approx(mu(-b2, b2), rel=1e-13)  # Eq. A4
    assert r.eta > blk.eta_H


def test_thesis_A7_A8_one_bump_and_n_bumps():
    h, b = 0.3, 0.06
    blk = Block(2 * b, 2 * h)
    a8 = (2 * h * h + 0.5 * b * b) / (2 * h * h + 2 * b * b)
    assert make_restitution("bumps", blk, n=1).eta == pytest.approx(a8, rel=1e-13)  # Eq. A8
    b2 = 0.04
    a7 = (2 * h * h + 0.5 * b * b) / (2 * h * h + 0.5 * b * b + 1.5 * b2 * b2)
    assert eta_bumps(blk, 1, b2) == pytest.approx(a7, rel=1e-13)  # Eq. A7
    assert eta_bumps(blk, 0) == pytest.approx(blk.eta_H, rel=1e-13)  # no bump: Housner
    etas = np.array([eta_bumps(blk, n) for n in (1, 2, 5, 20, 100, 1000, 10000)])
    assert np.all(np.diff(etas) > 0)  # more bumps, less loss
    # n -> inf: no loss; the deficit decays like 1/n (each step loses O(1/n^2))
    assert 1 - etas[-1] < 1e-3 * (1 - etas[0]) * 1.5
    assert (1 - etas[-1]) * 10000 == pytest.approx((1 - etas[-2]) * 1000, rel=0.01)


def test_general_alpha_I_housner():
    blk = Block.general(0.2, 0.25, alpha_I=1.0)  # mass at the centre of mass
    assert make_restitution("housner", blk).eta == pytest.approx(1 - 2 * math.sin(0.25) ** 2)
    assert eta_axes(blk, -blk.R_m * math.sin(0.25), blk.R_m * math.sin(0.25)) == pytest.approx(blk.eta_H)


def test_registry_and_objects():
    assert set(RESTITUTION_LAWS) >= {"housner", "modified", "constant", "bumps", "cut_corner", "axes", "per_impact"}
    blk = Block(0.1, 0.4)
    r = make_restitution(0.9, blk)
    assert isinstance(r, Restitution) and r.eta == 0.9 and r(1.0, 5) == 0.9
    t = make_restitution("per_impact", blk, func=lambda i: 0.9 - 0.01 * i, n_table=10)
    assert t(0.0, 3) == pytest.approx(0.87) and t(0.0, 50) == pytest.approx(0.81)
    v = make_restitution("per_impact", blk, func=lambda w: 0.9 + 0.01 * w, by="omega", omega_max_rad_s=4.0)
    assert v(2.0) == pytest.approx(0.92, abs=1e-12)


@pytest.mark.parametrize(
    "law,kw",
    [
        ("constant", {"eta": 1.2}),
        ("bumps", {"n": -1}),
        ("bumps", {"n": 1.5}),
        ("modified", {"k": "x"}),
        ("per_impact", {}),
        ("per_impact", {"eta": [0.9, 0.8], "omega_rad_s": [1.0, 0.5]}),
    ],
)
def test_bad_law_parameters(law, kw):
    with pytest.raises(InputError):
        make_restitution(law, Block(0.1, 0.4), **kw)
