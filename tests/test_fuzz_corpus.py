"""A corpus of bad and odd inputs across every reader and command.

Each case builds its input files in a fresh folder and runs the CLI in-process.
Every case asserts: the exit status, no Python traceback, at most one error line
(naming what is wrong), no partial output or staging leftovers, and for the
inputs that used to give a silently wrong result: the warning code on stderr.

Expected outcomes: ``("error", "words")`` exit 2 with the words in the one error
line; ``("warn", "W-CODE")`` exit 0 with that warning; ``("ok", None)`` exit 0
and no warning at all (odd but valid input: no false alarm); ``("fail", words)``
exit 1 (the command ran, its result failed, and says so).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from rocklab import Block
from rocklab.models import simulate

CASES: list[tuple[str, object, tuple]] = []


def case(name, expect, kind=None):
    """Register ``fn(tmp) -> argv`` as a corpus case."""

    def deco(fn):
        CASES.append((name, fn, (expect, kind)))
        return fn

    return deco


def many(prefix, items, expect_of):
    """Register one case per ``(suffix, fn, expect, kind)``."""
    for suffix, fn, expect, kind in items:
        CASES.append((f"{prefix}-{suffix}", fn, (expect, kind)))


# -- records: `rocklab pulse FILE` ---------------------------------------------------------------
SINE = 0.1 * np.sin(np.linspace(0, 12, 200))


def at2(
    values=SINE,
    units="ACCELERATION TIME SERIES IN UNITS OF G",
    npts=None,
    dt=".0100",
    station="Imperial Valley-02, El Centro",
    fmt="{: .7E}",
    tail=None,
):
    toks = [fmt.format(v) for v in values]
    if tail is not None:
        toks[-1] = tail
    rows = [" ".join(toks[i : i + 5]) for i in range(0, len(toks), 5)]
    return (
        "\n".join(
            [
                "PEER NGA STRONG MOTION DATABASE RECORD",
                station,
                units,
                f"NPTS= {npts if npts is not None else len(values):6d}, DT=   {dt} SEC,",
            ]
            + rows
        )
        + "\n"
    )


def _rec(text, name="r.AT2", binary=False):
    def build(tmp):
        p = tmp / name
        (p.write_bytes if binary else p.write_text)(text)
        return ["pulse", p, "--json"]

    return build


many(
    "record",
    [
        ("empty", _rec(""), "error", "empty"),
        ("binary", _rec(b"\x00\x01\x02NPTS=3" * 50, binary=True), "error", "binary"),
        ("header-only", _rec(at2(values=[])[:200], "h.AT2"), "error", "0 samples|NPTS"),
        ("npts-mismatch", _rec(at2(npts=300)), "error", "NPTS=300"),
        ("dt-zero", _rec(at2(dt="0.0")), "error", "DT"),
        ("dt-negative", _rec(at2(dt="-.01")), "error", "DT"),
        ("letters", _rec(at2(tail="abc")), "error", "not a number"),
        ("velocity", _rec(at2(units="VELOCITY TIME SERIES IN UNITS OF CM/S")), "error", "velocity"),
        ("displacement", _rec(at2(units="DISPLACEMENT TIME SERIES IN UNITS OF CM")), "error", "displacement"),
        ("velocity-units", _rec(at2(units="TIME SERIES IN UNITS OF CM/SEC")), "error", "velocity"),
        ("unknown-units", _rec(at2(units="TIME SERIES IN UNITS OF FURLONGS")), "error", "unknown units"),
        ("two-units", _rec(at2(units="UNITS OF G   and also UNITS OF CM/S/S")), "error", "two units"),
        ("cut-token", _rec(at2(tail="-.17901")), "error", "cut off"),
        ("galway", _rec(at2(station="Galway, Ireland")), "ok", None),
        ("portugal", _rec(at2(station="Portugal GAL station, CM/S")), "ok", None),
        ("cm-s2", _rec(at2(units="UNITS OF CM/S/S", values=SINE * 981)), "ok", None),
        ("old-style", _rec(at2(units="The units are (g)", fmt="{:10.5f}")), "ok", None),
        ("no-units-field", _rec(at2(units="a record without a units line")), "ok", None),
        ("pga-60g", _rec(at2(values=600 * SINE)), "warn", "W-RECORD-PGA"),
        ("dt-0.5", _rec(at2(dt=".5000")), "warn", "W-RECORD-DT"),
        ("two-samples", _rec(at2(values=[0.1, -0.1])), "error", "needs at least 16"),
        ("all-zero", _rec(at2(values=np.zeros(50))), "error", "all zeros"),
        ("nan", _rec(at2(tail="NaN")), "error", "NaN"),
        ("csv-no-time", _rec("a,b\n1,2\n2,3\n", "r.csv"), "error", "t_s"),
        ("csv-no-acc", _rec("t_s,x\n0,1\n0.01,2\n", "r.csv"), "error", "acceleration column"),
        ("csv-text", _rec("t_s,acc_g\n0,1\n0.01,oops\n", "r.csv"), "error", "non-numeric"),
        ("csv-decreasing", _rec("t_s,acc_g\n0,1\n0.02,2\n0.01,3\n", "r.csv"), "error", "does not increase"),
        ("csv-duplicate", _rec("t_s,acc_g\n0,1\n0.01,2\n0.01,3\n", "r.csv"), "error", "does not increase"),
        (
            "csv-gap",
            _rec(
                "t_s,acc_g\n" + "\n".join(f"{t:.2f},{math.sin(t)}" for t in list(np.arange(0, 1, 0.01)) + [1.5, 1.51]),
                "r.csv",
            ),
            "error",
            "non-uniform",
        ),
        ("cols-no-units", _rec("0 0.1\n0.01 0.2\n", "r.txt"), "error", "units"),
        ("cols-ragged", _rec("0 0.1\n0.01 0.2 5\n", "r.txt"), "error", "columns"),
        ("cols-text", _rec("0 0.1\n0.01 abc\n", "r.txt"), "error", "not numeric"),
        ("missing-file", lambda tmp: ["pulse", tmp / "nope.AT2"], "error", "not found"),
        ("folder", lambda tmp: ["pulse", tmp], "error", "is a folder"),
    ],
    None,
)


def _zero_sine(tmp):
    t = np.arange(0, 4, 0.001)
    a = np.sin(2 * np.pi * t)
    a[::500] = 0.0
    p = tmp / "s.csv"
    pd.DataFrame({"t_s": t, "acc_g": a}).to_csv(p, index=False)
    return ["pulse", p, "--json"]


case("record-exact-zero-crossings", "ok")(_zero_sine)


# -- simulate: numbers ---------------------------------------------------------------------------
def _sim(*extra, width=0.045, height=0.2025):
    return lambda tmp: ["simulate", "--width", width, "--height", height, *extra]


many(
    "simulate",
    [
        ("width-0", _sim(width=0), "error", "width"),
        ("width-neg", _sim(width=-1), "error", "width"),
        ("width-nan", _sim(width="nan"), "error", "width"),
        ("width-inf", _sim(width="inf"), "error", "width"),
        ("width-text", _sim(width="abc"), "error", "invalid float"),
        ("height-0", _sim(height=0), "error", "height"),
        ("theta0-alpha", _sim("--theta0", 0.3), "error", "alpha"),
        ("theta0-nan", _sim("--theta0", "nan"), "error", "theta0"),
        ("dt-1", _sim("--theta0", 0.05, "--dt", 1), "error", "too coarse"),
        ("dt-neg", _sim("--theta0", 0.05, "--dt", -1e-4), "error", "dt"),
        ("dt-coarse", _sim("--theta0", 0.05, "--dt", 0.005, "--duration", 3), "warn", "W-SIM-DT"),
        ("nano-block", _sim("--theta0", 1e-10, width=1e-9, height=2e-9), "error", "too coarse"),
        ("duration-neg", _sim("--theta0", 0.05, "--duration", -3), "error", "duration"),
        ("duration-huge", _sim("--theta0", 0.05, "--duration", 1e9), "error", "GiB of memory"),
        ("output-dt-small", _sim("--theta0", 0.05, "--output-dt", 1e-5), "error", "output_dt"),
        ("constant-no-eta", _sim("--theta0", 0.05, "--restitution", "constant"), "error", "--eta"),
        ("eta-2", _sim("--theta0", 0.05, "--restitution", "constant", "--eta", 2), "error", "eta"),
        ("bad-law", _sim("--restitution", "magic"), "error", "invalid choice"),
        ("scale-no-base", _sim("--scale-pga", 0.3), "error", "--base-motion"),
        ("base-missing", _sim("--base-motion", "nope.AT2"), "error", "not found"),
        (
            "units-bad",
            lambda tmp: [
                "simulate",
                "--width",
                0.045,
                "--height",
                0.2,
                "--base-motion",
                _write(tmp / "r.txt", "0 0.1\n0.01 0.2\n0.02 0.1\n"),
                "--units",
                "furlong",
            ],
            "error",
            "unknown acceleration unit",
        ),
        (
            "out-is-dir",
            lambda tmp: ["simulate", "--width", 0.045, "--height", 0.2, "--theta0", 0.05, "-o", tmp],
            "error",
            "is a folder",
        ),
        (
            "out-under-file",
            lambda tmp: [
                "simulate",
                "--width",
                0.045,
                "--height",
                0.2,
                "--theta0",
                0.05,
                "-o",
                _write(tmp / "f", "x") / "o.csv",
            ],
            "error",
            "is a file",
        ),
        ("free-ok", _sim("--theta0", 0.05, "--duration", 2, "--json"), "ok", None),
        ("zero-motion", _sim("--duration", 1, "--json"), "ok", None),
    ],
    None,
)


def _write(p: Path, text: str) -> Path:
    p.write_text(text)
    return p


# -- column -----------------------------------------------------------------------------------------
def _col(*extra):
    return lambda tmp: ["column", *extra]


many(
    "column",
    [
        ("no-blocks", _col("--theta0", 0.05), "error", "blocks"),
        ("bad-spec", _col("--blocks", "0.1by0.2", "--theta0", 0.01), "error", "WIDTHxHEIGHT"),
        ("neg-size", _col("--blocks=-0.1x0.2", "--theta0", 0.01), "error", "positive|WIDTHxHEIGHT"),
        ("neg-size-argparse", _col("--blocks", "-0.1x0.2", "--theta0", 0.01), "error", "expected one argument"),
        ("theta0-alpha", _col("--blocks", "0.1x0.2,0.1x0.2", "--theta0", "0.6,0.6"), "error", "alpha"),
        ("dt-0.5", _col("--blocks", "0.1x0.2,0.1x0.2", "--theta0", "0.05,0.05", "--dt", 0.5), "error", "too coarse"),
        ("theta-count", _col("--blocks", "0.1x0.2,0.1x0.2", "--theta0", "0.05,0.05,0.05"), "error", "theta0"),
        ("cut-big", _col("--blocks", "0.1x0.2", "--theta0", 0.05, "--cut", 0.06), "error", "cut"),
        ("nothing-moves", _col("--blocks", "0.1x0.2"), "error", "--theta0"),
        (
            "duration-huge",
            lambda tmp: [
                "column",
                "--blocks",
                "0.1x0.2,0.1x0.2",
                "--theta0",
                "0.02,0.02",
                "--duration",
                1e9,
                "-o",
                tmp / "c.csv",
            ],
            "error",
            "GiB of memory",
        ),
        ("ok", _col("--blocks", "0.1x0.2,0.1x0.2", "--theta0", "0.02,0.02", "--duration", 1, "--json"), "ok", None),
    ],
    None,
)


# -- IMU -----------------------------------------------------------------------------------------------
IMU_HEAD = (
    "Timestamp (us),Gyroscope X (deg/s),Gyroscope Y (deg/s),Gyroscope Z (deg/s),"
    "Accelerometer X (g),Accelerometer Y (g),Accelerometer Z (g)"
)


def _imu_rows(n=1024, rate=256.0, t0=19150794):
    t = t0 + np.rint(np.arange(n) / rate * 1e6).astype(np.int64)
    return [f"{ti},0.01,-0.02,0.03,0.001,0.002,1.0" for ti in t]


def _imu(text, name="Inertial.csv", extra=()):
    def build(tmp):
        d = tmp / "log"
        d.mkdir()
        (d / name).write_text(text) if isinstance(text, str) else (d / name).write_bytes(text)
        return ["imu", d, "--json", *extra]

    return build


ROWS = _imu_rows()
many(
    "imu",
    [
        ("empty", _imu(""), "error", "empty"),
        ("header-only", _imu(IMU_HEAD + "\n"), "error", "no data rows"),
        (
            "no-gyro",
            _imu("Timestamp (us),Accelerometer X (g),Accelerometer Y (g),Accelerometer Z (g)\n1,0,0,1\n"),
            "error",
            "missing columns",
        ),
        (
            "unknown-unit",
            _imu(IMU_HEAD.replace("(deg/s)", "(furlong/s)", 1) + "\n" + "\n".join(ROWS) + "\n"),
            "error",
            "unknown unit",
        ),
        (
            "text-cell",
            _imu(IMU_HEAD + "\n" + "\n".join(ROWS[:10] + ["1,a,b,c,d,e,f"] + ROWS[10:]) + "\n"),
            "error",
            "not a number",
        ),
        ("decreasing", _imu(IMU_HEAD + "\n" + "\n".join(ROWS[:10] + ROWS[5:]) + "\n"), "error", "time"),
        (
            "ms-as-us",
            _imu(
                IMU_HEAD
                + "\n"
                + "\n".join(",".join([f"{i * 3.906:.3f}"] + r.split(",")[1:]) for i, r in enumerate(ROWS))
                + "\n"
            ),
            "error",
            "not an IMU sample rate",
        ),
        ("truncated-last", _imu(IMU_HEAD + "\n" + "\n".join(ROWS) + "\n19150794,0.0"), "warn", "W-IMU-TRUNCATED"),
        ("rate-option", _imu(IMU_HEAD + "\n" + "\n".join(ROWS) + "\n", extra=("--rate", 100)), "warn", "W-IMU-RATE"),
        (
            "clock-jump",
            _imu(IMU_HEAD + "\n" + "\n".join(ROWS[:500] + _imu_rows(524, t0=19150794 + 7_000_000)) + "\n"),
            "warn",
            "W-IMU-CLOCK",
        ),
        ("rate-zero", _imu(IMU_HEAD + "\n" + "\n".join(ROWS) + "\n", extra=("--rate", 0)), "error", "rate"),
        ("binary", _imu(b"\x00\xff" * 400), "error", "log/Inertial.csv: binary data, not a text file"),
        # a picture or a film given for a log: refused by name before any reading (a PNG had been
        # read as a log cut short, W-IMU-TRUNCATED, then an error naming no file)
        ("png", lambda tmp: ["imu", _image(tmp / "photo.png")], "error", r"photo\.png: a PNG image, not a text file"),
        ("jpeg-as-csv", lambda tmp: ["imu", _image(tmp / "log.csv", ".jpg")], "error", r"log\.csv: a JPEG image"),
        ("film", lambda tmp: ["imu", _film(tmp / "v.mp4")], "error", r"v\.mp4: an MP4/MOV film"),
        ("utf16", _imu((IMU_HEAD + "\n" + "\n".join(ROWS) + "\n").encode("utf-16")), "error", "UTF-16 text"),
        (
            "latin1",
            _imu((IMU_HEAD.replace("deg/s", "°/s") + "\n" + "\n".join(ROWS) + "\n").encode("latin-1")),
            "error",
            r"Inertial\.csv: not UTF-8 text \(byte 0xb0",
        ),
        ("still", _imu(IMU_HEAD + "\n" + "\n".join(ROWS) + "\n"), "ok", None),
        ("missing", lambda tmp: ["imu", tmp / "nope"], "error", "not found"),
        ("two-csv", lambda tmp: ["imu", _two_csv(tmp)], "error", "no IMU log found"),
    ],
    None,
)


def _image(p: Path, ext: str = ".png") -> Path:
    import cv2

    img = np.random.default_rng(0).integers(0, 256, (64, 64), dtype=np.uint8)
    p.write_bytes(cv2.imencode(ext, img)[1].tobytes())
    return p


def _two_csv(tmp):
    d = tmp / "two"
    d.mkdir()
    for n in ("a.csv", "b.csv"):
        (d / n).write_text(IMU_HEAD + "\n" + "\n".join(ROWS[:20]) + "\n")
    return d


# -- fit --------------------------------------------------------------------------------------------
def _track_csv(tmp, gap=None, dup=False):
    blk = Block(0.1, 0.2)
    r = simulate(blk, 0.3, 0.0, 5.0, 1e-4, restitution="constant", eta=0.9)
    t = np.arange(0, 5.0, 1 / 50)
    th = np.interp(t - 0.6, r.t_s, r.theta_rad, left=0.3, right=0.0)
    th = th + np.random.default_rng(0).normal(0, 3e-4, t.size)
    if gap:
        th[(t >= gap[0]) & (t < gap[1])] = np.nan
    df = pd.DataFrame({"t_s": t, "theta_rad": th})
    if dup:
        df = pd.concat([df, df])
    p = tmp / "tracks.csv"
    df.to_csv(p, index=False)
    return p


def _fit(*extra, **kw):
    return lambda tmp: ["fit", "restitution", _track_csv(tmp, **kw), "--width", 0.1, "--height", 0.2, *extra]


def _table(rows, name="t.csv"):
    def build(tmp, cmd="eta-mat", extra=()):
        p = tmp / name
        p.write_text(rows)
        return ["fit", cmd, p, *extra]

    return build


many(
    "fit",
    [
        ("ok", _fit("--json"), "ok", None),
        ("occlusion", _fit("--json", gap=(1.9, 2.3)), "warn", "W-FIT-GAP"),
        (
            "width-cm",
            lambda tmp: ["fit", "restitution", _track_csv(tmp), "--width", 10, "--height", 0.2],
            "warn",
            "W-FIT-UNITS",
        ),
        (
            "swapped",
            lambda tmp: ["fit", "restitution", _track_csv(tmp), "--width", 0.2, "--height", 0.1, "--json"],
            "warn",
            "W-FIT-RESIDUAL",
        ),
        ("duplicated", _fit(dup=True), "error", "increase"),
        (
            "video-as-csv",
            lambda tmp: [
                "fit",
                "restitution",
                _write_bytes(tmp / "v.csv", b"\x1aE\xdf\xa3\x00\x81" * 99),
                "--width",
                0.1,
                "--height",
                0.2,
            ],
            "error",
            "",
        ),
        (
            "missing",
            lambda tmp: ["fit", "restitution", tmp / "no.csv", "--width", 0.1, "--height", 0.2],
            "error",
            "not found",
        ),
        (
            "no-theta",
            lambda tmp: ["fit", "restitution", _write(tmp / "x.csv", "t_s,x\n0,1\n"), "--width", 0.1, "--height", 0.2],
            "error",
            "theta",
        ),
        (
            "width-0",
            lambda tmp: ["fit", "restitution", _track_csv(tmp), "--width", 0, "--height", 0.2],
            "error",
            "width",
        ),
        ("eta-mat-cm", _table("block,b_m,h_m,eta_e\nB3M,4.5,0.1,0.85\nB6M,4.5,0.2,0.93\n"), "fail", "W-FIT-UNITS"),
        (
            "eta-mat-dup",
            _table("block,b_m,h_m,eta_e\nB3M,0.03,0.1,0.85\nB3M,0.03,0.1,0.85\nB6M,0.045,0.2025,0.93\n"),
            "warn",
            "W-FIT-DUPLICATE",
        ),
        ("eta-mat-eta-1", _table("block,b_m,h_m,eta_e\nB3M,0.03,0.1,1.2\n"), "error", "restitution"),
        ("eta-mat-cols", _table("block,b,h\nB3M,1,2\n"), "error", "missing column"),
        ("eta-mat-empty", _table(""), "error", "empty"),
        ("eta-mat-nan", _table("block,b_m,h_m,eta_e\nB3M,0.03,,0.85\n"), "error", "missing"),
        (
            "k-table-bad-eta",
            lambda tmp: _table("block,b_m,h_m,eta_e\nB3M,0.03,0.1,0.85\n")(tmp, "k-table", ("--eta-mat", 1.5)),
            "error",
            "eta_mat",
        ),
        ("k-predict-hb-neg", lambda tmp: ["fit", "k-predict", "--hb", -1, "--b-cm", 9], "error", "hb"),
        (
            "k-predict-json-bad",
            lambda tmp: ["fit", "k-predict", "--hb", 4, "--b-cm", 9, "--coefficients", _write(tmp / "c.json", "{oops")],
            "error",
            "JSON",
        ),
    ],
    None,
)


def _write_bytes(p: Path, b: bytes) -> Path:
    p.write_bytes(b)
    return p


# -- experiment configs: `rocklab run` -------------------------------------------------------------------
def _run(toml, make_track=True, out="out"):
    def build(tmp):
        if make_track:
            _track_csv(tmp)
        p = tmp / "experiment.toml"
        p.write_text(toml)
        return ["run", p, "--out", tmp / out]

    return build


GOOD = (
    'name = "e"\n[block]\nb_m = 0.1\nh_m = 0.2\n[sources.track]\npath = "tracks.csv"\n'
    "[output]\nrrd = false\nfigures = false\n"
)
many(
    "run",
    [
        ("toml-syntax", _run("name = \n"), "error", "TOML syntax"),
        ("unknown-section", _run(GOOD + "[magic]\nx = 1\n"), "error", "not a known"),
        (
            "typo-key",
            _run(GOOD.replace('path = "tracks.csv"', 'path = "tracks.csv"\nobjekt = "b"')),
            "error",
            "did you mean 'object'",
        ),
        ("typo-output", _run(GOOD + "videos = 1\n"), "error", "not a known key"),
        ("no-block", _run('[sources.track]\npath = "tracks.csv"\n'), "error", "[block]"),
        ("b-neg", _run(GOOD.replace("b_m = 0.1", "b_m = -0.1")), "error", "positive"),
        ("b-text", _run(GOOD.replace("b_m = 0.1", 'b_m = "wide"')), "error", "number"),
        ("unknown-id", _run(GOOD.replace("b_m = 0.1\nh_m = 0.2", 'id = "B99Q"')), "error", "catalogue"),
        ("missing-source", _run(GOOD, make_track=False), "error", "does not exist"),
        ("no-source", _run("[block]\nb_m = 0.1\nh_m = 0.2\n"), "error", "at least one"),
        ("primary-missing", _run(GOOD + '[sources]\nprimary = "imu"\n'), "error", "TOML syntax|primary"),
        ("edge-no-lc", _run(GOOD + '[contact]\ntype = "edge"\n'), "error", "l_c_m"),
        ("lc-too-big", _run(GOOD + '[contact]\ntype = "edge"\nl_c_m = 0.09\n'), "error", "half the block"),
        ("law-unknown", _run(GOOD + '[simulate]\nlaws = ["magic"]\n'), "error", "allowed"),
        ("eta-out", _run(GOOD + "[simulate]\neta = 1.5\n"), "error", "(-1, 1)"),
        ("duration-neg", _run(GOOD + "[simulate]\nduration_s = -3\n"), "error", ">= 0"),
        ("given-no-eta", _run(GOOD + '[simulate]\nlaws = ["given"]\n'), "error", "eta is not set"),
        (
            "decimation-0",
            _run(GOOD.replace("figures = false", "figures = false\nvideo_decimation = 0")),
            "error",
            "positive",
        ),
        ("window-bad", _run(GOOD + '[fit]\nwindow = "best"\n'), "error", "must be one of"),
        # theta0 0.3 rad > alpha 0.197 rad: the fit fails (the run is "partial"): exit 1, as documented
        ("h-too-big", _run(GOOD.replace("h_m = 0.2", "h_m = 0.5")), "fail", "partial"),
        (
            "out-is-file",
            lambda tmp: _run(GOOD)(tmp)[:2] + ["--out", _write(tmp / "afile.txt", "mine")],
            "error",
            "existing file",
        ),
        ("out-foreign", lambda tmp: _run(GOOD)(tmp)[:2] + ["--out", _foreign(tmp)], "error", "did not write"),
        ("ok", _run(GOOD), "ok", None),
    ],
    None,
)


def _foreign(tmp):
    d = tmp / "precious"
    d.mkdir()
    (d / "thesis.txt").write_text("years")
    return d


# -- track configs: `rocklab track` -------------------------------------------------------------------------
OBJ = '[targets]\nstyle = "aruco"\nmarker_size_m = 0.02\n\n[[objects]]\nid = "block_1"\nkind = "block"\nmarkers = [0]\n'


def _trk(toml, video=b"not a video"):
    def build(tmp):
        v = tmp / "v.mkv"
        v.write_bytes(video)
        c = tmp / "track.toml"
        c.write_text(toml)
        return ["track", v, "--config", c, "-o", tmp / "tracks.csv"]

    return build


many(
    "track",
    [
        ("toml-syntax", _trk("[video\n"), "error", "TOML|line"),
        ("unknown-table", _trk("[magic]\nx = 1\n" + OBJ), "error", "unknown table"),
        ("unknown-key", _trk("[video]\nfsp = 50\n" + OBJ), "error", "unknown key"),
        (
            "fx-zero",
            _trk("[video]\ncamera_matrix = [[0, 0, 320], [0, 900, 180], [0, 0, 1]]\n" + OBJ),
            "error",
            "fx, fy > 0",
        ),
        (
            "singular-h",
            _trk("[reference]\nhomography = [[1, 2, 0], [2, 4, 0], [0, 0, 1]]\n" + OBJ),
            "error",
            "singular",
        ),
        (
            "bad-dict",
            _trk(OBJ.replace('style = "aruco"', 'style = "aruco"\ndictionary = "DICT_MAGIC"')),
            "error",
            "dictionary",
        ),
        ("no-objects", _trk("[video]\nfps = 50\n"), "error", "object"),
        ("bad-style", _trk(OBJ.replace('"aruco"', '"laser"')), "error", "style"),
        ("not-a-video", _trk(OBJ), "error", "video|decode|open"),
        (
            "missing-video",
            lambda tmp: ["track", tmp / "none.mkv", "--config", _write(tmp / "t.toml", OBJ)],
            "error",
            "not found",
        ),
        ("stop-before-start", _trk("[video]\nstart_frame = 5\nstop_frame = 2\n" + OBJ), "error", "start_frame"),
        ("fps-neg", _trk("[video]\nfps = -5\n" + OBJ), "error", "> 0|positive"),
    ],
    None,
)


# -- spectra and design --------------------------------------------------------------------------------------
def _good_record(tmp):
    return _write(tmp / "r.AT2", at2())


many(
    "spectra",
    [
        (
            "oas-huge-grid",
            lambda tmp: ["oas", _good_record(tmp), "--levels", 100000, "--sizes", 100000],
            "error",
            "GiB of memory",
        ),
        (
            "oas-two-samples",
            lambda tmp: ["oas", _write(tmp / "r.AT2", at2(values=[0.1, -0.1]))],
            "error",
            "needs at least 16",
        ),
        ("oas-sizes-1", lambda tmp: ["oas", _good_record(tmp), "--sizes", 1], "error", "sizes"),
        ("oas-slender-0", lambda tmp: ["oas", _good_record(tmp), "--slenderness", 0], "error", "slenderness"),
        ("oas-not-record", lambda tmp: ["oas", _write(tmp / "notes.txt", "hello world\n")], "error", ""),
        ("oas-plot-dir", lambda tmp: ["oas", _good_record(tmp), "--plot", tmp], "error", "is a folder"),
        ("design-neg-h", lambda tmp: ["design", "--height", -12, "--ag", 0.14, "--tI", 0.7], "error", "height"),
        ("design-ti-0", lambda tmp: ["design", "--height", 12, "--ag", 0.14, "--tI", 0], "error", "t"),
        ("design-ag-nan", lambda tmp: ["design", "--height", 12, "--ag", "nan", "--tI", 0.7], "error", "a"),
        ("design-ok", lambda tmp: ["design", "--height", 12, "--ag", 0.14, "--tI", 0.7, "--json"], "ok", None),
        ("equivalent-missing", lambda tmp: ["equivalent", "wall"], "error", ""),
        ("equivalent-neg", lambda tmp: ["equivalent", "block", "--b", -1, "--h", 2], "error", ""),
        (
            "pulse-cm-file",
            lambda tmp: ["pulse", _write(tmp / "r.AT2", at2(units="UNITS OF CM/S/S", values=SINE * 981))],
            "ok",
            None,
        ),
    ],
    None,
)


# -- campaign and synth -------------------------------------------------------------------------------------------
many(
    "campaign",
    [
        ("missing", lambda tmp: ["campaign", tmp / "none", "--out", tmp / "o", "--no-progress"], "error", "not found"),
        ("empty", lambda tmp: ["campaign", tmp, "--out", tmp / "o", "--no-progress"], "error", "no experiment"),
        (
            "out-file",
            lambda tmp: ["campaign", _run(GOOD)(tmp)[1].parent, "--out", _write(tmp / "o.txt", "x"), "--no-progress"],
            "error",
            "existing file",
        ),
        ("one-broken", lambda tmp: _broken_campaign(tmp), "fail", "FAILED"),
    ],
    None,
)
many(
    "synth",
    [
        ("size-odd", lambda tmp: ["synth", "--out", tmp / "s", "--size", "10x10"], "error", "size"),
        ("fps-0", lambda tmp: ["synth", "--out", tmp / "s", "--fps", 0], "error", "fps"),
        ("out-foreign", lambda tmp: ["synth", "--out", _foreign(tmp)], "error", "did not write"),
        ("duration-neg", lambda tmp: ["synth", "--out", tmp / "s", "--duration", -1], "error", "duration"),
    ],
    None,
)


def _broken_campaign(tmp):
    root = tmp / "c"
    for name, toml in (("good", GOOD), ("bad", GOOD.replace("tracks.csv", "missing.csv"))):
        d = root / name
        d.mkdir(parents=True)
        _track_csv(d)
        # names must be unique in a campaign (a duplicate is refused before any work)
        (d / "experiment.toml").write_text(toml.replace('name = "e"', f'name = "{name}"'))
    return ["campaign", root, "--out", tmp / "out", "--workers", 1, "--no-progress"]


# -- inputs are sacred: an output naming an input is refused before any work ----------------------
SACRED = "would overwrite the input|are the same file"


def _film(p: Path, n: int = 6, size=(64, 48)) -> Path:
    """A short real film (PyAV, MPEG-4 part 2): the trackers can decode it."""
    av = pytest.importorskip("av")
    w, h = size
    with av.open(str(p), "w") as c:
        s = c.add_stream("mpeg4", rate=25)
        s.width, s.height, s.pix_fmt = w, h, "yuv420p"
        for i in range(n):
            img = np.full((h, w, 3), 30 + 20 * i, np.uint8)
            for pkt in s.encode(av.VideoFrame.from_ndarray(img, format="rgb24")):
                c.mux(pkt)
        for pkt in s.encode():
            c.mux(pkt)
    return p


def _points_csv(p: Path) -> Path:
    """Four targets of a block rocking about a base edge (long CSV, metres)."""
    t = np.arange(0, 2, 0.01)
    th = 0.05 * np.exp(-t) * np.cos(8 * t)
    rows = []
    for name, (x, z) in {"a": (0.0, 0.2), "b": (0.045, 0.2), "c": (0.0, 0.0), "d": (0.045, 0.0)}.items():
        X, Z = x * np.cos(th) + z * np.sin(th), -x * np.sin(th) + z * np.cos(th)
        rows += [f"{ti:.3f},{name},{xi:.6f},0,{zi:.6f}" for ti, xi, zi in zip(t, X, Z)]
    p.write_text("t_s,point,x_m,y_m,z_m\n" + "\n".join(rows) + "\n")
    return p


def _c3d(tmp: Path) -> Path:
    src = Path(__file__).parent / "data" / "c3d" / "Qualisys.c3d"
    p = tmp / "p.c3d"
    p.write_bytes(src.read_bytes())
    return p


def _imu_folder(tmp: Path, high_g: bool = False) -> Path:
    d = tmp / "log"
    d.mkdir()
    (d / "Inertial.csv").write_text(IMU_HEAD + "\n" + "\n".join(ROWS) + "\n")
    if high_g:
        (d / "HighGAccelerometer.csv").write_text("Timestamp (us),X (g),Y (g),Z (g)\n19150794,0,0,1\n")
    return d


def _trk_real(tmp: Path, toml: str = OBJ):
    return _film(tmp / "v.mp4"), _write(tmp / "t.toml", toml)


def _stereo_in(tmp: Path):
    return _film(tmp / "c1.mkv"), _film(tmp / "c2.mkv"), _write(tmp / "c.json", '{"K1": 1}')


def _symlink(target: Path, link: Path) -> Path:
    link.symlink_to(target.name)
    return link


def _hardlink(target: Path, link: Path) -> Path:
    import os

    os.link(target, link)
    return link


def _frames(tmp: Path) -> Path:
    import cv2

    d = tmp / "seq"
    d.mkdir()
    for i in range(1, 4):
        cv2.imwrite(str(d / f"{i:03d}.png"), np.full((48, 64, 3), 60 * i, np.uint8))
    return d


many(
    "sacred",
    [
        ("track-o-video", lambda tmp: ["track", *_trk_cmd(tmp), "-o", tmp / "v.mp4"], "error", SACRED),
        ("track-o-config", lambda tmp: ["track", *_trk_cmd(tmp), "-o", tmp / "t.toml"], "error", SACRED),
        (
            "track-o-calibration",
            lambda tmp: [
                "track",
                _film(tmp / "v.mp4"),
                "--config",
                _write(tmp / "t.toml", '[video]\ncalibration = "cam.json"\n' + OBJ),
                "-o",
                _write(tmp / "cam.json", "{}"),
            ],
            "error",
            SACRED,
        ),
        (
            "track-o-frame",
            lambda tmp: [
                "track",
                _frames(tmp) / "%03d.png",
                "--config",
                _write(tmp / "t.toml", OBJ),
                "-o",
                tmp / "seq" / "002.png",
            ],
            "error",
            SACRED,
        ),
        (
            "track-init-preview-video",
            lambda tmp: ["track", "init", _film(tmp / "v.mp4"), "-o", tmp / "n.toml", "--preview", tmp / "v.mp4"],
            "error",
            SACRED,
        ),
        (
            "track-init-o-preview",
            lambda tmp: ["track", "init", _film(tmp / "v.mp4"), "-o", tmp / "n.toml", "--preview", tmp / "n.toml"],
            "error",
            SACRED,
        ),
        (
            "track-preview-o-video",
            lambda tmp: ["track", "preview", *_trk_cmd(tmp), "-o", tmp / "v.mp4"],
            "error",
            SACRED,
        ),
        ("track3d-o-csv", lambda tmp: ["track3d", _points_csv(tmp / "p.csv"), "-o", tmp / "p.csv"], "error", SACRED),
        (
            "track3d-rrd-csv",
            lambda tmp: ["track3d", _points_csv(tmp / "p.csv"), "-o", tmp / "o.csv", "--rrd", tmp / "p.csv"],
            "error",
            SACRED,
        ),
        ("track3d-o-c3d", lambda tmp: ["track3d", _c3d(tmp), "-o", tmp / "p.c3d"], "error", SACRED),
        (
            "track3d-audit-is-input",
            lambda tmp: ["track3d", _points_csv(tmp / "audit.json"), "-o", tmp / "o.csv"],
            "error",
            SACRED,
        ),
        (
            "track3d-o-audit",
            lambda tmp: ["track3d", _points_csv(tmp / "p.csv"), "-o", tmp / "audit.json"],
            "error",
            SACRED,
        ),
        (
            "track3d-o-symlink",
            lambda tmp: ["track3d", _points_csv(tmp / "p.csv"), "-o", _symlink(tmp / "p.csv", tmp / "link.csv")],
            "error",
            SACRED,
        ),
        ("imu-o-log", lambda tmp: ["imu", _imu_folder(tmp), "-o", tmp / "log" / "Inertial.csv"], "error", SACRED),
        (
            "imu-o-companion",
            lambda tmp: ["imu", _imu_folder(tmp, True), "-o", tmp / "log" / "HighGAccelerometer.csv"],
            "error",
            SACRED,
        ),
        # a new user's findings: --plot naming the log or its rate register, and -o naming a file
        # of the log's folder that the reader does not open (the export's other tables)
        (
            "imu-plot-log",
            lambda tmp: ["imu", _imu_folder(tmp), "--plot", tmp / "log" / "Inertial.csv"],
            "error",
            SACRED,
        ),
        (
            "imu-plot-companion",
            lambda tmp: ["imu", _imu_folder(tmp, True), "--plot", tmp / "log" / "HighGAccelerometer.csv"],
            "error",
            SACRED,
        ),
        (
            "imu-o-folder-file",
            lambda tmp: ["imu", _imu_folder(tmp), "-o", _write(tmp / "log" / "Notes.csv", "my notes\n")],
            "error",
            SACRED,
        ),
        (
            "imu-o-plot-same",
            lambda tmp: ["imu", _imu_folder(tmp), "-o", tmp / "r.csv", "--plot", tmp / "r.csv"],
            "error",
            SACRED,
        ),
        ("oas-o-record", lambda tmp: ["oas", _good_record(tmp), "-o", tmp / "r.AT2"], "error", SACRED),
        ("oas-plot-record", lambda tmp: ["oas", _good_record(tmp), "--plot", tmp / "r.AT2"], "error", SACRED),
        (
            "oas-list-o-list",
            lambda tmp: ["oas", "--list", _write(tmp / "t.csv", f"{_good_record(tmp).name}\n"), "-o", tmp / "t.csv"],
            "error",
            SACRED,
        ),
        (
            "oas-folder-o-record",
            lambda tmp: ["oas", _good_record(tmp).parent, "-o", tmp / "r.AT2", "--no-progress"],
            "error",
            SACRED,
        ),
        (
            "simulate-o-base",
            lambda tmp: [*_sim()(tmp), "--base-motion", _good_record(tmp), "-o", tmp / "r.AT2"],
            "error",
            SACRED,
        ),
        (
            "simulate-o-hardlink",
            lambda tmp: [
                *_sim()(tmp),
                "--base-motion",
                _good_record(tmp),
                "-o",
                _hardlink(tmp / "r.AT2", tmp / "h.AT2"),
            ],
            "error",
            SACRED,
        ),
        (
            "column-o-base",
            lambda tmp: ["column", "--blocks", "0.3x1.5", "--base-motion", _good_record(tmp), "-o", tmp / "r.AT2"],
            "error",
            SACRED,
        ),
        (
            "column-maps-base",
            lambda tmp: [
                "column",
                "--blocks",
                "0.3x1.5",
                "--base-motion",
                _good_record(tmp),
                "--maps-png",
                tmp / "r.AT2",
            ],
            "error",
            SACRED,
        ),
        (
            "stereo-track-o-calib",
            lambda tmp: ["stereo", "track", *_stereo_in(tmp)[:2], "--calib", tmp / "c.json", "-o", tmp / "c.json"],
            "error",
            SACRED,
        ),
        (
            "stereo-track-points-side",
            lambda tmp: ["stereo", "track", *_stereo_in(tmp)[:2], "--calib", tmp / "c.json", "-o", tmp / "points.csv"],
            "error",
            SACRED,
        ),
        (
            "stereo-track-o-film2",
            lambda tmp: ["stereo", "track", *_stereo_in(tmp)[:2], "--calib", tmp / "c.json", "-o", tmp / "c2.mkv"],
            "error",
            SACRED,
        ),
        (
            "stereo-calibrate-o-film",
            lambda tmp: ["stereo", "calibrate", *_stereo_in(tmp)[:2], "-o", tmp / "c1.mkv"],
            "error",
            SACRED,
        ),
    ],
    None,
)


# -- limits and exits: bad input is exit 2 (never 3), physical ranges, time and memory estimates -------
RIG = {
    "K1": [[800, 0, 320], [0, 800, 240], [0, 0, 1]],
    "dist1": [0, 0, 0, 0, 0],
    "K2": [[800, 0, 320], [0, 800, 240], [0, 0, 1]],
    "dist2": [0, 0, 0, 0, 0],
    "R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
    "T_m": [0.2, 0, 0],
    "size_px": [64, 48],
}


def _rig(tmp, **change):
    import json

    return [
        "stereo",
        "track",
        _film(tmp / "c1.mkv"),
        _film(tmp / "c2.mkv"),
        "--calib",
        _write(tmp / "rig.json", json.dumps({**RIG, **change})),
        "-o",
        tmp / "t.csv",
    ]


def _two_records(tmp):
    return [_write(tmp / "a.AT2", at2()), _write(tmp / "b.AT2", at2(values=SINE[::-1]))]


def _small_oas(tmp, *extra):
    return ["oas", _good_record(tmp), "--levels", 4, "--sizes", 4, "--refine", 1, *extra]


many(
    "limits",
    [
        ("oas-workers-0", lambda tmp: ["oas", *_two_records(tmp), "--workers", 0], "error", "workers"),
        ("oas-refine-neg", lambda tmp: _small_oas(tmp, "--refine=-1"), "error", "refine"),
        ("campaign-workers-neg", lambda tmp: ["campaign", tmp, "--out", tmp / "o", "--workers=-1"], "error", "workers"),
        ("demo-workers-0", lambda tmp: ["demo", "--out", tmp / "d", "--workers", 0], "error", "workers"),
        (
            "equivalent-alpha-I-neg",
            lambda tmp: ["equivalent", "block", "--b", 1, "--h", 2, "--alpha-I=-1"],
            "error",
            "alpha_I",
        ),
        (
            "equivalent-alpha-I-0",
            lambda tmp: ["equivalent", "block", "--R", 1, "--alpha", 0.2, "--alpha-I", 0],
            "error",
            "alpha_I",
        ),
        (
            "equivalent-alpha-I-half",
            lambda tmp: ["equivalent", "frame", "--b", 1, "--h", 2, "--alpha-I", 0.5],
            "error",
            "parallel-axis",
        ),
        (
            "equivalent-asym-huge",
            lambda tmp: ["equivalent", "asym-frame", "--b", 0.2, "--H", 1e300, "--H1", 1.2, "--L", 3, "--h", 0.1],
            "error",
            "times",
        ),
        (
            "equivalent-arch-thin",
            lambda tmp: ["equivalent", "arch", "--beta", 1, "--thickness", 1e-300, "--radius", 1],
            "error",
            "times",
        ),
        ("oas-housner-squat", lambda tmp: _small_oas(tmp, "--slenderness", 0.5), "error", "Housner"),
        ("oas-housner-0.9", lambda tmp: _small_oas(tmp, "--slenderness", 0.9), "error", "Housner"),
        ("oas-squat-given-eta", lambda tmp: _small_oas(tmp, "--slenderness", 0.5, "--eta", 0.5, "--json"), "ok", None),
        ("oas-slender-1", lambda tmp: _small_oas(tmp, "--slenderness", 1, "--json"), "ok", None),
        ("oas-eta-neg", lambda tmp: _small_oas(tmp, "--eta=-0.5"), "error", "eta"),
        ("oas-eta-above-1", lambda tmp: _small_oas(tmp, "--eta", 1.01), "error", "eta"),
        ("oas-slender-1e300", lambda tmp: _small_oas(tmp, "--slenderness", 1e300), "error", "needle"),
        ("oas-level-max-1e300", lambda tmp: _small_oas(tmp, "--level-max", 1e300), "error", "level_max"),
        ("stereo-K1-2x2", lambda tmp: _rig(tmp, K1=[[1, 0], [0, 1]]), "error", "'K1' must be 3 x 3"),
        ("stereo-R-vector", lambda tmp: _rig(tmp, R=[1, 0]), "error", "'R' must be 3 x 3"),
        ("stereo-T-short", lambda tmp: _rig(tmp, T_m=[0.2, 0]), "error", "'T_m' must be 3"),
        ("stereo-dist-3", lambda tmp: _rig(tmp, dist2=[0, 0, 0]), "error", "'dist2'"),
        ("stereo-size-1", lambda tmp: _rig(tmp, size_px=[64]), "error", "size_px"),
        (
            "stereo-board-0x0",
            lambda tmp: [
                "stereo",
                "calibrate",
                *_stereo_in(tmp)[:2],
                "-o",
                tmp / "s.json",
                "--board",
                "0x0,0.03,0.022,DICT_5X5_100",
            ],
            "error",
            "3x3",
        ),
        (
            "stereo-board-marker-big",
            lambda tmp: [
                "stereo",
                "calibrate",
                *_stereo_in(tmp)[:2],
                "-o",
                tmp / "s.json",
                "--board",
                "9x6,0.03,0.05,DICT_5X5_100",
            ],
            "error",
            "marker side",
        ),
        (
            "stereo-board-square-neg",
            lambda tmp: [
                "stereo",
                "calibrate",
                *_stereo_in(tmp)[:2],
                "-o",
                tmp / "s.json",
                "--board",
                "9x6,-0.03,0.022,DICT_5X5_100",
            ],
            "error",
            "marker side",
        ),
        ("column-dt-1e-12", _col("--blocks", "0.1x0.2", "--theta0", 0.05, "--dt", 1e-12), "error", "would take about"),
        (
            "column-duration-1e300",
            _col("--blocks", "0.1x0.2", "--theta0", 0.05, "--duration", 1e300),
            "error",
            "would take about",
        ),
        (
            "column-dt-1e-300",
            _col("--blocks", "0.1x0.2,0.1x0.2", "--theta0", "0.02,0.02", "--dt", 1e-300),
            "error",
            "would take about",
        ),
        ("simulate-dt-1e-12", _sim("--theta0", 0.05, "--dt", 1e-12, "--output-dt", 1), "error", "would take about"),
        ("simulate-output-dt-huge", _sim("--theta0", 0.05, "--output-dt", 1e300), "error", "output_dt"),
        ("simulate-width-1e300", _sim("--theta0", 0.05, width=1e300), "error", "too large or too small"),
        (
            "design-tI-tiny",
            lambda tmp: ["design", "--height", 12, "--ag", 0.14, "--tI", 1e-300],
            "error",
            "no pier width",
        ),
        (
            "design-ag-huge",
            lambda tmp: ["design", "--height", 12, "--ag", 1e300, "--tI", 0.7],
            "error",
            "no pier width",
        ),
        (
            "design-cm-ratio-2",
            lambda tmp: ["design", "--height", 12, "--ag", 0.14, "--tI", 0.7, "--cm-ratio", 2],
            "error",
            "cm_height_ratio",
        ),
        (
            "design-alpha-I-nan",
            lambda tmp: ["design", "--height", 12, "--ag", 0.14, "--tI", 0.7, "--alpha-I", "nan"],
            "error",
            "alpha_I",
        ),
        (
            "design-g-tiny",
            lambda tmp: ["design", "--height", 12, "--ag", 0.14, "--tI", 0.7, "--g", 1e-300],
            "error",
            "no pier width",
        ),
    ],
    None,
)


# -- other tools' files: `rocklab import FILE` ----------------------------------------------------------------
IMPORTERS = Path(__file__).parent / "data" / "importers"


def _write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def _copy(src: Path, dst: Path) -> Path:
    dst.write_bytes(src.read_bytes())
    return dst


_PANEL = '<?xml version="1.0"?>\n<object class="org.opensourcephysics.cabrillo.tracker.TrackerPanel">\n{}</object>\n'
_KINOVEA_SHEET = (
    '<?xml version="1.0"?><Workbook xmlns="urn:schemas-microsoft-com:office:spreadsheet" '
    'xmlns:ss="urn:schemas-microsoft-com:office:spreadsheet"><Worksheet><Table>'
    '<Row><Cell><Data ss:Type="String">Label :</Data></Cell><Cell><Data ss:Type="String">A</Data></Cell></Row>'
    '<Row><Cell><Data ss:Type="String">Coords (x,y:{unit}; t:time)</Data></Cell></Row>'
    '<Row><Cell><Data ss:Type="String">x</Data></Cell><Cell><Data ss:Type="String">y</Data></Cell>'
    '<Cell><Data ss:Type="String">t</Data></Cell></Row>'
    "{rows}</Table></Worksheet></Workbook>"
)


def _sheet_row(x, y, t):
    return (
        f'<Row><Cell><Data ss:Type="Number">{x}</Data></Cell><Cell><Data ss:Type="Number">{y}</Data></Cell>'
        f'<Cell><Data ss:Type="String">{t}</Data></Cell></Row>'
    )


many(
    "import",
    [
        ("trk-ok", lambda tmp: ["import", _copy(IMPORTERS / "diabolo_rotation.trk", tmp / "d.trk")], "ok", None),
        ("trk-not-xml", lambda tmp: ["import", _write(tmp / "a.trk", "hello")], "error", "not valid XML"),
        (
            "trk-other-xml",
            lambda tmp: ["import", _write(tmp / "a.trk", "<object class='x.Other'/>")],
            "error",
            "not a Tracker project",
        ),
        ("trz-not-zip", lambda tmp: ["import", _write(tmp / "a.trz", "PK?")], "error", "not a zip file"),
        (
            "trk-no-masses",
            lambda tmp: ["import", _write(tmp / "a.trk", _PANEL.format(""))],
            "error",
            "delta_t|no point-mass track",
        ),
        (
            "trk-o-is-input",
            lambda tmp: ["import", _copy(IMPORTERS / "diabolo_rotation.trk", tmp / "d.trk"), "-o", tmp / "d.trk"],
            "error",
            SACRED,
        ),
        (
            "kinovea-pixels",
            lambda tmp: [
                "import",
                _write(tmp / "k.xml", _KINOVEA_SHEET.format(unit="px", rows=_sheet_row(1, 2, "0:00:00:00"))),
            ],
            "error",
            "not a length",
        ),
        (
            "kinovea-bad-time",
            lambda tmp: [
                "import",
                _write(tmp / "k.xml", _KINOVEA_SHEET.format(unit="cm", rows=_sheet_row(1, 2, "12 ms"))),
            ],
            "error",
            "time code",
        ),
        (
            "kinovea-doubled-time",
            lambda tmp: ["import", _copy(IMPORTERS / "kinovea_box_jump.xml", tmp / "k.xml")],
            "warn",
            "W-IMPORT-TIME",
        ),
        (
            "kinovea-text-no-unit",
            lambda tmp: [
                "import",
                _write(tmp / "k.txt", "#Kinovea Trajectory data export\n#T X Y\n\n# a\n0.000 1,0 2,0\n"),
            ],
            "error",
            "names no unit",
        ),
        (
            "dltdv-no-fps",
            lambda tmp: ["import", _write(tmp / "t_xyzpts.csv", "pt1_X,pt1_Y,pt1_Z\n1,2,3\n"), "--units", "m"],
            "error",
            "--fps",
        ),
        (
            "dltdv-bad-cell",
            lambda tmp: [
                "import",
                _write(tmp / "t_xyzpts.csv", "pt1_X,pt1_Y,pt1_Z\n1,2,3\n1,x,3\n"),
                "--fps",
                100,
                "--units",
                "mm",
            ],
            "error",
            "line 3, 'pt1_Y': not a number",
        ),
        (
            "dltdv-coefs-short",
            lambda tmp: [
                "import",
                _write(tmp / "t_xypts.csv", "pt1_cam1_X,pt1_cam1_Y,pt1_cam2_X,pt1_cam2_Y\n1,2,3,4\n"),
                "--coefs",
                _write(tmp / "c_DLTcoefs.csv", "1,2\n3,4\n"),
                "--fps",
                100,
                "--units",
                "m",
            ],
            "error",
            "11 finite rows",
        ),
        ("unknown-tool", lambda tmp: ["import", _write(tmp / "a.csv", "a,b\n1,2\n")], "error", "cannot tell"),
    ],
    None,
)


def _trk_cmd(tmp):
    v, c = _trk_real(tmp)
    return [v, "--config", c]


# -- the runner --------------------------------------------------------------------------------------------
def test_corpus_size():
    assert len(CASES) >= 150, len(CASES)


@pytest.mark.parametrize("name, build, expect", CASES, ids=[c[0] for c in CASES])
def test_corpus_case(tmp_path, run_cli, capsys, name, build, expect):
    import re

    kind, words = expect
    before = set()
    argv = build(tmp_path)
    before = {p for p in tmp_path.rglob("*")}
    # inputs are sacred: every file the case made keeps its bytes, whatever the outcome
    kept = {p: p.read_bytes() for p in before if p.is_file()}
    try:
        rc, out, err = run_cli(*argv)
    except SystemExit as e:  # argparse's own usage errors (one line, status 2)
        rc = e.code
        out, err = capsys.readouterr()
    assert "Traceback" not in err and "Traceback" not in out
    errors = [ln for ln in err.splitlines() if ": error:" in ln or "internal error" in ln]
    warns = [ln for ln in err.splitlines() if ": warning W-" in ln]
    noise = [ln for ln in err.splitlines() if not ln.startswith("rocklab")]
    assert not noise, noise  # only rocklab's own one-line messages (no library noise, no RuntimeWarning)
    if kind == "error":
        assert rc == 2, (rc, err)
        assert len(errors) == 1 and (not words or re.search(words, errors[0])), err
        # a refused log: the one error line, no warning about reading it (a PNG warned W-IMU-TRUNCATED)
        assert not (name.startswith("imu-") and warns), err
        # no partial output: nothing new but what the case itself built
        new = {p for p in tmp_path.rglob("*")} - before
        assert not new, sorted(map(str, new))
    elif kind == "warn":
        assert rc == 0 and not errors, err
        assert any(words in w for w in warns), err
    elif kind == "ok":
        assert rc == 0 and not errors and not warns, err
    else:  # "fail": ran, the result failed and says so
        assert rc == 1, (rc, err)
        assert re.search(words, err + out), (err, out)
    assert not [p for p in tmp_path.rglob(".*.tmp-*")], "staging leftovers"
    changed = [str(p) for p, b in kept.items() if not p.is_file() or p.read_bytes() != b]
    assert not changed, f"inputs changed: {changed}"
