"""``rocklab papers --out DIR``: regenerate the papers' figures and tables (the gallery).

Writes ``DIR/index.md`` (every figure and table of the three papers: regenerated, or why not),
one PNG and CSV per regenerated figure, and ``DIR/numbers.json`` with the paper's quantities
beside rocklab's. Figures that need records rocklab does not ship run with ``--records DIR``.
"""

from __future__ import annotations

import sys

__all__ = ["register", "run"]


def register(sub) -> None:
    """Add ``rocklab papers`` to the ``rocklab`` parser ``sub``."""
    p = sub.add_parser(
        "papers",
        help="regenerate the papers' figures and tables: PNG, CSV, numbers.json, index.md",
        description=__doc__.split("\n\n")[0] if __doc__ else None,
    )
    p.add_argument("--out", required=True, help="output folder (created)")
    p.add_argument(
        "--records", default=None, help="folder of records for the figures that need them (e.g. ../shared/data/records)"
    )
    p.add_argument(
        "--only",
        default=None,
        help="regenerate only these: comma-separated figures or papers (e.g. 'ther:Fig. 29,ceh2018')",
    )
    p.add_argument("--json", action="store_true", help="print one JSON summary object on stdout")
    p.set_defaults(func=run)


def run(args) -> int:
    """Run ``rocklab papers`` with parsed ``args``; returns the exit status (0 ok, 1 a figure failed)."""
    from pathlib import Path

    from ...._errors import InputError
    from ...papers import ENTRIES, regenerate
    from .._cli_base import emit_json

    if args.records is not None and not Path(args.records).is_dir():
        raise InputError(f"--records {args.records}: not a folder; give the folder that holds the records")

    def progress(key):
        print(f"rocklab papers: {key} ...", file=sys.stderr, flush=True)

    res = regenerate(ENTRIES, args.out, records=args.records, only=args.only, progress=progress)
    failed = [r for r in res.rows if r["status"] == "failed"]
    for r in failed:
        print(f"rocklab papers: error: {r['key']}: {r['note']}", file=sys.stderr)
    d = {
        "out": str(res.out),
        "n_rows": len(res.rows),
        "n_regenerated": res.n_regenerated,
        "failed": [r["key"] for r in failed],
        "status": "ok" if not failed else "failed",
    }
    if args.json:
        emit_json(d)
    else:
        print(
            f"{res.n_regenerated} of {len(res.rows)} figures and tables regenerated into {res.out} (index.md, numbers.json)"
        )
    return 1 if failed else 0
