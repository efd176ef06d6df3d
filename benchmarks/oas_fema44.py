"""The thesis's whole far-field study: 44 FEMA P695 records, H/B = 12, against Table 4 (issue 15).

Measures, in one process on all cores:

1. the adaptive OAS grid against the dense one (baseline: every grid point simulated):
   verdicts identical (pooled and worst record), t_I / t'_I identical, runs, wall time;
2. t_I bands (:func:`rocklab.models.t_I_band`, the default ensemble) of the 44 records:
   wall time, how many Table 4 t_I lie inside the 5-95 % band, median half-width;
3. the candidate rules for t'_I and beta (thesis Eq. 28 does not say how the line was
   fitted) against Table 4: rank correlation and records within 20 %.

The 44 records are not shipped (no licence to redistribute them); pass the folder of the
``SortedEQFile_1xxxxx.txt`` files (in g, one value per line after the header; e.g. from
github.com/Hadi-Azarnasab/scale_fema_p695). Not part of ``make bench`` (about 4-5 min).
Run: ``.venv/bin/python benchmarks/oas_fema44.py FOLDER``.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
from scipy.optimize import linprog
from scipy.stats import spearmanr

from rocklab.models import fit_inclined_line, load_base_motion, overturning_spectrum, t_I_band
from rocklab.pipelines.spectra import thesis_table4


def _line_ls(A, f):
    s, c = np.polyfit(A, f, 1)
    return c, s


def _ls_p(A, f):
    """Least squares in p = f/A against 1/A (p = 1/beta + (1/t'_I)/A): (1/t'_I, 1/beta)."""
    s, c = _line_ls(1.0 / A, f / A)
    return c, s


def _envelope(A, f):
    o = np.argsort(A)
    return A[o], np.minimum.accumulate(f[o][::-1])[::-1]


def _quantile(q):
    def fit(A, f):
        n = A.size
        cost = np.r_[0.0, 0.0, q * np.ones(n), (1 - q) * np.ones(n)]
        res = linprog(
            cost,
            A_eq=np.c_[np.ones(n), A, np.eye(n), -np.eye(n)],
            b_eq=f,
            bounds=[(None, None)] * 2 + [(0, None)] * (2 * n),
            method="highs",
        )
        return res.x[0], res.x[1]

    return fit


def _lp(A, f):
    tIp, beta = fit_inclined_line(f, A)
    return 1.0 / tIp, 1.0 / beta


#: Candidate rules: (A = a_p/a_p,min, f) points -> (1/t'_I, 1/beta).
RULES = {
    "lower line, max. mean (rocklab)": _lp,
    "least squares in f, all points": _line_ls,
    "least squares in p vs 1/A": _ls_p,
    "least squares on the envelope": lambda A, f: _line_ls(*_envelope(A, f)),
    "least squares in p, envelope": lambda A, f: _ls_p(*_envelope(A, f)),
    "10 % quantile line in f": _quantile(0.10),
    "25 % quantile line in f": _quantile(0.25),
    "least squares in f, A <= 5": lambda A, f: _line_ls(A[A <= 5], f[A <= 5]),
}


def main(folder: Path) -> int:
    files = sorted(folder.glob("SortedEQFile_*.txt"))
    if len(files) != 44:
        print(f"{folder}: expected the 44 SortedEQFile_*.txt records, found {len(files)}")
        return 2
    table = {str(r.fema_id): r for r in thesis_table4().itertuples()}
    recs = [load_base_motion(f, units="g") for f in files]
    overturning_spectrum(recs[0], 12, levels=2, sizes=2, refine=1)  # compile / load the cache

    print("1. adaptive grid against the dense grid (baseline: every point simulated)")
    same = worst = 1.0
    n_same = n_all = runs = 0
    eq_tI = eq_tIp = 0
    t_dense = t_adapt = 0.0
    oas = {}
    for b in recs:
        t0 = time.perf_counter()
        d = overturning_spectrum(b, 12, grid="dense")
        t1 = time.perf_counter()
        a = overturning_spectrum(b, 12)
        t_adapt += time.perf_counter() - t1
        t_dense += t1 - t0
        k = int(np.sum(a.overturned == d.overturned))
        n_same += k
        n_all += d.overturned.size
        worst = min(worst, k / d.overturned.size)
        runs += a.n_runs
        eq_tI += a.t_I_s == d.t_I_s
        eq_tIp += a.t_I_prime_s == d.t_I_prime_s
        oas[b.name] = a
    same = n_same / n_all
    print(
        f"   verdicts identical: {100 * same:.2f} % of {n_all} (worst record {100 * worst:.2f} %); "
        f"t_I identical {eq_tI}/44, t'_I {eq_tIp}/44; {100 * runs / n_all:.1f} % of the grid simulated"
    )
    print(f"   44 OAS: adaptive {t_adapt:.1f} s, dense {t_dense:.1f} s ({t_dense / t_adapt:.2f}x)")

    print("2. t_I bands (default ensemble) against Table 4")
    t0 = time.perf_counter()
    inside = 0
    half = []
    for b in recs:
        band = t_I_band(b, 12)
        th = float(table[b.name.split("_")[-1]].t_I_s)
        inside += band.t_I_p05_s <= th <= band.t_I_p95_s
        half.append(band.half_width_rel)
    t_band = time.perf_counter() - t0
    print(
        f"   44 records with bands: {t_band:.1f} s (target <= 60 s); Table 4 t_I inside the band: "
        f"{inside}/44 (target >= 40); median half-width {100 * np.median(half):.1f} % (<= 25 %)"
    )

    print("3. rules for t'_I and beta (Eq. 28) against Table 4: rank correlation, records within 20 %")
    for name, rule in RULES.items():
        got_t, got_b, want_t, want_b = [], [], [], []
        for b in recs:
            o = oas[b.name]
            ok = np.isfinite(o.f_rad_s)
            c, s = rule(o.levels[ok], o.f_rad_s[ok])
            got_t.append(1 / c if c > 1e-9 else np.inf)
            got_b.append(1 / s if s > 1e-9 else np.inf)
            row = table[b.name.split("_")[-1]]
            want_t.append(float(row.t_I_prime_s))
            want_b.append(float(row.beta))
        gt, gb, wt, wb = map(np.asarray, (got_t, got_b, want_t, want_b))
        with np.errstate(divide="ignore", invalid="ignore"):
            in_t = np.abs(np.log(gt / wt)) < np.log(1.2)
            in_b = np.abs(np.log(gb / wb)) < np.log(1.2)
        print(
            f"   {name:34s} t'_I rho {spearmanr(gt, wt)[0]:.3f}, {in_t.sum():2d}/44; beta rho "
            f"{spearmanr(gb, wb)[0]:.3f}, {in_b.sum():2d}/44; both {np.sum(in_t & in_b):2d}/44"
        )
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print(__doc__)
        raise SystemExit(2)
    raise SystemExit(main(Path(sys.argv[1])))
