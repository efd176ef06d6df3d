"""Reference pages of a config file, generated from its schema dataclasses and their docstrings."""

from __future__ import annotations

import dataclasses
import inspect
import re

__all__ = ["tables_markdown"]


def _attr_docs(cls) -> dict:
    """{field: text} from the numpydoc ``Attributes`` section of ``cls``'s docstring."""
    doc = inspect.getdoc(cls) or ""
    body = doc.split("Attributes\n----------\n", 1)[-1] if "Attributes" in doc else ""
    out, key = {}, None
    for ln in body.splitlines():
        m = re.match(r"^(\w+(?:, \w+)*)\s*:\s*(.*)$", ln)
        if m and not ln.startswith(" "):
            names = [n.strip() for n in m.group(1).split(",")]
            key = names
            for n in names:
                out[n] = [f"*{m.group(2).strip()}*:"]
        elif key and ln.strip():
            for n in key:
                out[n].append(ln.strip())
    return {k: " ".join(v) for k, v in out.items()}


def tables_markdown(sections) -> str:
    """One Markdown table per ``(title, dataclass)``: every field, its default and its meaning.

    Parameters
    ----------
    sections : sequence of (str, type)
        The TOML table's title (``"[video]"``) and the dataclass it maps onto.
    """
    lines = []
    for title, cls in sections:
        first = (inspect.getdoc(cls) or "").splitlines()[0]
        lines += [f"## `{title}`", "", first, "", "| key | default | type and meaning |", "| --- | --- | --- |"]
        docs = _attr_docs(cls)
        for f in dataclasses.fields(cls):
            if f.default is not dataclasses.MISSING:
                dflt = f"`{f.default!r}`"
            elif f.default_factory is not dataclasses.MISSING:
                dflt = f"`{f.default_factory()!r}`"
            else:
                dflt = "required"
            text = docs.get(f.name, "").replace("|", "/")
            lines.append(f"| `{f.name}` | {dflt} | {text} |")
        lines.append("")
    return "\n".join(lines)
