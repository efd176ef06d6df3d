"""Physics: single-block rocking, restitution laws, integrators, columns, spectra."""

from ._records import BUNDLED_RECORDS, UNITS_TO_M_S2, BaseMotion, bundled_record, load_base_motion
from ._restitution import RESTITUTION_LAWS, Restitution, make_restitution
from ._batch import simulate_batch
from ._result import BatchResult, RockingResult, block_energy
from ._single import simulate

__all__ = ["BaseMotion", "load_base_motion", "UNITS_TO_M_S2", "bundled_record", "BUNDLED_RECORDS",
           "simulate", "RockingResult", "block_energy", "simulate_batch", "BatchResult",
           "RESTITUTION_LAWS", "Restitution", "make_restitution"]
