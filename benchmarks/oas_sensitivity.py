"""How much each open definition choice moves t_I (issue 8; thesis §5.3, Table 4).

For the FEMA P695 far-field pair FF-1 / FF-2 (Northridge, Beverly Hills MUL009 / MUL279,
NGA-West1 processing, as in the thesis) and, when present, the NGA-West2 file of FF-41
(San Fernando, LA Hollywood Stor PEL090), prints t_I, t'_I and beta of the defaults and
of one changed option at a time, next to Table 4. The table in the docstring of
``rocklab/models/spectra/_oas.py`` is this script's output.

Not part of ``make bench`` (about 1-2 min on 2 cores). Needs ../shared.
Run: ``.venv/bin/python benchmarks/oas_sensitivity.py``.
"""

from __future__ import annotations

import time
from pathlib import Path

from rocklab.models import load_base_motion, overturning_spectrum, pulse_parameters

DATA = Path(__file__).resolve().parents[2] / "shared/data/records"
RECORDS = {  # id: (file, units, thesis t_p, t_I, t'_I, beta)
    "FF-1": ("fema-p695-far-field/SortedEQFile_120111.txt", "g", 0.405, 0.266, 0.387, 1.744),
    "FF-2": ("fema-p695-far-field/SortedEQFile_120112.txt", "g", 0.367, 0.360, 0.538, 1.467),
    "FF-41": ("RSN68_SFERN_PEL090.AT2", None, 0.224, 0.503, 0.897, 1.841),
}
VARIANTS = [
    ("defaults", {}),
    ("search=contiguous", {"search": "contiguous"}),
    ("criterion=fall", {"criterion": "fall"}),
    ("free=none", {"free": "none"}),
    ("free=10 s", {"free": 10.0}),
    ("refine=0", {"refine": 0}),
    ("levels=160", {"levels": 160}),
    ("sizes=240", {"sizes": 240}),
    ("newmark p h 0.001", {"method": "newmark"}),
    ("newmark p h 0.02", {"method": "newmark", "max_p_dt": 0.02}),
    ("newmark p h 0.005", {"method": "newmark", "max_p_dt": 0.005}),
    ("eta=0.95", {"eta": 0.95}),
]


def main() -> int:
    if not DATA.is_dir():
        print(f"no {DATA}: nothing to measure")
        return 0
    recs = {}
    for rid, (name, units, tp, tI, tIp, beta) in RECORDS.items():
        if (DATA / name).is_file():
            b = load_base_motion(DATA / name, units=units)
            recs[rid] = b
            pp = pulse_parameters(b)
            print(f"{rid} {b.name}: t_p {pp.t_p_s:.3f} s (Table 4: {tp}), Table 4 t_I {tI}, t'_I {tIp}, beta {beta}")
    overturning_spectrum(next(iter(recs.values())), 12, levels=2, sizes=2, refine=1)  # compile
    print(f"\n{'variant':<20}" + "".join(f"{rid:>26}" for rid in recs) + "   time")
    for label, kw in VARIANTS:
        t0 = time.perf_counter()
        cells = []
        for rid, b in recs.items():
            o = overturning_spectrum(b, 12, **kw)
            dev = 100 * (o.t_I_s / RECORDS[rid][3] - 1)
            cells.append(f"{o.t_I_s:.3f} ({dev:+4.0f} %) {o.t_I_prime_s:.3f}/{o.beta:.2f}")
        print(f"{label:<20}" + "".join(f"{c:>26}" for c in cells) + f"   {time.perf_counter() - t0:.1f} s", flush=True)
    print("\ncells: t_I s (vs Table 4), t'_I s / beta")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
