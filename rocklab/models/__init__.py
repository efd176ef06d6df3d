"""Physics: single-block rocking, restitution laws, integrators, columns, spectra."""

from ._records import BUNDLED_RECORDS, UNITS_TO_M_S2, BaseMotion, bundled_record, load_base_motion

__all__ = ["BaseMotion", "load_base_motion", "UNITS_TO_M_S2", "bundled_record", "BUNDLED_RECORDS"]
