"""Which tool wrote a file: from its suffix, its name or its first bytes."""

from __future__ import annotations

from pathlib import Path

from ..._errors import InputError

__all__ = ["detect_tool", "IMPORT_TOOLS"]

#: Tools the importers read.
IMPORT_TOOLS = ("tracker", "dltdv")


def detect_tool(path: Path) -> str:
    """The tool that wrote ``path`` (one of :data:`IMPORT_TOOLS`): from its suffix, name, or first bytes.

    Raises
    ------
    InputError
        None of the tools' marks: the user names the tool (``--tool``).
    """
    path = Path(path)
    name = path.name.lower()
    if path.suffix.lower() in (".trk", ".trz"):
        return "tracker"
    if name.endswith(("xypts.csv", "xyzpts.csv")):
        return "dltdv"
    try:
        with open(path, "rb") as fh:
            head = fh.read(4096).decode("utf-8", "replace")
    except OSError:
        head = ""
    if "org.opensourcephysics.cabrillo.tracker" in head:
        return "tracker"
    first = head.splitlines()[0] if head else ""
    if first.startswith("pt1_"):
        return "dltdv"
    raise InputError(f"{path}: cannot tell which tool wrote it (not .trk/.trz, no DLTdv pt1_... header); give --tool")
