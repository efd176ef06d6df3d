"""Simulated lab sessions with exact truth, for tests, demos and benchmarks.

Here: a motion-capture (3D point) record of a free-rocking block, with
injectable sliding, jumping, twist and double impacts
(:func:`synth_points3d`), and the same motion filmed by a two-camera rig with
its ChArUco calibration films (:func:`synth_stereo`). The rendered-video and IMU sessions are built by
:func:`rocklab.tracking.synth_session`.
"""

from ._points3d import Points3DSession, synth_points3d
from ._stereo import StereoCamera, synth_stereo

__all__ = ["Points3DSession", "synth_points3d", "StereoCamera", "synth_stereo"]
