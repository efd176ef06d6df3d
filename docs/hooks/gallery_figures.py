"""The papers' regenerated figures in the site: ``rocklab papers`` runs at build time.

The figures are computed, not stored: at each build the gallery is regenerated into a temporary
folder (the figures that need no record files, about 70 s on one core, half of it the nine
column OAS of thesis Fig. 43) and added to the site as
``gallery/figures/index.md`` with every PNG beside it. The page is the gallery's own index (one
row per figure and table of the three papers) followed by the images themselves, so a reader sees
each figure with its comparison. A figure that fails to regenerate fails the build.

``ROCKLAB_DOCS_FIGURES=0`` skips the regeneration (the page then says how to make the figures),
for a quick local build of the prose.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from mkdocs.structure.files import File

PAGE = "gallery/figures/index.md"
_tmp: tempfile.TemporaryDirectory | None = None


def _page(index_md: str, rows) -> str:
    shown = [r for r in rows if r["png"]]
    body = [index_md.rstrip(), "", "## The figures", ""]
    for r in shown:
        paper, what = r["key"].split(":", 1)
        body += [f"### {paper} {what}", "", f"{r['caption']}", "", f"![{r['key']}]({r['png']})", ""]
    return "\n".join(body) + "\n"


def on_files(files, config):
    global _tmp
    if os.environ.get("ROCKLAB_DOCS_FIGURES", "1") == "0":
        text = "# The papers' figures\n\nNot built here: run `make figures` (or `rocklab papers --out DIR`).\n"
        files.append(File.generated(config, PAGE, content=text))
        return files
    from rocklab.pipelines.papers import ENTRIES, regenerate

    _tmp = tempfile.TemporaryDirectory(prefix="rocklab-docs-figures-")
    out = Path(_tmp.name)
    res = regenerate(ENTRIES, out)
    failed = [r["key"] for r in res.rows if r["status"] == "failed"]
    if failed:
        raise RuntimeError(
            f"docs: the gallery failed to regenerate {failed}; run 'rocklab papers --out DIR' to see why"
        )
    index = (out / "index.md").read_text(encoding="utf-8")
    files.append(File.generated(config, PAGE, content=_page(index, res.rows)))
    for p in sorted(out.iterdir()):
        if p.suffix in (".png", ".csv") or p.name == "numbers.json":
            files.append(File.generated(config, f"gallery/figures/{p.name}", abs_src_path=str(p)))
    return files


def on_post_build(config):
    global _tmp
    if _tmp is not None:
        _tmp.cleanup()
        _tmp = None
