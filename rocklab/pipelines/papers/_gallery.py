"""The papers' figures and tables, regenerated: one row per figure, its data, and the comparison.

Every figure and table of the three papers (``ceh2018``, ``ther``, ``dejong2014``) has a
:class:`Entry`: a builder that regenerates it, or the reason it is not regenerated (a drawing of
the apparatus, data the paper does not give, or work still open). :func:`regenerate` runs the
builders and writes, into one folder:

- ``<paper>_<figure>.png`` and ``.csv`` per regenerated figure or table;
- ``numbers.json``: ``{"<paper>:<figure>": {"<quantity>": {"paper": ..., "rocklab": ..., "unit": ...}}}``;
- ``index.md``: every row with the paper's caption, the comparison and any discrepancy explained.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["Entry", "Built", "GalleryResult", "Context", "regenerate", "number"]

PAPERS = {
    "ceh2018": "Čeh, Jelenić, Bićanić (2018), Analysis of restitution in rocking of single rigid blocks",
    "ther": "Ther, PhD thesis, Analysis and design of rocking mechanisms",
    "dejong2014": "DeJong & Dimitrakopoulos (2014), Dynamically equivalent rocking structures",
}


def number(paper, rocklab, unit: str = "") -> dict:
    """One quantity of ``numbers.json``: the paper's value (None where it prints none) and ours."""
    return {"paper": paper, "rocklab": rocklab, "unit": unit}


@dataclass(frozen=True)
class Built:
    """What a builder returns.

    Attributes
    ----------
    frame : pandas.DataFrame
        The data behind the figure (written as CSV, unit suffixes in the columns).
    numbers : dict
        ``{quantity: number(paper, rocklab, unit)}``.
    note : str
        The comparison in words, and the discrepancy explained where there is one.
    """

    frame: object
    numbers: dict
    note: str


@dataclass(frozen=True)
class Context:
    """Where a builder writes (``png(key)``) and what it may read (``records``: a folder of records)."""

    out: Path
    records: Path | None = None

    def png(self, key: str) -> Path:
        return self.out / f"{slug(key)}.png"


@dataclass(frozen=True)
class Entry:
    """One figure or table of a paper.

    Attributes
    ----------
    key : str
        ``"<paper>:Fig. N"`` or ``"<paper>:Table N"``.
    caption : str
        The paper's caption (shortened).
    build : callable or None
        ``build(ctx) -> Built``; None when not regenerated.
    why_not : str
        Why it is not regenerated (when ``build`` is None), or what it needs.
    needs_records : bool
        The builder reads records from ``Context.records`` (not shipped with rocklab).
    """

    key: str
    caption: str
    build: Callable | None = None
    why_not: str = ""
    needs_records: bool = False


@dataclass(frozen=True)
class GalleryResult:
    """Rows written by :func:`regenerate`: ``rows`` are dicts with ``key``, ``status``
    (``regenerated``, ``not regenerated``, ``failed``), ``note``, ``png``, ``csv``, ``seconds``."""

    out: Path
    rows: list = field(default_factory=list)

    @property
    def n_regenerated(self) -> int:
        return sum(r["status"] == "regenerated" for r in self.rows)

    def to_frame(self):
        import pandas as pd

        return pd.DataFrame(self.rows)


def slug(key: str) -> str:
    """``"dejong2014:Fig. 15"`` -> ``"dejong2014_fig15"``."""
    paper, what = key.split(":", 1)
    return f"{paper}_{re.sub(r'[^a-z0-9]+', '', what.lower())}"


def regenerate(entries, out, records=None, only=None, progress=None) -> GalleryResult:
    """Run the builders of ``entries`` and write the gallery into ``out``.

    Parameters
    ----------
    entries : sequence of Entry
    out : path
        Output folder (created).
    records : path, optional
        Folder with the records some figures need (e.g. ``../shared/data/records``); without it
        those rows say what to give.
    only : str, optional
        Regenerate only these: comma-separated keys (``ther:Fig. 29``) or papers (``ceh2018``);
        the index still lists every row.
    progress : callable, optional
        Called with each key as it starts.
    """
    from ..._io import write_frame_atomic, write_json_atomic, write_text_atomic

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    ctx = Context(out=out, records=None if records is None else Path(records))
    rows, numbers = [], {}
    for e in entries:
        row = {"key": e.key, "caption": e.caption, "status": "not regenerated", "note": e.why_not, "png": "", "csv": ""}
        run = e.build is not None and _selected(e.key, only)
        if e.build is not None and e.needs_records and ctx.records is None:
            row["note"] = "needs records that rocklab does not ship: give --records DIR (e.g. ../shared/data/records)"
            run = False
        elif e.build is not None and not run:
            row["note"] = "not run (--only)"
        if run:
            if progress is not None:
                progress(e.key)
            t0 = time.perf_counter()
            try:
                b = e.build(ctx)
            except Exception as exc:  # one figure's failure is reported in its row, the rest still run
                row.update(status="failed", note=f"{type(exc).__name__}: {exc}")
            else:
                csv = out / f"{slug(e.key)}.csv"
                write_frame_atomic(csv, b.frame)
                png = ctx.png(e.key)
                row.update(status="regenerated", note=b.note, png=png.name if png.exists() else "", csv=csv.name)
                numbers[e.key] = b.numbers
            row["seconds"] = round(time.perf_counter() - t0, 3)
        rows.append(row)
    write_json_atomic(out / "numbers.json", numbers)
    write_text_atomic(out / "index.md", _index(rows))
    return GalleryResult(out=out, rows=rows)


def _selected(key: str, only) -> bool:
    if only is None:
        return True
    paper = key.split(":", 1)[0]
    return any(o.strip() in (key, paper, paper + ":") for o in str(only).split(","))


def _index(rows) -> str:
    n = sum(r["status"] == "regenerated" for r in rows)
    lines = [
        "# The papers' figures and tables, regenerated by rocklab",
        "",
        f"{n} of {len(rows)} figures and tables regenerated. Each row: the paper's caption, what rocklab "
        "computed and how it compares (numbers in `numbers.json`, data in the CSV), or why the figure is "
        "not regenerated. Nothing is invented: figures whose data the papers do not give say so.",
        "",
    ]
    for paper, title in PAPERS.items():
        lines += [f"## {title}", "", "| figure | caption | status | comparison / reason |", "| --- | --- | --- | --- |"]
        for r in rows:
            if not r["key"].startswith(paper + ":"):
                continue
            what = r["key"].split(":", 1)[1]
            cell = f"[{what}]({r['png']})" if r["png"] else what
            note = r["note"].replace("|", "\\|").replace("\n", " ")
            lines.append(f"| {cell} | {r['caption']} | {r['status']} | {note} |")
        lines.append("")
    return "\n".join(lines)
