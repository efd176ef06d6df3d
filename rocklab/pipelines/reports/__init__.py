"""Reports for people: one self-contained HTML file beside each Markdown summary.

:func:`write_html_report` turns a ``summary.md`` that rocklab wrote (headings, paragraphs,
lists, tables, links, images) into one HTML file with its figures inlined as data URIs, so it
opens offline, can be mailed, and shows exactly what the Markdown says; :func:`sig` writes the
numbers in both (4 significant digits).
"""

from ._format import sig
from ._html import markdown_to_html, write_html_report

__all__ = ["markdown_to_html", "write_html_report", "sig"]
