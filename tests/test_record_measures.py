"""Ground-motion measures by eqsig: closed forms on a sine, and the bundled record's published peaks."""

import math

import numpy as np
import pytest

from rocklab import G, InputError
from rocklab.series import BaseMotion
from rocklab.models import bundled_record
from rocklab.models.spectra import record_measures, response_spectrum


def _sine(A, f, T, dt=0.002):
    t = np.arange(0.0, T, dt)
    return BaseMotion(t, A * np.sin(2 * math.pi * f * t))


def test_sine_closed_forms():
    A, f, T = 2.0, 2.0, 5.0
    m = record_measures(_sine(A, f, T))
    assert m.pga_m_s2 == pytest.approx(A, rel=1e-3)
    # Arias: pi/(2g) * A^2 T / 2
    assert m.arias_m_s == pytest.approx(math.pi / (2 * G) * A * A * T / 2, rel=0.01)
    # a steady sine builds its energy uniformly: D5-95 = 0.9 T (to a quarter cycle)
    assert m.d5_95_s == pytest.approx(0.9 * T, abs=0.25 / f + 0.05)
    # a = A cos(wt) integrates to v = (A/w) sin(wt): PGV = A/w, and d = (A/w^2)(1 - cos wt): PGD = 2 A/w^2
    w = 2 * math.pi * f
    t = np.arange(0.0, T, 0.002)
    cos = BaseMotion(t, A * np.cos(w * t))
    raw = record_measures(cos, baseline_poly=-1)  # integrated as it is
    assert raw.pgv_m_s == pytest.approx(A / w, rel=0.005)
    assert raw.pgd_m == pytest.approx(2 * A / w**2, rel=0.01)
    # the default linear baseline moves a clean record's peaks by a few per cent at most (1.9 % here)
    assert record_measures(cos).pgv_m_s == pytest.approx(A / w, rel=0.03)
    for freq in (2.0, 0.5):  # the velocity pulse period of a steady sine is its period (grid 2.9 %)
        assert record_measures(_sine(A, freq, 10.0)).t_v_s == pytest.approx(1 / freq, rel=0.03)


def test_response_spectrum_limits():
    b = bundled_record("elcentro")
    Sa = response_spectrum(b, [0.005, 0.5, 20.0])
    assert Sa[0] == pytest.approx(b.pga_m_s2, rel=0.01)  # a rigid oscillator moves with the ground
    assert Sa[1] > 2 * b.pga_m_s2  # resonant amplification at 0.5 s (El Centro's plateau)
    assert Sa[2] < 0.2 * b.pga_m_s2  # a very soft oscillator barely accelerates
    with pytest.raises(InputError, match="periods"):
        response_spectrum(b, [0.0, 1.0])


def test_el_centro_peaks():
    # Imperial Valley 1940, El Centro 180 (RSN6): PGA 0.281 g and PGV about 31 cm/s (NGA-West2 flatfile)
    m = record_measures(bundled_record("elcentro"))
    assert m.pga_m_s2 / G == pytest.approx(0.281, abs=0.005)
    assert m.pgv_m_s == pytest.approx(0.31, abs=0.03)
    assert 20.0 < m.d5_95_s < 30.0


def test_cli_pulse_prints_measures(run_cli, shared_data):
    import json

    rc, out, err = run_cli("pulse", shared_data / "records" / "RSN68_SFERN_PEL090.AT2", "--json")
    assert rc == 0, err
    d = json.loads(out)["measures"]
    assert d["pga_m_s2"] == pytest.approx(2.2042, rel=1e-3) and d["arias_m_s"] > 0 and d["baseline_poly"] == 1
