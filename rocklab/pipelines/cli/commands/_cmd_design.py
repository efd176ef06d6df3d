"""``rocklab pulse|oas|design|equivalent``: record pulses, OAS and t_I, pier design, equivalent blocks.

- ``rocklab pulse RECORD [--units g]`` → a_max_m_s2, I_max_m_s, t_p_s (thesis Eq. 16, 25)
- ``rocklab oas RECORD... --slenderness 12 [--levels 80] [--sizes 120] [-o oas.csv] [--plot oas.png]``
- ``rocklab oas FOLDER --slenderness 3,5,8,12 --band -o study.csv [--resume] [--scheduler ADDR]``: the
  thesis's whole record study, a row per record and h/b, resumable after a stop
  → t_I_s, t_I_prime_s, beta, f_min (thesis §5.1.3, §5.3); ``--column N [--impacts K]`` the OAS of a
  column of N blocks (thesis Fig. 43, one record or --pulse); several records run in
  parallel (``--workers``, or ``--scheduler ADDR`` for Dask) and ``-o`` is then the
  summary table ``record, t_p_s, t_I_s, t_I_prime_s, beta, f_min, error``.
- ``rocklab design --height 12 --ag 0.14 --tI 0.7 [--mass-at-top]`` → width_m (Eq. 21/23)
- ``rocklab equivalent block|strut|frame|wall|asym-frame|arch ...`` → p_rad_s, theta_cr_rad,
  lambda, eta, kappa1, kappa2 (DeJong & Dimitrakopoulos 2014)
"""

from __future__ import annotations

import math
import sys

from ...._errors import InputError


from .._cli_base import PULSE_HELP, add_base_motion_args, base_motion_from_args, count, pulse_from_spec
from .._cli_base import emit_json as _emit


def register(sub):
    """Add this module's subcommands (pulse, oas, design, equivalent) to the ``rocklab`` parser ``sub``."""
    for add in (_register_pulse, _register_oas, _register_design, _register_equivalent):
        add(sub).set_defaults(func=run)


