"""``rocklab fit``: restitution calibration (issue 5).

Subcommands::

    rocklab fit restitution TRACK.csv --width W --height H [--object ID] [--window middle50|all|first]
    rocklab fit eta-mat EDGE.csv --lc-m 0.0015 [--contact inner|midway] [--rule mean|median|lsq]
    rocklab fit k-table FULL.csv --eta-mat 0.989 [--form ceh19|...]
    rocklab fit k-predict --hb 4.5 --b-cm 9 [--coefficients FILE.json]

``--json`` prints one JSON object (NaN as null) on stdout; otherwise a text report.
Sizes on the command line are in metres except ``--b-cm`` (Čeh Eq. 19 uses cm).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

from ...._errors import InputError, where
from ....config import FIT_WINDOWS


def register(sub):
    """Add this module's subcommand(s) to the ``rocklab`` parser ``sub``."""
    p = sub.add_parser(
        "fit",
        help="restitution calibration: eta_e, eta_mat, inverse k, k regression",
        description=(__doc__ or "").split("\n\n")[0],
    )
    fs = p.add_subparsers(dest="fit_command", metavar="WHAT")

    r = fs.add_parser("restitution", help="fit a constant eta_e to a free-rocking record (t_s, theta_rad)")
    r.add_argument("track", help="CSV with t_s, theta_rad (tracks.csv with an object column, or an IMU export)")
    r.add_argument("--width", type=float, required=True, help="block width b, m")
    r.add_argument("--height", type=float, required=True, help="block height h, m")
    r.add_argument("--object", default=None, help="object id in tracks.csv (default: the only block)")
    r.add_argument(
        "--window",
        choices=FIT_WINDOWS,
        default=FIT_WINDOWS[0],
        help="samples compared: between the impacts at 25 %% and 75 %% of the count (Čeh's middle 50 %%, "
        "default), the whole response, or the first half-period after an impact",
    )
    r.add_argument(
        "--objective",
        choices=("theta", "peaks"),
        default="theta",
        help="least squares on theta(t) (default) or on the arches' amplitudes and half-periods",
    )
    r.add_argument(
        "--fit-offset",
        action="store_true",
        help="also fit a constant level offset of theta (camera level error, IMU bias)",
    )
    r.add_argument(
        "--nan",
        choices=("raise", "skip"),
        default="skip",
        help="rows with NaN/not-ok samples: skip them (counted) or stop with an error",
    )
    _common(r)

    e = fs.add_parser("eta-mat", help="material restitution eta_mat from edge-contact results (Čeh Eq. 16)")
    e.add_argument("table", help="CSV with block,b_m,h_m,eta_e")
    e.add_argument("--lc-m", type=float, default=0.0015, help="base strip width l_c, m (default 0.0015)")
    e.add_argument(
        "--contact",
        choices=("inner", "midway"),
        default="inner",
        help="impulse at the strip's inner edge, k = 1 - 2 l_c/b (default), or midway across it, k = 1 - l_c/b",
    )
    e.add_argument("--rule", choices=("mean", "median", "lsq"), default="mean", help="averaging rule")
    e.add_argument("--min-hb", type=float, default=0.0, help="use only blocks with h/b >= this")
    e.add_argument(
        "--nan",
        choices=("raise", "skip"),
        default="raise",
        help="rows with NaN: stop with an error (default) or skip them",
    )
    _common(e)

    k = fs.add_parser("k-table", help="k and b_bar per full-contact block (Čeh Eq. 17-18) and the k regression")
    k.add_argument("table", help="CSV with block,b_m,h_m,eta_e (eta_e,full)")
    k.add_argument("--eta-mat", type=float, required=True, help="material restitution (Čeh: 0.989)")
    k.add_argument("--form", default="ceh19", help="regression form: ceh19|linear|quadratic_b|hb_only|interaction")
    k.add_argument("--feasible-only", action="store_true", help="fit the regression to k <= 1 blocks only")
    k.add_argument(
        "--nan",
        choices=("raise", "skip"),
        default="raise",
        help="rows with NaN: stop with an error (default) or skip them",
    )
    _common(k)

    q = fs.add_parser("k-predict", help="predict k, eta_M and b_bar for a new block (Čeh Eq. 19 by default)")
    q.add_argument("--hb", type=float, required=True, help="aspect ratio h/b")
    q.add_argument("--b-cm", type=float, required=True, help="block width b, cm")
    q.add_argument(
        "--coefficients", default=None, help="JSON file: a 'k-table --json' output or a {hb2, hb, const, b_cm} object"
    )
    _common(q)
    p.set_defaults(func=run, _fit_parser=p)


def _common(p):
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")


def _emit(args, payload: dict, text: str) -> None:
    if args.json:
        from .._cli_base import emit_json

        emit_json(payload)
    else:
        sys.stdout.write(text + "\n")


def run(args) -> int:
    """Run ``rocklab fit`` with parsed ``args``; returns the exit status (0 ok)."""
    cmd = getattr(args, "fit_command", None)
    if cmd is None:
        args._fit_parser.print_help()
        return 2
    return {
        "restitution": _run_restitution,
        "eta-mat": _run_eta_mat,
        "k-table": _run_k_table,
        "k-predict": _run_k_predict,
    }[cmd](args)


