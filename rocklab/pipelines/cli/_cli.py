"""The ``rocklab`` command line.

Each subcommand group lives in its own ``_cmd_<name>.py`` module exposing
``register(subparsers)``; the module imports heavy dependencies (OpenCV, Rerun,
numba kernels) inside its handler so ``rocklab --help`` stays fast.

Exit status (the policy scripts rely on):

- 0: the command ran; its result is ``ok`` or ``suspect`` (every plausibility
  warning is one line on stderr, ``rocklab CMD: warning W-CODE: ...``, and in the
  JSON output's ``warnings`` list); with ``--strict`` a suspect result exits 4;
- 1: the command ran but (part of) its result failed: a failed fit, a campaign
  with a failed experiment (the others are still reported);
- 2: bad input, or an output that cannot be written or is one of the command's
  inputs (checked before any work, :mod:`._io_plan`): one line on stderr naming
  the file/line or parameter, the rule and the fix; nothing is written;
- 3: an internal error (a bug): one line, ``--debug`` shows the traceback;
- 4: ``--strict`` and a warning of severity ``suspect``;
- 130/143: interrupted (Ctrl-C / SIGTERM); staged outputs are removed.

A closed output pipe (``rocklab ... --json | head -1``) is not an error: the
command stops writing to it and exits 0.
"""

from __future__ import annotations

import argparse
import errno
import importlib
import sys
import threading

from ..._errors import InputError

#: Subcommand modules, in help order.
COMMAND_MODULES = (
    "_cmd_simulate",
    "_cmd_imu",
    "_cmd_track",
    "_cmd_track3d",
    "_cmd_import",
    "_cmd_stereo",
    "_cmd_synth",
    "_cmd_fit",
    "_cmd_run",
    "_cmd_campaign",
    "_cmd_demo",
    "_cmd_column",
    "_cmd_design",
    "_cmd_curve",
    "_cmd_papers",
)


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # argparse's usage errors: one line, status 2
        sys.stderr.write(f"rocklab: error: {message} (see '{self.prog} --help')\n")
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    """The ``rocklab`` argument parser with every subcommand registered."""
    from ... import __version__

    p = _Parser(prog="rocklab", description="Rocking-block experiments to calibrated physics.")
    p.add_argument("--version", action="version", version=f"rocklab {__version__}")
    p.add_argument("--debug", action="store_true", help="show Python tracebacks and numerical warnings")
    p.add_argument(
        "--strict", action="store_true", help="exit 4 when a result is suspect (any W- warning of severity suspect)"
    )
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for mod in COMMAND_MODULES:
        importlib.import_module(f"{__package__}.commands.{mod}").register(sub)
    return p


def _check_file_outputs(args) -> None:
    """Output files are checked before any work starts: writable, and none of them an input."""
    from ..._inputs import check_outputs_not_inputs
    from ..._outdir import check_output_file
    from ._io_plan import io_plan

    for attr, opt in (("output", "-o"), ("plot", "--plot"), ("maps_png", "--maps-png"), ("rrd", "--rrd")):
        v = getattr(args, attr, None)
        if v:
            check_output_file(v, opt)
    if args.command not in FOLDER_COMMANDS and getattr(args, "out", None):
        check_output_file(args.out, "-o/--out")
    check_outputs_not_inputs(*io_plan(args))


#: Commands whose ``--out`` is a folder (checked by :func:`rocklab._outdir.check_output_dir`).
FOLDER_COMMANDS = ("run", "campaign", "synth", "demo", "papers")

_ERRNO_FIX = {
    errno.ENOSPC: "no space left on the device; free space or choose another output location",
    errno.EACCES: "permission denied; choose a location you can write to (or read)",
    errno.EROFS: "read-only file system; choose another output location",
    errno.EISDIR: "is a folder; give a file name",
    errno.ENOTDIR: "a part of the path is a file, not a folder; check the path",
    errno.ENOENT: "file not found; check the path",
    errno.EDQUOT: "disk quota exceeded; free space or choose another output location",
}


def _os_error_line(e: OSError) -> str:
    name = e.filename or ""
    fix = _ERRNO_FIX.get(e.errno, f"{e.strerror or e}; check the path")
    return f"{name}: {fix}" if name else fix


def _silence_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush into a closed pipe says nothing."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # stdout replaced by an object without a descriptor
        pass


class _Terminated(SystemExit):
    """SIGTERM: unwinds the stack (staged outputs are removed on the way out), then exits 143."""


