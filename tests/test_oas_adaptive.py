"""The adaptive OAS grid against a known verdict image and against the dense grid."""

from __future__ import annotations

import numpy as np
import pytest

from rocklab._errors import InputError
from rocklab.series import BaseMotion
from rocklab.models import load_base_motion, overturning_spectrum
from rocklab.models.spectra._oas_grid import adaptive_verdicts, boundary_verdicts

FF1 = "records/fema-p695-far-field/SortedEQFile_120111.txt"


def _image(n_rows=80, n_cols=120):
    """Safe large blocks (left), unsafe small ones (right), a staircase boundary with bays."""
    i, j = np.mgrid[:n_rows, :n_cols]
    edge = 90 - 0.5 * i + 4 * np.sin(i / 5.0)
    over = j >= edge
    over[40:52, 30:42] = True  # an unsafe island (12 x 12) far left of the boundary
    over[20:24, 95:99] = False  # a safe bay inside the unsafe region
    over[60, 50] = True  # a lone unsafe grid point 7 steps before row 60's boundary
    return over


def test_adaptive_grid_reproduces_a_known_image_with_fewer_runs():
    truth = _image()
    calls = []

    def run(r, c):
        calls.append(len(r))
        return truth[r, c]

    over, known = adaptive_verdicts(run, *truth.shape)
    assert np.array_equal(over, truth)
    # every point was simulated at most once, and far fewer than all of them
    assert sum(calls) == known.sum() < 0.45 * truth.size
    # the lone point is found by the frontier check, not by the refinement
    assert known[60, 50] and over[60, 50]


def test_lone_unsafe_point_beyond_the_frontier_is_missed_as_on_ff10():
    """FEMA FF-10 (SortedEQFile_120612) is the one record whose adaptive t_I (0.516 s) differs from the
    dense grid's (0.560 s): the dense t_I comes from one unsafe cell (a_p/a_p,min 1.68, R 6.53 m) 12
    sizes before its row's first unsafe size, inside a cell whose corners are all safe; it is
    chaotic (safe at 1 -/+ 1e-4 times the amplitude). The same pattern here: missed with the
    default frontier of 8, found with 12."""
    for row in (28, 35):
        truth = _image()
        first = int(np.argmax(truth[row]))
        truth[row, first - 12] = True
        over, known = adaptive_verdicts(lambda r, c: truth[r, c], *truth.shape)
        assert not known[row, first - 12] and not over[row, first - 12]
        assert np.count_nonzero(over != truth) == 1
        over, known = adaptive_verdicts(lambda r, c: truth[r, c], *truth.shape, frontier=12)
        assert np.array_equal(over, truth)


def test_adaptive_grid_uniform_image_only_coarse_points():
    calls = []

    def run(r, c):
        calls.append(len(r))
        return np.zeros(len(r), bool)

    over, known = adaptive_verdicts(run, 80, 120, coarse=8)
    assert not over.any()
    assert known.sum() == sum(calls) == 11 * 16  # rows 0, 8, ..., 72, 79; columns 0, 8, ..., 112, 119


def test_adaptive_oas_equals_dense_on_fema_ff1(shared_data):
    r = load_base_motion(shared_data / FF1, units="g")
    d = overturning_spectrum(r, 12, grid="dense")
    a = overturning_spectrum(r, 12)
    assert a.options["grid"] == "adaptive" and d.n_runs == d.overturned.size
    # chaotic bays make single verdicts hard to guess; the 44-record figure is 99.93 %
    assert np.mean(a.overturned == d.overturned) >= 0.998
    assert a.n_runs < 0.3 * d.n_runs
    # the boundary behind t_I comes from simulated points on both grids
    assert a.t_I_s == d.t_I_s and a.f_min_at == d.f_min_at
    assert np.array_equal(a.overturned[a.evaluated], d.overturned[a.evaluated])


def test_oas_grid_option_is_checked():
    m = BaseMotion.from_samples(np.sin(np.arange(400) * 0.05), 0.01)
    with pytest.raises(InputError, match="grid='sparse'"):
        overturning_spectrum(m, 12, grid="sparse")


