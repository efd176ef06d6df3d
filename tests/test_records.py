import numpy as np
import pytest

from rocklab import G, InputError
from rocklab.series import BaseMotion
from rocklab.models import load_base_motion


def test_at2_nga_west2(shared_data):
    r = load_base_motion(shared_data / "records/RSN6_IMPVALL.I_I-ELC180.AT2")
    assert r.t_s.size == 5372 and r.dt_s == pytest.approx(0.01)
    assert r.acc_m_s2[0] == pytest.approx(0.9984852e-3 * G)


def test_at2_old_style_same_event(shared_data):
    r = load_base_motion(shared_data / "records/elCentro.AT2")
    assert r.t_s.size == 1559 and r.dt_s == pytest.approx(0.02)
    assert r.acc_m_s2[0] == pytest.approx(0.00630 * G)
    # El Centro NS 1940 PGA is about 0.32 g (Peknold version 0.319 g)
    assert r.pga_m_s2 / G == pytest.approx(0.319, abs=0.01)


def test_two_column_needs_units_and_matches(shared_data):
    p = shared_data / "records/fema-p695-far-field/SortedEQFile_120111.txt"
    with pytest.raises(InputError, match="units"):
        load_base_motion(p)
    r = load_base_motion(p, units="g")
    assert r.dt_s == pytest.approx(0.01) and r.t_s.size == 3000
    rc = load_base_motion(p, units="cm/s2")
    assert rc.pga_m_s2 == pytest.approx(r.pga_m_s2 / G / 100)


def test_scale_and_interp():
    r = BaseMotion.from_samples([0, 1, -2, 0.5], 0.1, units="m/s2")
    assert r.scaled_to_pga(0.3, "g").pga_m_s2 == pytest.approx(0.3 * G)
    assert r.at([0.05, 0.15, 1.0]) == pytest.approx([0.5, -0.5, 0.0])
    rr = r.resample(0.05)
    assert rr.t_s.size == 7 and rr.acc_m_s2[3] == pytest.approx(-0.5)


def test_bad_records(tmp_path):
    p = tmp_path / "bad.AT2"
    p.write_text("x\ny\nz\nNPTS=   4, DT=   .0100 SEC,\n 1 2 3\n")
    with pytest.raises(InputError, match="NPTS=4 but the file holds 3"):
        load_base_motion(p)
    q = tmp_path / "nan.csv"
    q.write_text("t_s,acc_m_s2\n0,1\n0.1,nan\n")
    with pytest.raises(InputError, match="line 3"):
        load_base_motion(q)
    q.write_text("t_s,acc_m_s2\n0,1\n0.1,2\n0.1,3\n")
    with pytest.raises(InputError, match="line 4.*does not increase"):
        load_base_motion(q)
    with pytest.raises(InputError, match="unknown acceleration unit"):
        load_base_motion(tmp_path / "nan.csv", units="furlongs")
    with pytest.raises(InputError, match="non-uniform"):
        BaseMotion(np.array([0, 0.1, 0.3]), np.zeros(3))
    (tmp_path / "empty.txt").write_text("")
    with pytest.raises(InputError, match="empty"):
        load_base_motion(tmp_path / "empty.txt")


def test_bundled_elcentro_matches_shared_copy(shared_data):
    from rocklab.models import bundled_record

    a = bundled_record("elcentro")
    b = load_base_motion(shared_data / "records/RSN6_IMPVALL.I_I-ELC180.AT2")
    assert np.array_equal(a.acc_m_s2, b.acc_m_s2)
    # El Centro Array #9 180° (NGA-West2): PGA about 0.28 g
    assert a.pga_m_s2 / G == pytest.approx(0.28, abs=0.02)
    with pytest.raises(InputError, match="not bundled"):
        bundled_record("kobe")
