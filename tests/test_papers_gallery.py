"""The papers' gallery (``rocklab papers``): every figure has a row; regenerated ones match the papers."""

import json
import re

import pytest

import numpy as np
import pandas as pd
from scipy.optimize import brentq

from rocklab.blocks import Block
from rocklab.models import eta_axes, eta_bumps
from rocklab.models.spectra import normalised_critical_impulse
from rocklab.pipelines.papers import ENTRIES, regenerate


def test_every_figure_and_table_has_one_row():
    keys = [e.key for e in ENTRIES]
    assert len(keys) == len(set(keys))
    expected = {"ceh2018": (23, 5), "ther": (59, 5), "dejong2014": (15, 1)}
    for paper, (n_fig, n_tab) in expected.items():
        figs = {int(re.search(r"Fig\. (\d+)", k).group(1)) for k in keys if k.startswith(paper + ":Fig.")}
        tabs = {int(re.search(r"Table (\d+)", k).group(1)) for k in keys if k.startswith(paper + ":Table")}
        assert figs == set(range(1, n_fig + 1)), paper
        assert tabs == set(range(1, n_tab + 1)), paper
    # a row is regenerated or says why not: never silently empty
    assert all((e.build is not None) != bool(e.why_not) for e in ENTRIES)
    assert sum(e.build is not None for e in ENTRIES) >= 49
    assert not [e.key for e in ENTRIES if "open" in e.why_not]  # every row regenerated or says the true reason


def _run(tmp_path, only, records=None):
    res = regenerate(ENTRIES, tmp_path, records=records, only=only)
    numbers = json.loads((tmp_path / "numbers.json").read_text())
    return res, numbers


def test_thesis_fig29_two_block_release_events(tmp_path):
    res, numbers = _run(tmp_path, "ther:Fig. 29")
    row = next(r for r in res.rows if r["key"] == "ther:Fig. 29")
    assert row["status"] == "regenerated" and (tmp_path / row["png"]).exists() and (tmp_path / row["csv"]).exists()
    for q in numbers["ther:Fig. 29"].values():
        assert abs(q["rocklab"] - q["paper"]) <= 0.01 and q["unit"] == "s"  # measured 0.005, 0.0032, 0.0001
    index = (tmp_path / "index.md").read_text()
    assert index.count("\n| ") >= len(ENTRIES)  # every row listed, run or not
    assert "not run (--only)" in index


def test_dejong_fig15_block_and_frame_identical(tmp_path):
    _, numbers = _run(tmp_path, "dejong2014:Fig. 15")
    assert numbers["dejong2014:Fig. 15"]["max_dimensionless_difference"]["rocklab"] < 1e-5  # measured 1.8e-7


def test_dejong_arch_kappa2_improves_on_kappa1(tmp_path):
    # DeJong §5.2.3: "Use of kappa2 causes a remarkable improvement, reducing the error considerably"
    _, numbers = _run(tmp_path, "dejong2014:Fig. 12,dejong2014:Fig. 13,dejong2014:Fig. 10")
    assert numbers["dejong2014:Fig. 13"]["kappa2_better_than_kappa1"]["rocklab"] is True
    e1 = numbers["dejong2014:Fig. 12"]["mean_abs_error"]["rocklab"]
    e2 = numbers["dejong2014:Fig. 13"]["mean_abs_error"]["rocklab"]
    assert e2 < 0.5 * e1  # measured 0.049 against 0.247
    f10 = numbers["dejong2014:Fig. 10"]
    assert f10["lambda_falls_with_beta"]["rocklab"] and f10["lambda_rises_with_thickness"]["rocklab"]


def test_ceh_table5_and_eq19(tmp_path):
    _, numbers = _run(tmp_path, "ceh2018")
    t5 = numbers["ceh2018:Table 5"]
    assert t5["max_k_difference_except_B2M"]["rocklab"] <= 1.01e-4
    assert abs(t5["B2M_k"]["rocklab"] - 0.8006) <= 1e-4  # the printed 0.8805 is a misprint
    for q in numbers["ceh2018:Fig. 22"].values():
        assert q["rocklab"] == q["paper"]


def test_thesis_fig14_needs_records_then_matches(tmp_path, shared_data):
    res, _ = _run(tmp_path / "a", "ther:Fig. 14")
    row = next(r for r in res.rows if r["key"] == "ther:Fig. 14")
    assert row["status"] == "not regenerated" and "--records" in row["note"]
    res, numbers = _run(tmp_path / "b", "ther:Fig. 14", records=shared_data / "records")
    n = numbers["ther:Fig. 14"]
    assert n["housner_peak_over_alpha"]["rocklab"] == pytest.approx(0.80, rel=0.05)  # "about 80 percent"
    assert n["bump_overturn_t_s"]["rocklab"] == pytest.approx(11.0, rel=0.05)  # "at about 11 s"


