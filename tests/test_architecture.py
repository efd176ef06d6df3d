"""The package's shape: no import circles, dependencies flow one way, only pipelines draw or log."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "rocklab"

# Known and documented exceptions, each to disappear with the restructure of issue 16:
#: TrackConfig.from_dict imports its parser lazily, and the parser builds TrackConfig.
KNOWN_CYCLES = [{"rocklab.tracking.video._config", "rocklab.tracking.video._config_parse"}]
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


def _imports():
    """{module: set of imported rocklab modules and top-level third-party names}, every import (lazy ones too)."""
    graph = {}
    for path in PKG.rglob("*.py"):
        mod = _module_name(path)
        pkg = mod if path.name == "__init__.py" else mod.rsplit(".", 1)[0]
        deps = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
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


def test_packages_hold_at_most_12_modules_where_split():
    # every package
    for pkg in (
        "synth",
        "tracking",
        "tracking/video",
        "tracking/video/targets",
        "tracking/imu",
        "tracking/rigid",
        "tracking/stereo",
        "models",
        "models/rocking",
        "models/column",
        "models/spectra",
        "models/mechanisms",
        "fitting",
        "pipelines",
        "pipelines/cli",
        # pipelines/cli/commands is cut by concept, one module per rocklab command, however many
        "pipelines/experiment",
        "pipelines/campaign",
        "pipelines/spectra",
    ):
        mods = [p for p in (PKG / pkg).glob("*.py") if p.name != "__init__.py"]
        assert len(mods) <= 12, (pkg, len(mods))


def test_no_module_over_500_lines():
    long = {
        str(p.relative_to(PKG)): n
        for p in PKG.rglob("*.py")
        if (n := len(p.read_text(encoding="utf-8").splitlines())) > 500
    }
    assert not long
