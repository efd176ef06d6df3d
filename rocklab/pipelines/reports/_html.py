"""Markdown summaries → one self-contained HTML file (figures inlined, no network, no scripts).

Only the Markdown that rocklab's own summaries use is understood: ``#``/``##``/``###``
headings, paragraphs, ``-`` lists, pipe tables, ``**bold**``, ``*italic*``, ```code```,
``[text](href)`` links and ``![alt](path)`` images. A general Markdown library would add a
dependency for text that rocklab writes itself; anything else passes through as escaped text.
"""

from __future__ import annotations

import base64
import html
import re
from pathlib import Path

from ..._io import write_text_atomic

__all__ = ["markdown_to_html", "write_html_report"]

_MIME = {".png": "image/png", ".jpg": "image/jpeg", ".jpeg": "image/jpeg", ".svg": "image/svg+xml"}

_CSS = """
body { font: 15px/1.45 system-ui, -apple-system, "Segoe UI", sans-serif; max-width: 1100px;
       margin: 2em auto; padding: 0 1em; color: #1b1b1b; }
h1 { font-size: 1.6em; border-bottom: 2px solid #333; padding-bottom: .2em; }
h2 { font-size: 1.25em; margin-top: 1.6em; }
table { border-collapse: collapse; margin: .8em 0; }
th, td { border: 1px solid #bbb; padding: .25em .6em; text-align: left; }
th { background: #eee; }
td { font-variant-numeric: tabular-nums; }
img { max-width: 100%; border: 1px solid #ddd; margin: .5em 0; display: block; }
code { background: #f3f3f3; padding: 0 .25em; }
.missing { color: #a00; }
"""


def _inline(text: str, base: Path | None) -> str:
    """Escape ``text`` and render the inline Markdown subset."""
    out, pos = [], 0
    pat = re.compile(r"!\[([^\]]*)\]\(([^)\s]+)\)|\[([^\]]+)\]\(([^)\s]+)\)|`([^`]+)`")
    for m in pat.finditer(text):
        out.append(_emph(html.escape(text[pos : m.start()], quote=False)))
        if m.group(2) is not None:
            out.append(_image(m.group(1), m.group(2), base))
        elif m.group(4) is not None:
            out.append(f'<a href="{html.escape(m.group(4))}">{_emph(html.escape(m.group(3), quote=False))}</a>')
        else:
            out.append(f"<code>{html.escape(m.group(5), quote=False)}</code>")
        pos = m.end()
    out.append(_emph(html.escape(text[pos:], quote=False)))
    return "".join(out)


def _emph(s: str) -> str:
    s = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", s)
    return re.sub(r"(?<![\w*])\*(?!\s)(.+?)(?<!\s)\*(?![\w*])", r"<em>\1</em>", s)


def _image(alt: str, src: str, base: Path | None) -> str:
    """An ``<img>`` with the file inlined as a data URI; a visible note when it is missing."""
    p = (base / src) if base is not None and not re.match(r"^[a-z]+:", src) else None
    mime = _MIME.get(Path(src).suffix.lower())
    if p is None or mime is None or not p.is_file():
        return f'<p class="missing">figure {html.escape(src)} not found</p>'
    data = base64.b64encode(p.read_bytes()).decode("ascii")
    return f'<img alt="{html.escape(alt)}" src="data:{mime};base64,{data}">'


def _cells(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")]


def markdown_to_html(md: str, base_dir=None, title: str = "rocklab report") -> str:
    """One HTML document from rocklab's Markdown ``md``; images under ``base_dir`` are inlined.

    Parameters
    ----------
    md : str
        The Markdown text (a ``summary.md``).
    base_dir : path, optional
        Folder that relative image paths are read from.
    title : str
        The document's ``<title>``.

    Returns
    -------
    str
        A complete HTML5 document with no external references except the Markdown's own links.
    """
    base = Path(base_dir) if base_dir is not None else None
    lines = md.splitlines()
    body: list[str] = []
    para: list[str] = []
    i = 0

    def flush():
        if para:
            body.append(f"<p>{_inline(' '.join(para), base)}</p>")
            para.clear()

    while i < len(lines):
        line = lines[i].rstrip()
        m = re.match(r"^(#{1,3})\s+(.*)$", line)
        if not line.strip():
            flush()
        elif m:
            flush()
            n = len(m.group(1))
            body.append(f"<h{n}>{_inline(m.group(2), base)}</h{n}>")
        elif line.lstrip().startswith("|") and i + 1 < len(lines) and re.match(r"^\s*\|[\s:|-]+\|\s*$", lines[i + 1]):
            flush()
            head = "".join(f"<th>{_inline(c, base)}</th>" for c in _cells(line))
            rows = []
            i += 2
            while i < len(lines) and lines[i].lstrip().startswith("|"):
                rows.append("<tr>" + "".join(f"<td>{_inline(c, base)}</td>" for c in _cells(lines[i])) + "</tr>")
                i += 1
            body.append(f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(rows)}</tbody></table>")
            continue
        elif re.match(r"^\s*[-*]\s+", line):
            flush()
            items = []
            while i < len(lines) and re.match(r"^\s*[-*]\s+", lines[i]):
                item = re.sub(r"^\s*[-*]\s+", "", lines[i])
                items.append(f"<li>{_inline(item, base)}</li>")
                i += 1
            body.append(f"<ul>{''.join(items)}</ul>")
            continue
        elif re.match(r"^\s*!\[", line):
            flush()
            body.append(_inline(line.strip(), base))
        else:
            para.append(line.strip())
        i += 1
    flush()
    return (
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f"<title>{html.escape(title)}</title>\n<style>{_CSS}</style>\n</head>\n<body>\n"
        + "\n".join(body)
        + "\n</body>\n</html>\n"
    )


def write_html_report(md: str, out_path, base_dir=None, title: str = "rocklab report") -> Path:
    """Write :func:`markdown_to_html` of ``md`` to ``out_path`` atomically; returns the path."""
    out = Path(out_path)
    write_text_atomic(out, markdown_to_html(md, base_dir if base_dir is not None else out.parent, title))
    return out
