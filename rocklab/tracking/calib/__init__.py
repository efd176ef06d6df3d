"""Camera calibration from the boards labs have: checkerboards and ChArUco boards, filmed or photographed.

- :func:`parse_board`: the ``--board`` spec (``checkerboard,9x6,0.025``: inner corners;
  ``charuco,9x6,0.03,0.022,DICT_5X5_100``: squares) as a :class:`Board`, which finds its
  corners in a picture;
- :func:`open_views`: the pictures of a calibration (a film, a folder of photos, a file pattern;
  no frame rate needed);
- :func:`calibrate_lens`: one camera's intrinsics and distortion (:class:`Lens`, written as the
  lens file ``track.toml`` names in ``[video] calibration``), :func:`load_lens` to read it back.

Two cameras: :func:`rocklab.tracking.stereo.calibrate_stereo` with the same boards.
"""

from ._boards import Board, parse_board
from ._lens import LENS_FORMAT, Lens, calibrate_lens, load_lens
from ._views import Views, open_views

__all__ = ["Board", "parse_board", "Views", "open_views", "Lens", "calibrate_lens", "load_lens", "LENS_FORMAT"]
