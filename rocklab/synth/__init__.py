"""Simulated lab sessions with exact truth: a simulator of the lab, for tests, demos and benchmarks.

- Rendered video sessions: blocks with ArUco, dot, edge or markerless targets on a table
  (still, sine, a record), filmed by a distorted camera, with x-IMU logs and the configs
  to track them (:func:`synth_session`, :class:`SynthSession`, :func:`load_synth_session`);
  the IMU simulator alone (:func:`simulate_imu_log`, :func:`write_ximu_csv`,
  :func:`write_ximu3_csv`).
- A motion-capture (3D point) record of a free-rocking block, with injectable sliding,
  jumping, twist and double impacts (:func:`synth_points3d`).
- The same motion filmed by a two-camera rig with its ChArUco calibration films
  (:func:`synth_stereo`).

Everything here may use the physics (:mod:`rocklab.models`) and the measurement code
(:mod:`rocklab.tracking`); nothing in tracking depends on it.
"""

from ._imu_sim import simulate_imu_log, write_ximu3_csv, write_ximu_csv
from ._points3d import Points3DSession, synth_points3d
from ._session import SynthSession, load_synth_session, synth_session, parse_size
from ._stereo import StereoCamera, synth_stereo

__all__ = [
    "synth_session",
    "SynthSession",
    "load_synth_session",
    "simulate_imu_log",
    "write_ximu_csv",
    "write_ximu3_csv",
    "Points3DSession",
    "synth_points3d",
    "StereoCamera",
    "synth_stereo",
    "parse_size",
]
