"""Every command's input and output files, resolved before any work.

:func:`io_plan` lists, for the parsed arguments of a command, the files it reads
(named on the command line, named in a config, read inside an input folder) and
the files it writes (named on the command line, default names, side files). The
CLI passes them to :func:`rocklab._inputs.check_outputs_not_inputs` before the
command starts, so no output ever replaces an input.

The default names and side files listed here are the ones the commands write;
``tests/test_fuzz_corpus.py`` checks each pairing on real inputs.
"""

from __future__ import annotations

from pathlib import Path

__all__ = [
    "io_plan",
    "import_output",
    "track_outputs",
    "track3d_outputs",
    "stereo_track_outputs",
    "TABLE",
    "AUDIT",
    "POINTS",
]

#: Labels of the side files (keys of the ``*_outputs`` dicts; they name the file in error messages).
TABLE = "the table CSV written beside -o"
AUDIT = "the audit.json written beside -o"
POINTS = "the points.csv written beside -o"


def track_outputs(out: Path) -> dict[str, Path]:
    """``rocklab track``'s tracks CSV and its table side file."""
    return {"-o": out, TABLE: out.with_name(out.stem + "_table.csv")}


def track3d_outputs(out: Path) -> dict[str, Path]:
    """``rocklab track3d``'s tracks CSV and its ``audit.json`` side file."""
    return {"-o": out, AUDIT: out.with_name("audit.json")}


def stereo_track_outputs(out: Path) -> dict[str, Path]:
    """``rocklab stereo track``'s outputs: tracks CSV, ``audit.json`` and ``points.csv`` beside it."""
    return {**track3d_outputs(out), POINTS: out.with_name("points.csv")}


def _opt(v) -> Path | None:
    return Path(v) if v else None


def _video(label, path) -> list:
    from ..._inputs import sequence_files

    return [(label, p) for p in sequence_files(path)]


def _track_config_inputs(cfg_path: Path) -> tuple[list, object]:
    """The config and the calibration file it names; the parsed config (None when missing)."""
    if not cfg_path.is_file():
        return [], None
    from ...config import load_track_config

    cfg = load_track_config(cfg_path)
    return [("config", cfg_path)] + [("[video] calibration of the config", p) for p in cfg.named_files], cfg


def _track(args):
    if args.video in ("init", "preview"):
        if args.video2 is None:
            return [], []
        video = Path(args.video2)
        ins = _video("video", video)
        if args.video == "init":
            out = _opt(args.out) or video.parent / "track.toml"
            preview = _opt(args.preview) or out.with_name(out.stem + "_init.png")
            lens = _opt(getattr(args, "lens", None))
            return ins + ([("--lens", lens)] if lens is not None else []), [("-o", out), ("--preview", preview)]
        cfg_ins, _ = _track_config_inputs(_opt(args.config) or video.parent / "track.toml")
        return ins + cfg_ins + _fixes(args), [("-o", _opt(args.out) or video.parent / "track_preview.png")]
    video = Path(args.video)
    cfg_ins, cfg = _track_config_inputs(_opt(args.config) or video.parent / "track.toml")
    outs = track_outputs(_opt(args.out) or video.parent / "tracks.csv")
    if cfg is None or cfg.table is None:
        outs.pop(TABLE)
    return _video("video", video) + cfg_ins + _fixes(args), [
        *outs.items(),
        ("--plot", _opt(getattr(args, "plot", None))),
    ]


def _fixes(args) -> list:
    f = _opt(getattr(args, "corrections", None))
    return [] if f is None else [("--corrections", f)]


def _track3d(args):
    src = Path(args.points)
    outs = track3d_outputs(_opt(args.out) or src.parent / "tracks.csv")
    return [("points", src)], [*outs.items(), ("--rrd", _opt(args.rrd))]


def import_output(path: Path, tool: str) -> Path:
    """``rocklab import``'s default output beside FILE: ``points.csv`` (DLTdv) or ``tracks.csv``."""
    return path.parent / ("points.csv" if tool == "dltdv" else "tracks.csv")


