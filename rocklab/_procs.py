"""Worker processes that die with their parent.

A campaign, the demo and record batches run work in child processes. If the
parent is killed (``kill -9``, an out-of-memory kill), its children must not go
on writing into the output folder: on Linux each worker asks the kernel for
SIGKILL when its parent exits (``prctl(PR_SET_PDEATHSIG)``). Elsewhere this is
a no-op and the executor's own shutdown is relied on.
"""

from __future__ import annotations

import os
import signal
import sys

__all__ = ["die_with_parent", "pool_initializer", "dask_client"]

_PR_SET_PDEATHSIG = 1


def die_with_parent(parent_pid: int | None = None) -> bool:
    """Ask the kernel to SIGKILL this process when its parent exits. Returns True when armed.

    ``parent_pid``: the parent expected; if it is already gone (it died before this
    call), the process exits at once.
    """
    if not sys.platform.startswith("linux"):
        return False
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        if libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) != 0:
            return False
    except (OSError, AttributeError):
        return False
    if parent_pid is not None and os.getppid() != parent_pid:
        os._exit(1)  # the parent died before the request was armed
    return True


def pool_initializer(parent_pid: int, then=None, *args) -> None:
    """ProcessPoolExecutor ``initializer``: :func:`die_with_parent`, then ``then(*args)``.

    The CLI's SIGTERM handler raises to unwind the command's staged outputs; a worker has none
    (a forked one would inherit the handler, and the executor ends the workers of a broken pool
    with SIGTERM): it dies as by default.
    """
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    die_with_parent(parent_pid)
    if then is not None:
        then(*args)


def dask_client(address: str, timeout_s: float = 10.0):
    """A ``dask.distributed.Client`` connected to ``address``, or a one-line :class:`InputError`.

    Raises
    ------
    InputError
        dask[distributed] is not installed, or no scheduler answers at ``address``
        within ``timeout_s``.
    """
    import logging

    from ._errors import InputError

    try:
        from dask.distributed import Client
    except ImportError:
        raise InputError("--scheduler needs dask[distributed]: pip install 'rocklab[dask]'") from None
    # a failed connection is reported below as one line, not as the library's log records
    logging.getLogger("distributed").setLevel(logging.CRITICAL)
    try:
        return Client(address, timeout=f"{timeout_s}s")
    except (OSError, TimeoutError, ValueError, TypeError) as e:
        msg = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise InputError(
            f"--scheduler {address}: no Dask scheduler answered ({msg[:120]}); start one "
            "with 'dask scheduler' and give its address, or drop --scheduler"
        ) from None


def spawn_pool(workers: int):
    """A ``ProcessPoolExecutor`` of ``workers`` fresh (spawned) processes that die with this one.

    Spawned rather than forked: numba's OpenMP threads do not survive a fork.
    """
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    return ProcessPoolExecutor(
        max_workers=workers, mp_context=mp.get_context("spawn"), initializer=pool_initializer, initargs=(os.getpid(),)
    )
