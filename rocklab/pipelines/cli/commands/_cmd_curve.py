"""``rocklab curve``: the overturning curve and the overturning impulse curve of a simple pulse.

Thesis Figs. 33-34 and 39: for a block of slenderness H/B, the lowest pulse amplitude
a_p/a_p,min that overturns it at each p t_p (t_p = one lobe's duration, p the block's frequency
parameter), and the impulse p I / a_p,min that goes with it; multi-lobe pulses show bays and
islands on the grid. Columns' overturning maps under full-sine pulses are ``rocklab column
--maps-png`` (thesis Fig. 40).

    rocklab curve --kind half-sine --slenderness 5 -o curve.csv --plot curve.png
    rocklab curve --kind n-half-sines --lobes 3 --ptp 0.5,20,60 --levels 1,10,80
"""

from __future__ import annotations

import sys

from ...._errors import InputError

__all__ = ["register", "run"]


def _grid(text: str, option: str, default):
    """``START,STOP,N`` (log-spaced for p t_p, linear for the levels) or the default grid."""
    if text is None:
        return default
    parts = text.split(",")
    try:
        lo, hi, n = float(parts[0]), float(parts[1]), int(parts[2])
        if len(parts) != 3:
            raise ValueError
    except (ValueError, IndexError):
        raise InputError(f"{option} {text!r}: give START,STOP,N (e.g. {option} 0.5,20,40)") from None
    if not (0 < lo < hi) or n < 2:
        raise InputError(f"{option} {text!r}: need 0 < START < STOP and N >= 2")
    return lo, hi, n


def register(sub) -> None:
    """Add ``rocklab curve`` to the ``rocklab`` parser ``sub``."""
    p = sub.add_parser(
        "curve",
        help="overturning curve and impulse curve of a simple pulse (thesis Figs. 33-34)",
        description=__doc__.split("\n\n")[0] if __doc__ else None,
    )
    p.add_argument(
        "--kind",
        default="half-sine",
        help="pulse: half-sine (default), sine (one full sine), n-half-sines, rectangular, triangular, "
        "cycloidal-a, cycloidal-b",
    )
    p.add_argument("--lobes", type=int, default=1, help="number of lobes of n-half-sines (default 1)")
    p.add_argument("--slenderness", type=float, default=5.0, help="block H/B (default 5)")
    p.add_argument(
        "--ptp", default=None, help="p t_p grid START,STOP,N, log-spaced (default 0.5,20,40; t_p = one lobe)"
    )
    p.add_argument("--levels", default=None, help="a_p/a_p,min grid START,STOP,N, linear (default 1,10,60)")
    p.add_argument("--eta", type=float, default=None, help="restitution (default Housner's of the block)")
    p.add_argument(
        "--criterion",
        choices=("angle", "fall"),
        default="angle",
        help="overturned when theta reaches alpha (angle, default) or the block falls (fall)",
    )
    p.add_argument("-o", "--out", default=None, help="CSV: p_tp, a_min_ratio, impulse_ratio")
    p.add_argument("--plot", default=None, help="PNG of the curve over its grid and the impulse curve")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.set_defaults(func=run)


def run(args) -> int:
    """Run ``rocklab curve`` with parsed ``args``; returns the exit status (0 ok)."""
    import numpy as np

    from ...._io import write_frame_atomic
    from ....models import overturning_curve
    from .._cli_base import emit_json

    if args.lobes < 1:
        raise InputError(f"--lobes {args.lobes}: a pulse has at least 1 lobe")
    lo, hi, n = _grid(args.ptp, "--ptp", (0.5, 20.0, 40))
    ptp = np.geomspace(lo, hi, n)
    lo, hi, n = _grid(args.levels, "--levels", (1.0, 10.0, 60))
    levels = np.linspace(lo, hi, n)
    c = overturning_curve(
        args.kind, args.slenderness, ptp, levels, n=args.lobes, criterion=args.criterion, eta=args.eta
    )
    import pandas as pd

    frame = pd.DataFrame({"p_tp": c.ptp, "a_min_ratio": c.a_min_ratio, "impulse_ratio": c.impulse_ratio})
    if args.out:
        write_frame_atomic(args.out, frame)
    if args.plot:
        from ...spectra import plot_overturning_curve

        plot_overturning_curve(c, args.plot)
    never = int(np.isnan(c.a_min_ratio).sum())
    if never:
        print(
            f"rocklab curve: note: {never} of {c.ptp.size} p t_p values do not overturn up to a_p/a_p,min = "
            f"{levels[-1]:.4g} (a_min_ratio NaN there); raise --levels' STOP to see them",
            file=sys.stderr,
        )
    d = {
        "kind": c.kind,
        "lobes": c.n,
        "slenderness": args.slenderness,
        "alpha_rad": c.alpha_rad,
        "i_cr": c.i_cr,
        "p_tp": c.ptp.tolist(),
        "a_min_ratio": [None if not np.isfinite(v) else float(v) for v in c.a_min_ratio],
        "impulse_ratio": [None if not np.isfinite(v) else float(v) for v in c.impulse_ratio],
        "status": "ok",
    }
    if args.json:
        emit_json(d)
    else:
        k = int(np.nanargmin(c.a_min_ratio)) if never < c.ptp.size else None
        low = "" if k is None else f"; lowest a_p/a_p,min {c.a_min_ratio[k]:.4g} at p t_p = {c.ptp[k]:.4g}"
        print(
            f"{c.kind} x{c.n}, H/B = {args.slenderness:g} (alpha = {c.alpha_rad:.4g} rad): "
            f"short-pulse impulse limit i_cr = {c.i_cr:.4g}{low}"
        )
    return 0
