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
    """A rendered session, run end to end: report.html and session.rrd. Without the IMU, whose log
    starts before the film, so the viewer opens (time 0) on the film's first frame."""
    d = tmp_path_factory.mktemp("browser")
    exe = Path(sys.executable).parent / "rocklab"
    subprocess.run(
        [exe, "synth", "--out", d / "session", "--seed", "1", "--size", "640x360", "--duration", "4", "--no-imu"],
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


def test_rerun_web_viewer_draws_the_recording(browser, run_dir, tmp_path):
    """The viewer opens session.rrd and draws it: the film (the AV1 video asset, decoded by the
    browser) with the tracked outline on it, and the θ plot with the measured series (black, bold)
    and the η_e simulation in its own colour."""
    from PIL import Image

    web, grpc = _free_port(), _free_port()
    rerun = Path(sys.executable).parent / "rerun"
    srv = subprocess.Popen(
        [rerun, run_dir / "session.rrd", "--serve-web", "--web-viewer-port", str(web), "--port", str(grpc)],
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
        shot = tmp_path / "viewer.png"
        img = None
        for _ in range(40):  # software rendering: wait until the plots are drawn
            time.sleep(1.0)
            page.screenshot(path=str(shot))
            img = np.asarray(Image.open(shot).convert("RGB"))
            right = img[60:340, 720:]  # the θ view: top right of the blueprint
            film = img[70:540, 10:690]  # the video view: top left
            if (
                _near(right, (0, 114, 178), 30).sum() > 150
                and _near(right, (0, 0, 0), 30).sum() > 150
                and film.std() > 30
            ):
                break
        assert img is not None and img.std() > 10  # not a blank canvas
        right = img[60:340, 720:]
        assert _near(right, (0, 114, 178), 30).sum() > 150, "η_e simulation (blue) not drawn"
        assert _near(right, (0, 0, 0), 30).sum() > 150, "measured θ (black) not drawn"
        film = img[70:540, 10:690]
        # a decoded picture, not the viewer's empty "No data available" panel (std ~5)
        assert film.std() > 30, "the film is not shown"
        assert _near(film, (255, 128, 0), 40).sum() > 100, "the tracked outline is not drawn on the film"
        page.close()
    finally:
        os.killpg(srv.pid, signal.SIGKILL)
        srv.wait()
