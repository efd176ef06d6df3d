"""The package's shape: no import circles, dependencies flow one way, only pipelines draw or log."""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "rocklab"

# Known and documented exceptions, each to disappear with the restructure of issue 16:
#: None left: track.toml's schema and reader are one module of rocklab.config.
KNOWN_CYCLES: list = []
#: Measurement modules that call the physics (none: the base motion they make lives in rocklab.series).
TRACKING_TO_MODELS: set = set()
#: What the ground floor (rocklab.series, the data that crosses packages) may import from rocklab.
SERIES_MAY_IMPORT = {"rocklab.blocks", "rocklab._errors", "rocklab._diagnostics", "rocklab._io"}


def _module_name(path: Path) -> str:
    rel = path.relative_to(PKG.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


@functools.cache
def _parse(path: Path, mtime_ns: int) -> ast.Module:
    """One module's syntax tree, parsed once per test process (``mtime_ns`` keys an edited file anew)."""
    return ast.parse(path.read_text(encoding="utf-8"))


def _tree(path: Path) -> ast.Module:
    return _parse(path, path.stat().st_mtime_ns)


def _imports():
    """{module: set of imported rocklab modules and top-level third-party names}, every import (lazy ones too)."""
    return {mod: set(deps) for mod, deps in _import_graph(tuple(sorted(PKG.rglob("*.py")))).items()}


@functools.cache
def _import_graph(paths):
    graph = {}
    for path in paths:
        mod = _module_name(path)
        pkg = mod if path.name == "__init__.py" else mod.rsplit(".", 1)[0]
        deps = set()
        for node in ast.walk(_tree(path)):
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = pkg.split(".")
                    base = base[: len(base) - (node.level - 1)]
                    target = ".".join(base + ([node.module] if node.module else []))
                else:
                    target = node.module or ""
                if target.startswith("rocklab"):
                    # "from . import x" / "from .pkg import mod": the imported names may be modules
                    for a in node.names:
                        cand = f"{target}.{a.name}"
                        deps.add(cand if (PKG.parent / (cand.replace(".", "/") + ".py")).exists() else target)
                else:
                    deps.add(target.split(".")[0])
            elif isinstance(node, ast.Import):
                for a in node.names:
                    deps.add(a.name if a.name.startswith("rocklab") else a.name.split(".")[0])
        graph[mod] = deps
    return graph


def _cycles(graph):
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in graph:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = set()
            while True:
                w = stack.pop()
                on.discard(w)
                comp.add(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(comp)

    for v in graph:
        if v not in index:
            visit(v)
    return out


def _internal(graph):
    """The graph restricted to modules, without package __init__ re-exports (they import downwards)."""
    mods = {m for m in graph if (PKG.parent / (m.replace(".", "/") + ".py")).exists()}
    return {m: {d for d in graph[m] if d in mods} for m in mods}


def test_no_import_circles_but_the_known_one():
    cycles = _cycles(_internal(_imports()))
    assert sorted(map(sorted, cycles)) == sorted(map(sorted, KNOWN_CYCLES))


def _subpackage(mod):
    parts = mod.split(".")
    return parts[1] if len(parts) >= 2 else ""


#: Allowed imports against the layering (none: the tracking -> synth forwarding shim is gone).
ALIASES: set = set()


@pytest.mark.parametrize(
    "layer, forbidden",
    [
        ("models", {"fitting", "pipelines", "tracking", "synth"}),
        ("fitting", {"pipelines", "tracking", "synth"}),
        ("tracking", {"pipelines", "fitting", "synth"}),
        ("synth", {"pipelines", "fitting"}),
        # the ground floor: config files' schemas, which every package may read
        ("config", {"models", "fitting", "pipelines", "tracking", "synth", "series"}),
        ("series", {"models", "fitting", "pipelines", "tracking", "synth", "config"}),
    ],
)
def test_dependencies_flow_one_way(layer, forbidden):
    bad = []
    for mod, deps in _imports().items():
        if _subpackage(mod) != layer:
            continue
        for d in deps:
            if d.startswith("rocklab.") and _subpackage(d) in forbidden and (mod, d) not in ALIASES:
                bad.append(f"{mod} -> {d}")
    assert not bad


def test_config_stands_on_the_ground_floor():
    # rocklab.config may use only the package's base modules (errors, diagnostics, atomic
    # files, blocks) besides third-party code, so every layer can import it
    base = {"rocklab._errors", "rocklab._diagnostics", "rocklab._io", "rocklab.blocks"}
    bad = {
        f"{mod} -> {d}"
        for mod, deps in _imports().items()
        if _subpackage(mod) == "config"
        for d in deps
        if d.startswith("rocklab") and _subpackage(d) != "config" and d not in base
    }
    assert not bad, bad


def test_only_config_reads_toml():
    # track.toml, experiment.toml and corrections are read through rocklab.config's one reader
    readers = {mod for mod, deps in _imports().items() if "tomllib" in deps}
    assert readers and readers <= {"rocklab.config._toml"}, readers


def test_series_is_the_ground_floor():
    graph = _imports()
    series = [m for m in graph if m == "rocklab.series" or m.startswith("rocklab.series.")]
    assert len(series) >= 4  # the package and its modules were found
    bad = [
        f"{m} -> {d}"
        for m in series
        for d in graph[m]
        if d.startswith("rocklab") and not d.startswith("rocklab.series") and d not in SERIES_MAY_IMPORT
    ]
    assert not bad


def test_model_subpackages_do_not_import_up_into_spectra():
    # the simulator's input (BaseMotion) lives in rocklab.series, not in the record readers
    bad = [
        f"{m} -> {d}"
        for m, deps in _imports().items()
        if m.startswith(("rocklab.models.rocking", "rocklab.models.column"))
        for d in deps
        if d.startswith("rocklab.models.spectra")
    ]
    assert not bad


def test_tracking_uses_the_physics_only_where_known():
    users = {
        mod
        for mod, deps in _imports().items()
        if _subpackage(mod) == "tracking" and any(_subpackage(d) == "models" for d in deps)
    }
    assert users <= TRACKING_TO_MODELS, users - TRACKING_TO_MODELS


def test_only_pipelines_draw_or_log_to_rerun():
    bad = [
        mod for mod, deps in _imports().items() if deps & {"matplotlib", "rerun"} and _subpackage(mod) != "pipelines"
    ]
    assert not bad


def test_synth_names_live_in_synth_only():
    # simulated sessions are a simulator of the lab, not a measurement: tracking does not forward them
    import rocklab.synth
    import rocklab.tracking

    assert callable(rocklab.synth.synth_session)
    for name in ("synth_session", "SynthSession", "simulate_imu_log"):
        assert not hasattr(rocklab.tracking, name)


def _function_lengths():
    """{"package.module:function": whole lines, from ``def`` to the last line, signature and docstring
    included} for every function, and the numba kernels apart (their loops are long by nature: one
    kernel, one compiled unit)."""
    out, kernels = {}, set()
    for path in PKG.rglob("*.py"):
        mod = _module_name(path).removeprefix("rocklab.")
        _source_lengths(_tree(path), mod, out, kernels)
    return out, kernels


def _source_lengths(source, mod, out, kernels):
    """Add the functions of one module's ``source`` (text or syntax tree) to ``out`` (whole lengths) and its
    kernels to ``kernels``."""
    for node in ast.walk(ast.parse(source) if isinstance(source, str) else source):
        if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        key = f"{mod}:{node.name}"
        out[key] = max(out.get(key, 0), node.end_lineno - node.lineno + 1)
        if any("jit" in ast.unparse(d) for d in node.decorator_list):
            kernels.add(key)


def test_function_length_counts_the_whole_function():
    # issue 28 counts a function from its def to its last line: signature and docstring are part of it
    source = (
        "@njit(cache=True)\n"
        "def kernel(x):\n"
        "    return x\n"
        "\n"
        "def f(\n"
        "    a,\n"
        "    b,\n"
        "):\n"
        '    """Doc.\n'
        "\n"
        "    More doc.\n"
        '    """\n'
        "    c = a + b\n"
        "    return c\n"
    )
    out, kernels = {}, set()
    _source_lengths(source, "m", out, kernels)
    assert out == {"m:kernel": 2, "m:f": 10}
    assert kernels == {"m:kernel"}


#: Functions still over the limit, each to be cut into steps (issue 28). The list only shrinks:
#: a new long function fails, and so does a listed one that has become short (take it off).
LONG_FUNCTIONS: set[str] = set()


def test_no_function_over_120_lines_outside_numba_kernels():
    lengths, kernels = _function_lengths()
    long = {k for k, n in lengths.items() if n > 120 and k not in kernels}
    assert long - LONG_FUNCTIONS == set(), "new functions over 120 lines: cut them into named steps"
    assert LONG_FUNCTIONS - long == set(), "these are no longer long: take them off LONG_FUNCTIONS"


#: File names used by more than one module, each for a different job (issue 28: to become distinct).
SHARED_FILE_NAMES: set = set()


def test_distinct_file_names_for_distinct_jobs():
    seen: dict = {}
    for p in PKG.rglob("_*.py"):
        if p.name != "__init__.py":
            seen.setdefault(p.name, set()).add(str(p.parent.relative_to(PKG)))
    shared = {k for k, v in seen.items() if len(v) > 1}
    assert shared - SHARED_FILE_NAMES == set(), "a new module reuses another's file name: name it for its job"
    assert SHARED_FILE_NAMES - shared == set(), "these names are now distinct: take them off SHARED_FILE_NAMES"


def _private_imports():
    """Imports that reach into another package's private module, or take a ``_name`` from a module."""
    cross, names = [], []
    for path in PKG.rglob("*.py"):
        mod = _module_name(path)
        pkg = mod if path.name == "__init__.py" else mod.rsplit(".", 1)[0]
        for node in ast.walk(_tree(path)):
            if not isinstance(node, ast.ImportFrom):
                continue
            if node.level:
                base = pkg.split(".")
                target = ".".join(base[: len(base) - (node.level - 1)] + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if not target.startswith("rocklab"):
                continue
            parts = target.split(".")
            private = [i for i, x in enumerate(parts) if x.startswith("_")]
            owner = ".".join(parts[: private[0]]) if private else target
            # the house's ground-floor helpers (rocklab._errors, _io, _diagnostics...) are shared on purpose
            if private and owner not in ("rocklab", pkg) and not pkg.startswith(owner + "."):
                cross.append(f"{mod} -> {target}")
            names += [
                f"{mod} -> {target}.{a.name}"
                for a in node.names
                if a.name.startswith("_") and not a.name.startswith("__")
            ]
    return cross, names


#: The imports that still reach into another package's private module (issue 28: at most 15), each
#: with its reason. A new one fails; so does one listed here that has gone (take it off).
PRIVATE_IMPORTS = {
    "rocklab.pipelines.campaign._campaign_rrd -> rocklab.pipelines.experiment._rerun": (
        "the campaign recording opens, closes and lays out its Rerun file with the experiment's helpers"
    ),
    "rocklab.tracking.stereo._calib -> rocklab.tracking.calib._views": (
        "stereo calibration reads its board views with the lens calibration's frame reader"
    ),
    "rocklab.tracking.stereo._calib -> rocklab.tracking.calib._boards": (
        "stereo calibration parses the same board specs as the lens calibration"
    ),
    "rocklab.tracking.stereo._calib -> rocklab.tracking.calib._lens": (
        "stereo calibration detects each camera's views and judges them by the lens calibration's rules"
    ),
    "rocklab.tracking.stereo._calib -> rocklab.tracking.video._checks": (
        "a mirrored film is refused by the one check the single-camera tracker uses"
    ),
    "rocklab.tracking.stereo._dots3d -> rocklab.tracking.video._checks": "the same mirrored-film check",
    "rocklab.tracking.stereo._world -> rocklab.tracking.rigid._rigidity": (
        "triangulated points are grouped into rigid bodies by the 3D import's rule"
    ),
    "rocklab.tracking.video._track -> rocklab.tracking.video.targets._observability": (
        "the tracker asks the targets which objects' angle cannot be observed"
    ),
    "rocklab.tracking.video._plane -> rocklab.tracking.video.targets._aruco": (
        "the plane map refines marker corners with the ArUco detector's own refinement"
    ),
    "rocklab.tracking.video._camera_model -> rocklab.tracking.calib._boards": (
        "the reference board is found with the calibration's corner window"
    ),
    "rocklab.tracking.video._propose -> rocklab.tracking.video.targets._table_edge": (
        "proposals look for the table's top edge with the edge target's finder and blur"
    ),
    "rocklab.tracking.video._init -> rocklab.tracking.video.targets._markerless": (
        "init refuses a region with the markerless tracker's own texture floor, before writing a config"
    ),
    "rocklab.tracking.calib._views -> rocklab.tracking.video.sequences._imageseq": (
        "calibration photos are read as 8-bit frames by the image-sequence reader"
    ),
    "rocklab.synth._points3d -> rocklab.tracking.rigid._rocking": (
        "synthetic 3D points turn about the rocking axis the 3D decomposition parses"
    ),
}


def test_private_imports_are_listed_with_their_reason():
    cross, names = _private_imports()
    found = set(cross) | set(names)
    assert len(cross) + len(names) <= 15
    assert found - set(PRIVATE_IMPORTS) == set(), "import the name from its package's face instead"
    assert set(PRIVATE_IMPORTS) - found == set(), "these are gone: take them off PRIVATE_IMPORTS"


def _listed_by_hand(tree) -> set:
    """Names written as string literals in a module's ``__all__`` assignments (``=``, ``+=``, annotated)."""
    names = set()
    for node in tree.body:
        if isinstance(node, ast.Assign):
            targets = node.targets
        elif isinstance(node, (ast.AugAssign, ast.AnnAssign)):
            targets = [node.target]
        else:
            continue
        if node.value is not None and any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets):
            names |= {e.value for e in ast.walk(node.value) if isinstance(e, ast.Constant) and isinstance(e.value, str)}
    return names


def test_each_public_name_is_listed_by_one_face():
    # issue 28: a package's __all__ is its names' one list; a face that takes another face's names
    # builds its __all__ from that face's __all__ (as rocklab.models does), never copies them by hand
    import importlib

    faces = {_module_name(p): p for p in PKG.rglob("__init__.py")}
    copies = []
    for face, path in faces.items():
        tree = _tree(path)
        by_hand = _listed_by_hand(tree)
        for node in tree.body:
            if not isinstance(node, ast.ImportFrom):
                continue
            if node.level:
                base = face.split(".")
                src = ".".join(base[: len(base) - (node.level - 1)] + ([node.module] if node.module else []))
            else:
                src = node.module or ""
            if src not in faces:
                continue  # a face's own modules are where its names live
            theirs = set(getattr(importlib.import_module(src), "__all__", ()))
            copies += [f"{face}: {a.name} (listed by {src})" for a in node.names if a.name in by_hand & theirs]
    assert len(faces) > 20  # every package's face was read
    assert not copies, copies
