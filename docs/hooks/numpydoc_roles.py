"""Sphinx/numpydoc roles (``:func:`x```, ``:mod:``, ``:meth:``, ``:class:``, ...) as links in the site.

rocklab's docstrings use numpydoc's roles; mkdocstrings renders Markdown, where a role would show
as raw text. Two entry points share one rewrite:

- :class:`NumpydocRoles`, a griffe extension (mkdocs.yml: the python handler's ``extensions``),
  rewrites every docstring of the loaded package; a name is resolved where the docstring sits
  (its class, its module and the modules above, then a unique public name of the package);
- :func:`on_page_markdown`, a MkDocs hook (mkdocs.yml: ``hooks``), rewrites the pages' own
  Markdown (e.g. the generated ``track-toml.md``), where only full dotted names resolve.

A resolved public object becomes an optional autoref (a link when the site documents it, code
otherwise: never a broken link, so ``mkdocs build --strict`` stays clean); a private one
(``_module``) or an unknown name becomes code, never a link into a private module.
"""

from __future__ import annotations

import re

ROLE = re.compile(r":(?:py:)?(func|mod|meth|class|data|attr|obj|exc|const|term):`(?P<target>[^`]+)`")


def _public(path: str) -> bool:
    return not any(part.startswith("_") for part in path.split("."))


def _title(target: str) -> str:
    """What the reader sees: ``~a.b.c`` → ``c``; a private path → its last name."""
    if target.startswith("~"):
        return target[1:].split(".")[-1].lstrip(".")
    return target if _public(target.lstrip(".")) else target.split(".")[-1]


def _render(title: str, identifier: str | None) -> str:
    if identifier is None:
        return f"`{title}`"
    return f'<autoref identifier="{identifier}" optional><code>{title}</code></autoref>'


def rewrite(text: str, resolve) -> str:
    """Replace every role in ``text``; ``resolve(name)`` gives a public dotted path or None."""

    def sub(m: re.Match) -> str:
        target = m["target"].strip()
        name = target.lstrip("~")
        return _render(_title(target), resolve(name))

    return ROLE.sub(sub, text)


# ---- the MkDocs hook: full dotted names only -------------------------------------------------


def on_page_markdown(markdown, page, config, files):  # noqa: ARG001 (MkDocs hook signature)
    def resolve(name: str):
        return name if name.startswith("rocklab.") and _public(name) else None

    return rewrite(markdown, resolve)


# ---- the griffe extension: names resolved where the docstring sits ---------------------------

try:
    import griffe
except ImportError:  # the hook alone still works without griffe
    griffe = None


def _public_path(obj) -> str | None:
    """The shortest public dotted path of ``obj`` (itself or one of its re-exports), or None."""
    try:
        target = obj.final_target if obj.is_alias else obj
        paths = [target.path, *target.aliases]
    except Exception:  # noqa: BLE001 (an unresolvable alias: no link)
        return None
    good = sorted((p for p in paths if _public(p)), key=lambda p: (p.count("."), p))
    return good[0] if good else None


if griffe is not None:

    class NumpydocRoles(griffe.Extension):
        """Rewrite the numpydoc roles of every docstring of a loaded package (see the module)."""

        def on_package(self, *, pkg, loader, **kwargs):  # noqa: ARG002
            loader.resolve_aliases(implicit=False, external=False)
            coll = loader.modules_collection
            by_name: dict[str, set[str]] = {}
            objects = list(self._walk(pkg))
            for obj in objects:
                p = _public_path(obj)
                if p is not None:
                    by_name.setdefault(p.rsplit(".", 1)[-1], set()).add(p)

            def lookup(path: str):
                try:
                    return _public_path(coll[path])
                except Exception:  # noqa: BLE001 (not an object of the package)
                    return None

            for obj in objects:
                if obj.is_alias or obj.docstring is None or ":" not in obj.docstring.value:
                    continue
                scopes = []
                s = obj if obj.is_class or obj.is_module else obj.parent
                while s is not None:
                    scopes.append(s)
                    s = s.parent

                def resolve(name: str, scopes=scopes):
                    if name.startswith("."):  # relative to the module's package
                        mod = next(x for x in scopes if x.is_module)
                        base = mod if mod.is_package else mod.parent
                        return lookup(base.path + name)
                    if name.startswith(pkg.name + "."):
                        return lookup(name)
                    for sc in scopes:
                        if name.split(".")[0] in sc.members:
                            hit = lookup(f"{sc.path}.{name}")
                            if hit:
                                return hit
                    found = by_name.get(name.split(".")[-1], set()) if "." not in name else set()
                    return next(iter(found)) if len(found) == 1 else lookup(f"{pkg.name}.{name}")

                obj.docstring.value = rewrite(obj.docstring.value, resolve)

        def _walk(self, obj):
            yield obj
            for m in list(obj.members.values()):
                if m.is_alias:
                    yield m
                    continue
                yield from self._walk(m)
