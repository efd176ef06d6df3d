"""Set-up errors of a two-camera test, named before the 3D audit reads them as physics.

One film given twice, or the two films given in the wrong order, still triangulate: the
first to points at infinity, the second to a mirrored scene behind the cameras. The rocking
audit then reports slides, jumps and twists of a block that never moved that way. These
checks run on the 2D tracks and the triangulated depth, before any pose is fitted.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..._diagnostics import warn
from ..._errors import InputError, where
from ._calib import SAME_FILM_PX
from ._epipolar import epipolar_misfit_px

__all__ = ["check_distinct_films", "check_film_order", "check_depth_in_front", "check_unsynchronised"]

#: Median epipolar misfit of the matched targets above which the other film order is tried, px
#: (a calibrated rig fits its own order to a few tenths of a pixel, with up to a frame of
#: clock offset still in it).
ORDER_MISFIT_PX = 1.0
#: The other order is the right one when it fits this much better (swapped films of the
#: default rig: 1.9 px against 0.014 px, medians over frames and targets).
ORDER_RATIO = 0.25
#: A clock offset found on films given as synchronised is reported when it exceeds this
#: share of a frame and this many of its own standard deviations.
NOSYNC_MIN_FRAMES = 0.1
NOSYNC_MIN_SIGMAS = 5.0


def check_distinct_films(uv1, uv2, film1, film2) -> None:
    """:class:`InputError` when the matched targets sit on the same pixels in both films.

    Parameters
    ----------
    uv1, uv2 : ndarray, shape (n, k, 2)
        The matched targets' image points in film 1 and film 2, px (NaN where not seen).
    film1, film2 : path-like
        The films (for the message).
    """
    n = min(len(uv1), len(uv2))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        gap = float(np.nanmedian(np.linalg.norm(np.asarray(uv1[:n], float) - np.asarray(uv2[:n], float), axis=-1)))
    if np.isfinite(gap) and gap < SAME_FILM_PX:
        raise InputError(
            f"{where(film2)}every target sits where it sits in {film1} (median {gap:.2g} px apart): the same "
            "film twice, or one camera's; give the second camera's film"
        )


def check_depth_in_front(xyz_m, film1, film2) -> None:
    """:class:`InputError` when the triangulated scene lies behind camera 1.

    Parameters
    ----------
    xyz_m : ndarray, shape (n, k, 3)
        Triangulated points in camera 1's axes, m (NaN where rejected).
    film1, film2 : path-like
        The films (for the message).
    """
    z = np.asarray(xyz_m, float)[..., 2]
    z = z[np.isfinite(z)]
    if z.size and float(np.median(z)) <= 0:
        raise InputError(
            f"{where(film1)}the targets triangulate to {float(np.median(z)):.4g} m, behind camera 1: the films are in "
            f"the wrong order (give camera 1's film first, then {film2}) or the calibration's cameras are swapped"
        )


def check_film_order(rig, uv1, uv2, film1, film2) -> None:
    """:class:`InputError` when two films are one film, or fit the rig far better in the other order.

    Parameters
    ----------
    rig : StereoRig
    uv1, uv2 : ndarray, shape (n, k, 2)
        The matched targets' image points in film 1 and film 2, px.
    film1, film2 : path-like
        The films as given (for the message).
    """
    check_distinct_films(uv1, uv2, film1, film2)
    given = epipolar_misfit_px(rig, uv1, uv2)
    if given > ORDER_MISFIT_PX:
        other = epipolar_misfit_px(rig, uv2, uv1)  # film 2 as camera 1
        if other < ORDER_RATIO * given:
            raise InputError(
                f"{where(film1)}the targets miss their epipolar lines by {given:.3g} px in this order and "
                f"by {other:.3g} px in the other: the films are in the wrong order (give camera 1's film "
                f"({film2}) first, then {film1}) or the calibration's cameras are swapped"
            )


def check_unsynchronised(found, film1, film2) -> None:
    """``W-STEREO-NOSYNC`` when films given as triggered together show a clock offset.

    Parameters
    ----------
    found : SyncOffset
        The offset estimated from the films although the user asked for none.
    film1, film2 : path-like
        The films (for the message).
    """
    off_s, sig_s = abs(found.offset_s), found.sigma_s
    fps = abs(found.offset_frames / found.offset_s) if found.offset_s else float("inf")
    if abs(found.offset_frames) > NOSYNC_MIN_FRAMES and np.isfinite(sig_s) and off_s > NOSYNC_MIN_SIGMAS * sig_s:
        warn(
            "W-STEREO-NOSYNC",
            f"{film2} runs {found.offset_s * 1e3:.4g} ms (+/- {sig_s * 1e3:.2g} ms, {found.offset_frames:+.3g} frames at "
            f"{fps:.4g} fps) off {film1}, measured from the targets although --no-sync takes them as one clock: "
            "moving targets are triangulated from different instants; run without --no-sync",
        )
