"""docs/papers.md: every equation of the three papers has a row; its function imports and its test exists."""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "papers.md"
SECTIONS = {"Čeh": ("## Čeh", 19), "thesis": ("## Ther", 31), "DeJong": ("## DeJong", 42)}
ROW = re.compile(r"^\| ([^|]+) \| [^|]+ \| ([^|]+) \| ([^|]+) \|$")


def _rows(paper: str):
    """(label, function, test) rows of one paper's section."""
    head = SECTIONS[paper][0]
    text = PAGE.read_text(encoding="utf-8").split(head, 1)[1].split("\n## ", 1)[0]
    out = []
    for line in text.splitlines():
        m = ROW.match(line.strip())
        if m and not set(m.group(1).strip()) <= set("- ") and m.group(2).strip() != "Function":
            out.append(tuple(g.strip() for g in m.groups()))
    return out


def _numbers(label: str) -> set[int]:
    """Equation numbers of a row label: ``7``, ``8–9``, ``26–32``; appendices/tables give none."""
    m = re.fullmatch(r"(\d+)(?:[–-](\d+))?", label)
    if not m:
        return set()
    lo = int(m.group(1))
    return set(range(lo, int(m.group(2) or lo) + 1))


def _resolve(dotted: str):
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for name in parts[i:]:
            obj = getattr(obj, name)
        return obj
    raise ImportError(dotted)


@pytest.mark.parametrize("paper", list(SECTIONS))
def test_every_equation_has_a_row(paper):
    covered = set().union(*(_numbers(r[0]) for r in _rows(paper)))
    assert covered == set(range(1, SECTIONS[paper][1] + 1)), sorted(set(range(1, SECTIONS[paper][1] + 1)) ^ covered)


@pytest.mark.parametrize("paper", list(SECTIONS))
def test_functions_import_and_tests_exist(paper):
    rows = _rows(paper)
    assert len(rows) >= 10
    for label, func, test in rows:
        if func.startswith("—"):  # not implemented: the row says why, and names no test
            assert test == "—" and len(func) > 5, label
            continue
        assert callable(_resolve(func.strip("`"))) or isinstance(_resolve(func.strip("`")), property), func
        path, name = test.strip("`").split("::")
        src = (ROOT / path).read_text(encoding="utf-8")
        assert re.search(rf"^def {name}\(", src, re.M), test


CITE = re.compile(r"(Čeh|thesis|DeJong)[^.\n]{0,12}?Eqs?\.\s*\(?(\d+)(?:\s*[–-]\s*(\d+))?")


def test_equations_cited_in_the_code_have_rows():
    cited: dict[str, set[int]] = {p: set() for p in SECTIONS}
    for f in (ROOT / "rocklab").rglob("*.py"):
        for m in CITE.finditer(f.read_text(encoding="utf-8")):
            lo, hi = int(m.group(2)), int(m.group(3) or m.group(2))
            if hi - lo > 8:  # a package's summary ("Eq. 13-31"), not a citation of each
                continue
            cited[m.group(1)] |= set(range(lo, hi + 1))
    assert sum(map(len, cited.values())) >= 25  # the code does cite the papers
    for paper, nums in cited.items():
        implemented = set().union(*(_numbers(r[0]) for r in _rows(paper) if not r[1].startswith("—")))
        assert nums <= implemented, (paper, sorted(nums - implemented))


def test_discrepancies_page_names_existing_tests():
    text = (ROOT / "docs" / "discrepancies.md").read_text(encoding="utf-8")
    refs = re.findall(r"`(tests/[\w/]+\.py)::(\w+)`", text)
    assert len(refs) >= 10
    for path, name in refs:
        assert re.search(rf"^def {name}\(", (ROOT / path).read_text(encoding="utf-8"), re.M), (path, name)


def test_experiment_toml_page_lists_every_key_the_reader_reads():
    from rocklab.config._experiment_toml import SCHEMA

    # the reader rejects every key outside its schema: the schema's keys are what it reads
    read = {".".join((*t, k)) for t, keys in SCHEMA.items() for k in keys if (*t, k) not in SCHEMA}
    page = (ROOT / "docs" / "experiment-toml.md").read_text(encoding="utf-8")
    documented = set(re.findall(r"^\| `([a-z0-9_.]+)` \|", page, re.M))
    assert len(read) >= 30
    assert read == documented, (sorted(read - documented), sorted(documented - read))
