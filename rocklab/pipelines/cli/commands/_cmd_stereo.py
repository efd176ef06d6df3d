"""``rocklab stereo``: two-camera 3D tracking of dots or ArUco markers (a GOM Pontos-style rig);
``rocklab calibrate``: one camera's lens.

- ``rocklab stereo calibrate LEFT RIGHT -o stereo.json [--board checkerboard,9x6,0.025]``:
  intrinsics, distortion and relative pose from films, folders of photos or quoted file
  patterns (``'calib/left*.jpg'``) of a board seen by both cameras (photos paired by the number
  in their names); prints the reprojection RMS (px) and the baseline (m). ``--board`` is
  ``checkerboard,COLSxROWS,SQUARE_M`` (inner corners) or ``charuco,COLSxROWS,SQUARE_M,MARKER_M,DICT``
  (squares; default ``charuco,9x6,0.03,0.022,DICT_5X5_100``).
- ``rocklab calibrate FILM_OR_FOLDER --board ... -o lens.json [--every N] [--fix-k3]``: one
  camera's intrinsics and distortion (the lens file ``track.toml`` names in ``[video]
  calibration`` and ``rocklab track init --lens`` writes there); prints fx, fy, their 1-sigma and
  the reprojection RMS. No frame rate is needed.
- ``rocklab stereo track FILM1 FILM2 --calib stereo.json -o tracks.csv [--targets dots|aruco]
  [--fps F] [--no-sync] [--body NAME=P1,...] [--rest ...]``: dots detected and followed (or
  ArUco corners found by id), clock offset estimated (no shared trigger needed), matched
  along epipolar lines (dots) or by name (corners) and triangulated; the targets are
  split into the table (still) and the blocks (moving) and put in a table frame (z up);
  writes ``points.csv`` (``t_s, point, x_m, y_m, z_m``), ``tracks.csv`` and ``audit.json``
  exactly as ``rocklab track3d`` does.
"""

from __future__ import annotations

import math
from pathlib import Path

from ...._errors import InputError

#: ``--board``'s two forms and their corner conventions (rocklab.tracking.calib.parse_board).
BOARD_HELP = (
    "checkerboard,COLSxROWS,SQUARE_M (COLSxROWS = INNER corners, e.g. 9x6 on a board of 10x7 squares) or "
    "charuco,COLSxROWS,SQUARE_M,MARKER_M,DICT (COLSxROWS = squares, e.g. charuco,9x6,0.03,0.022,DICT_5X5_100)"
)


def register(sub):
    """Add ``stereo`` to the ``rocklab`` parser ``sub``."""
    p = sub.add_parser("stereo", help="two-camera 3D dot tracking: calibrate a rig, track a test", description=__doc__)
    p.add_argument("action", choices=("calibrate", "track"), help="calibrate | track")
    p.add_argument("film1", help="camera 1's film (a video file, a folder of frames, a .cih/.mraw or .cine)")
    p.add_argument("film2", help="camera 2's film")
    p.add_argument(
        "-o",
        "--out",
        default=None,
        help="calibrate: stereo.json (default next to FILM1); track: tracks.csv (default next to FILM1)",
    )
    p.add_argument(
        "--board",
        default=None,
        metavar="SPEC",
        help="calibrate: the board, " + BOARD_HELP + " (default charuco,9x6,0.03,0.022,DICT_5X5_100)",
    )
    p.add_argument(
        "--every", type=int, default=None, metavar="N", help="calibrate, films: every N-th frame (default: all)"
    )
    p.add_argument("--calib", default=None, help="track: stereo.json from 'rocklab stereo calibrate'")
    p.add_argument("--fps", type=float, default=None, help="track: frame rate, Hz (default: the containers')")
    p.add_argument(
        "--targets",
        choices=("dots", "aruco"),
        default="dots",
        help="track: bright dots (default) or ArUco markers (each corner a target named M<id>c<k>)",
    )
    p.add_argument("--dictionary", default="DICT_4X4_50", help="track --targets aruco: ArUco dictionary")
    p.add_argument("--no-sync", action="store_true", help="track: the cameras share a trigger (no offset estimated)")
    p.add_argument(
        "--body",
        action="append",
        default=[],
        metavar="NAME=P1,P2,...",
        help="track: bodies by point label (default: still targets = table, moving = block)",
    )
    p.add_argument("--rest", default="auto", metavar="auto|first|last|T0,T1", help="track: the upright rest")
    p.add_argument("--rrd", default=None, metavar="FILE", help="track: also write a Rerun review (see track3d)")
    p.add_argument("--json", action="store_true", help="print a JSON summary on stdout")
    p.add_argument("--progress", action="store_true", help="progress bar on stderr")
    p.set_defaults(func=run)
    _register_calibrate(sub)