def _read_track(path: Path, obj: str | None, nan: str):
    """(t_s, theta_rad, n_skipped) of one object of a tracks.csv / IMU CSV: its usable samples
    (:meth:`rocklab.series.Tracks.usable`, the rule ``rocklab run`` fits by too)."""
    import numpy as np

    from ....series import read_tracks

    rows = read_tracks(path).rows(obj, fix="--object")
    t, th = rows.theta()
    bad = ~np.isfinite(th)
    if bad.any() and nan == "raise":
        line = int(rows.column("line")[np.flatnonzero(bad)[0]])
        raise InputError(
            f"{where(path, line)}NaN or not-ok sample ({int(bad.sum())} such rows); use --nan skip to drop them"
        )
    if int((~bad).sum()) < 10:  # named here: the fit's own message cannot say which file
        raise InputError(
            f"{path}: {int((~bad).sum())} usable samples (status ok or corrected, finite θ): too short, a fit needs "
            "at least 10 over a few rocking cycles: check the file, its object and its status column"
        )
    return t[~bad], th[~bad], int(bad.sum())


def _run_restitution(args) -> int:
    from ....blocks import Block
    from ....fitting import fit_restitution

    block = Block(b_m=args.width, h_m=args.height, name=Path(args.track).stem)
    t, y, n_skip = _read_track(Path(args.track), args.object, args.nan)
    if n_skip:
        sys.stderr.write(f"rocklab fit restitution: skipped {n_skip} NaN/not-ok row(s)\n")
    fit = fit_restitution(
        t, y, block, window=args.window, objective=args.objective, nan="raise", fit_offset=args.fit_offset
    )
    d = fit.to_dict()
    d["n_skipped"] = n_skip
    keys = (
        "eta_e",
        "eta_e_first",
        "ci95_eta_e",
        "theta0_rad",
        "release_t_s",
        "rms_residual_rad",
        "per_impact_eta",
        "status",
    )
    payload = {k: d[k] for k in keys}
    payload.update(
        {
            k: d[k]
            for k in (
                "message",
                "suspicious",
                "flags",
                "n_impacts",
                "window",
                "objective",
                "n_skipped",
                "theta_offset_rad",
                "sigma_theta_rad",
                "at_bound",
            )
        }
    )
    _emit(args, payload, fit.report())
    return 0 if fit.ok else 1


def _run_eta_mat(args) -> int:
    from ....fitting import fit_eta_mat, read_block_table

    table = read_block_table(Path(args.table), nan=args.nan)
    res = fit_eta_mat(table, l_c_m=args.lc_m, contact=args.contact, rule=args.rule, min_hb=args.min_hb)
    pb = res.per_block[["block", "b_m", "h_m", "h_over_b", "k", "eta_M", "eta_e", "ratio", "used", "above_one"]]
    payload = dict(
        eta_mat=res.eta_mat,
        std=res.std,
        n=res.n,
        rule=res.rule,
        contact=res.contact,
        l_c_m=res.l_c_m,
        per_block=pb.to_dict(orient="records"),
        message=res.message,
        status=res.status,
    )
    _emit(args, payload, res.report())
    return 0 if res.status != "failed" else 1


def _run_k_table(args) -> int:
    from ....fitting import k_table

    res = k_table(Path(args.table), args.eta_mat, form=args.form, feasible_only=args.feasible_only, nan=args.nan)
    d = res.to_dict()
    d["per_block"] = [{k: r[k] for k in ("block", "k", "b_bar_m", "feasible")} for r in d["per_block"]]
    _emit(args, d, res.report())
    return 0


def _run_k_predict(args) -> int:
    from ....fitting import KRegression

    if args.coefficients is None:
        reg = KRegression.ceh2018()
    else:
        path = Path(args.coefficients)
        if not path.is_file():
            raise FileNotFoundError(2, "not found", str(path))
        try:
            obj = json.loads(path.read_text(encoding="utf-8"))
        except json.JSONDecodeError as e:
            raise InputError(f"{where(path, e.lineno)}not valid JSON ({e.msg})") from None
        if not isinstance(obj, dict):
            raise InputError(f"{where(path)}expected a JSON object with 'coefficients' or hb2/hb/const/b_cm")
        coefs = obj.get("coefficients", obj)
        if not isinstance(coefs, dict):
            raise InputError(f"{where(path, key='coefficients')}must be an object of name: value")
        reg = KRegression.from_coefficients(
            coefs,
            hb_range=obj.get("hb_range", (math.nan, math.nan)),
            b_cm_range=obj.get("b_cm_range", (math.nan, math.nan)),
        )
    pred = reg.predict(args.hb, args.b_cm / 100.0)
    d = pred.to_dict()
    text = f"k = {pred.k:.4f}, eta_M = {pred.eta_M:.4f}, b_bar = {pred.b_bar_m * 1000:.2f} mm" + (
        f"  [{pred.message}]" if pred.message else ""
    )
    _emit(args, d, text)
    return 0
