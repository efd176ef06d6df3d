"""One BLAS thread for per-frame work.

NumPy's OpenBLAS splits even a 6 x 90 000 matrix-vector product over every core and its
threads spin while they wait. Per-frame tracking is a long run of such small products: beside a
decoder (or any other busy core) the spinning threads steal the core the decoder needs and the
tracker's own rate drops 2.6 times (1080p markerless, 2 cores: 200 frames/s alone, 75 beside a
busy process; 240 and 225 with one BLAS thread). The products are memory-bound, so one thread
loses nothing.
"""

from __future__ import annotations

import contextlib

__all__ = ["one_blas_thread"]

_controller = None


@contextlib.contextmanager
def one_blas_thread():
    """Context: BLAS libraries loaded in the process use one thread inside it (threadpoolctl).

    The libraries are looked up on first use; entering and leaving costs about 10 µs, so the
    context can wrap each frame. Without threadpoolctl it does nothing.
    """
    global _controller
    if _controller is None:
        try:
            from threadpoolctl import ThreadpoolController
        except ImportError:  # an optional speed-up, never a failure
            _controller = False
        else:
            _controller = ThreadpoolController()
    if not _controller:
        yield
        return
    with _controller.limit(limits=1, user_api="blas"):
        yield