def _register_calibrate(sub):
    p = sub.add_parser(
        "calibrate",
        help="one camera's lens (intrinsics, distortion) from pictures of a checkerboard or ChArUco board",
        description=__doc__,
    )
    p.add_argument("source", help="a film, a folder of photos or a quoted pattern such as 'calib/cam*.jpg'")
    p.add_argument("--board", required=True, metavar="SPEC", help="the board: " + BOARD_HELP)
    p.add_argument("-o", "--out", default=None, help="lens file (default: lens.json beside SOURCE)")
    p.add_argument(
        "--every", type=int, default=None, metavar="N", help="films: every N-th frame (default: <= 100 frames)"
    )
    p.add_argument("--fix-k3", action="store_true", help="hold the radial term k3 at 0 (few views, a mild lens)")
    p.add_argument("--json", action="store_true", help="print a JSON summary on stdout")
    p.set_defaults(func=run_calibrate)


def run_calibrate(args) -> int:
    """Run ``rocklab calibrate`` with parsed ``args``; returns the exit status (0 ok)."""
    from ....tracking.calib import calibrate_lens, parse_board
    from .._io_plan import lens_out

    board = parse_board(args.board)
    out = lens_out(args)
    if out.suffix.lower() != ".json":
        raise InputError(f"-o {out}: the lens file is JSON; give e.g. -o lens.json")
    lens = calibrate_lens(args.source, board, every=args.every, fix_k3=args.fix_k3)
    lens.save(out, side=not args.out)
    d = dict(lens.to_dict(), lens_json=str(out))
    sx, sy = lens.sigma_px["fx"], lens.sigma_px["fy"]
    worst = lens.views[max(range(lens.n_views), key=lambda k: lens.view_rms_px[k])]
    lines = [
        f"calibrated from {lens.n_views} of {lens.n_seen} pictures ({lens.board}): fx {lens.K[0, 0]:.2f} +/- {sx:.2g} px, "
        f"fy {lens.K[1, 1]:.2f} +/- {sy:.2g} px, principal point ({lens.K[0, 2]:.1f}, {lens.K[1, 2]:.1f}) px; "
        f"reprojection RMS {lens.rms_px:.3g} px (worst view {worst} {max(lens.view_rms_px):.3g} px); status {lens.status}",
        f"wrote {out}; use it with [video] calibration = \"{out.name}\" in track.toml (or 'rocklab track init --lens {out}')",
    ]
    _emit(args, d, lines)
    return 0


def _board(spec):
    from ....tracking.calib import parse_board

    return None if spec is None else parse_board(spec)


#: Shapes of a ``stereo.json``'s arrays (StereoRig's fields).
_RIG_SHAPES = {"K1": (3, 3), "K2": (3, 3), "R": (3, 3), "T": (3,)}


def _check_rig(rig, path) -> None:
    """A ``stereo.json`` whose arrays have the shapes the triangulation needs (one line otherwise)."""
    import numpy as np

    for name, shape in _RIG_SHAPES.items():
        v = np.asarray(getattr(rig, name))
        if v.shape != shape or not np.all(np.isfinite(v)):
            key = "T_m" if name == "T" else name
            raise InputError(
                f"{path}: '{key}' must be {' x '.join(map(str, shape))} finite numbers (has shape {v.shape}); "
                "make the file with 'rocklab stereo calibrate'"
            )
    for name in ("dist1", "dist2"):
        v = np.asarray(getattr(rig, name)).ravel()
        if v.size not in (4, 5, 8, 12, 14) or not np.all(np.isfinite(v)):
            raise InputError(
                f"{path}: '{name}' must be 4, 5, 8, 12 or 14 finite distortion coefficients (has {v.size}); "
                "make the file with 'rocklab stereo calibrate'"
            )
    size = tuple(rig.size)
    if len(size) != 2 or not all(float(s) > 0 for s in size):
        raise InputError(f"{path}: 'size_px' must be [width, height] in pixels (has {list(size)})")


