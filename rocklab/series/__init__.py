"""The data that crosses packages: one definition each, on the ground floor.

- :class:`BaseMotion`: a base (ground or table) acceleration history, the simulator's input;
- :class:`Tracks`: the ``tracks.csv`` table (2D and 3D): its columns, units, the ``status``
  vocabulary and which statuses are usable samples, its one reader and one writer;
- :class:`TableMotion`: a measured table's displacement, velocity and acceleration.

Every package may import this one; it imports only :mod:`rocklab.blocks` and the private
helpers (errors, diagnostics, atomic files), never a sibling package.
"""

from ._base_motion import UNITS_TO_M_S2, BaseMotion, acc_unit_factor
from ._table_motion import TableMotion
from ._tracks import (
    COLUMN_UNITS,
    CORRECTION_STATUSES,
    NOT_BLOCKS,
    STATUSES,
    TRACK3D_COLUMNS,
    TRACK_COLUMNS,
    USABLE_STATUSES,
    Tracks,
    read_tracks,
    write_tracks,
)

__all__ = [
    "BaseMotion",
    "UNITS_TO_M_S2",
    "acc_unit_factor",
    "TableMotion",
    "Tracks",
    "read_tracks",
    "write_tracks",
    "TRACK_COLUMNS",
    "TRACK3D_COLUMNS",
    "COLUMN_UNITS",
    "STATUSES",
    "USABLE_STATUSES",
    "CORRECTION_STATUSES",
    "NOT_BLOCKS",
]
