"""Which tool wrote a file (from its suffix, its name or its first bytes), and a plane tool's points
read by that tool's reader."""

from __future__ import annotations

from pathlib import Path

from ..._errors import InputError
from ._kinovea import read_kinovea
from ._tracker_table import looks_like_tracker_table, read_tracker_table
from ._tracker_trk import read_trk

__all__ = ["detect_tool", "read_plane_points", "IMPORT_TOOLS", "PLANE_TOOLS"]

#: Tools the importers read.
IMPORT_TOOLS = ("tracker", "kinovea", "dltdv")
#: Tools whose files hold points in one film's plane (read by :func:`read_plane_points`).
PLANE_TOOLS = ("tracker", "kinovea")


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
            head = fh.read(65536).decode("utf-8", "replace")
    except OSError:
        head = ""
    if "org.opensourcephysics.cabrillo.tracker" in head:
        return "tracker"
    if looks_like_tracker_table(head):
        return "tracker"
    if head.startswith("#Kinovea") or ("<?xml" in head[:100] and "Coords (x,y:" in head):
        return "kinovea"
    first = head.splitlines()[0] if head else ""
    if first.startswith("pt1_"):
        return "dltdv"
    raise InputError(
        f"{path}: cannot tell which tool wrote it (not .trk/.trz or Tracker's data export, no Kinovea trajectory, no DLTdv pt1_... header); give --tool"
    )


def read_plane_points(path, tool: str | None = None, *, member=None, units=None, fps=None):
    """The points of a plane tool's file (:data:`PLANE_TOOLS`) as :class:`PlanePoints`.

    Parameters
    ----------
    path : str or Path
    tool : {"tracker", "kinovea"}, optional
        The tool; None: :func:`detect_tool`.
    member, units, fps
        Passed to :func:`read_trk` (``member``, ``units``) or :func:`read_kinovea` (``units``,
        ``fps``).
    """
    tool = detect_tool(path) if tool is None else tool
    if tool == "tracker":
        if Path(path).suffix.lower() in (".trk", ".trz"):
            return read_trk(path, member=member, units=units)
        return read_tracker_table(path, units=units)
    if tool == "kinovea":
        return read_kinovea(path, units=units, fps=fps)
    raise InputError(f"{path}: a {tool} file holds no plane track; import it with rocklab import")
