"""Target-style detectors behind :func:`rocklab.tracking.track_frames`: one per style, merged
when objects of one video use different styles (a block with markers on a markerless table)."""

from __future__ import annotations

import dataclasses

__all__ = ["make_detector"]


class _MixedDetector:
    """Objects of different target styles: one detector per style, results merged.

    ``parts``: (object ids, detector) per style; questions about one object go to its own.
    """

    def __init__(self, parts):
        self.parts = parts

    def detect(self, gray, frame):
        out = {}
        for _, d in self.parts:
            out.update(d.detect(gray, frame))
        return out

    def _ask(self, method, oid):
        d = next((d for ids, d in self.parts if oid in ids), None)
        return getattr(d, method)(oid) if hasattr(d, method) else None

    def lost_reason(self, oid):
        """Why object ``oid`` was lost in the last frame, from its own style's detector."""
        return self._ask("lost_reason", oid)

    def theta_note(self, oid):
        """Why object ``oid``'s angle cannot be measured, from its own style's detector, or None."""
        return self._ask("theta_note", oid)

    def disk_lever(self, oid):
        """Object ``oid``'s disk in its own frame once its angle was dropped, or None (its own
        style's detector)."""
        return self._ask("disk_lever", oid)


def make_detector(config, pm, first_gray):
    """The detector for ``config``'s objects: one per target style, merged when styles mix."""

    def style(o):
        return o.style or config.targets.style

    parts = []
    for st in sorted({style(o) for o in config.objects}):
        sub = dataclasses.replace(
            config,
            objects=tuple(o for o in config.objects if style(o) == st),
            targets=dataclasses.replace(config.targets, style=st),
        )
        parts.append(({o.id for o in sub.objects}, _make_single(sub, pm, first_gray)))
    return parts[0][1] if len(parts) == 1 else _MixedDetector(parts)


def _make_single(config, pm, first_gray):
    style = config.targets.style
    if style == "markerless":
        from ._markerless import MarkerlessDetector

        return MarkerlessDetector(config, pm, first_gray)
    from ._verify_points import VerifiedDetector

    return VerifiedDetector(_point_detector(config, pm, first_gray))


def _point_detector(config, pm, first_gray):
    style = config.targets.style
    if style in ("aruco", "apriltag"):
        from ._aruco import ArucoDetector

        return ArucoDetector(config, pm)
    if style == "dots":
        from ._dots import DotDetector

        return DotDetector(config, pm, first_gray)
    if style == "edges":
        from ._edges import EdgeDetector

        return EdgeDetector(config, pm, first_gray)
    from ._region import RegionDetector

    return RegionDetector(config, pm, first_gray)
