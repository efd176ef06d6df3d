"""``rocklab synth``: render a synthetic lab session with exactly known truth."""

from __future__ import annotations

import sys

from ...._errors import InputError


def register(sub):
    """Add this module's subcommand(s) to the ``rocklab`` parser ``sub``."""
    p = sub.add_parser(
        "synth",
        help="render a synthetic lab session (video, truth, IMU logs, configs)",
        description="Simulate rocking blocks and render a lab session: video.mkv (FFV1 lossless), "
        "video.mp4, truth.csv, track.toml, experiment.toml, imu/<object>/ x-IMU logs, "
        "session.json. Deterministic for a seed.",
    )
    p.add_argument("--out", required=True, metavar="DIR", help="output folder (new or empty)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--blocks", type=int, choices=(1, 3), default=1, help="number of blocks")
    p.add_argument(
        "--layout",
        choices=("column", "side"),
        default=None,
        help="with --blocks 3: stacked column (default when the column model is "
        "available) or independent blocks side by side",
    )
    p.add_argument(
        "--table",
        choices=("none", "sine", "record"),
        default="none",
        help="none: free rocking after a thread-burn release; sine: 0.6 s / 45 mm pulse; "
        "record: an earthquake record scaled to the table stroke",
    )
    p.add_argument(
        "--record",
        metavar="FILE",
        default=None,
        help="record for --table record (.AT2 or CSV; default: bundled El Centro 1940)",
    )
    p.add_argument("--fps", type=float, default=None, help="frame rate, Hz (default 50; 150 with --points3d)")
    p.add_argument("--size", default="1920x1080", help="frame size WxH, px (default 1920x1080)")
    p.add_argument(
        "--targets",
        choices=("aruco", "dots", "edges", "markerless"),
        default=None,
        help="target style (default aruco; with --stereo: dots, or aruco)",
    )
    p.add_argument(
        "--duration",
        type=float,
        default=None,
        metavar="S",
        help="video length, s (default: until at rest + 0.6 s, at most 12 s)",
    )
    p.add_argument(
        "--occlusion", default=None, metavar="T0,T1", help="hide block_1 behind a dark patch from T0 to T1 s"
    )
    p.add_argument(
        "--hand", default=None, metavar="T0,T1", help="a hand reaches down over the top of block_1 from T0 to T1 s"
    )
    p.add_argument("--rolling-shutter", action="store_true", help="rolling-shutter readout")
    p.add_argument(
        "--exposure",
        type=float,
        default=None,
        metavar="S",
        help="shutter time, s (default half a frame period; 0: no motion blur)",
    )
    p.add_argument("--noise", type=float, default=1.0, metavar="DN", help="sensor noise sigma, grey levels (default 1)")
    p.add_argument(
        "--flicker",
        type=float,
        default=0.0,
        metavar="A",
        help="exposure flicker, relative amplitude 0-0.5 (automatic exposure hunting under mains light; default 0)",
    )
    p.add_argument(
        "--texture",
        choices=("procedural", "photo"),
        default="procedural",
        help="surfaces from synthetic noise (default) or photographs: a brick wall, gravel-like stone on "
        "markerless blocks (CC0, shipped with rocklab)",
    )
    p.add_argument("--no-imu", action="store_true", help="do not write IMU logs")
    p.add_argument(
        "--uncalibrated",
        action="store_true",
        help="leave the camera matrix, distortion and plane homography out of track.toml (they stay in session.json)",
    )
    p.add_argument("--force", action="store_true", help="replace a non-empty --out folder")
    p.add_argument("--json", action="store_true", help="print one JSON object with the paths")
    p.add_argument("--progress", action="store_true", help="progress bar on stderr")
    g = p.add_argument_group("3D points (a motion-capture export instead of a video)")
    g.add_argument(
        "--points3d",
        action="store_true",
        help="write points.csv, points.c3d and truth.csv of a free-rocking block with dot targets",
    )
    g.add_argument("--up", default="z", help="the rig's vertical axis (default z)")
    g.add_argument("--slide", default=None, metavar="K,MM", help="slide the block by MM mm at impact K")
    g.add_argument("--jump", default=None, metavar="K,MM", help="a jump of MM mm at impact K")
    g.add_argument("--twist", default=None, metavar="K,DEG", help="twist the block by DEG deg at impact K")
    g.add_argument("--double-impact", type=int, default=None, metavar="K", help="a bounce at impact K")
    g.add_argument(
        "--stereo",
        action="store_true",
        help="two camera films of dot targets (and the ChArUco calibration films) instead of points; "
        "--size (default 2400x1728), --fps (default 150), and the events above apply",
    )
    g.add_argument("--offset-ms", type=float, default=2.7, help="--stereo: camera 2's clock lag, ms (default 2.7)")
    p.set_defaults(func=run)


def _event(spec, option, scale):
    if spec is None:
        return None
    try:
        k, v = spec.split(",")
        return int(k), float(v) * scale
    except ValueError:
        raise InputError(f"{option} {spec!r}: give K,VALUE (impact number, size), e.g. 3,1.0") from None


