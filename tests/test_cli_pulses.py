"""Pulses wherever a record goes (``--pulse KIND,PEAK,T_P[,N]``) and ``rocklab curve``."""

import json
import math

import numpy as np
import pandas as pd
import pytest

from rocklab import G, InputError
from rocklab.models import pulse_parameters
from rocklab.pipelines.cli._cli_base import pulse_from_spec


def test_pulse_spec_units_and_shape():
    b = pulse_from_spec("half-sine,0.3g,0.5")
    assert b.pga_m_s2 == pytest.approx(0.3 * G, rel=1e-3)
    # Eq. 25: the replacement lobe of a half sine is the half sine itself
    assert pulse_parameters(b).t_p_s == pytest.approx(0.5, rel=0.01)
    assert b.t_s[-1] == pytest.approx(1.0, abs=0.01)  # the pulse and one t_p of zeros
    s = pulse_from_spec("sine,2.94m/s2,0.25")
    assert s.pga_m_s2 == pytest.approx(2.94, rel=1e-3)
    assert s.t_s[-1] == pytest.approx(0.75, abs=0.01)  # two lobes and one t_p
    n3 = pulse_from_spec("n-half-sines,0.2g,0.3,3")
    lobes = np.diff(np.sign(n3.acc_m_s2[np.abs(n3.acc_m_s2) > 1e-9])) != 0
    assert int(lobes.sum()) == 2  # three alternating lobes
    for bad, msg in (
        ("half-sine,0.3,0.5", "no unit"),
        ("half-sine,0.3g", "fields"),
        ("half-sine,-0.3g,0.5", "> 0"),
        ("half-sine,x g,0.5", "numbers"),
        ("wobble,0.3g,0.5", "unknown"),
    ):
        with pytest.raises(InputError, match=msg):
            pulse_from_spec(bad)


def test_simulate_pulse_equals_the_same_pulse_as_a_record(run_cli, tmp_path):
    b = pulse_from_spec("half-sine,0.5g,0.3")
    rec = tmp_path / "p.csv"
    pd.DataFrame({"t_s": b.t_s, "acc_m_s2": b.acc_m_s2}).to_csv(rec, index=False)
    common = ("simulate", "--width", "0.2", "--height", "0.8", "--duration", "4", "--json")
    rc1, out1, err1 = run_cli(*common, "--pulse", "half-sine,0.5g,0.3")
    rc2, out2, err2 = run_cli(*common, "--base-motion", rec)
    assert rc1 == 0 and rc2 == 0, err1 + err2
    d1, d2 = json.loads(out1), json.loads(out2)
    assert d1["n_impacts"] == d2["n_impacts"] > 3
    assert d1["max_abs_theta_rad"] == pytest.approx(d2["max_abs_theta_rad"], rel=1e-6)
    rc, out, err = run_cli(*common, "--pulse", "half-sine,0.5g,0.3", "--base-motion", rec)
    assert rc == 2 and "--pulse replaces" in err


def test_oas_of_a_pulse(run_cli):
    args = ("oas", "--pulse", "half-sine,0.3g,0.5", "--slenderness", "5", "--levels", "20", "--sizes", "30")
    rc, out, err = run_cli(*args, "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["t_p_s"] == pytest.approx(0.5, rel=0.01)
    # a single half sine: its replacement impulse is a share of the lobe (measured 0.29 s)
    assert 0.2 < d["t_I_s"] < 0.5
    rc, out, err = run_cli("oas", "--pulse", "half-sine,0.3g,0.5", "--band")
    assert rc == 2 and "--pulse is one base motion" in err


def test_curve_cli(run_cli, tmp_path):
    out_csv = tmp_path / "c.csv"
    rc, out, err = run_cli(
        "curve", "--kind", "half-sine", "--slenderness", "5", "--ptp", "0.5,10,5", "--levels", "1,6,11",
        "-o", out_csv, "--json",
    )  # fmt: skip
    assert rc == 0, err
    d = json.loads(out)
    df = pd.read_csv(out_csv)
    a, imp, x = df["a_min_ratio"].to_numpy(), df["impulse_ratio"].to_numpy(), df["p_tp"].to_numpy()
    ok = np.isfinite(a)
    assert ok.sum() >= 4
    # the impulse curve is the amplitude curve times the half sine's fullness and p t_p (Eq. 16)
    assert imp[ok] == pytest.approx((2 / math.pi) * a[ok] * x[ok], rel=1e-9)
    # longer pulses need less amplitude, never below the static uplift level
    assert np.all(np.diff(a[ok]) < 0) and np.all(a[ok] >= 1.0)
    # short pulses approach the impulse limit i_cr from above
    assert imp[ok][0] > d["i_cr"] and imp[ok][0] < 1.5 * d["i_cr"]
    rc, out, err = run_cli("curve", "--ptp", "5,1,3")
    assert rc == 2 and "START < STOP" in err
