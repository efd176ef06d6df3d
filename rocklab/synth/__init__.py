"""Simulated lab sessions with exact truth, for tests, demos and benchmarks.

Here: a motion-capture (3D point) record of a free-rocking block, with
injectable sliding, jumping, twist and double impacts
(:func:`synth_points3d`). The rendered-video and IMU sessions are built by
:func:`rocklab.tracking.synth_session`.
"""

from ._points3d import Points3DSession, synth_points3d

__all__ = ["Points3DSession", "synth_points3d"]