def test_boundary_search_finds_each_rows_first_unsafe_point():
    truth = _image()
    first = truth.argmax(axis=1)
    calls = []

    def run(r, c):
        calls.append(len(r))
        return truth[r, c]

    # a guess 3 columns off either way, as a neighbouring grid's boundary would be
    guess = first + np.where(np.arange(truth.shape[0]) % 2, 3, -3)
    over, known = boundary_verdicts(run, *truth.shape, guess)
    assert np.array_equal(over.argmax(axis=1), first)
    assert known[np.arange(truth.shape[0]), first].all()
    assert sum(calls) == known.sum() < 0.2 * truth.size
    # a guess of "no unsafe point" walks from the smallest blocks leftwards to the boundary;
    # the island 18+ columns before it (rows 40-51) is out of the search's reach
    over, _ = boundary_verdicts(run, *truth.shape, np.full(truth.shape[0], truth.shape[1]))
    rows = np.r_[0:40, 52:80]
    assert np.array_equal(over.argmax(axis=1)[rows], first[rows])
    assert (over.argmax(axis=1)[40:52] > first[40:52] + 8).all()


def test_boundary_grid_gives_the_adaptive_grids_t_I(shared_data):
    r = load_base_motion(shared_data / FF1, units="g")
    guide = overturning_spectrum(r, 12)
    full = overturning_spectrum(r, 12, level_offset=0.5)
    fast = overturning_spectrum(r, 12, level_offset=0.5, grid="boundary", guide=guide)
    assert fast.t_I_s == full.t_I_s and fast.t_I_prime_s == full.t_I_prime_s and fast.beta == full.beta
    assert fast.n_runs < 0.7 * full.n_runs
    with pytest.raises(InputError, match="guide"):
        overturning_spectrum(r, 12, grid="boundary")


def test_boundary_search_by_key_finds_the_smallest_key_with_fewer_runs():
    truth = _image()
    first = truth.argmax(axis=1)
    n_rows, n_cols = truth.shape
    # key = level x p, as f = A p: the smallest key sits at one row of the staircase
    key = np.linspace(1.0, 10.0, n_rows)[:, None] * 1.04 ** np.arange(n_cols)[None, :]
    runs = {"all": 0, "key": 0}

    def counted(name):
        def run(r, c):
            runs[name] += len(r)
            return truth[r, c]

        return run

    for shift in (-3, 2):  # the guess a few columns off, both ways
        guess = first + shift
        full, _ = boundary_verdicts(counted("all"), n_rows, n_cols, guess)
        fast, known = boundary_verdicts(counted("key"), n_rows, n_cols, guess, key=key)
        f_full = key[np.arange(n_rows), full.argmax(axis=1)]
        has = fast.any(axis=1)
        f_fast = key[np.flatnonzero(has), fast[has].argmax(axis=1)]
        assert f_fast.min() == f_full.min() == key[np.arange(n_rows), first].min()
        # rows searched hold their true first unsafe point; the others are left without a boundary
        assert np.array_equal(fast[has].argmax(axis=1), first[has]) and not has.all()
    assert runs["key"] < 0.5 * runs["all"]
    # a key whose minimum lies at the last rows (larger levels cheaper) is found there too
    key2 = key[::-1]
    fast, _ = boundary_verdicts(counted("key"), n_rows, n_cols, first - 3, key=key2)
    has = fast.any(axis=1)
    assert key2[np.flatnonzero(has), fast[has].argmax(axis=1)].min() == key2[np.arange(n_rows), first].min()


def _count_batch_runs(monkeypatch):
    """Count the runs the OAS hands its batch kernel from now on: ``n["runs"]``."""
    import rocklab.models.spectra._oas as oas

    n = {"runs": 0}
    real = oas.batch_runs

    def counted(base, scale, p, args):
        n["runs"] += np.size(scale)
        return real(base, scale, p, args)

    monkeypatch.setattr(oas, "batch_runs", counted)
    return n


def test_bisecting_only_the_levels_behind_t_I_and_the_line_changes_neither(shared_data, monkeypatch):
    r = load_base_motion(shared_data / FF1, units="g")
    kw = dict(levels=30, sizes=45, refine=8)
    n = _count_batch_runs(monkeypatch)
    full = overturning_spectrum(r, 12, refine_where="all", **kw)
    runs_full, n["runs"] = n["runs"], 0
    fit = overturning_spectrum(r, 12, refine_where="fit", verdicts=full, **kw)
    runs_fit, n["runs"] = n["runs"], 0
    only = overturning_spectrum(r, 12, refine_where="t_I", verdicts=full, **kw)
    runs_only = n["runs"]
    assert fit.t_I_s == full.t_I_s and only.t_I_s == full.t_I_s
    assert fit.t_I_prime_s == pytest.approx(full.t_I_prime_s, rel=1e-12)
    assert fit.beta == pytest.approx(full.beta, rel=1e-12)
    assert np.isnan(only.t_I_prime_s) and np.isnan(only.beta)
    # the bisection alone: every level with a boundary x 8 steps, against a few levels
    n_levels = int(np.isfinite(full.p_min_rad_s).sum())
    assert runs_only < runs_fit < 0.5 * 8 * n_levels < runs_full
    with pytest.raises(InputError, match="refine_where"):
        overturning_spectrum(r, 12, refine_where="some", **kw)


