"""In a real browser (Debian's Chromium driven by Playwright): the HTML report and the Rerun web viewer render.

Run with ``make test-browser`` (installs Chromium from the system packages and Playwright from
PyPI, pointed at that Chromium: no browser download). Skipped, with the reason, when either is
missing; the default test run deselects these tests (marker ``browser``).
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.parse
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.browser

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
ARGS = ["--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"]


@pytest.fixture(scope="module")
def browser():
    if CHROMIUM is None:
        pytest.skip("no Chromium on this machine (make test-browser installs Debian's chromium)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright not installed (pip install '.[browser]')")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield b
        b.close()


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    """A rendered session, run end to end: report.html and session.rrd. With its IMU, whose log
    starts before the film (the review must still open on the film's first frame)."""
    d = tmp_path_factory.mktemp("browser")
    exe = Path(sys.executable).parent / "rocklab"
    subprocess.run(
        [exe, "synth", "--out", d / "session", "--seed", "1", "--size", "640x360", "--duration", "4"],
        check=True,
        capture_output=True,
    )
    subprocess.run(
        [exe, "run", d / "session" / "experiment.toml", "--out", d / "results"], check=True, capture_output=True
    )
    return d / "results"


def test_html_report_renders_its_figures_and_numbers(browser, run_dir):
    rep = json.loads((run_dir / "report.json").read_text())
    page = browser.new_page()
    page.goto((run_dir / "report.html").as_uri())
    sizes = page.evaluate("Array.from(document.images).map(i => [i.complete, i.naturalWidth, i.naturalHeight])")
    assert len(sizes) == len(rep["outputs"]["figures"]) >= 2
    assert all(ok and w > 200 and h > 100 for ok, w, h in sizes), sizes  # every figure decoded and drawn
    text = page.inner_text("body")
    assert f"η_e = {rep['fit']['eta_e']:.4g}" in text and rep["name"] in page.title()
    rows = page.evaluate("Array.from(document.querySelectorAll('tbody tr')).map(r => r.cells[0].innerText)")
    assert set(rows) == set(rep["simulations"])  # the simulation table, one row per law
    page.close()


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _near(img, rgb, tol=40):
    return np.abs(img[..., :3].astype(int) - np.asarray(rgb)).max(axis=-1) <= tol


def _serve_and_shoot(browser, rrd, shot, ready, tries=40):
    """Serve ``rrd`` with Rerun's web viewer, open it in the browser and screenshot it every second
    until ``ready(img)`` (or ``tries`` seconds). Returns the last screenshot, (h, w, 3) uint8."""
    from PIL import Image

    web, grpc = _free_port(), _free_port()
    rerun = Path(sys.executable).parent / "rerun"
    srv = subprocess.Popen(
        [rerun, rrd, "--serve-web", "--web-viewer-port", str(web), "--port", str(grpc)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        page = browser.new_page(viewport={"width": 1400, "height": 900})
        url = urllib.parse.quote(f"rerun+http://localhost:{grpc}/proxy", safe="")
        for _ in range(30):  # the server takes a moment to listen
            try:
                page.goto(f"http://localhost:{web}/?url={url}", timeout=5000)
                break
            except Exception:  # noqa: BLE001
                time.sleep(0.5)
        img = None
        for _ in range(tries):  # software rendering: wait until the views are drawn
            time.sleep(1.0)
            page.screenshot(path=str(shot))
            img = np.asarray(Image.open(shot).convert("RGB"))
            if ready(img):
                break
        page.close()
        return img
    finally:
        os.killpg(srv.pid, signal.SIGKILL)
        srv.wait()


def test_rerun_web_viewer_draws_the_recording(browser, run_dir, tmp_path):
    """The viewer opens session.rrd and draws it: the film (the AV1 video asset, decoded by the
    browser) on first load, although the IMU log starts before the film, with the tracked outline
    on it, and the θ plot with the measured series (black, bold) and the η_e simulation in its own
    colour."""

    def ready(img):
        right, film = img[60:340, 720:], img[70:540, 10:690]  # θ view top right, video top left
        return (
            _near(right, (0, 114, 178), 30).sum() > 150 and _near(right, (0, 0, 0), 30).sum() > 150 and film.std() > 30
        )

    img = _serve_and_shoot(browser, run_dir / "session.rrd", tmp_path / "viewer.png", ready)
    assert img is not None and img.std() > 10  # not a blank canvas
    right = img[60:340, 720:]
    assert _near(right, (0, 114, 178), 30).sum() > 150, "η_e simulation (blue) not drawn"
    assert _near(right, (0, 0, 0), 30).sum() > 150, "measured θ (black) not drawn"
    film = img[70:540, 10:690]
    # a decoded picture, not the viewer's empty "No data available" panel (std ~5)
    assert film.std() > 30, "the film is not shown on first load"
    # (tolerance 20: Housner's simulated outline, (230, 159, 0), is drawn beside it)
    assert _near(film, (255, 128, 0), 20).sum() > 100, "the tracked outline is not drawn on the film"
    assert _near(film, (0, 114, 178), 30).sum() > 50, "the η_e simulation's block is not drawn on the film"


#: Rerun draws a view's error ("Can only show one text document at a time; was given 7") in a
#: pink box with a red icon.
ERROR_BOX, ERROR_ICON = (253, 230, 238), (236, 0, 79)


def test_campaign_recording_opens_without_an_error(browser, tmp_path):
    """campaign.rrd of seven experiments: the viewer shows the η vs h/b plot with a marker per
    experiment in its contact's colour and the campaign summary, and no view shows an error."""
    from types import SimpleNamespace

    import pandas as pd

    from rocklab.pipelines.campaign._campaign_rrd import CONTACT_COLOURS, campaign_rrd

    rows = [
        ("B3M_full", "B3M", "full", 3.0, 0.81, 0.80),
        ("B4L_full", "B4L", "full", 4.0, 0.84, 0.85),
        ("B5M_full", "B5M", "full", 5.0, 0.87, 0.88),
        ("B7M_full", "B7M", "full", 7.0, 0.90, 0.91),
        ("B9M_full", "B9M", "full", 9.0, 0.93, 0.93),
        ("B3M_edge", "B3M", "edge", 3.0, 0.77, 0.80),
        ("B5M_edge", "B5M", "edge", 5.0, 0.83, 0.88),
    ]
    t = pd.DataFrame(rows, columns=["experiment", "block", "contact", "hb", "eta_e", "eta_H"])
    t["eta_true"], t["b_m"] = t["eta_e"] + 0.001, 0.05
    t["out"] = ["c/experiments/" + n for n in t["experiment"]]
    summary = "# Campaign c\n\n" + "\n".join(f"- {n}: η_e = {e}" for n, e in zip(t.experiment, t.eta_e))
    res = SimpleNamespace(ok_table=t, summary_md=lambda figures=None: summary)
    campaign_rrd(res, tmp_path / "campaign.rrd")

    def markers(img):
        plot = img[60:740, 200:740]  # the scatter plot: left half
        return [_near(plot, rgb, 30).sum() for rgb in CONTACT_COLOURS.values()]

    img = _serve_and_shoot(
        browser, tmp_path / "campaign.rrd", tmp_path / "campaign.png", lambda i: min(markers(i)) > 60
    )
    assert img is not None and img.std() > 10
    assert min(markers(img)) > 60, f"η_e markers (full, edge) not drawn: {markers(img)} px"
    box, icon = _near(img, ERROR_BOX, 6).sum(), _near(img, ERROR_ICON, 30).sum()
    assert box < 500 and icon < 30, f"a view shows an error ({box} px of its box, {icon} of its icon)"
    doc = img[60:560, 745:1090]  # the summary: dark text on the right
    assert (doc.max(axis=-1) < 80).sum() > 300, "the campaign summary is not shown"


@pytest.fixture(scope="module")
def docs_site(tmp_path_factory):
    pytest.importorskip("mkdocs", reason="the docs extra is not installed")
    out = tmp_path_factory.mktemp("site")
    root = Path(__file__).resolve().parents[2]
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1", PYTHONPATH=str(root))
    subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", out],
        cwd=root,
        env=env,
        check=True,
        capture_output=True,
    )
    return out


def test_docs_site_links_work_from_disk(browser, docs_site):
    """Opened from file://, every navigation link of the home page loads a page with its heading
    (not a directory listing), and an API page links to another package's page."""
    page = browser.new_page()
    page.goto((docs_site / "index.html").as_uri())
    hrefs = page.evaluate(
        "Array.from(document.querySelectorAll('nav.md-nav--primary a.md-nav__link[href]')).map(a => a.href)"
    )
    hrefs = sorted({h.split("#")[0] for h in hrefs if h.startswith("file://")})
    assert len(hrefs) >= 15
    for h in hrefs:
        page.goto(h)
        assert "Index of" not in page.title(), h
        assert page.locator("article h1").count() == 1, h
    cross = []  # links from one package's API page into another's
    for pkg in ("blocks", "models", "fitting", "tracking", "synth"):
        page.goto((docs_site / "api" / f"{pkg}.html").as_uri())
        links = page.evaluate("Array.from(document.querySelectorAll('a.autorefs-internal')).map(a => a.href)")
        cross += [h for h in links if "/api/" in h and f"/api/{pkg}.html" not in h.split("#")[0]]
    assert cross
    for h in cross:
        page.goto(h)
        assert page.evaluate("id => document.getElementById(id) !== null", urllib.parse.unquote(h.split("#")[1])), h
    page.close()