def _on_sigterm(signum, frame):  # a killed run removes its staged outputs on the way out
    from ..._outdir import defer_stop

    if _inside_numba(frame):
        # A compiled loop cannot be interrupted; Python runs this handler when numba boxes the
        # loop's results, inside numba's own callback (it unpickles types). An exception raised
        # there leaves a NULL in the returned tuple and the interpreter crashes (exit 139), so
        # the signal is sent again a moment later, once the call has returned.
        import os

        # and if the run finishes before that, it stops before publishing any output
        defer_stop(_Terminated(143))
        again = threading.Timer(0.05, os.kill, (os.getpid(), signum))
        again.daemon = True
        again.start()
        return
    defer_stop(None)
    raise _Terminated(143)


def _inside_numba(frame) -> bool:
    """Whether the Python stack at ``frame`` runs numba's own code (compiling, boxing results)."""
    import os

    nb = sys.modules.get("numba")
    root = os.path.dirname(getattr(nb, "__file__", "") or "")
    while root and frame is not None:
        if frame.f_code.co_filename.startswith(root + os.sep):
            return True
        frame = frame.f_back
    return False


def _exit_now(code: int, line: str) -> None:
    """One line on stderr, then leave without the interpreter's teardown.

    The teardown would free native encoders (SVT-AV1 of the review film) in the middle of a
    film, which abort the process (status 134/139, "deinit called without sending EOS!");
    the stack has already unwound, so every staged output is gone and nothing is lost.
    """
    import os

    sys.stderr.write(line)
    for f in (sys.stdout, sys.stderr):
        try:
            f.flush()
        except (OSError, ValueError):
            pass
    os._exit(code)


def main(argv=None) -> int:
    """Run the CLI on ``argv`` (default ``sys.argv[1:]``); returns the exit status (see the module doc)."""
    import signal
    import warnings

    from ..._diagnostics import collecting, stderr_echo

    from_command_line = argv is None
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    cmd = args.command
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _on_sigterm)
        if hasattr(signal, "pthread_sigmask"):
            # a blocked signal mask is inherited from the parent (a job runner, a test process that
            # blocked SIGTERM): blocked, a SIGTERM would wait until the run ends and publish anyway
            signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGTERM, signal.SIGINT})

    try:
        with warnings.catch_warnings(), collecting(echo=stderr_echo(cmd)) as diags:
            if not args.debug:  # numpy's RuntimeWarnings name source paths; results carry W- codes instead
                warnings.simplefilter("ignore", RuntimeWarning)
            _check_file_outputs(args)
            rc = int(args.func(args) or 0)
            from ..._outdir import raise_pending_stop

            raise_pending_stop()  # a stop deferred by a compiled loop, for a command that published nothing
    except InputError as e:
        sys.stderr.write(f"rocklab {cmd}: error: {e}\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write(f"rocklab {cmd}: interrupted; staged outputs removed\n")
        return 130
    except _Terminated:
        line = f"rocklab {cmd}: terminated (SIGTERM); staged outputs removed\n"
        if from_command_line:  # the process ends here; in-process callers get the status back
            _exit_now(143, line)
        sys.stderr.write(line)
        return 143
    except SystemExit:
        raise
    except OverflowError as e:  # a number given beyond what floats hold (1e300 m, a step of 1e-300 s)
        if args.debug:
            raise
        sys.stderr.write(
            f"rocklab {cmd}: error: a value given is too large or too small to compute with ({e}); "
            "check the numbers and their units\n"
        )
        return 2
    except MemoryError:
        sys.stderr.write(
            f"rocklab {cmd}: error: not enough memory for this request; reduce its size (duration, grid, frames)\n"
        )
        return 2
    except UnicodeDecodeError as e:
        sys.stderr.write(
            f"rocklab {cmd}: error: an input is not a text file ({e.reason} at byte {e.start}); "
            "give the CSV/text file the option expects\n"
        )
        return 2
    except BrokenPipeError:  # the reader stopped early (`rocklab ... --json | head`): not an error
        _silence_stdout()
        return 0
    except OSError as e:
        if args.debug:
            raise
        sys.stderr.write(f"rocklab {cmd}: error: {_os_error_line(e)}\n")
        return 2
    except Exception as e:  # noqa: BLE001 - a bug: one line, not a traceback
        if args.debug:
            raise
        msg = str(e).splitlines()[0][:200] if str(e) else ""
        sys.stderr.write(
            f"rocklab {cmd}: internal error: {type(e).__name__}: {msg} "
            "(run with --debug for the traceback, and please report it)\n"
        )
        return 3
    if rc == 0 and args.strict and any(d.severity == "suspect" for d in diags):
        return 4
    return rc


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
