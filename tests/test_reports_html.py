"""summary.md → report.html: one offline file that says what the Markdown says, figures inlined."""

import base64
import re

import numpy as np
import pytest

from rocklab.pipelines.reports import markdown_to_html, write_html_report


@pytest.fixture
def figure(tmp_path):
    import cv2

    (tmp_path / "figures").mkdir()
    img = np.zeros((7, 11, 3), np.uint8)
    img[2:5, 3:9] = (0, 0, 255)
    ok, buf = cv2.imencode(".png", img)
    (tmp_path / "figures" / "theta.png").write_bytes(buf.tobytes())
    return buf.tobytes()


MD = """# run <1>

Status: **suspect**, η_e = 0.9301 (*fit* `ok`)

| simulation | η | RMS (rad) |
|---|---|---|
| housner | 0.9294 | 0.0123 |
| eta_e | 0.9301 | 0.0004 |

- **warning W-VIDEO-LOST**: 5 of 200 frames lost
- note: a & b < c

## Figures

![theta](figures/theta.png)
![gone](figures/missing.png)

Data: [report.json](report.json)
"""


def test_markdown_subset_to_html(tmp_path, figure):
    html = markdown_to_html(MD, tmp_path, title="t")
    assert "<h1>run &lt;1&gt;</h1>" in html and "<h2>Figures</h2>" in html
    assert "<strong>suspect</strong>" in html and "<em>fit</em>" in html and "<code>ok</code>" in html
    # the table: header and every cell, in order
    rows = re.findall(r"<tr>(.*?)</tr>", html)
    cells = [re.findall(r"<t[hd]>(.*?)</t[hd]>", r) for r in rows]
    assert cells == [["simulation", "η", "RMS (rad)"], ["housner", "0.9294", "0.0123"], ["eta_e", "0.9301", "0.0004"]]
    assert html.count("<li>") == 2 and "a &amp; b &lt; c" in html
    # the figure is inlined byte for byte; a missing one is said, not silently dropped
    (data,) = re.findall(r'src="data:image/png;base64,([^"]+)"', html)
    assert base64.b64decode(data) == figure
    assert "figures/missing.png not found" in html
    assert '<a href="report.json">report.json</a>' in html
    assert "<script" not in html and "http" not in html  # opens offline, nothing fetched


def test_write_is_atomic_and_complete(tmp_path, figure):
    out = write_html_report(MD, tmp_path / "report.html")
    text = out.read_text(encoding="utf-8")
    assert text.startswith("<!DOCTYPE html>") and text.rstrip().endswith("</html>")
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".") or p.suffix == ".tmp"] == []
