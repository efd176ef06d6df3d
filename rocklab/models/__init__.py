"""Physics: single-block rocking, columns, spectra and records, equivalent mechanisms.

Sub-packages, one subject each (the paper equations they implement are in each docstring):

- :mod:`rocklab.models.rocking`: one block, restitution laws, integrators;
- :mod:`rocklab.models.column`: multi-block columns;
- :mod:`rocklab.models.spectra`: records, pulses, OAS, t_I, design;
- :mod:`rocklab.models.mechanisms`: equivalent rocking mechanisms.

Every public name of the sub-packages is also here: each sub-package's ``__all__`` is the one
list (a name added there is exported here too).
"""

from . import column, mechanisms, rocking, spectra
from .column import *  # noqa: F403
from .mechanisms import *  # noqa: F403
from .rocking import *  # noqa: F403
from .spectra import *  # noqa: F403

__all__: list[str] = []
__all__ += rocking.__all__
__all__ += column.__all__
__all__ += spectra.__all__
__all__ += mechanisms.__all__