def test_default_bisects_every_level_to_the_curve_resolution_and_t_I_and_the_line_in_full(shared_data, monkeypatch):
    import rocklab.models.spectra._oas as oas

    r = load_base_motion(shared_data / FF1, units="g")
    kw = dict(levels=30, sizes=45, refine=8)
    full = overturning_spectrum(r, 12, refine_where="all", **kw)
    n = _count_batch_runs(monkeypatch)
    curve = overturning_spectrum(r, 12, verdicts=full, **kw)  # the default: refine_where="curve"
    assert curve.options["refine_where"] == "curve"
    assert curve.t_I_s == full.t_I_s and curve.f_min_at == full.f_min_at
    assert curve.t_I_prime_s == full.t_I_prime_s and curve.beta == full.beta
    # every level's boundary: the first steps of its full bisection, so the full value lies inside the last bracket
    # (at most CURVE_REL_P below); here neighbouring sizes lie 11 % apart in p, 1e-3 takes 7 of the 8 steps
    ok = np.isfinite(full.p_min_rad_s)
    assert np.array_equal(ok, np.isfinite(curve.p_min_rad_s))
    rel = curve.p_min_rad_s[ok] / full.p_min_rad_s[ok] - 1.0
    assert rel.min() >= 0.0 and 0.0 < rel.max() <= oas.CURVE_REL_P
    assert np.count_nonzero(rel) > ok.sum() // 4  # most levels stop early, some happen to end where the full one does
    assert n["runs"] < 8 * ok.sum() and n["runs"] >= 7 * ok.sum()


def test_inclined_line_without_the_solver_matches_linprog():
    from rocklab.models.spectra._oas import _line_of, fit_inclined_line

    rng = np.random.default_rng(3)
    for _ in range(300):
        lv = np.linspace(1.0, 10.0, 40)
        f = 3.0 + rng.uniform(0, 1, lv.size) * rng.uniform(0, 3) + lv * rng.uniform(-0.5, 0.8)
        f = np.abs(np.where(rng.uniform(size=lv.size) < 0.1, np.nan, f)) + 0.01
        tIp, beta = fit_inclined_line(f, lv)  # scipy's HiGHS
        c0, s0 = (1 / tIp if np.isfinite(tIp) else 0.0), (1 / beta if np.isfinite(beta) else 0.0)
        c, s = _line_of(f, lv)
        ok = np.isfinite(f)
        mid = 0.5 * (lv[ok].min() + lv[ok].max())
        # the same optimum (height at the middle of the range); both lines below every point
        assert c + s * mid == pytest.approx(c0 + s0 * mid, rel=1e-9)
        assert np.all(c + s * lv[ok] <= f[ok] * (1 + 1e-9)) and c >= 0 and s >= 0


def test_guide_bisected_only_where_the_members_windows_need_it(shared_data, monkeypatch):
    import rocklab.models.spectra._oas as oas

    r = load_base_motion(shared_data / FF1, units="g")
    kw = dict(levels=30, sizes=45, refine=8)
    full = overturning_spectrum(r, 12, **kw)
    # three member grids: sizes shifted half a step, levels shifted, a coarser grid
    places = [
        oas.grid_axes(dict(full.options, **ch), full.alpha_I)[::2]
        for ch in ({"size_offset": 0.5}, {"level_offset": 0.5}, {"levels": 22, "sizes": 34})
    ]
    coarse = overturning_spectrum(r, 12, verdicts=full, **dict(kw, refine=0))
    n = _count_batch_runs(monkeypatch)
    settled = oas.settle_guide(r, coarse, places, refine=8)
    assert settled.t_I_s == full.t_I_s and settled.f_min_at == full.f_min_at
    assert settled.t_I_prime_s == pytest.approx(full.t_I_prime_s, rel=1e-12)
    for lv, p in places:
        assert np.array_equal(oas._guess_first(settled, lv, p), oas._guess_first(full, lv, p))
    # without the places only the fitted levels are bisected; the places need more, all levels far more
    n_levels = int(np.isfinite(full.p_min_rad_s).sum())
    assert n["runs"] < 0.8 * 8 * n_levels
    assert not np.array_equal(oas._guess_first(coarse, *places[2]), oas._guess_first(full, *places[2]))