def _register_pulse(sub):
    p = sub.add_parser(
        "pulse", help="pulse parameters of a record (a_max, I_max, t_p) and its PGV, PGD, Arias, D5-95, T_v"
    )
    p.add_argument("record", help="the record file (.AT2, CSV t_s,acc_m_s2, two-column text)")
    p.add_argument(
        "--units",
        default=None,
        help="units of a record that states none (g, m/s2, cm/s2); a file's own units win, a conflict is an error",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    return p


def _register_oas(sub):
    p = sub.add_parser("oas", help="Overturning Acceleration Spectrum and t_I of record(s)")
    p.add_argument(
        "record",
        nargs="*",
        help="record files or folders of records (every visible record in them; other files and "
        "subfolders are left out with a note)",
    )
    p.add_argument(
        "--recursive", action="store_true", help="also read the records in the folders' subfolders (at any depth)"
    )
    p.add_argument("--pulse", default=None, metavar="KIND,PEAK,T_P[,N]", help="the OAS of " + PULSE_HELP)
    p.add_argument(
        "--list",
        default=None,
        metavar="FILE",
        help="a text file naming one record per line (relative to its folder; # comments)",
    )
    p.add_argument(
        "--units",
        default=None,
        help="units of records that state none (g, m/s2, cm/s2); a file's own units are kept, "
        "and one record stating other units is an error",
    )
    p.add_argument(
        "--slenderness",
        default="12",
        help="block h/b (default 12); several, comma-separated (3,5,8,12), make a row per record and h/b",
    )
    p.add_argument("--levels", type=int, default=None, help="a_p/a_p,min levels 1..level-max (80; with --column 19)")
    p.add_argument("--level-max", type=float, default=10.0, help="largest a_p/a_p,min level (default 10)")
    p.add_argument("--sizes", type=int, default=None, help="log-spaced R from 1000 m to 0.1 m (120; with --column 49)")
    p.add_argument(
        "--column",
        type=count(1),
        default=None,
        metavar="N",
        help="the OAS of a column of N equal blocks stacked to --slenderness (thesis Fig. 43; one record or --pulse)",
    )
    p.add_argument(
        "--impacts",
        type=count(1),
        default=1,
        help="with --column: consecutive impacts per closing (1 Housner, 2 the thesis's model, 10 'rolling')",
    )
    p.add_argument("--refine", type=count(0), default=10, help="bisection steps on the boundary (10)")
    p.add_argument(
        "--criterion",
        choices=("angle", "fall"),
        default="angle",
        help="overturned when theta reaches alpha (angle, default) or the block falls (fall)",
    )
    p.add_argument("--free", default="energy", help="after the record: energy | none | SECONDS")
    p.add_argument(
        "--search",
        choices=("scan", "contiguous"),
        default="scan",
        help="boundary search: every level of the grid (scan, default) or the first contiguous overturning region",
    )
    p.add_argument("--eta", type=float, default=None, help="restitution (default Housner)")
    p.add_argument(
        "-o",
        "--out",
        default=None,
        help="CSV: OAS boundary (one record) or the record table (several; also written as .parquet)",
    )
    p.add_argument(
        "--plot",
        default=None,
        help="PNG: OAS, transformed OAS, 1/p view (one record), or t_I vs t_p with the thesis's values",
    )
    p.add_argument(
        "--band",
        action="store_true",
        help="t_I, t'_I and beta over an ensemble of grid placements, densities, step, eta and search "
        "(median and 5-95 %% band; 8 OAS per record)",
    )
    p.add_argument("--workers", type=count(1), default=None, help="local processes for several records")
    p.add_argument("--scheduler", default=None, help="Dask distributed scheduler address")
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    p.add_argument(
        "--resume",
        action="store_true",
        help="with -o: go on from the rows an interrupted run of the same command finished "
        "(kept in OUT.journal.json while it runs)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    return p


def _register_design(sub):
    p = sub.add_parser("design", help="pier width for a PGA and t_I (thesis Eq. 21/23)")
    p.add_argument("--height", type=float, required=True, help="pier height H, m")
    p.add_argument("--ag", type=float, required=True, help="design PGA, g")
    p.add_argument("--tI", type=float, required=True, help="replacement impulse duration, s")
    p.add_argument("--mass-at-top", action="store_true", help="mass on top of a weightless pier")
    p.add_argument("--alpha-I", type=float, default=None, help="I_O/(m R^2) (4/3 solid, 1 mass on top)")
    p.add_argument("--cm-ratio", type=float, default=None, help="centre-of-mass height / H")
    p.add_argument("--g", type=float, default=None, help="gravity, m/s^2 (default 9.80665)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    return p


def _register_equivalent(sub):
    p = sub.add_parser(
        "equivalent",
        help="equivalent-block parameters of a rocking mechanism",
        description="Equivalent-block parameters of a rocking mechanism (DeJong & Dimitrakopoulos 2014). "
        "What each mechanism needs: block, strut, frame, wall: --R and --alpha, or --b and --h "
        "(frame: also --gamma; block, frame, wall: --alpha-I); asym-frame: --b --H --H1 --L --h "
        "[--masses]; arch: --beta --thickness --radius; cone: --H --base-radius. A time history "
        "needs --base-motion or --pulse.",
    )
    p.add_argument(
        "mechanism",
        choices=("block", "strut", "frame", "wall", "asym-frame", "arch", "cone"),
        help="the rocking mechanism (DeJong & Dimitrakopoulos 2014; cone: a thin conical shell, a spire)",
    )
    p.add_argument("--R", type=float, help="corner-to-centre distance of the (column/wall) block, m")
    p.add_argument("--alpha", type=float, help="slenderness angle, rad")
    p.add_argument("--b", type=float, help="width b (block) or half-width (asym-frame), m")
    p.add_argument("--h", type=float, help="height h (block) or beam half-depth (asym-frame), m")
    p.add_argument("--alpha-I", type=float, default=4.0 / 3.0, help="I_O/(m R^2) of each block (default 4/3: solid)")
    p.add_argument("--gamma", type=float, default=0.0, help="frame: m_beam / m_columns")
    p.add_argument("--H", type=float, help="asym-frame: half-height of the left column; cone: height, m")
    p.add_argument("--base-radius", type=float, help="cone: radius of the shell's base, m")
    p.add_argument("--H1", type=float, help="asym-frame: half-height of the right column, m")
    p.add_argument("--L", type=float, help="asym-frame: distance between the columns' left faces, m")
    p.add_argument("--masses", type=float, nargs=3, default=(1.0, 1.0, 1.0), help="m_AB m_BC m_CD")
    p.add_argument("--beta", type=float, help="arch inclusion angle, rad")
    p.add_argument("--thickness", type=float, help="arch thickness t_a, m")
    p.add_argument("--radius", type=float, help="arch centre-line radius r_a, m")
    add_base_motion_args(p)
    p.add_argument(
        "--eta",
        type=float,
        default=None,
        help="time history: restitution at every impact (default the mechanism's own, Table I; "
        "the wall, asymmetric frame and arch have none and need it)",
    )
    p.add_argument(
        "--kappa",
        choices=("kappa1", "kappa2"),
        default="kappa1",
        help="time history: scaling of the equivalent blocks, Eq. 19 (kappa1) or Eq. 20 (kappa2)",
    )
    p.add_argument("--phi0", type=float, default=0.0, help="time history: initial rotation, rad (signed)")
    p.add_argument(
        "-o",
        "--output",
        default=None,
        help="time history: write t_s and phi_<model>_rad of the mechanism and its equivalent blocks (CSV)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    return p


# -- handlers -------------------------------------------------------------------------


def run(args) -> int:
    """Run ``rocklab design`` with parsed ``args``; returns the exit status (0 ok)."""
    return {"pulse": run_pulse, "oas": run_oas, "design": run_design, "equivalent": run_equivalent}[args.command](args)


def run_pulse(args) -> int:
    from ....models import load_base_motion, pulse_parameters

    from ....models.spectra import record_measures

    base = load_base_motion(args.record, units=args.units)
    pp = pulse_parameters(base)
    rm = record_measures(base)
    d = pp.to_dict() | {"measures": rm.to_dict()}
    if args.json:
        _emit(d)
    else:
        print(
            f"{pp.name}: a_max = {pp.a_max_m_s2:.4f} m/s2, I_max = {pp.I_max_m_s:.4f} m/s, "
            f"t_p = {pp.t_p_s:.4f} s (lobe {pp.lobe_start_s:.2f}-{pp.lobe_end_s:.2f} s)"
        )
        tv = f"{rm.t_v_s:.4g} s" if math.isfinite(rm.t_v_s) else "outside 0.1-10 s"
        print(
            f"  PGV = {rm.pgv_m_s:.4g} m/s, PGD = {rm.pgd_m:.4g} m (linear baseline removed), Arias = "
            f"{rm.arias_m_s:.4g} m/s, D5-95 = {rm.d5_95_s:.4g} s, velocity-pulse period T_v = {tv}"
        )
    return 0


def _free(v):
    if v in ("energy", "none"):
        return v
    try:
        return float(v)
    except ValueError:
        raise InputError(f"--free {v!r}: use energy, none or a number of seconds") from None


def run_oas(args) -> int:
    from pathlib import Path

    from ...._io import write_frame_atomic
    from ...spectra import h_over_b_values

    hbs = h_over_b_values(str(args.slenderness).split(","))
    if args.resume and not args.out:
        raise InputError(
            "rocklab oas --resume: give the same -o TABLE.csv as the run to resume (its journal is beside it)"
        )
    if len(hbs) > 1 and (args.pulse is not None or args.column is not None):
        raise InputError(
            "rocklab oas: several --slenderness values make a record study; give one with --pulse or --column"
        )
    args.slenderness = hbs if len(hbs) > 1 else hbs[0]
    if args.column is not None:
        return _run_oas_column(args)
    kw = dict(
        levels=80 if args.levels is None else args.levels,
        level_max=args.level_max,
        sizes=120 if args.sizes is None else args.sizes,
        refine=args.refine,
        criterion=args.criterion,
        free=_free(args.free),
        search=args.search,
        eta=args.eta,
    )

    if args.pulse is not None and (args.record or args.list or args.band):
        raise InputError("rocklab oas: --pulse is one base motion; give it without records, --list or --band")
    if not args.record and not args.list and args.pulse is None:
        raise InputError("rocklab oas: give record files, folders of records, --list FILE or --pulse KIND,PEAK,T_P")
    if (
        args.list
        or args.band
        or args.resume
        or isinstance(args.slenderness, list)
        or len(args.record) > 1
        or any(Path(r).is_dir() for r in args.record)
    ):
        return _run_oas_batch(args, kw)
    from ....models import load_base_motion, overturning_spectrum, pulse_parameters

    rec = pulse_from_spec(args.pulse) if args.pulse is not None else load_base_motion(args.record[0], units=args.units)
    o = overturning_spectrum(rec, args.slenderness, **kw)
    if args.out:
        write_frame_atomic(args.out, o.to_frame())
    if args.plot:
        from ...spectra import plot_oas

        plot_oas(o, args.plot)
    d = o.to_dict()
    d["t_p_s"] = pulse_parameters(rec).t_p_s
    if args.json:
        _emit(d)
    else:
        lv, R = o.f_min_at
        print(
            f"{rec.name}: t_I = {o.t_I_s:.4f} s, t'_I = {o.t_I_prime_s:.4f} s, beta = {o.beta:.3f}, "
            f"f_min = {o.f_min_rad_s:.4f} 1/s at a_p/a_p,min = {lv:.3f}, R = {R:.3f} m "
            f"(H/B = {args.slenderness:g})"
        )
    return 0


def _run_oas_column(args) -> int:
    """``rocklab oas REC --column N [--impacts K]``: the OAS of a column (thesis Fig. 43)."""
    from pathlib import Path

    from ...._io import write_frame_atomic
    from ....models import column_overturning_spectrum, load_base_motion

    fixed = {
        "--band": args.band,
        "--list": args.list,
        "--eta": args.eta is not None,
        "--criterion": args.criterion != "angle",
        "--free": args.free != "energy",
    }
    bad = [k for k, v in fixed.items() if v]
    if bad:
        raise InputError(
            f"rocklab oas --column: {', '.join(bad)} apply to a single block (a column's restitution follows "
            "from --impacts, it overturns when a joint's centre of mass passes its pivot); leave them out"
        )
    if args.pulse is not None and args.record:
        raise InputError("rocklab oas --column: give one record or --pulse, not both")
    if args.pulse is None and (len(args.record) != 1 or Path(args.record[0]).is_dir()):
        raise InputError("rocklab oas --column: give one record file (or --pulse KIND,PEAK,T_P)")
    rec = pulse_from_spec(args.pulse) if args.pulse is not None else load_base_motion(args.record[0], units=args.units)
    kw = {k: v for k, v in (("levels", args.levels), ("sizes", args.sizes)) if v is not None}
    o = column_overturning_spectrum(
        rec,
        args.slenderness,
        args.column,
        n_impacts=args.impacts,
        level_max=args.level_max,
        refine=args.refine,
        search=args.search,
        **kw,
    )
    if args.out:
        write_frame_atomic(args.out, o.to_frame())
    if args.plot:
        from ...spectra import plot_oas

        plot_oas(o, args.plot)
    d = o.to_dict()
    if args.json:
        _emit(d)
    else:
        lv, R = o.f_min_at
        print(
            f"{rec.name}: column of {args.column} block(s), {args.impacts} impact(s) per closing, "
            f"H/B = {args.slenderness:g}: t_I = {o.t_I_s:.4f} s, f_min = {o.f_min_rad_s:.4f} 1/s at "
            f"a_p/a_p,min = {lv:.3f}, R = {R:.3f} m (the whole column's p and R); "
            f"{o.options['n_terminated']} run(s) ended by tension or sliding (counted unsafe)"
        )
    return 0


def _run_oas_batch(args, kw) -> int:
    import sys
    from pathlib import Path

    from .... import __version__
    from ...spectra import StudyJournal, expand_records, oas_table

    skipped: list = []
    notes: list = []
    items = expand_records(args.record, args.list, skipped, recursive=args.recursive, notes=notes)
    for n in notes:
        sys.stderr.write(f"rocklab oas: note: {n}\n")
    for f in skipped:
        sys.stderr.write(f"rocklab oas: not reading {f}: an output rocklab wrote (name it to read it as a record)\n")
    if not items:
        raise InputError(f"rocklab oas: no records in {', '.join(args.record) or args.list}; give record files")
    for _, _, err in items:
        if err:
            sys.stderr.write(f"rocklab oas: error: {err}\n")
    journal = None
    if args.out:
        opts = {"oas": kw, "units": args.units, "band": bool(args.band), "rocklab": __version__}
        journal = StudyJournal.open(args.out, opts, resume=args.resume)
        if args.resume:
            sys.stderr.write(
                f"rocklab oas: resuming from {journal.path} ({journal.resumed} finished run(s)); runs of "
                "changed records are done again\n"
            )
    try:
        tab = oas_table(
            items,
            units=args.units,
            slenderness=args.slenderness,
            oas_kwargs=kw,
            workers=args.workers,
            scheduler=args.scheduler,
            progress=not args.no_progress,
            band=args.band,
            journal=journal,
        )
    except BaseException:  # Ctrl-C, SIGTERM, a lost cluster: say where the finished runs are
        if journal is not None and journal.rows:
            sys.stderr.write(
                f"rocklab oas: {len(journal.rows)} finished run(s) kept in {journal.path}; run the same "
                "command with --resume to go on\n"
            )
        raise
    n_hb = len(args.slenderness) if isinstance(args.slenderness, list) else 1
    for (_, _, err), row_err in zip([it for it in items for _ in range(n_hb)], tab["error"]):  # items' order
        if row_err and not err:  # the expansion's errors are printed above
            sys.stderr.write(f"rocklab oas: error: {row_err}\n")
    if args.out:
        _write_study_table(tab, Path(args.out))
        journal.close()
    return _report_oas_batch(args, tab)


def _write_study_table(tab, out) -> None:
    """The record table as CSV (the path given) and Parquet beside it, each atomically."""
    from ...._io import atomic_path, write_frame_atomic

    write_frame_atomic(out, tab, float_format="%.6g")
    with atomic_path(out.with_suffix(".parquet"), side=True) as tmp:
        tab.to_parquet(tmp, index=False)


def _report_oas_batch(args, tab) -> int:
    """Figures, the t_I-t_p regression per h/b (thesis Fig. 53) and the printed or JSON table."""
    from pathlib import Path

    from ....models.spectra import tI_tp_regression

    hbs = args.slenderness if isinstance(args.slenderness, list) else [args.slenderness]
    regs = {}
    for hb in hbs:
        sub = tab[tab["h_over_b"] == hb]
        ok = sub[(sub["error"] == "") & sub["t_I_s"].notna() & sub["t_p_s"].notna()]
        regs[hb] = tI_tp_regression(ok["t_p_s"], ok["t_I_s"]).to_dict() if len(ok) >= 3 else None
        if args.plot:
            from ...spectra import plot_tI_vs_tp

            plot = Path(args.plot)
            if len(hbs) > 1:  # one figure per h/b: OUT_hb12.png
                plot = plot.with_name(f"{plot.stem}_hb{hb:g}{plot.suffix}")
            plot_tI_vs_tp(sub, plot, hb)
    n_bad = int((tab["error"] != "").sum())
    if args.json:
        d = {"records": tab.to_dict(orient="records"), "failed": n_bad, "tI_tp_regression": regs[hbs[0]]}
        if len(hbs) > 1:
            d["tI_tp_regression"] = {f"{hb:g}": r for hb, r in regs.items()}
        _emit(d)
        return 0 if n_bad == 0 else 1
    cols = (
        ["name"]
        + (["h_over_b"] if len(hbs) > 1 else [])
        + ["t_p_s", "t_I_s"]
        + (["t_I_p05_s", "t_I_p95_s"] if args.band else [])
        + ["t_I_prime_s", "beta", "thesis_id", "thesis_t_I_s"]
    )
    print(tab[cols].to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    what = "records" if len(hbs) == 1 else "runs (record x h/b)"
    print(f"{len(tab) - n_bad}/{len(tab)} {what} done" + (f", {n_bad} failed (see above)" if n_bad else ""))
    for hb, reg in regs.items():
        if reg is not None:
            print(
                f"t_I = {reg['slope']:.4g} t_p + {reg['intercept']:.4g} s over {reg['n']} records, "
                f"correlation r = {reg['r']:.4g} (thesis Fig. 53, H/B = {hb:g})"
            )
    return 0 if n_bad == 0 else 1


def run_design(args) -> int:
    from ....blocks import G
    from ....models import required_width, required_width_slender

    g = G if args.g is None else args.g
    c = args.cm_ratio if args.cm_ratio is not None else (1.0 if args.mass_at_top else 0.5)
    aI = args.alpha_I if args.alpha_I is not None else (1.0 if args.mass_at_top else 4.0 / 3.0)
    ag = args.ag * g
    kw = dict(cm_height_ratio=c, alpha_I=aI, g=g)
    d = dict(
        width_m=required_width(args.height, ag, args.tI, exact_icr=True, **kw),
        width_eq31_m=required_width(args.height, ag, args.tI, exact_icr=False, **kw),
        width_slender_m=required_width_slender(args.height, ag, args.tI, **kw),
        width_no_uplift_m=2 * c * args.height * args.ag,
        cm_height_ratio=c,
        alpha_I=aI,
        g_m_s2=g,
    )
    if args.json:
        _emit(d)
    else:
        print(
            f"required width {d['width_m']:.4g} m (Eq. 21 exact; i_cr = 1: {d['width_eq31_m']:.4g} m, "
            f"slender: {d['width_slender_m']:.4g} m, no uplift: {d['width_no_uplift_m']:.4g} m)"
        )
    return 0


def _need(args, *names):
    miss = [n for n in names if getattr(args, n.replace("-", "_")) is None]
    if miss:
        raise InputError(f"equivalent {args.mechanism}: missing --{', --'.join(miss)}")


def _R_alpha(args):
    if args.R is not None and args.alpha is not None:
        return args.R, args.alpha
    if args.b is not None and args.h is not None:
        return 0.5 * math.hypot(args.b, args.h), math.atan2(args.b, args.h)
    raise InputError(f"equivalent {args.mechanism}: give --R and --alpha, or --b and --h (m)")


def run_equivalent(args) -> int:
    from .... import models as m
    from ....blocks import G as G_M_S2
    from ....models import mechanisms as mm

    mech = args.mechanism
    extra = {}
    if mech in ("block", "strut", "frame", "wall"):
        R, a = _R_alpha(args)
        fp = {
            "block": lambda: m.block_parameters(R, a, args.alpha_I),
            "strut": lambda: m.strut_parameters(R, a),
            "frame": lambda: m.frame_parameters(R, a, args.gamma, args.alpha_I),
            "wall": lambda: m.wall_parameters(R, a, args.alpha_I),
        }[mech]()
        out = fp.to_dict()
        if mech == "wall":
            w = mm.wall_mechanism(R, a, alpha_I=args.alpha_I)
            pair = (w, None)
        else:
            # Table I: the strut and the symmetric frame are the block with their own p (alpha_I)
            aI = {"block": args.alpha_I, "strut": 1.0}.get(mech, G_M_S2 / (R * fp.p_rad_s**2))
            pair = (mm.block_mechanism(R, a, aI, eta=fp.eta, name=mech), None)
    elif mech == "cone":
        _need(args, "H", "base-radius")
        R, a, aI = mm.conical_shell_geometry(args.H, args.base_radius)
        fp = mm.conical_shell_parameters(args.H, args.base_radius)
        out = fp.to_dict()
        pair = (mm.block_mechanism(R, a, aI, eta=fp.eta, name="conical-shell"), None)
    elif mech == "asym-frame":
        _need(args, "b", "H", "H1", "L", "h")
        pos, neg = m.asymmetric_frame(args.b, args.H, args.H1, args.L, args.h, *args.masses)
        fp, fpn = pos.parameters(), neg.parameters()
        out = fp.to_dict()
        pair = (pos, neg)
        extra = {"negative": fpn.to_dict()}
    else:
        _need(args, "beta", "thickness", "radius")
        arch, info = m.arch_mechanism(args.beta, args.thickness, args.radius)
        fp = arch.parameters()
        out = fp.to_dict()
        pair = (arch, None)
        extra = {"hinges": list(info["hinges"]), "faces": info["faces"]}
    out.update(extra)
    eq = mm.equivalent_block(fp)
    out["equivalent_block"] = {"b_m": eq.b_m, "h_m": eq.h_m, "match": "uplift"}
    base = base_motion_from_args(args)
    if base is None:
        for opt in ("eta", "output"):
            if getattr(args, opt) is not None:
                raise InputError(f"equivalent {mech}: --{opt} is for a time history; add --base-motion FILE")
    else:
        out["time_history"] = _equivalent_history(args, mech, base, pair)
    if args.json:
        _emit(out)
    else:
        keys = ("p_rad_s", "theta_cr_rad", "lambda", "lambda_lin", "eta", "kappa1", "kappa2", "phi_cr_rad")

        def line(d):
            # a mechanism without a restitution of its own (the paper gives none) says so, not "nan"
            return ", ".join(
                f"{k} = none (give --eta)" if k == "eta" and not math.isfinite(d[k]) else f"{k} = {d[k]:.5g}"
                for k in keys
            )

        print(f"{mech}: " + line(out))
        if "negative" in out:
            print("negative direction: " + line(out["negative"]))
        e = out["equivalent_block"]
        print(
            f"equivalent block for the OAS and the design check: b = {e['b_m']:.4g} m, h = {e['h_m']:.4g} m "
            "(the same p; tan(alpha) = lambda, the exact uplift)"
        )
        for name, r in out.get("time_history", {}).get("models", {}).items():
            over = (
                f"overturned at {r['t_overturn_s']:.4g} s" if r["overturned"] else f"peak {r['peak_ratio']:.4g} phi_cr"
            )
            print(f"  {name:9s}: {r['n_impacts']} impacts, {over}, status {r['status']}")
            if r["status"] == "falling":
                print(f"rocklab equivalent: note: {name}: {r['message']}", file=sys.stderr)
    sys.stdout.flush()
    return 0


def _equivalent_history(args, mech: str, base, pair) -> dict:
    """The mechanism and its equivalent blocks under ``base`` (DeJong & Dimitrakopoulos Fig. 14)."""
    from ...._io import write_frame_atomic
    from ....models import mechanisms as mm

    pos, neg = pair
    hist = mm.mechanism_time_histories(pos, base, eta=args.eta, negative=neg, phi0_rad=args.phi0, kappa=args.kappa)
    if args.output:
        import pandas as pd

        cols = {"t_s": base.t_s}
        for name, r in hist.items():
            cols[f"phi_{name}_rad"] = r.phi_rad
        write_frame_atomic(args.output, pd.DataFrame(cols))
    return {
        "base_motion": base.name,
        "eta": next(iter(hist.values())).eta,
        "kappa": args.kappa,
        "models": {name: r.to_dict() for name, r in hist.items()},
    }