def test_thesis_record_figures(tmp_path, shared_data):
    _, numbers = _run(tmp_path, "ther:Fig. 52,ther:Fig. 55,ther:Fig. 53,ther:Fig. 47", records=shared_data / "records")
    assert -1 <= numbers["ther:Fig. 53"]["r"]["rocklab"] <= 1
    # Fig. 47: t_I of the characteristic OAS is i_cr over the leftmost point of its transform (Eq. 20)
    char = pd.read_csv(tmp_path / "ther_fig47.csv")
    f_min = (char.level * char.p_min_rad_s).min()
    assert char.f_rad_s.min() == pytest.approx(f_min, rel=1e-12)
    t_I = numbers["ther:Fig. 47"]["t_I_s"]["rocklab"]
    assert t_I == pytest.approx(normalised_critical_impulse(np.arctan(1 / 12)) / f_min, rel=1e-12)
    assert 0.1 < t_I < 1.0  # the records' own t_I lie between 0.2 and 0.5 s
    assert numbers["ther:Fig. 52"]["t_p_s"]["rocklab"] == pytest.approx(0.405, abs=0.0005)  # Table 4: 0.405 s
    n55 = numbers["ther:Fig. 55"]
    assert n55["t_I_s"]["paper"] == 0.27  # Fig. 55's own printed value, not Table 4's 0.266
    # FF-1's t_I is 26 % above the print, a confirmed boundary point (docs/discrepancies.md)
    assert n55["t_I_s"]["rocklab"] == pytest.approx(0.336, abs=0.005)


def test_more_figures_state_what_the_papers_state(tmp_path):
    keys = "ceh2018:Table 4,ceh2018:Fig. 21,ther:Fig. 9,ther:Fig. 35,ther:Fig. 40"
    _, numbers = _run(tmp_path, keys)
    for q in numbers["ceh2018:Table 4"].values():  # k1 = 1 - 2 l_c/b, k2 = 1 - l_c/b: every printed value
        assert q["rocklab"] == pytest.approx(q["paper"], abs=1e-12)
    f21 = numbers["ceh2018:Fig. 21"]  # a constant k models the largest scale best
    assert f21["rms_L"]["rocklab"] < 0.5 * min(f21["rms_S"]["rocklab"], f21["rms_M"]["rocklab"])
    for q in numbers["ther:Fig. 9"].values():  # a short pulse overturns above the critical impulse only
        assert q["rocklab"] == q["paper"]
    r = [q["rocklab"] for q in numbers["ther:Fig. 35"].values()]  # the OAS of a pulse scales with t_p
    assert max(r) == pytest.approx(min(r), rel=0.01)
    assert numbers["ther:Fig. 40"]["single_block_most_vulnerable"]["rocklab"] is True


def test_cli_papers(run_cli, tmp_path):
    rc, out, err = run_cli("papers", "--out", tmp_path / "g", "--only", "ther:Fig. 4", "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["n_rows"] == len(ENTRIES) and d["n_regenerated"] == 1 and d["failed"] == []
    rc, out, err = run_cli("papers", "--out", tmp_path / "h", "--records", tmp_path / "nowhere")
    assert rc == 2 and "not a folder" in err


def test_ceh_table1_and_fig5(tmp_path):
    _, numbers = _run(tmp_path, "ceh2018:Table 1,ceh2018:Fig. 5")
    for q in numbers["ceh2018:Table 1"].values():  # alpha, R, eta_H rounded as printed, and "rocking"
        assert q["rocklab"] == q["paper"]
    for q in numbers["ceh2018:Fig. 5"].values():  # the simulated omega jumps are eta_H's (0.9294, 0.5385)
        assert q["rocklab"] == pytest.approx(q["paper"], abs=5e-5)


def test_thesis_tables2_3_agree_through_the_implied_widths():
    # Fig. 23 (the blocks' widths) is not held; Table 2's printed cut-corner losses (5 mm cuts, Eq. A3)
    # fix b, and with it rocklab's laws give Table 3's printed model losses: config b (one middle
    # bump, Eq. A7) within 0.1 point, c (wires 7 mm in) and d (c and a middle wire) within 0.8: c's
    # 27.3 % against the printed 26.5 % (h/b 2.79) and 17.0 % against 17.2 % (h/b 3.70) are the
    # largest gaps, of opposite sign, so no single width explains them (docs/discrepancies.md)
    from rocklab.pipelines.papers._ther import TABLE23_IMPLIED_B_MM

    def loss(eta):
        return 1 - eta**2

    printed = {2.79: (0.284, 0.148, 0.265, 0.138), 3.70: (0.177, 0.090, 0.172, 0.086)}
    for (hb, (a, b_, c, d)), b_mm in zip(printed.items(), TABLE23_IMPLIED_B_MM):
        b = brentq(lambda w: loss(eta_axes(Block(w, hb * w), 0.005 - w / 2, w / 2 - 0.005)) - a, 0.02, 2.0)
        assert b * 1e3 == pytest.approx(b_mm, abs=0.1)  # the row's text quotes these
        blk = Block(b, hb * b)
        assert loss(eta_bumps(blk, 1, b / 2 - 0.005)) == pytest.approx(b_, abs=0.001)
        assert loss(eta_axes(blk, 0.007 - b / 2, b / 2 - 0.007)) == pytest.approx(c, abs=0.008)
        assert loss(eta_bumps(blk, 1, b / 2 - 0.007)) == pytest.approx(d, abs=0.005)
