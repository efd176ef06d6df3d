"""One module per ``rocklab`` command (``_cmd_<name>.py``), each with ``register(subparsers)`` and ``run(args)``."""

__all__: list[str] = []
