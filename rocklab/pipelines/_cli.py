"""The ``rocklab`` command line.

Each subcommand group lives in its own ``_cmd_<name>.py`` module exposing
``register(subparsers)``; the module imports heavy dependencies (OpenCV, Rerun,
numba kernels) inside its handler so ``rocklab --help`` stays fast.

Bad input (:class:`rocklab.InputError`, a missing file) prints one line on
stderr and exits with status 2, never a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from .._errors import InputError

#: Subcommand modules, in help order.
COMMAND_MODULES = (
    "_cmd_simulate", "_cmd_imu", "_cmd_track", "_cmd_synth", "_cmd_fit", "_cmd_run",
    "_cmd_campaign", "_cmd_demo", "_cmd_column", "_cmd_design",
)


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # argparse's usage errors: one line, status 2
        sys.stderr.write(f"rocklab: error: {message} (see '{self.prog} --help')\n")
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    """The ``rocklab`` argument parser with every subcommand registered."""
    from .. import __version__

    p = _Parser(prog="rocklab", description="Rocking-block experiments to calibrated physics.")
    p.add_argument("--version", action="version", version=f"rocklab {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for mod in COMMAND_MODULES:
        importlib.import_module(f"{__package__}.{mod}").register(sub)
    return p


def main(argv=None) -> int:
    """Run the CLI on ``argv`` (default ``sys.argv[1:]``); returns the exit status (2: bad input)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        rc = args.func(args)
    except InputError as e:
        sys.stderr.write(f"rocklab {args.command}: error: {e}\n")
        return 2
    except FileNotFoundError as e:
        sys.stderr.write(f"rocklab {args.command}: error: {e.filename or e}: file not found; check the path\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write("rocklab: interrupted\n")
        return 130
    return int(rc or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
