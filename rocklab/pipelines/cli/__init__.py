"""The ``rocklab`` command line: the parser, the exit-status policy and one module per command.

:func:`main` builds the parser from :data:`COMMAND_MODULES` (each ``commands/_cmd_<name>.py``
exposes ``register(subparsers)`` and imports its heavy dependencies only when run), turns
bad input into one line and status 2, and internal errors into one line and status 3.
"""

from ._cli import COMMAND_MODULES, main

__all__ = ["main", "COMMAND_MODULES"]
