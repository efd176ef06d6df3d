"""Experiment configuration (``experiment.toml``) for ``rocklab run``: schema, reader and writer.

A commented example is in ``examples/experiment.toml`` and in :data:`EXAMPLE_TOML`, which documents
every key, its default and its choices (all lengths in m, times in s, angles in rad). Paths in the
file are relative to the file's folder. Every error names the file, the key and (where it can be
found) the line.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path

from .._errors import InputError
from ._toml import TomlDoc, default_of, dumps_toml

__all__ = [
    "ExperimentConfig",
    "SourceVideo",
    "SourceTrack",
    "SourceImu",
    "SourceTable",
    "load_experiment_config",
    "experiment_name",
    "load_experiment_tags",
    "EXAMPLE_TOML",
    "CONTACT_TYPES",
    "PRIMARY_SOURCES",
    "TABLE_SOURCES",
    "SYNC_METHODS",
    "FIT_WINDOWS",
    "SIMULATED_LAWS",
]

CONTACT_TYPES = ("full", "edge")
#: The sources a measured theta(t) comes from, in the order one is chosen when ``primary`` is not set.
PRIMARY_SOURCES = ("video", "track", "imu")
TABLE_SOURCES = ("video", "imu", "record", "none")
SYNC_METHODS = ("xcorr", "none")
#: The stretch of a free-rocking record a restitution fit uses (:func:`rocklab.fitting.fit_restitution`;
#: the first is the default).
FIT_WINDOWS = ("middle50", "all", "first")
#: The restitution laws a run simulates against the measurement ("given": ``[simulate] eta``).
SIMULATED_LAWS = ("housner", "eta_e", "modified", "eta_e_first", "given", "axes", "cut_corner", "bumps")
#: ``[sources.imu] axis``: the block's rocking axis in the IMU's frame, optionally signed.
IMU_AXIS = re.compile(r"auto|[+-]?[xyz]")


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
    """An already tracked CSV with ``t_s, theta_rad`` (and optionally ``object``), or a Tracker
    project / Kinovea spreadsheet whose points are one block (``rocklab.tracking.imports``)."""

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

    source: str = "none"  # one of TABLE_SOURCES
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
    fit_window: str = FIT_WINDOWS[0]
    laws: tuple = ("housner", "eta_e", "modified")
    duration_s: float = 0.0
    eta_given: float | None = None
    bumps_n: int = 1  # the bumps law (thesis App. A): bumps between the contact corners
    b2_m: float | None = None  # cut_corner, bumps: half-distance of the outer contact lines (None: b/2)
    x1_m: float | None = None  # axes: the rotation axis before an impact, m from the middle (None: -b/2)
    x2_m: float | None = None  # axes: the axis after it (None: +b/2)
    rrd: bool = True
    video_decimation: int = 1
    figures: bool = True
    columns: tuple = ()  # for column experiments: object ids bottom to top
    column_cut_m: float = 0.0
    column_impacts: int = 1
    column_b_m: tuple = ()  # width of each level, m, bottom to top (empty: [block] b_m at every level)
    column_h_m: tuple = ()  # height of each level, m (empty: [block] h_m)
    column_mass_kg: tuple = ()  # mass of each level, kg (empty: [block] mass_kg, else granite)
    column_theta0_rad: tuple = ()  # free release: each level's start angle, measured sense (empty: measured)
    column_imus: tuple = ()  # one IMU log (folder or CSV) per level, bottom to top
    column_imu_axis: str | None = None  # the levels' IMUs' rocking axis, signed for the camera's sense
    column_event_tol_s: float = 0.02  # a simulated event matches a measured one within this, s
    truth: Path | None = None  # synthetic sessions: truth.csv for the report
    tags: tuple = ()  # ``[experiment] tags``: (key, value) pairs a campaign groups repeats by

    @property
    def tag_dict(self) -> dict:
        """``[experiment] tags`` as a dict (key: str, int or bool)."""
        return dict(self.tags)

    def block(self):
        """The :class:`rocklab.Block` of this experiment."""
        from ..blocks import Block

        return Block(self.b_m, self.h_m, mass_kg=self.mass_kg, name=self.block_id or self.name)

    def column_blocks(self) -> list:
        """The :class:`rocklab.Block` of each column level, bottom to top: ``[column] b_m, h_m,
        mass_kg`` where given, else the ``[block]`` values (identical blocks)."""
        from ..blocks import Block

        out = []
        for i, oid in enumerate(self.columns):
            b = self.column_b_m[i] if self.column_b_m else self.b_m
            h = self.column_h_m[i] if self.column_h_m else self.h_m
            m = self.column_mass_kg[i] if self.column_mass_kg else self.mass_kg
            out.append(Block(b, h, mass_kg=m, name=oid))
        return out

    def input_files(self) -> list[Path]:
        """Every input file the run reads (for the unchanged-inputs check)."""
        out = [self.path]
        if self.video is not None:
            out.append(self.video.path)
            if self.video.corrections:
                out.append(self.video.corrections)
            if self.video.track_config:
                out += [self.video.track_config, *_track_config_files(self.video.track_config)]
        out += [src.path for src in (self.track, self.imu) if src is not None]
        out += list(self.column_imus)
        for p in (self.table.imu, self.table.record, self.truth):
            if p:
                out.append(p)
        files = []
        for p in out:
            files.extend(sorted(q for q in p.rglob("*") if q.is_file()) if p.is_dir() else [p])
        return files

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        return _paths_to_str(asdict(self))

    def to_toml(self, header=()) -> str:
        """``experiment.toml`` text that :func:`load_experiment_config` reads back to this config:
        paths relative to the file's folder, keys at their default left out (``header``: comment
        lines written first)."""
        rel = self.path.parent

        def p(v):
            return None if v is None else Path(os.path.relpath(Path(v), rel)).as_posix()

        def src(obj, paths):
            d = {k: (p(v) if k in paths else v) for k, v in dataclasses.asdict(obj).items()}
            return {k: v for k, v in d.items() if v is not None}

        d: dict = {"name": self.name, "truth": p(self.truth)}
        if self.tags:
            d["experiment"] = {"tags": self.tag_dict}
        d["block"] = {"id": self.block_id, "b_m": self.b_m, "h_m": self.h_m, "mass_kg": self.mass_kg}
        for (table, key), name in _FIELDS.items():
            v = getattr(self, name)
            if v != default_of(ExperimentConfig, name):
                d.setdefault(table, {})[key] = list(v) if isinstance(v, tuple) else v
        sources: dict = {"primary": self.primary}
        if self.video is not None:
            sources["video"] = src(self.video, ("path", "track_config", "corrections"))
        if self.track is not None:
            sources["track"] = src(self.track, ("path",))
        if self.imu is not None:
            sources["imu"] = src(self.imu, ("path",))
        table = src(self.table, ("imu", "record"))
        sources["table"] = {"from": table.pop("source"), **table}
        d["sources"] = sources
        if self.column_imus:
            d.setdefault("column", {})["imu"] = [p(v) for v in self.column_imus]
        order = (
            "name",
            "truth",
            "experiment",
            "block",
            "contact",
            "sources",
            "sync",
            "fit",
            "simulate",
            "column",
            "output",
        )
        return dumps_toml({k: d[k] for k in order if k in d}, header)


#: ``experiment.toml`` keys read straight into one :class:`ExperimentConfig` field (their default).
_FIELDS = {
    ("contact", "type"): "contact",
    ("contact", "l_c_m"): "l_c_m",
    ("contact", "k"): "k",
    ("sync", "method"): "sync_method",
    ("sync", "max_offset_s"): "max_offset_s",
    ("fit", "restitution"): "fit_restitution",
    ("fit", "window"): "fit_window",
    ("simulate", "laws"): "laws",
    ("simulate", "eta"): "eta_given",
    ("simulate", "duration_s"): "duration_s",
    ("simulate", "bumps"): "bumps_n",
    ("simulate", "b2_m"): "b2_m",
    ("simulate", "x1_m"): "x1_m",
    ("simulate", "x2_m"): "x2_m",
    ("column", "objects"): "columns",
    ("column", "cut_m"): "column_cut_m",
    ("column", "impacts"): "column_impacts",
    ("column", "b_m"): "column_b_m",
    ("column", "h_m"): "column_h_m",
    ("column", "mass_kg"): "column_mass_kg",
    ("column", "theta0_rad"): "column_theta0_rad",
    ("column", "imu_axis"): "column_imu_axis",
    ("column", "event_tol_s"): "column_event_tol_s",
    ("output", "rrd"): "rrd",
    ("output", "video_decimation"): "video_decimation",
    ("output", "figures"): "figures",
}

#: Every table of ``experiment.toml`` and its keys (what the unknown-key rule checks against).
SCHEMA: dict[tuple, tuple] = {
    (): ("name", "truth", "experiment", "block", "contact", "sources", "sync", "fit", "simulate", "column", "output"),
    ("experiment",): ("tags",),
    ("block",): ("id", "b_m", "h_m", "mass_kg"),
    ("sources",): ("primary", "video", "track", "imu", "table"),
    ("sources", "video"): tuple(f.name for f in dataclasses.fields(SourceVideo)),
    ("sources", "track"): tuple(f.name for f in dataclasses.fields(SourceTrack)),
    ("sources", "imu"): tuple(f.name for f in dataclasses.fields(SourceImu)),
    ("sources", "table"): ("from", "object", "imu", "record", "units"),
    **{(t,): tuple(k for (tt, k) in _FIELDS if tt == t) for t, _ in _FIELDS},
}
SCHEMA[("column",)] += ("imu",)  # paths, read by _column_keys (relative to the file's folder)


def _track_config_files(path: Path) -> list[Path]:
    """Files a ``track.toml`` names (its lens calibration): a run reads them, so a changed
    calibration must change the fingerprint. Unreadable configs add nothing here; the
    tracking stage reports them with their line."""
    from ._track_toml import load_track_config

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


def experiment_name(path) -> str | None:
    """The ``name`` an ``experiment.toml`` gives (its folder's name when it gives none); None when
    the file cannot be read or the name is not a string (its own run reports that)."""
    try:
        doc = TomlDoc.read(path, "experiment config")
    except InputError:
        return None
    name = doc.data.get("name", Path(path).parent.name)
    return name if isinstance(name, str) else None


def load_experiment_tags(path) -> tuple:
    """The ``[experiment] tags`` of an ``experiment.toml`` as (name, value) pairs, checked as
    :func:`load_experiment_config` checks them; () when the file cannot be read (its own run
    reports that)."""
    try:
        doc = TomlDoc.read(path, "experiment config")
        return _tags(_Reader(doc.data, doc.text, Path(path)))
    except InputError:
        return ()


# ---------------------------------------------------------------------- reading
class _Reader(TomlDoc):
    """``experiment.toml`` values by key path, with their defaults from :class:`ExperimentConfig`."""

    def at(self, key):
        node = self.data
        for p in key:
            if not isinstance(node, dict) or p not in node:
                return None
            node = node[p]
        return node

    def field(self, key, kind, positive=False):
        """The value at ``key`` (an :data:`_FIELDS` key), its field's default when absent."""
        name = _FIELDS[key]
        v = self.at(key)
        if v is None:
            return default_of(ExperimentConfig, name)
        return self.typed(key, v, kind, positive=positive)

    def get(self, key, kind, default=None, choices=None, positive=False):
        """The value at ``key`` checked as ``kind`` (float, int, bool, str, list of str), ``default``
        when absent."""
        v = self.at(key)
        return default if v is None else self.typed(key, v, kind, choices, positive)

    def typed(self, key, v, kind, choices=None, positive=False):
        if v is None:
            return None
        if kind is float:
            v = self.number(key, v, positive=positive)
        elif kind is int:
            v = self.number(key, v, positive=positive, integer=True)
        elif kind is bool:
            v = self.boolean(key, v)
        elif kind is str:
            v = self.string(key, v, choices)
        elif kind is list:
            if not isinstance(v, list) or not all(isinstance(x, str) for x in v):
                self.fail(key, f"must be an array of strings, got {v!r}")
            v = tuple(v)
        return v

    def path(self, key, allow_dir=False) -> Path:
        """The existing file (or folder, with ``allow_dir``) a required key names."""
        p = self.file(key, required=True, allow_dir=allow_dir)
        if p is None:
            self.fail(key, "is required")
        return p

    def file(self, key, required=False, allow_dir=False) -> Path | None:
        """The existing file (or folder) ``key`` names, relative to the config's folder."""
        v = self.typed(key, self.at(key), str)
        if v is None:
            if required:
                self.fail(key, "is required")
            return None
        return self.existing(key, v, allow_dir)

    def existing(self, key, v, allow_dir=False) -> Path:
        """The existing file (or folder) the string ``v`` at ``key`` names, relative to the config's folder."""
        if not isinstance(v, str):
            self.fail(key, f"must be a path (a string), got {v!r}")
        p = (self.source.parent / v).resolve()
        if not (p.is_file() or (allow_dir and p.is_dir())):
            self.fail(key, f"names {v!r}, which does not exist (looked in {p.parent}); fix the path")
        return p


def load_experiment_config(path, block_catalogue: Callable[[], Mapping[str, dict]] | None = None) -> ExperimentConfig:
    """Read and validate an ``experiment.toml``.

    Parameters
    ----------
    path : path
    block_catalogue : callable or None
        Returns ``{block id: {"b_m", "h_m", "mass_kg"}}`` for ``[block] id`` without dimensions
        (:func:`rocklab.pipelines.load_experiment` passes Čeh Table 2); called only then.

    Raises
    ------
    InputError
        Missing file, TOML syntax error (with its line), unknown table or key, wrong type or
        value (naming the key and its line), missing input files.
    """
    path = Path(path).resolve()
    doc = TomlDoc.read(path, "experiment config")
    r = _Reader(doc.data, doc.text, path)
    data = r.data
    r.reject_unknown((), data, SCHEMA[()])
    for t in SCHEMA:
        if t and len(t) == 1:
            r.table(t, data.get(t[0]))
    sources = data.get("sources", {})
    for s in ("video", "track", "imu", "table"):
        r.table(("sources", s), sources.get(s))

    # -- block ----------------------------------------------------------------
    if "block" not in data:
        raise InputError(f'{path}: missing [block] section; give id = "B6M" or b_m/h_m')
    bid = r.get(("block", "id"), str)
    b = r.get(("block", "b_m"), float, positive=True)
    h = r.get(("block", "h_m"), float, positive=True)
    m = r.get(("block", "mass_kg"), float, positive=True)
    if bid is not None and (b is None or h is None):
        cat = block_catalogue() if block_catalogue is not None else {}
        if bid not in cat:
            r.fail(
                ("block", "id"), f"= {bid!r} is not in the Čeh Table 2 catalogue (B1S..B10L); give b_m and h_m instead"
            )
        row = cat[bid]
        b = b or row["b_m"]
        h = h or row["h_m"]
        m = m or row.get("mass_kg")
    if b is None or h is None:
        r.fail(("block",), "needs b_m and h_m (m), or an id from the catalogue")

    contact = r.get(("contact", "type"), str, default_of(ExperimentConfig, "contact"), choices=CONTACT_TYPES)
    l_c = r.field(("contact", "l_c_m"), float, positive=True)
    if contact == "edge" and l_c is None:
        r.fail(("contact", "l_c_m"), "is required for edge contact (width of the base strip, m)")
    if l_c is not None and l_c >= b / 2:
        r.fail(("contact", "l_c_m"), f"= {l_c} m must be less than half the block width ({b / 2} m)")
    k = r.field(("contact", "k"), float, positive=True)

    # -- sources --------------------------------------------------------------
    video, track, imu, table, primary = _sources(r, path, sources, column_imus="imu" in data.get("column", {}))

    laws = r.field(("simulate", "laws"), list)
    for law in laws:
        if law not in SIMULATED_LAWS:
            r.fail(("simulate", "laws"), f"contains {law!r}; allowed: {', '.join(SIMULATED_LAWS)}")
    eta_given = r.field(("simulate", "eta"), float)
    if eta_given is not None and not -1.0 < eta_given < 1.0:
        r.fail(("simulate", "eta"), f"= {eta_given} must lie in (-1, 1) (ratio of angular velocities)")
    if eta_given is not None and "given" not in laws:
        laws = laws + ("given",)
    if "given" in laws and eta_given is None:
        r.fail(("simulate", "laws"), "contains 'given' but [simulate] eta is not set")
    columns = r.field(("column", "objects"), list)
    col = _column_keys(r, columns, video, b)
    duration = r.field(("simulate", "duration_s"), float)
    if not (math.isfinite(duration) and duration >= 0):
        r.fail(("simulate", "duration_s"), f"= {duration} must be >= 0 s (0: as long as the measurement)")
    cfg = ExperimentConfig(
        path=path,
        name=r.get(("name",), str, path.parent.name),
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
        sync_method=r.get(("sync", "method"), str, default_of(ExperimentConfig, "sync_method"), choices=SYNC_METHODS),
        max_offset_s=r.field(("sync", "max_offset_s"), float, positive=True),
        fit_restitution=r.field(("fit", "restitution"), bool),
        fit_window=r.get(("fit", "window"), str, default_of(ExperimentConfig, "fit_window"), choices=FIT_WINDOWS),
        laws=laws,
        duration_s=duration,
        eta_given=eta_given,
        bumps_n=_bumps(r),
        b2_m=r.field(("simulate", "b2_m"), float, positive=True),
        x1_m=r.field(("simulate", "x1_m"), float),
        x2_m=r.field(("simulate", "x2_m"), float),
        rrd=r.field(("output", "rrd"), bool),
        video_decimation=r.field(("output", "video_decimation"), int, positive=True),
        figures=r.field(("output", "figures"), bool),
        columns=columns,
        column_impacts=r.field(("column", "impacts"), int, positive=True),
        **col,
        truth=r.file(("truth",), required=False),
        tags=_tags(r),
    )
    for t, known in SCHEMA.items():
        if t and isinstance(r.at(t), dict):
            r.reject_unknown(t, r.at(t), known)
    return cfg


def _column_keys(r: _Reader, columns: tuple, video, b_block: float) -> dict:
    """``[column]``'s per-level keys, checked: one value per object, a signed axis with IMUs, every
    level measured (video or its IMU), cuts narrower than half the narrowest joint."""
    n = len(columns)
    out = {}
    for key in ("b_m", "h_m", "mass_kg", "theta0_rad"):
        v = r.vector(("column", key), r.at(("column", key)))
        if v is not None and len(v) != n:
            r.fail(("column", key), f"has {len(v)} values for {n} [column] objects; give one per level, bottom to top")
        if v is not None and key != "theta0_rad" and not all(x > 0 for x in v):
            r.fail(("column", key), f"= {list(v)} must all be positive")
        out[f"column_{key}"] = tuple(v or ())
    imus = r.at(("column", "imu"))
    paths: tuple = ()
    if imus is not None:
        if not isinstance(imus, list) or len(imus) != n:
            r.fail(("column", "imu"), f"must be an array of {n} IMU log paths (one per [column] object, bottom to top)")
        paths = tuple(r.existing(("column", "imu"), v, allow_dir=True) for v in imus)
    axis = r.get(("column", "imu_axis"), str)
    if paths and (axis is None or not re.fullmatch(r"[+-]?[xyz]", axis)):
        r.fail(
            ("column", "imu_axis"),
            f"= {axis!r}: the levels' IMUs need their rocking axis with the sign that turns "
            "counter-clockwise as the camera sees it positive (e.g. '-y'); 'auto' cannot tell the levels' senses apart",
        )
    if columns and video is None and not paths:
        r.fail(("column", "objects"), "needs a [sources.video] section or [column] imu (one IMU log per level)")
    widths = out["column_b_m"] or (b_block,) * n
    cut = r.field(("column", "cut_m"), float)
    narrow = min((min(widths[j], widths[j - 1]) if j else widths[j]) for j in range(n)) if n else b_block
    if cut < 0 or cut >= narrow / 2:
        r.fail(("column", "cut_m"), f"= {cut} m must be in [0, {narrow / 2:g}) (half the narrowest joint)")
    tol = r.field(("column", "event_tol_s"), float, positive=True)
    return dict(out, column_cut_m=cut, column_imus=paths, column_imu_axis=axis, column_event_tol_s=tol)


def _sources(r: _Reader, path: Path, sources: dict, column_imus: bool = False):
    """``[sources]``: (video, track, imu, table, primary); a column measured by its levels' IMUs
    needs no other source."""
    video = track = imu = None
    s = "sources"
    if "video" in sources:
        V = SourceVideo
        video = V(
            path=r.path((s, "video", "path"), allow_dir=True),
            track_config=r.file((s, "video", "track_config"), required=False),
            object=r.get((s, "video", "object"), str, default_of(V, "object")),
            fps=r.get((s, "video", "fps"), float, positive=True),
            corrections=r.file((s, "video", "corrections"), required=False),
        )
    if "track" in sources:
        track = SourceTrack(path=r.path((s, "track", "path")), object=r.get((s, "track", "object"), str))
    if "imu" in sources:
        imu = SourceImu(
            path=r.path((s, "imu", "path"), allow_dir=True),
            axis=r.get((s, "imu", "axis"), str, default_of(SourceImu, "axis")),
            rate_hz=r.get((s, "imu", "rate_hz"), float, positive=True),
        )
        if not IMU_AXIS.fullmatch(imu.axis):
            r.fail((s, "imu", "axis"), f"= {imu.axis!r} must be x, y, z (optionally signed, e.g. -y) or auto")
    if video is None and track is None and imu is None and not column_imus:
        raise InputError(f"{path}: [sources] needs at least one of [sources.video], [sources.track], [sources.imu]")
    given = {"video": video, "track": track, "imu": imu}
    primary = r.get((s, "primary"), str, choices=PRIMARY_SOURCES)
    if primary is None:
        primary = next((p for p in PRIMARY_SOURCES if given[p] is not None), "imu")
    if given[primary] is None and not (column_imus and primary == "imu"):
        r.fail((s, "primary"), f"= {primary!r} but there is no [sources.{primary}] section")
    T = SourceTable
    tsrc = r.get((s, "table", "from"), str, default_of(T, "source"), choices=TABLE_SOURCES)
    table = T(
        source=tsrc,
        object=r.get((s, "table", "object"), str, default_of(T, "object")),
        imu=r.file((s, "table", "imu"), required=tsrc == "imu", allow_dir=True),
        record=r.file((s, "table", "record"), required=tsrc == "record"),
        units=r.get((s, "table", "units"), str),
    )
    if tsrc == "video" and video is None:
        r.fail((s, "table", "from"), "= 'video' needs a [sources.video] section")
    return video, track, imu, table, primary


def _choices(options) -> str:
    return " | ".join(options)


EXAMPLE_TOML = f"""\
name = "B6M_full_01"              # optional; defaults to the file's folder name
truth = "truth.csv"               # optional (synthetic sessions): the true motion, for the report

[experiment]                      # optional: free-form tags; `rocklab campaign` groups repeats by them
tags = {{ config = "a", tape = "micropore" }}   # values: strings, integers or true/false

[block]                           # either a catalogue id ...
id = "B6M"                        # Čeh et al. (2018) Table 2 (B1S..B10L)
# ... or dimensions (override the catalogue when both are given)
b_m = 0.045
h_m = 0.2025
mass_kg = 1.0896                  # optional

[contact]
type = "full"                     # {_choices(CONTACT_TYPES)}
l_c_m = 0.0015                    # edge only: width of the base strip
k = 0.9                           # optional: k for eta_M (else from l_c or the Eq. 19 regression)

[sources]
primary = "video"                 # {_choices(PRIMARY_SOURCES)} (default: the first given, in this order)

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
from = "video"                    # {_choices(TABLE_SOURCES)} (video: the tracked table object)
object = "table"
imu = "imu/table"                 # when from = "imu"
record = "elcentro.AT2"           # when from = "record"
units = "g"

[sync]
method = "xcorr"                  # {_choices(SYNC_METHODS)}
max_offset_s = 5.0

[fit]
restitution = true
window = "middle50"               # {_choices(FIT_WINDOWS)}

[simulate]
laws = ["housner", "eta_e", "modified"]   # of {", ".join(SIMULATED_LAWS)} ("given" uses eta below)
eta = 0.93                        # optional: a known constant restitution, simulated as "given"
duration_s = 0                    # 0: as long as the measurement
bumps = 1                         # law "bumps" (thesis App. A): bumps between the contact corners
b2_m = 0.02                       # laws "cut_corner", "bumps": half-distance of the outer contact lines, m (default b/2)
x1_m = -0.0225                    # law "axes" (thesis Eq. A3): rotation axis before the impact, m from the middle
x2_m = 0.0225                     # ... and after it (defaults -b/2, +b/2: Housner)

[column]                          # column experiments (thesis §4.2-4.3): levels bottom to top
objects = ["block_1", "block_2", "block_3"]   # their ids (the tracked objects when there is a video)
cut_m = 0.002                     # cut edge at every joint, m
impacts = 1                       # consecutive impacts per joint closing (thesis: 2)
b_m = [0.12, 0.1, 0.08]           # optional: each level's width, m (default: [block] b_m at every level)
h_m = [0.3, 0.2, 0.2]             # optional: each level's height, m (default: [block] h_m)
mass_kg = [9.7, 5.4, 3.5]         # optional: each level's mass, kg (default: [block] mass_kg)
theta0_rad = [0.0, 0.0, -0.1]     # optional, free release: each level's start angle, counter-clockwise
                                  # as the camera sees it (default: measured in the rest before the release)
imu = ["imu/block_1", "imu/block_2", "imu/block_3"]  # optional: one IMU log per level (video optional then)
imu_axis = "-y"                   # with imu: the rocking axis, signed so that counter-clockwise is positive
event_tol_s = 0.02                # a simulated opening or impact matches a measured one within ± this, s

[output]
rrd = true
video_decimation = 1              # log every n-th frame to Rerun
figures = true
"""
"""The commented schema of ``experiment.toml``: every key, an example value and its choices."""


def _bumps(r) -> int:
    """``[simulate] bumps``: a whole number of bumps, 0 or more."""
    n = r.at(("simulate", "bumps"))
    if n is None:
        return default_of(ExperimentConfig, "bumps_n")
    if isinstance(n, bool) or not isinstance(n, int) or n < 0:
        r.fail(("simulate", "bumps"), f"= {n!r} must be a whole number of bumps, 0 or more")
    return n


#: A tag's name: it becomes the campaign column ``tag_<name>``.
TAG_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


def _tags(r) -> tuple:
    """``[experiment] tags``: (name, value) pairs in the file's order; values are strings,
    integers or booleans (a float would group 0.1 and 0.10000001 apart)."""
    v = r.at(("experiment", "tags"))
    if v is None:
        return ()
    key = ("experiment", "tags")
    if not isinstance(v, dict):
        r.fail(key, f'must be a table of names and values, e.g. tags = {{ config = "a" }}, got {v!r}')
    for name, val in v.items():
        if not TAG_NAME.fullmatch(name):
            r.fail(
                key, f"has the name {name!r}, which is not usable: use letters, digits and _, starting with a letter"
            )
        if isinstance(val, float) or not isinstance(val, (str, int, bool)):
            r.fail(key, f'{name} = {val!r}: a tag must be a string, an integer or true/false; e.g. {name} = "{val}"')
    return tuple(v.items())
