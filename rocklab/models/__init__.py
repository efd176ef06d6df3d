"""Physics: single-block rocking, restitution laws, integrators, columns, spectra."""

from ._records import UNITS_TO_M_S2, BaseMotion, load_base_motion

__all__ = ["BaseMotion", "load_base_motion", "UNITS_TO_M_S2"]
