"""``rocklab campaign DIR --out OUT``: every experiment under DIR, then the campaign fits."""

from __future__ import annotations

from .._cli_base import count


def register(sub):
    """Add this module's subcommand(s) to the ``rocklab`` parser ``sub``."""
    p = sub.add_parser("campaign", help="run every experiment.toml under DIR in parallel, then campaign fits")
    p.add_argument("dir", help="folder searched recursively for experiment*.toml")
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--workers", type=count(1), default=2, help="local processes (default 2)")
    p.add_argument("--scheduler", metavar="ADDR", help="run the experiments on a Dask distributed cluster")
    p.add_argument("--force", action="store_true", help="re-run unchanged experiments too")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument(
        "--group-by",
        action="append",
        metavar="TAGS",
        help="group repeats by these [experiment] tags (comma-separated: one grouping; repeat the option "
        "for more); default: one grouping per tag found. Mean ± std of eta_e and the Eq. 12 energy loss",
    )
    p.add_argument("--json", action="store_true", help="print the campaign summary as one JSON object")
    p.set_defaults(func=run)


def run(args) -> int:
    """Run ``rocklab campaign`` with parsed ``args``; returns the exit status (0 ok)."""
    from ...campaign import run_campaign

    res = run_campaign(
        args.dir,
        args.out,
        workers=args.workers,
        scheduler=args.scheduler,
        force=args.force,
        progress=not args.no_progress,
        group_by=args.group_by or (),
    )
    if args.json:
        from .._cli_base import emit_json

        emit_json(res.to_dict())
    else:
        print(res.summary_text())
    return 0 if res.n_failed == 0 else 1
