"""Fits that would be silently wrong now warn, cut what they cannot use, or fail."""

import math

import numpy as np
import pandas as pd
import pytest

from rocklab import Block
from rocklab._diagnostics import collecting
from rocklab.fitting import fit_eta_mat, fit_restitution, read_block_table
from rocklab.models import simulate

BLK = Block(0.1, 0.2)  # the synth session's block


def _track(eta=0.75, fps=50.0, seed=0, gap=None):
    th0 = 0.8 * BLK.alpha_rad
    r = simulate(BLK, th0, 0.0, 6.0, 1e-4, restitution="constant", eta=eta)
    t = np.arange(0, 6.0, 1 / fps)
    th = np.interp(t - 0.6, r.t_s, r.theta_rad, left=th0, right=0.0)
    th = th + np.random.default_rng(seed).normal(0, math.radians(0.02), t.size)
    if gap is not None:
        th[(t >= gap[0]) & (t < gap[1])] = np.nan
    return t, th


@pytest.mark.parametrize("drop", [None, 29, 30, 31, 100])
def test_a_dropped_frame_or_a_variable_rate_is_no_gap(drop):
    """One missing sample (a dropped video frame, here at and after the release at 0.6 s) cannot
    hide two impacts the sampling would resolve; nor can a phone's 14-26 ms frame intervals.
    The fit was cut there against "the shortest half-cycle (0 s)" and failed."""
    th0 = 0.8 * BLK.alpha_rad
    r = simulate(BLK, th0, 0.0, 6.0, 1e-4, restitution="constant", eta=0.8)
    if drop is None:
        steps = np.random.default_rng(1).integers(14, 27, 400) / 1000.0
        t = np.concatenate(([0.0], np.cumsum(steps)))
    else:
        t = np.delete(np.arange(0, 6.0, 1 / 50), drop)
    th = np.interp(t - 0.6, r.t_s, r.theta_rad, left=th0, right=0.0)
    th += np.random.default_rng(0).normal(0, math.radians(0.02), t.size)
    with collecting() as found:
        f = fit_restitution(t, th, BLK)
    assert found == [] and f.status == "ok" and f.eta_e == pytest.approx(0.8, abs=0.003)


def test_a_gap_before_the_second_impact_is_judged_by_the_half_cycle_after_it():
    t, th = _track(eta=0.8)
    # 4 samples lost right after the release: the first half-cycles last 0.26 s
    keep = (t < 0.62) | (t >= 0.7)
    with collecting() as found:
        f = fit_restitution(t[keep], th[keep], BLK)
    assert found == [] and f.eta_e == pytest.approx(0.8, abs=0.003)
    # 14 lost there could hide two impacts: cut, and too few impacts are left
    keep = (t < 0.62) | (t >= 0.9)
    with collecting() as found:
        f = fit_restitution(t[keep], th[keep], BLK)
    assert [d.code for d in found] == ["W-FIT-GAP"] and "half-cycle after it" in found[0].message
    assert f.status == "failed"


def test_occlusion_is_cut_not_miscounted():
    t, th = _track(eta=0.9)
    clean = fit_restitution(t, th, BLK)
    assert clean.status == "ok" and clean.eta_e == pytest.approx(0.9, abs=0.003)
    # 20 lost frames (0.4 s, impacts every 0.1-0.2 s there): counting half-cycles across the gap
    # gave a wrong eta_e with status ok; now the fit uses the data before the gap and says so
    t, th = _track(eta=0.9, gap=(1.9, 2.3))
    with collecting() as found:
        f = fit_restitution(t, th, BLK, nan="skip")
    assert [d.code for d in found] == ["W-FIT-GAP"] and f.status == "suspect" and "W-FIT-GAP" in f.warnings
    assert f.eta_e == pytest.approx(0.9, abs=0.005)
    # the same occlusion where too few impacts precede it: the fit fails rather than guess
    t, th = _track(eta=0.75, gap=(1.2, 1.6))
    with collecting() as found:
        f = fit_restitution(t, th, BLK, nan="skip")
    assert [d.code for d in found] == ["W-FIT-GAP"] and f.status == "failed"
    # two lost frames where a half-cycle lasts 0.34 s hide no impact: no warning, same answer
    t, th = _track(eta=0.9, gap=(1.0, 1.04))
    f = fit_restitution(t, th, BLK, nan="skip")  # filterwarnings=error: any warning fails here
    assert f.status == "ok" and f.eta_e == pytest.approx(0.9, abs=0.003)


def test_swapped_or_wrong_dimensions_are_not_silent():
    t, th = _track()
    # h 2.5x too large (alpha below the measured release angle): theta0 > alpha fails, naming b and h
    g = fit_restitution(t, th, Block(0.1, 0.2 * 2.5))
    assert g.status == "failed" and "check b and h" in g.message
    # theta0 just under alpha: a warning, not a silent fit
    th0 = 0.8 * BLK.alpha_rad
    blk = Block(0.1, 0.1 / math.tan(th0 / 0.95))
    assert 0.9 * blk.alpha_rad < th0 < blk.alpha_rad
    with collecting() as found:
        fit_restitution(t, th, blk)
    assert [d.code for d in found][:1] == ["W-FIT-THETA0"]  # (and the misfit: W-FIT-RESIDUAL)


def test_block_tables_in_cm_and_duplicates(tmp_path):
    p = tmp_path / "edge.csv"
    # widths in cm in a b_m column: 4.5 "m" wide, 0.2 m tall blocks (was eta_mat = -1.83, status ok)
    pd.DataFrame({"block": ["B3M", "B6M"], "b_m": [4.5, 4.5], "h_m": [0.1, 0.2], "eta_e": [0.85, 0.93]}).to_csv(
        p, index=False
    )
    with collecting() as found:
        res = fit_eta_mat(read_block_table(p))
    assert "W-FIT-UNITS" in [d.code for d in found]
    assert res.status == "failed" and "outside (0, 1]" in res.message
    q = tmp_path / "dup.csv"
    pd.DataFrame(
        {
            "block": ["B3M", "B3M", "B6M"],
            "b_m": [0.03, 0.03, 0.045],
            "h_m": [0.1, 0.1, 0.2025],
            "eta_e": [0.85, 0.85, 0.93],
        }
    ).to_csv(q, index=False)
    with collecting() as found:
        tab = read_block_table(q)
    assert [d.code for d in found] == ["W-FIT-DUPLICATE"] and len(tab) == 2 and "line 3" in found[0].message


def test_wrong_block_size_shows_in_the_residual():
    t, th = _track()
    # width and height swapped (was eta_e 0.67 for a true 0.75, status ok), or b twice the truth:
    # the fit converges but misses the measurement by 20x the noise floor (1e-3 rad)
    for blk in (Block(0.2, 0.1), Block(0.2, 0.2)):
        with collecting() as found:
            f = fit_restitution(t, th, blk)
        assert [d.code for d in found][0] == "W-FIT-RESIDUAL" and f.status == "suspect"
        assert f.rms_residual_rad > 20 * 1e-3