def _import(args):
    from ...tracking.imports import detect_tool

    src = Path(args.file)
    ins = [("file", src)] + ([("--coefs", Path(args.coefs))] if args.coefs else [])
    if args.out:
        return ins, [("-o", Path(args.out))]
    try:
        tool = detect_tool(src) if args.tool == "auto" else args.tool
    except Exception:  # noqa: BLE001 - an unknown file is reported by the command itself
        return ins, []
    return ins, [("-o", import_output(src, tool))]


def _stereo(args):
    f1 = Path(args.film1)
    ins = [("film", f1), ("film", Path(args.film2))]
    if args.action == "calibrate":
        return ins, [("-o", _opt(args.out) or f1.parent / "stereo.json")]
    if args.calib:
        ins.append(("calibration --calib", Path(args.calib)))
    outs = stereo_track_outputs(_opt(args.out) or f1.parent / "tracks.csv")
    return ins, [*outs.items(), ("--rrd", _opt(args.rrd))]


def lens_out(args) -> Path:
    """Where ``rocklab calibrate`` writes its lens file: ``-o``, else ``lens.json`` beside the source."""
    return Path(args.out) if args.out else Path(args.source).parent / "lens.json"


def _calibrate(args):
    return [("source", Path(args.source))], [("-o", lens_out(args))]


def _imu(args):
    from ..._outdir import rocklab_wrote
    from ...tracking.imu import imu_log_files

    outs = [("-o", _opt(args.out)), ("--plot", _opt(getattr(args, "plot", None)))]
    if not any(p for _, p in outs):
        return [], []
    ins = [("IMU log", p) for p in imu_log_files(args.path)]
    # the rest of a log's export (a folder given, or the x-IMU GUI's <base>_*.csv family) is the
    # user's data too, read or not; an earlier output of rocklab's there is not
    given = Path(args.path)
    if given.is_dir():
        ins += [("file of the IMU log folder", p) for p in given.iterdir() if p.is_file() and not rocklab_wrote(p)]
    elif ins and "_" in ins[0][1].name:
        base = ins[0][1].name.rsplit("_", 1)[0]
        ins += [
            ("file of the IMU log's export", p)
            for p in ins[0][1].parent.glob(base + "_*")
            if p.is_file() and not rocklab_wrote(p)
        ]
    return ins, outs


def _base_motion(args) -> list:
    return [("record --base-motion", Path(args.base_motion))] if getattr(args, "base_motion", None) else []


def _simulate(args):
    return _base_motion(args), [("-o", _opt(args.output))]


def _column(args):
    return _base_motion(args), [("-o", _opt(args.output)), ("--maps-png", _opt(args.maps_png))]


def _oas(args):
    from ..spectra import expand_records

    ins = []
    if args.list:
        ins.append(("list --list", Path(args.list)))
    try:
        items = expand_records(args.record, args.list, recursive=getattr(args, "recursive", False))
    except Exception:  # noqa: BLE001 - an unreadable list is reported by the command itself
        items = [(None, r, "") for r in args.record]
    ins += [("record", Path(p)) for _, p, _ in items]
    outs = [("-o", _opt(args.out)), ("--plot", _opt(args.plot))]
    batch = args.list or args.band or len(args.record) > 1 or any(Path(r).is_dir() for r in args.record)
    if batch and args.out:
        outs.append(("the .parquet copy of -o", Path(args.out).with_suffix(".parquet")))
    return ins, outs


_PLANS = {
    "track": _track,
    "track3d": _track3d,
    "import": _import,
    "stereo": _stereo,
    "calibrate": _calibrate,
    "imu": _imu,
    "simulate": _simulate,
    "column": _column,
    "oas": _oas,
}


def io_plan(args) -> tuple[list, list]:
    """``(inputs, outputs)``: the ``(label, path)`` pairs of the files command ``args`` reads and writes."""
    fn = _PLANS.get(args.command)
    return fn(args) if fn is not None else ([], [])
