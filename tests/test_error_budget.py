"""The input error budget of a base-excited run: each measured input's share of the model's spread."""

import numpy as np
import pytest

from rocklab import Block
from rocklab.fitting import BUDGET_SOURCES, InputUncertainty, error_budget


def _table():
    t = np.arange(0.0, 4.0, 0.005)
    a = 3.0 * np.sin(2 * np.pi * 1.5 * t) * (t < 2.0)
    return t, a


def _budget(unc, eta_sd=0.0):
    blk = Block(0.1, 0.4)
    t, a = _table()
    return error_budget(
        blk, t, a, np.arange(0.0, 4.0, 0.01), eta=0.9, eta_sd=eta_sd, theta0_rad=0.0, t_start_s=0.0, unc=unc, n=12
    )


def test_one_source_owns_the_whole_budget():
    b = _budget(InputUncertainty(0.05, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    assert set(b["sources"]) == set(BUDGET_SOURCES)
    assert b["sources"]["acc_noise_m_s2"]["share"] == pytest.approx(1.0)
    assert b["sources"]["acc_noise_m_s2"]["sd_rad"] > 0
    assert b["all_sd_rad"] == pytest.approx(b["sources"]["acc_noise_m_s2"]["sd_rad"], rel=1e-9)  # same draws


def test_a_larger_input_error_takes_a_larger_share():
    small = _budget(InputUncertainty(0.02, 0.02, 0.0, 0.0, 0.0, 0.0, 0.0))
    big = _budget(InputUncertainty(0.02, 0.2, 0.0, 0.0, 0.0, 0.0, 0.0))
    assert big["sources"]["acc_bias_m_s2"]["share"] > small["sources"]["acc_bias_m_s2"]["share"]
    shares = [d["share"] for d in big["sources"].values()]
    assert sum(shares) == pytest.approx(1.0)
    with_eta = _budget(InputUncertainty(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0), eta_sd=0.01)
    assert with_eta["sources"]["eta"]["share"] == pytest.approx(1.0)
