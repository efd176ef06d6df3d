"""Experiment configuration (``experiment.toml``) for ``rocklab run``.

A commented example is in ``examples/experiment.toml`` and in
:data:`EXAMPLE_TOML`. Paths in the file are relative to the file's folder.
Every error names the file, the key and (where it can be found) the line.

The schema, with every key and its default, is :data:`EXAMPLE_TOML` (all lengths in m, times in
s, angles in rad).
"""

from __future__ import annotations

import math
import re
import textwrap
import tomllib
from dataclasses import asdict, dataclass, field
from pathlib import Path

from ..._errors import InputError

__all__ = ["ExperimentConfig", "load_experiment", "EXAMPLE_TOML"]

_LAWS = ("housner", "eta_e", "modified", "eta_e_first", "given")
_WINDOWS = ("middle50", "all", "first")


@dataclass(frozen=True)
class SourceVideo:
    """A video file and the tracking config that reads it."""

    path: Path
    track_config: Path | None = None
    object: str = "block_1"
    fps: float | None = None
    corrections: Path | None = None  # manual corrections of the track (rocklab.tracking._corrections)


@dataclass(frozen=True)
class SourceTrack:
    """An already tracked CSV with ``t_s, theta_rad`` (and optionally ``object``)."""

    path: Path
    object: str | None = None


@dataclass(frozen=True)
class SourceImu:
    """An IMU log (folder or CSV) on the block."""

    path: Path
    axis: str = "auto"
    rate_hz: float | None = None


@dataclass(frozen=True)
class SourceTable:
    """Where the base (table) motion comes from."""

    source: str = "none"  # video | imu | record | none
    object: str = "table"
    imu: Path | None = None
    record: Path | None = None
    units: str | None = None  # a record's units when it states none (None: g); never overrides the file's


@dataclass(frozen=True)
class ExperimentConfig:
    """A parsed, validated experiment config. Lengths m, times s, angles rad."""

    path: Path
    name: str
    b_m: float
    h_m: float
    mass_kg: float | None
    block_id: str | None
    contact: str = "full"
    l_c_m: float | None = None
    k: float | None = None
    primary: str = "video"
    video: SourceVideo | None = None
    track: SourceTrack | None = None
    imu: SourceImu | None = None
    table: SourceTable = field(default_factory=SourceTable)
    sync_method: str = "xcorr"
    max_offset_s: float = 5.0
    fit_restitution: bool = True
    fit_window: str = "middle50"
    laws: tuple = ("housner", "eta_e", "modified")
    duration_s: float = 0.0
    eta_given: float | None = None
    rrd: bool = True
    video_decimation: int = 1
    figures: bool = True
    columns: tuple = ()  # for column experiments: object ids bottom to top
    column_cut_m: float = 0.0
    column_impacts: int = 1
    truth: Path | None = None  # synthetic sessions: truth.csv for the report

    def block(self):
        """The :class:`rocklab.Block` of this experiment."""
        from ...blocks import Block

        return Block(self.b_m, self.h_m, mass_kg=self.mass_kg, name=self.block_id or self.name)

    def input_files(self) -> list[Path]:
        """Every input file the run reads (for the unchanged-inputs check)."""
        out = [self.path]
        for src in (self.video, self.track, self.imu):
            if src is None:
                continue
            out.append(src.path)
            if getattr(src, "corrections", None):
                out.append(src.corrections)
            tc = getattr(src, "track_config", None)
            if tc:
                out.append(tc)
                out.extend(_track_config_files(tc))
        for p in (self.table.imu, self.table.record, self.truth):
            if p:
                out.append(p)
        files = []
        for p in out:
            files.extend(sorted(q for q in p.rglob("*") if q.is_file()) if p.is_dir() else [p])
        return files

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        d = asdict(self)
        return _paths_to_str(d)


def _track_config_files(path: Path) -> list[Path]:
    """Files a ``track.toml`` names (its lens calibration): a run reads them, so a changed
    calibration must change the fingerprint. Unreadable configs add nothing here; the
    tracking stage reports them with their line."""
    from ...tracking import load_track_config

    try:
        named = load_track_config(path).named_files
    except InputError:
        return []
    return [p for p in named if p.is_file()]