def _run_stereo(args, out, events) -> int:
    import shutil

    from ...._outdir import publish_dir, stage_dir
    from ....synth import synth_stereo
    from ....synth import parse_size

    size = parse_size(args.size if args.size != "1920x1080" else "2400x1728")
    tmp = stage_dir(out)
    try:
        if args.targets not in (None, "dots", "aruco"):
            raise ValueError(f"--targets {args.targets}: a stereo session has dots or aruco targets")
        r = synth_stereo(
            tmp,
            size=size,
            fps=args.fps or 150.0,
            f_px=1.25 * size[0],
            offset_s=args.offset_ms * 1e-3,
            seed=args.seed,
            noise_dn=args.noise,
            duration_s=args.duration,
            targets=args.targets or "dots",
            **events,
        )
        publish_dir(tmp, out, command="synth")
    except ValueError as e:
        shutil.rmtree(tmp, ignore_errors=True)
        raise InputError(f"rocklab synth --stereo: {e}") from None
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    d = {
        "out_dir": str(out),
        "files": sorted(p.name for p in r["paths"].values()),
        "frames": int(r["t_s"].size),
        "size": list(size),
        "offset_s": r["offset_s"],
        "injected": r["session"].injected,
    }
    if args.json:
        from .._cli_base import emit_json

        emit_json(d)
    else:
        sys.stdout.write(
            f"wrote two {size[0]}x{size[1]} films of {d['frames']} frames, the calibration films and "
            f"truth to {out}; next: rocklab stereo calibrate {out / 'calib_cam1.mkv'} "
            f"{out / 'calib_cam2.mkv'}, then rocklab stereo track {out / 'cam1.mkv'} "
            f"{out / 'cam2.mkv'} --calib {out / 'stereo.json'}\n"
        )
    return 0


def _run_points3d(args) -> int:
    import math
    import shutil

    from ...._outdir import check_output_dir, publish_dir, stage_dir
    from ....synth import synth_points3d

    out = check_output_dir(args.out, force=args.force)
    if out.is_dir() and any(out.iterdir()) and not args.force:
        raise InputError(f"--out {out}: folder is not empty; choose a new --out or pass --force")
    events = dict(
        slide=_event(args.slide, "--slide", 1e-3),
        jump=_event(args.jump, "--jump", 1e-3),
        twist=_event(args.twist, "--twist", math.pi / 180.0),
        double_impact=args.double_impact,
    )
    if args.stereo:
        return _run_stereo(args, out, events)
    try:
        s = synth_points3d(rate_hz=args.fps or 150.0, seed=args.seed, up=args.up, **events)
    except ValueError as e:
        raise InputError(f"rocklab synth --points3d: {e}; choose an earlier impact") from None
    tmp = stage_dir(out)
    try:
        paths = s.write(tmp)
        publish_dir(tmp, out, command="synth")
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    d = {
        "out_dir": str(out),
        "files": sorted(p.name for p in paths.values()),
        "samples": int(s.series.t_s.size),
        "rate_hz": s.series.rate_hz,
        "impacts": int(s.impacts_t_s.size),
        "bodies": {k: list(v) for k, v in s.bodies.items()},
        "injected": s.injected,
    }
    if args.json:
        from .._cli_base import emit_json

        emit_json(d)
    else:
        body = " ".join(f"--body {k}={','.join(v)}" for k, v in s.bodies.items())
        sys.stdout.write(
            f"wrote {d['samples']} samples at {d['rate_hz']:.4g} Hz ({d['impacts']} impacts) to "
            f"{out}; track with: rocklab track3d {out / 'points.csv'} {body} --up={args.up}\n"
        )
    return 0


def run(args) -> int:
    """Run ``rocklab synth`` with parsed ``args``; returns the exit status (0 ok)."""
    from ....synth import synth_session
    from ....synth import parse_size

    if args.points3d or args.stereo:
        return _run_points3d(args)
    if args.fps is None:
        args.fps = 50.0
    if args.targets is None:
        args.targets = "aruco"

    size = parse_size(args.size)
    occ = None
    if args.occlusion and args.hand:
        raise InputError("--occlusion and --hand: give one of them (one occluder per session)")
    for flag, text, kind in (("--occlusion", args.occlusion, "patch"), ("--hand", args.hand, "hand")):
        if not text:
            continue
        try:
            t0, t1 = (float(v) for v in text.split(","))
        except ValueError:
            raise InputError(f"{flag}={text!r}: give T0,T1 in seconds, e.g. 1.0,2.0") from None
        if not t1 > t0:
            raise InputError(f"{flag}={text!r}: T1 must be after T0")
        occ = {"object": "block_1", "t0_s": t0, "t1_s": t1, "kind": kind}
    if args.record is not None and args.table != "record":
        raise InputError("--record is only used with --table record; add --table record")
    s = synth_session(
        args.out,
        seed=args.seed,
        blocks=args.blocks,
        table=args.table,
        fps=args.fps,
        size=size,
        targets=args.targets,
        duration_s=args.duration,
        occlusion=occ,
        rolling_shutter=args.rolling_shutter,
        record=args.record,
        imu=not args.no_imu,
        layout=args.layout,
        calibrated=not args.uncalibrated,
        force=args.force,
        exposure_s=args.exposure,
        noise_dn=args.noise,
        flicker=args.flicker,
        texture=args.texture,
        progress=args.progress,
    )
    d = s.to_dict()
    if args.json:
        from .._cli_base import emit_json

        emit_json(d)
    else:
        sys.stdout.write(
            f"wrote {d['n_frames']} frames ({d['size'][0]}x{d['size'][1]}, {d['fps']:g} fps) "
            f"and truth for {', '.join(d['objects'])} to {d['out_dir']} "
            f"in {d['render_s']:.1f} s\n"
        )
    return 0