def run(args) -> int:
    """Run ``rocklab stereo`` with parsed ``args``; returns the exit status (0 ok)."""
    for f in (args.film1, args.film2):
        pattern = args.action == "calibrate" and any(c in f for c in "*?[")
        if not (Path(f).is_file() or Path(f).is_dir() or pattern):  # a folder of frames is a film too
            raise InputError(f"{f}: not found; give the two cameras' films (video files or folders of frames)")
    if args.action == "calibrate":
        return _calibrate(args)
    return _track(args)


def stereo_out(film1) -> Path:
    """``stereo.json`` beside camera 1's film, folder or pattern."""
    return Path(film1).parent / "stereo.json"


def _emit(args, d, lines):
    if args.json:
        from .._cli_base import emit_json

        emit_json(d)
    else:
        print("\n".join(lines))


def _calibrate(args) -> int:
    from ....tracking.stereo import calibrate_stereo

    board = _board(args.board)
    from ...._io import write_json_atomic

    out = Path(args.out) if args.out else stereo_out(args.film1)
    rig = calibrate_stereo(args.film1, args.film2, board, every=args.every)
    write_json_atomic(out, rig.to_dict(), side=not args.out)  # StereoRig.save's file; a default name keeps a user's
    d = dict(rig.to_dict(), stereo_json=str(out))
    _emit(
        args,
        d,
        [
            f"calibrated from {rig.n_frames} board poses seen by both: reprojection RMS "
            f"{rig.rms_px['cam1']:.4g} / {rig.rms_px['cam2']:.4g} px (each camera), "
            f"{rig.rms_px['stereo']:.4g} px (stereo); baseline {rig.baseline_m:.4g} m",
            f"wrote {out}",
        ],
    )
    return 0


def _track(args) -> int:
    import numpy as np

    from ....tracking.rigid import parse_bodies, track_points3d, write_points_csv
    from ....tracking.stereo import load_rig, stereo_point_series, track_dots_stereo
    from .._io_plan import POINTS, stereo_track_outputs
    from ._cmd_track3d import rest_spec, write_track3d_outputs

    if not args.calib:
        raise InputError("rocklab stereo track: give --calib stereo.json (from 'rocklab stereo calibrate')")
    if args.fps is not None and not (math.isfinite(args.fps) and args.fps > 0):
        raise InputError(f"--fps {args.fps}: must be a positive number of frames per second")
    rig = load_rig(args.calib)
    _check_rig(rig, args.calib)
    rest = rest_spec(args.rest)
    out = Path(args.out) if args.out else Path(args.film1).parent / "tracks.csv"
    if args.targets == "aruco":
        from ....tracking.stereo import track_markers_stereo

        sp = track_markers_stereo(
            args.film1, args.film2, rig, dictionary=args.dictionary, fps=args.fps, sync=not args.no_sync
        )
    else:
        sp = track_dots_stereo(args.film1, args.film2, rig, fps=args.fps, sync=not args.no_sync, progress=args.progress)
    series, bodies, notes = stereo_point_series(sp, str(args.film1))
    if args.body:
        bodies = parse_bodies(args.body, series.labels, series.source)
    if not bodies:
        raise InputError(f"{args.film1}: no moving group of targets found; name the block's points with --body")
    res = track_points3d(series, bodies, up="z", rest=rest)
    pts_path = stereo_track_outputs(out)[POINTS]
    write_points_csv(series, pts_path, side=True)
    d = write_track3d_outputs(out, series, res, args.rrd, out_side=not args.out)
    d.update(
        points_csv=str(pts_path),
        sync=None if sp.sync is None else sp.sync.to_dict(),
        bodies={k: list(v) for k, v in bodies.items()},
        median_reprojection_px=float(np.nanmedian(sp.reproj_px)),
    )
    lines = [f"note: {n}" for n in notes]
    if sp.sync is not None:
        lines.append(
            f"clock offset: camera 2 exposes {1e3 * sp.sync.offset_s:.4g} ms after camera 1 "
            f"(± {1e3 * sp.sync.sigma_s:.2g} ms)"
        )
    lines.append(
        f"{len(sp.pairs)} targets matched, median reprojection {d['median_reprojection_px']:.3g} px; "
        f"bodies: " + ", ".join(f"{k} ({len(v)} points)" for k, v in bodies.items())
    )
    for b in res.blocks:
        lines.append(b.audit.report())
    lines.append(f"wrote {pts_path}, {out} and {d['audit_json']} (verdict {d['verdict']})")
    _emit(args, d, lines)
    return 0
