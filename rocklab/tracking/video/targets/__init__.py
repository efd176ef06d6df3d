"""Target detectors: what finds an object in a frame, one module per target style.

ArUco/AprilTag markers (:class:`ArucoDetector`), dot patterns (:class:`DotDetector`),
printed rectangles' edges (:class:`EdgeDetector`), a textured region
(:class:`RegionDetector`) and the markerless keyframe tracker
(:class:`MarkerlessDetector`). Each returns a :class:`Detection` per frame;
:func:`make_detector` builds the right one for a ``track.toml`` (a style per object).
"""

from ._aruco import ArucoDetector
from ._detection import Detection
from ._detectors import make_detector
from ._dots import DotDetector, dot_centroid
from ._edges import EdgeDetector, refine_rectangle
from ._markerless import MarkerlessDetector, MarkerlessTracker
from ._region import RegionDetector, RegionTracker
from ._table_edge import table_top_edge
from ._turn_search import PolarRings


__all__ = [
    "Detection",
    "make_detector",
    "ArucoDetector",
    "DotDetector",
    "dot_centroid",
    "EdgeDetector",
    "refine_rectangle",
    "RegionDetector",
    "RegionTracker",
    "MarkerlessDetector",
    "MarkerlessTracker",
    "table_top_edge",
    "PolarRings",
]
