"""rocklab: rocking-block lab experiments to calibrated physics.

Subpackages: :mod:`rocklab.models` (physics), :mod:`rocklab.tracking`
(video and IMU measurement), :mod:`rocklab.fitting` (restitution calibration),
:mod:`rocklab.pipelines` (experiments, Rerun review, CLI).
"""

from ._errors import InputError
from .blocks import G, Block

__all__ = ["Block", "G", "InputError", "__version__"]
__version__ = "0.1.0"
