"""OAS verdicts against the converged reference, per record (issue 27 item 1).

For each record, H/B = 12, default grid (80 levels x 120 sizes): the reference
(:func:`rocklab.models.oas_reference`: every cell by the Taylor-series integrator, checked at a
finer tolerance, and at the amplitude times 1 -/+ 1e-3) and, in the same process, the OAS paths
measured against it on the decided (neither chaotic nor unresolved) cells:

- ``default``: :func:`~rocklab.models.overturning_spectrum` with its defaults;
- ``newmark``: the adaptive grid with Newmark runs at p h <= 0.001 (the default before
  session 13; the same as ``default`` when the default is Newmark);
- ``taylor``: the adaptive grid with Taylor runs (``method="taylor"``).

Prints per record: cells, chaotic fraction, unresolved cells, agreement of each path
(target >= 99.5 %), t_I of the reference and of each path (s), and the wall time of each
(the machine may be loaded: compare within a row only); under a record, for each path whose
t_I differs from the reference's by more than 0.5 %, the differing cells behind it.

Records: the five in ``../shared/data/records`` (FEMA P695 FF-1, FF-2 and three AT2 files);
pass a folder of the 44 ``SortedEQFile_1xxxxx.txt`` FEMA far-field records (see
``benchmarks/oas_fema44.py``) to add the others. Not part of ``make bench`` (about 1 min per
30 s record on 2 cores). With ``ROCKLAB_REF_CACHE=DIR`` the references are kept in DIR
(``<record>.npz``) and read back on the next run, so a changed path is measured without
recomputing them. Run: ``.venv/bin/python benchmarks/oas_reference.py [FOLDER]``.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

from rocklab.models import load_base_motion, oas_reference, overturning_spectrum
from rocklab.pipelines.spectra import thesis_table4

DATA = Path(__file__).resolve().parents[2] / "shared/data/records"
SHARED = [
    ("fema-p695-far-field/SortedEQFile_120111.txt", "g"),
    ("fema-p695-far-field/SortedEQFile_120112.txt", "g"),
    ("elCentro.AT2", None),
    ("RSN6_IMPVALL.I_I-ELC180.AT2", None),
    ("RSN68_SFERN_PEL090.AT2", None),
]
PATHS = {"default": {}, "newmark": {"method": "newmark", "max_p_dt": 0.001}, "taylor": {"method": "taylor"}}


def _records(folder: Path | None):
    ff = {str(r.fema_id): r.ff_id for r in thesis_table4().itertuples()}
    out = []
    for name, units in SHARED:
        if (DATA / name).is_file():
            out.append((DATA / name, units))
    if folder is not None:
        have = {p.name for p, _ in out}
        out += [(f, "g") for f in sorted(folder.glob("SortedEQFile_*.txt")) if f.name not in have]
    return [(ff.get(p.stem.split("_")[-1], p.stem[:10]), load_base_motion(p, units=units)) for p, units in out]


def _reference(rid, b):
    """(verdicts, decided mask, chaotic fraction, unresolved cells, reference t_I s, seconds); cached in
    ``$ROCKLAB_REF_CACHE`` when set."""
    cache = os.environ.get("ROCKLAB_REF_CACHE")
    path = Path(cache) / f"{rid}.npz" if cache else None
    if path is not None and path.is_file():
        z = np.load(path)
        return z["over"], z["decided"], float(z["chaos"]), int(z["unres"]), float(z["tI"]), float(z["secs"])
    t0 = time.perf_counter()
    ref = oas_reference(b, 12)
    secs = time.perf_counter() - t0
    out = (ref.overturned, ref.decided, ref.chaotic_fraction, int(ref.unresolved.sum()), ref.oas.t_I_s, secs)
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        np.savez(path, over=out[0], decided=out[1], chaos=out[2], unres=out[3], tI=out[4], secs=secs)
    return out


def _why(o, over, decided, t_I_ref):
    """Where a path's t_I differs from the reference's by more than 0.5 %: the cells behind it.

    t_I rests on one boundary point; at the levels whose first unsafe size sets the path's or the
    reference's leftmost f, the cells where the two verdict maps differ are named with their kind:
    chaotic/unresolved in the reference, decided (an integrator error), or filled by the adaptive grid.
    """
    if not (np.isfinite(o.t_I_s) and np.isfinite(t_I_ref)) or abs(o.t_I_s / t_I_ref - 1) < 0.005:
        return ""
    first = np.where(over.any(axis=1), over.argmax(axis=1), over.shape[1] - 1)
    f_ref = o.levels * o.p_rad_s[first]
    rows = {int(np.nanargmin(o.f_rad_s)), int(np.argmin(f_ref))}
    out = []
    for i in sorted(rows):
        for j in np.flatnonzero(o.overturned[i] != over[i]):
            if j > max(first[i], np.argmax(o.overturned[i])):
                continue  # beyond both boundaries: not behind t_I
            kind = "chaotic" if not decided[i, j] else "decided"
            if o.evaluated is not None and not o.evaluated[i, j]:
                kind += ", filled"
            out.append(f"L{o.levels[i]:.2f}/R{o.R_m[j]:.3g}:{kind}")
    return " ".join(out) if out else "bisection inside the boundary cell"


def main(folder: Path | None) -> int:
    recs = _records(folder)
    if not recs:
        print(f"no records in {DATA}: nothing to measure")
        return 0
    overturning_spectrum(recs[0][1], 12, levels=2, sizes=2, refine=1)  # compile / load the caches
    overturning_spectrum(recs[0][1], 12, levels=2, sizes=2, refine=1, method="taylor")
    head = "".join(f" {k:>8} agree  t_I s   time" for k in PATHS)
    print(f"{'record':<10} {'dur s':>6} {'cells':>6} {'chaos %':>7} {'unres':>5} {'ref t_I':>8} {'ref s':>6}{head}")
    worst = {k: 1.0 for k in PATHS}
    for rid, b in recs:
        over, decided, chaos, unres, t_I_ref, t_ref = _reference(rid, b)
        cells, whys = [], []
        for k, kw in PATHS.items():
            t0 = time.perf_counter()
            o = overturning_spectrum(b, 12, **kw)
            dt = time.perf_counter() - t0
            a = float(np.mean(o.overturned[decided] == over[decided]))
            worst[k] = min(worst[k], a)
            cells.append(f" {'':>8} {100 * a:6.2f} {o.t_I_s:6.4f} {dt:6.2f}")
            why = _why(o, over, decided, t_I_ref)
            if why:
                whys.append(f"    {k}: t_I {o.t_I_s:.4f} vs {t_I_ref:.4f}: {why}")
        print(
            f"{rid:<10} {b.duration_s:6.1f} {over.size:6d} {100 * chaos:7.2f} "
            f"{unres:5d} {t_I_ref:8.4f} {t_ref:6.1f}" + "".join(cells),
            flush=True,
        )
        for w in whys:
            print(w)
    print("worst agreement on decided cells: " + ", ".join(f"{k} {100 * v:.2f} %" for k, v in worst.items()))
    print("(agree: % of the cells neither chaotic nor unresolved; times in s on a possibly loaded machine;")
    print(" indented: where a path's t_I differs from the reference's by > 0.5 %, the cells at the levels behind it")
    print(" whose verdicts differ, by level a_p/a_p,min and size R m: chaotic/decided in the reference, filled)")
    return 0


if __name__ == "__main__":
    if len(sys.argv) > 2:
        print(__doc__)
        raise SystemExit(2)
    raise SystemExit(main(Path(sys.argv[1]) if len(sys.argv) == 2 else None))