def _paths_to_str(obj):
    if isinstance(obj, dict):
        return {k: _paths_to_str(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_paths_to_str(v) for v in obj]
    return str(obj) if isinstance(obj, Path) else obj


class _Reader:
    """Typed access to a TOML table with errors naming file, key and line."""

    def __init__(self, path: Path, text: str, data: dict):
        self.path, self.text, self.data = path, text, data
        self.used: set[str] = set()
        self.asked: set[str] = set()

    def check_unknown(self) -> None:
        """Every key in the file must be one the reader asked for: a typo (``fsp = 50``) is an
        error naming its line and the nearest known key, never silently ignored."""
        import difflib

        def leaves(node, pre):
            for k, v in node.items():
                d = f"{pre}.{k}" if pre else k
                if isinstance(v, dict):
                    yield from leaves(v, d)
                else:
                    yield d

        for d in leaves(self.data, ""):
            if d in self.asked:
                continue
            section = d.rpartition(".")[0]
            known = sorted(a.rpartition(".")[2] for a in self.asked if a.rpartition(".")[0] == section)
            near = difflib.get_close_matches(d.rpartition(".")[2], known, n=1)
            hint = f"did you mean '{near[0]}'? " if near else ""
            self.fail(
                d,
                f"is not a known key{' of [' + section + ']' if section else ''}; {hint}"
                f"known: {', '.join(known) or '(none)'}",
            )

    def line_of(self, dotted: str) -> int | None:
        parts = dotted.split(".")
        key = parts[-1]
        section = ".".join(parts[:-1])
        lines = self.text.splitlines()
        start = 0
        if section:
            pat = re.compile(r"^\s*\[+\s*" + re.escape(section) + r"\s*\]+\s*(#.*)?$")
            hit = [i for i, ln in enumerate(lines) if pat.match(ln)]
            if hit:
                start = hit[0] + 1
        kpat = re.compile(r"^\s*" + re.escape(key) + r"\s*=")
        for i in range(start, len(lines)):
            if i > start and section and re.match(r"^\s*\[", lines[i]):
                break
            if kpat.match(lines[i]):
                return i + 1
        if section:
            for i, ln in enumerate(lines):
                if re.match(r"^\s*\[+\s*" + re.escape(section) + r"\s*\]+", ln):
                    return i + 1
        return None

    def fail(self, dotted: str, msg: str):
        ln = self.line_of(dotted)
        loc = f"{self.path}, line {ln}" if ln else str(self.path)
        raise InputError(f"{loc}: '{dotted}' {msg}")

    def get(self, dotted: str, default=None, kind=None, choices=None, positive=False):
        self.asked.add(dotted)
        node = self.data
        for p in dotted.split("."):
            if not isinstance(node, dict) or p not in node:
                return default
            node = node[p]
        self.used.add(dotted)
        v = node
        if kind is float:
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                self.fail(dotted, f"must be a number, got {v!r}")
            v = float(v)
            if positive and not v > 0:
                self.fail(dotted, f"must be positive, got {v}")
        elif kind is int:
            if isinstance(v, bool) or not isinstance(v, int):
                self.fail(dotted, f"must be an integer, got {v!r}")
            if positive and v <= 0:
                self.fail(dotted, f"must be positive, got {v}")
        elif kind is bool:
            if not isinstance(v, bool):
                self.fail(dotted, f"must be true or false, got {v!r}")
        elif kind is str:
            if not isinstance(v, str):
                self.fail(dotted, f"must be a string, got {v!r}")
        if choices is not None and v not in choices:
            self.fail(dotted, f"must be one of {', '.join(map(str, choices))}, got {v!r}")
        return v

    def file(self, dotted: str, required=True, allow_dir=False) -> Path | None:
        v = self.get(dotted, kind=str)
        if v is None:
            if required:
                self.fail(dotted, "is required")
            return None
        p = (self.path.parent / v).resolve()
        if not (p.is_file() or (allow_dir and p.is_dir())):
            self.fail(dotted, f"names {v!r}, which does not exist (looked in {p.parent}); fix the path")
        return p


_KNOWN = {"name", "block", "contact", "sources", "sync", "fit", "simulate", "output", "column", "truth"}


def load_experiment(path) -> ExperimentConfig:
    """Read and validate an ``experiment.toml``.

    Raises
    ------
    InputError
        Missing file, TOML syntax error (with its line), unknown section,
        wrong type or value (naming the key and its line), missing input files.
    """
    path = Path(path).resolve()
    if not path.is_file():
        raise InputError(f"{path}: experiment config not found; check the path")
    text = path.read_text(encoding="utf-8", errors="replace")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise InputError(f"{path}: TOML syntax error: {e}") from None
    r = _Reader(path, text, data)
    for k in data:
        if k not in _KNOWN:
            r.fail(k, f"is not a known section/key; expected one of {', '.join(sorted(_KNOWN))}")

    # -- block ----------------------------------------------------------------
    if "block" not in data:
        raise InputError(f'{path}: missing [block] section; give id = "B6M" or b_m/h_m')
    bid = r.get("block.id", kind=str)
    b = r.get("block.b_m", kind=float, positive=True)
    h = r.get("block.h_m", kind=float, positive=True)
    m = r.get("block.mass_kg", kind=float, positive=True)
    if bid is not None and (b is None or h is None):
        cat = _catalogue()
        if bid not in cat:
            r.fail("block.id", f"= {bid!r} is not in the Čeh Table 2 catalogue (B1S..B10L); give b_m and h_m instead")
            raise AssertionError  # unreachable
        row = cat[bid]
        b = b or row["b_m"]
        h = h or row["h_m"]
        m = m or row.get("mass_kg")
    if b is None or h is None:
        r.fail("block", "needs b_m and h_m (m), or an id from the catalogue")

    contact = r.get("contact.type", "full", kind=str, choices=("full", "edge"))
    l_c = r.get("contact.l_c_m", kind=float, positive=True)
    if contact == "edge" and l_c is None:
        r.fail("contact.l_c_m", "is required for edge contact (width of the base strip, m)")
    if l_c is not None and l_c >= b / 2:
        r.fail("contact.l_c_m", f"= {l_c} m must be less than half the block width ({b / 2} m)")
    k = r.get("contact.k", kind=float, positive=True)

    # -- sources --------------------------------------------------------------
    video = track = imu = None
    if "video" in data.get("sources", {}):
        video = SourceVideo(
            path=r.file("sources.video.path", allow_dir=True),
            track_config=r.file("sources.video.track_config", required=False),
            object=r.get("sources.video.object", "block_1", kind=str),
            fps=r.get("sources.video.fps", kind=float, positive=True),
            corrections=r.file("sources.video.corrections", required=False),
        )
    if "track" in data.get("sources", {}):
        track = SourceTrack(path=r.file("sources.track.path"), object=r.get("sources.track.object", kind=str))
    if "imu" in data.get("sources", {}):
        imu = SourceImu(
            path=r.file("sources.imu.path", allow_dir=True),
            axis=r.get("sources.imu.axis", "auto", kind=str),
            rate_hz=r.get("sources.imu.rate_hz", kind=float, positive=True),
        )
        if not re.fullmatch(r"auto|[+-]?[xyz]", imu.axis):
            r.fail("sources.imu.axis", f"= {imu.axis!r} must be x, y, z (optionally signed, e.g. -y) or auto")
    if video is None and track is None and imu is None:
        raise InputError(f"{path}: [sources] needs at least one of [sources.video], [sources.track], [sources.imu]")
    primary = r.get("sources.primary", None, kind=str, choices=("video", "imu", "track"))
    if primary is None:
        primary = "video" if video else "track" if track else "imu"
    if {"video": video, "imu": imu, "track": track}[primary] is None:
        r.fail("sources.primary", f"= {primary!r} but there is no [sources.{primary}] section")
    tsrc = r.get("sources.table.from", "none", kind=str, choices=("video", "imu", "record", "none"))
    table = SourceTable(
        source=tsrc,
        object=r.get("sources.table.object", "table", kind=str),
        imu=r.file("sources.table.imu", required=tsrc == "imu", allow_dir=True),
        record=r.file("sources.table.record", required=tsrc == "record"),
        units=r.get("sources.table.units", None, kind=str),
    )
    if tsrc == "video" and video is None:
        r.fail("sources.table.from", "= 'video' needs a [sources.video] section")

    laws = tuple(r.get("simulate.laws", ["housner", "eta_e", "modified"]))
    for law in laws:
        if law not in _LAWS:
            r.fail("simulate.laws", f"contains {law!r}; allowed: {', '.join(_LAWS)}")
    eta_given = r.get("simulate.eta", kind=float)
    if eta_given is not None and not -1.0 < eta_given < 1.0:
        r.fail("simulate.eta", f"= {eta_given} must lie in (-1, 1) (ratio of angular velocities)")
    if eta_given is not None and "given" not in laws:
        laws = laws + ("given",)
    if "given" in laws and eta_given is None:
        r.fail("simulate.laws", "contains 'given' but [simulate] eta is not set")
    columns = tuple(r.get("column.objects", []))
    if columns and _video_missing(data):
        r.fail("column.objects", "needs a [sources.video] section (the blocks are tracked on video)")
    cut = r.get("column.cut_m", 0.0, kind=float)
    if cut < 0 or cut >= (b or 1) / 2:
        r.fail("column.cut_m", f"= {cut} m must be in [0, b/2)")
    n_imp = r.get("column.impacts", 1, kind=int, positive=True)
    truth = r.file("truth", required=False)
    duration = r.get("simulate.duration_s", 0.0, kind=float)
    if not (math.isfinite(duration) and duration >= 0):
        r.fail("simulate.duration_s", f"= {duration} must be >= 0 s (0: as long as the measurement)")
    cfg = ExperimentConfig(
        path=path,
        name=r.get("name", path.parent.name, kind=str),
        b_m=b,
        h_m=h,
        mass_kg=m,
        block_id=bid,
        contact=contact,
        l_c_m=l_c,
        k=k,
        primary=primary,
        video=video,
        track=track,
        imu=imu,
        table=table,
        sync_method=r.get("sync.method", "xcorr", kind=str, choices=("xcorr", "none")),
        max_offset_s=r.get("sync.max_offset_s", 5.0, kind=float, positive=True),
        fit_restitution=r.get("fit.restitution", True, kind=bool),
        fit_window=r.get("fit.window", "middle50", kind=str, choices=_WINDOWS),
        laws=laws,
        duration_s=duration,
        eta_given=eta_given,
        rrd=r.get("output.rrd", True, kind=bool),
        video_decimation=r.get("output.video_decimation", 1, kind=int, positive=True),
        figures=r.get("output.figures", True, kind=bool),
        columns=columns,
        column_cut_m=cut,
        column_impacts=n_imp,
        truth=truth,
    )
    r.check_unknown()
    return cfg


def _video_missing(data: dict) -> bool:
    """True when the config has no [sources.video] section."""
    return "video" not in data.get("sources", {})


def _catalogue() -> dict:
    """Čeh Table 2 as {id: {b_m, h_m, mass_kg}} (from rocklab.fitting's package data)."""
    from ...fitting import ceh_catalogue

    return {
        str(r["block"]): {"b_m": float(r["b_m"]), "h_m": float(r["h_m"]), "mass_kg": float(r["mass_kg"])}
        for _, r in ceh_catalogue().iterrows()
    }


EXAMPLE_TOML = textwrap.dedent(
    """\
    name = "B6M_full_01"              # optional; defaults to the file's folder name

    [block]                           # either a catalogue id ...
    id = "B6M"                        # Čeh et al. (2018) Table 2 (B1S..B10L)
    # ... or dimensions (override the catalogue when both are given)
    b_m = 0.045
    h_m = 0.2025
    mass_kg = 1.0896                  # optional

    [contact]
    type = "full"                     # full | edge
    l_c_m = 0.0015                    # edge only: width of the base strip
    k = 0.9                           # optional: k for eta_M (else from l_c or the Eq. 19 regression)

    [sources]
    primary = "video"                 # video | imu | track

    [sources.video]                   # a video and its tracking config ...
    path = "video.mkv"
    track_config = "track.toml"
    object = "block_1"                # which tracked object is this block
    fps = 50                          # only if the container has none
    corrections = "fix.csv"           # optional: manual corrections of the track (drop / set)

    [sources.track]                   # ... or an already tracked CSV (t_s, theta_rad[, object])
    path = "tracks.csv"
    object = "block_1"

    [sources.imu]                     # x-IMU / x-IMU3 / Fusion log folder or CSV
    path = "imu/block_1"
    axis = "auto"                     # x|y|z with optional sign, or auto
    rate_hz = 256                     # only if the log does not say

    [sources.table]                   # shake-table runs: base motion from ...
    from = "video"                    # video (tracked table object) | imu | record | none
    object = "table"
    imu = "imu/table"                 # when from = "imu"
    record = "elcentro.AT2"           # when from = "record"
    units = "g"

    [sync]
    method = "xcorr"                  # xcorr | none
    max_offset_s = 5.0

    [fit]
    restitution = true
    window = "middle50"               # middle50 | all | first

    [simulate]
    laws = ["housner", "eta_e", "modified"]   # also "eta_e_first", "given" (uses eta below)
    eta = 0.93                        # optional: a known constant restitution, simulated as "given"
    duration_s = 0                    # 0: as long as the measurement

    [column]                          # column experiments (thesis §4.3): tracked objects bottom to top
    objects = ["block_1", "block_2", "block_3"]
    cut_m = 0.002                     # cut edge at every joint, m
    impacts = 1                       # consecutive impacts per joint closing (thesis: 2)

    [output]
    rrd = true
    video_decimation = 1              # log every n-th frame to Rerun
    figures = true
"""
)
"""The commented schema of ``experiment.toml``: every key, its default and its choices."""
