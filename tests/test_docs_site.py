"""The documentation site as a reader gets it: built once with MkDocs (``--strict``), then read
as files, the way a browser opens ``site/index.html`` from disk.

Skipped when the ``docs`` extra (MkDocs) is not installed.
"""

from __future__ import annotations

import html
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ["blocks", "series", "models", "fitting", "tracking", "synth"]
HREF = re.compile(r'href="([^"]*)"')


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    pytest.importorskip("mkdocs", reason="the docs extra is not installed (pip install -e '.[docs]')")
    pytest.importorskip("mkdocstrings_handlers.python")
    out = tmp_path_factory.mktemp("site")
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1", PYTHONPATH=str(ROOT))
    p = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert p.returncode == 0, p.stderr[-3000:]
    return out


def _pages(site):
    """The site's pages (404.html is served by a web server only, with absolute links)."""
    return sorted(p for p in site.rglob("*.html") if "assets" not in p.parts and p.name != "404.html")


def test_internal_links_open_files_from_disk(site):
    """Every internal link names a file that exists (no folder URL ending in ``/``, which a
    browser shows as a directory listing from ``file://``)."""
    n = 0
    for page in _pages(site):
        for href in HREF.findall(page.read_text(encoding="utf-8")):
            href = html.unescape(href)
            if re.match(r"^[a-z][a-z0-9+.-]*:", href) or href.startswith(("#", "//")):
                continue  # external, mailto or an anchor on the same page
            path = href.split("#")[0].split("?")[0]
            assert not path.endswith("/") and path not in ("", "."), f"{page.name}: folder link {href!r}"
            assert (page.parent / path).resolve().is_file(), f"{page.name}: {href!r} is not a file"
            n += 1
    assert n > 200


def test_api_is_one_page_per_package_with_roles_rendered(site):
    import importlib

    api = site / "api"
    for pkg in PACKAGES:
        text = (api / f"{pkg}.html").read_text(encoding="utf-8")
        assert f'<h1 id="rocklab.{pkg}"' in text
        mod = importlib.import_module(f"rocklab.{pkg}")
        # every public function and class of the package is on its own page and on no other
        for name in mod.__all__:
            if not callable(getattr(mod, name)):
                continue
            anchor = f'id="rocklab.{pkg}.{name}"'
            assert anchor in text, (pkg, name)
            others = [p for p in PACKAGES if p != pkg and anchor in (api / f"{p}.html").read_text(encoding="utf-8")]
            assert not others, (pkg, name, others)
    n_links = 0
    for page in _pages(site):
        text = page.read_text(encoding="utf-8")
        raw = re.findall(r":(?:func|mod|meth|class|data|attr|obj|exc):", re.sub(r"<[^>]+>", "", text))
        assert not raw, f"{page.name}: raw numpydoc roles {raw[:3]}"
        for href in HREF.findall(text):
            if not (href.startswith("#") or ".html" in href):
                continue  # stylesheets, scripts, images
            target = href.split("#", 1)[-1] if "#" in href else href
            assert not re.search(r"(^|[./])_[a-z]", target), f"{page.name}: links a private name: {href}"
        if page.parent.name == "api":
            n_links += text.count('class="autorefs autorefs-internal"')
    assert n_links >= 100  # the roles became links between the API pages


def test_readme_figures_are_in_the_site(site):
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme.split("## What has been measured", 1)[1].split("\n## ", 1)[0]
    rows = [r.split("|")[1].strip() for r in section.splitlines() if r.startswith("| ") and "---" not in r]
    assert len(rows) >= 15
    text = html.unescape(re.sub(r"<[^>]+>", "", (site / "measured.html").read_text(encoding="utf-8")))
    missing = [r for r in rows if re.sub(r"`", "", r) not in text]
    assert not missing, missing
    assert "η_mat comes\nout at" in readme and "out at 0.9890" in text.replace("\n", " ").replace("  ", " ")
