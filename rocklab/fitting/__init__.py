"""rocklab.fitting (see the package docs)."""

__all__: list[str] = []
