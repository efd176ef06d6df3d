"""The thesis's whole far-field study: 44 FEMA P695 records, H/B = 12, against Table 4 (issue 15).

Measures, in one process on all cores:

1. the adaptive OAS grid against the dense one (baseline: every grid point simulated):
   verdicts identical (pooled and worst record), t_I / t'_I identical, runs, wall time; each
   record whose t_I differs, with the cells behind both values;
2. t_I bands (:func:`rocklab.models.t_I_band`, the default ensemble) of the 44 records:
   wall time, how many Table 4 t_I lie inside the 5-95 % band, median half-width;
3. the candidate rules for t'_I and beta (thesis Eq. 28 does not say how the line was
   fitted) against Table 4: rank correlation and records within 20 %.

The 44 records are not shipped (no licence to redistribute them); pass the folder of the
``SortedEQFile_1xxxxx.txt`` files (in g, one value per line after the header; e.g. from
github.com/Hadi-Azarnasab/scale_fema_p695). Not part of ``make bench`` (about 4-5 min).
Run: ``.venv/bin/python benchmarks/oas_fema44.py FOLDER [--bands] [--baseline]``.

``--grid`` skips part 2. ``--bands`` runs part 2 only: the figure issue 27 asks for (the 44 records with bands on all
cores, <= 60 s), printed as wall time and process CPU time, for the default bands (t_I, t'_I and beta of
every member) and for t_I bands only (``lines=False``: the members after the first compute t_I alone);
``--baseline`` adds, in the same process, the same bands with the Newmark runs at p h <= 0.001 (the OAS
default before session 13).
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


def bands(recs, table, **options) -> tuple[float, float, int, float]:
    """t_I bands of every record: (wall s, process CPU s, Table 4 t_I inside the 5-95 % band, median half-width)."""
    w0, c0 = time.perf_counter(), time.process_time()
    inside = 0
    half = []
    for b in recs:
        band = t_I_band(b, 12, **options)
        th = float(table[b.name.split("_")[-1]].t_I_s)
        inside += band.t_I_p05_s <= th <= band.t_I_p95_s
        half.append(band.half_width_rel)
    return time.perf_counter() - w0, time.process_time() - c0, inside, float(np.median(half))


def main(folder: Path, only_bands: bool = False, baseline: bool = False, skip_bands: bool = False) -> int:
    files = sorted(folder.glob("SortedEQFile_*.txt"))
    if len(files) != 44:
        print(f"{folder}: expected the 44 SortedEQFile_*.txt records, found {len(files)}")
        return 2
    table = {str(r.fema_id): r for r in thesis_table4().itertuples()}
    recs = [load_base_motion(f, units="g") for f in files]
    overturning_spectrum(recs[0], 12, levels=2, sizes=2, refine=1)  # compile / load the cache
    overturning_spectrum(recs[0], 12, levels=2, sizes=2, refine=1, method="newmark")
    if only_bands:
        import numba

        print(f"t_I bands of the 44 records (default ensemble), {numba.get_num_threads()} threads")
        for label, kw in (("t_I only (lines=False)", {"lines": False}), ("default (t_I, t'_I, beta)", {})):
            wall, cpu, inside, half = bands(recs, table, **kw)
            print(
                f"   {label}: {wall:.1f} s wall (target <= 60 s on 2 cores), {cpu:.1f} s CPU; Table 4 t_I "
                f"inside the band: {inside}/44 (>= 29); median half-width {100 * half:.1f} % (<= 25 %)"
            )
        if baseline:
            wall_n, cpu_n, inside_n, half_n = bands(recs, table, method="newmark")
            print(
                f"   baseline, Newmark runs at p h <= 0.001 (default before session 13), same process: {wall_n:.1f} s "
                f"wall, {cpu_n:.1f} s CPU; inside {inside_n}/44, median half-width {100 * half_n:.1f} %; "
                f"the default is {wall_n / wall:.2f}x faster (wall), {cpu_n / cpu:.2f}x (CPU)"
            )
        return 0

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
        if a.t_I_s != d.t_I_s:
            (la, ra), (ld, rd) = a.f_min_at, d.f_min_at
            i, j = int(np.argmin(np.abs(d.levels - ld))), int(np.argmin(np.abs(d.R_m - rd)))
            print(
                f"   t_I differs on {b.name}: adaptive {a.t_I_s:.4f} s (level {la:.3f}, R {ra:.3f} m), dense "
                f"{d.t_I_s:.4f} s (level {ld:.3f}, R {rd:.3f} m; that cell simulated by the adaptive grid: "
                f"{bool(a.evaluated[i, j])}; {int(np.argmax(a.overturned[i]) - np.argmax(d.overturned[i]))} sizes "
                "before the adaptive row's first unsafe size)"
            )
        eq_tIp += a.t_I_prime_s == d.t_I_prime_s
        oas[b.name] = a
    same = n_same / n_all
    print(
        f"   verdicts identical: {100 * same:.2f} % of {n_all} (worst record {100 * worst:.2f} %); "
        f"t_I identical {eq_tI}/44, t'_I {eq_tIp}/44; {100 * runs / n_all:.1f} % of the grid simulated"
    )
    print(f"   44 OAS: adaptive {t_adapt:.1f} s, dense {t_dense:.1f} s ({t_dense / t_adapt:.2f}x)")

    print("2. t_I bands (default ensemble) against Table 4" + (": skipped (--grid)" if skip_bands else ""))
    t_band, c_band, inside, half = (0.0, 0.0, 0, 0.0) if skip_bands else bands(recs, table)
    print(
        f"   44 records with bands: {t_band:.1f} s wall (target <= 60 s on 2 cores), {c_band:.1f} s CPU; Table 4 t_I "
        f"inside the band: {inside}/44 (>= 29); median half-width {100 * half:.1f} % (<= 25 %)"
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
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    flags = {a for a in sys.argv[1:] if a.startswith("--")}
    if len(args) != 1 or flags - {"--bands", "--baseline", "--grid"}:
        print(__doc__)
        raise SystemExit(2)
    raise SystemExit(main(Path(args[0]), "--bands" in flags, "--baseline" in flags, "--grid" in flags))
