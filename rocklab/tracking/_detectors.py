"""Target-style detectors behind :func:`rocklab.tracking.track_frames`: one per style, merged
when objects of one video use different styles (a block with markers on a markerless table)."""

from __future__ import annotations

__all__ = ["make_detector"]


class _MixedDetector:
    """Objects of different target styles: one detector per style, results merged."""

    def __init__(self, parts):
        self.parts = parts

    def detect(self, gray, frame):
        out = {}
        for d in self.parts:
            out.update(d.detect(gray, frame))
        return out


def make_detector(config, pm, first_gray):
    """The detector for ``config``'s objects: one per target style, merged when styles mix."""
    styles = {o.style or config.targets.style for o in config.objects}
    if len(styles) > 1:
        import dataclasses

        parts = []
        for st in sorted(styles):
            objs = tuple(o for o in config.objects if (o.style or config.targets.style) == st)
            sub = dataclasses.replace(config, objects=objs,
                                      targets=dataclasses.replace(config.targets, style=st))
            parts.append(_make_single(sub, pm, first_gray))
        return _MixedDetector(parts)
    if styles and styles != {config.targets.style}:
        import dataclasses

        config = dataclasses.replace(config, targets=dataclasses.replace(config.targets, style=styles.pop()))
    return _make_single(config, pm, first_gray)


def _make_single(config, pm, first_gray):
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
    if style == "markerless":
        from ._markerless import MarkerlessDetector

        return MarkerlessDetector(config, pm, first_gray)
    from ._region import RegionDetector

    return RegionDetector(config, pm, first_gray)
