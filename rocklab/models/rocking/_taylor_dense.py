"""Numba: one Taylor step's series sampled on an even output grid, in blocks of samples.

A step of :func:`~rocklab.models.rocking._taylor.run_taylor` holds the series of theta to
order 12 over ``p h <= 0.2``; on a 1e-4 s grid that is a few hundred samples, and two
Horner chains of order 12 per sample (theta and omega) would cost more than the
integration itself. Over a block of :data:`BLOCK` consecutive samples the same polynomial,
re-expanded about the block's centre, needs only :data:`DEGREE` terms: with
``p u <= R_BLOCK`` (u the offset from the centre) the first term left out is below
``R_BLOCK^9 / 9!`` = 5e-20 of the amplitude in theta and ``R_BLOCK^8 / 8!`` = 2e-17 of
``p`` times it in omega, under the rounding of the samples (blocks and one evaluation per
sample agree within 2.5e-16 of alpha and of p alpha, tests/test_single_taylor.py). The
re-expansion costs one short Horner chain per kept term and block (independent chains),
and the block's samples are then one polynomial of low degree at fixed offsets, which the
compiler vectorises across samples.

Grids too coarse for a block (``p dt`` above :func:`blocks_fit`'s bound, e.g. a camera
frame rate) keep one order-12 evaluation per sample (:func:`dense_samples`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = [
    "BLOCK",
    "DEGREE",
    "R_BLOCK",
    "blocks_fit",
    "dense_blocks",
    "dense_samples",
    "block_scratch",
    "series_value",
    "series_slope",
]

#: Samples per block.
BLOCK = 32
#: Degree of the re-expanded polynomial of theta inside a block (:func:`dense_blocks` spells out its terms).
DEGREE = 8
#: Largest p times the distance from a block's centre to its outer samples.
R_BLOCK = 0.03


@njit(cache=True)
def blocks_fit(p, out_dt):
    """True when blocks of :data:`BLOCK` samples spaced ``out_dt`` (s) keep ``p u <= R_BLOCK`` (p in rad/s)."""
    return p * out_dt * 0.5 * (BLOCK - 1) <= R_BLOCK


@njit(cache=True)
def block_scratch(n, out_dt):
    """Work arrays of :func:`dense_blocks` for series of order ``n`` on a grid of spacing ``out_dt`` (s):
    ``binom`` (DEGREE+1, n+1), ``ab`` (DEGREE+1, n+1), ``u`` (BLOCK,) offsets from a block's centre (s),
    ``v``, ``d`` (BLOCK,)."""
    binom = np.zeros((DEGREE + 1, n + 1))
    for k in range(n + 1):
        c = 1.0
        for m in range(min(k, DEGREE) + 1):
            binom[m, k] = c
            c = c * (k - m) / (m + 1)
    u = np.empty(BLOCK)
    for j in range(BLOCK):
        u[j] = (j - 0.5 * (BLOCK - 1)) * out_dt
    return binom, np.zeros((DEGREE + 1, n + 1)), u, np.empty(BLOCK), np.empty(BLOCK)


@njit(cache=True, fastmath={"contract"})
def dense_blocks(a, n, out_th, out_w, out_e, k0, k1, out_dt, t, energy, binom, ab, u, v, d):
    """theta, omega and energy at the samples ``k0 <= k < k1`` (times ``k out_dt``, s) of the series
    ``a[0..n]`` of theta about time ``t`` (s), block by block; needs :func:`blocks_fit`.

    ``binom, ab, u, v, d`` come from :func:`block_scratch`; ``energy`` fills ``out_e``.
    """
    for m in range(DEGREE + 1):
        for k in range(m, n + 1):
            ab[m, k] = binom[m, k] * a[k]
    i = k0
    while i < k1:
        xc = (i + 0.5 * (BLOCK - 1)) * out_dt - t
        # coefficient m of the series about xc: sum_k binom(k, m) a_k xc^(k - m), one chain per m
        b0 = _chain(ab, 0, n, xc)
        b1 = _chain(ab, 1, n, xc)
        b2 = _chain(ab, 2, n, xc)
        b3 = _chain(ab, 3, n, xc)
        b4 = _chain(ab, 4, n, xc)
        b5 = _chain(ab, 5, n, xc)
        b6 = _chain(ab, 6, n, xc)
        b7 = _chain(ab, 7, n, xc)
        b8 = _chain(ab, 8, n, xc)
        for j in range(BLOCK):
            x = u[j]
            v[j] = (((((((b8 * x + b7) * x + b6) * x + b5) * x + b4) * x + b3) * x + b2) * x + b1) * x + b0
            d[j] = (
                (((((8.0 * b8 * x + 7.0 * b7) * x + 6.0 * b6) * x + 5.0 * b5) * x + 4.0 * b4) * x + 3.0 * b3) * x
                + 2.0 * b2
            ) * x + b1
        m_out = min(BLOCK, k1 - i)
        for j in range(m_out):
            out_th[i + j] = v[j]
            out_w[i + j] = d[j]
            out_e[i + j] = energy
        i += BLOCK


@njit(cache=True, inline="always", fastmath={"contract"})
def _chain(ab, m, n, x):
    """Horner of row ``m`` of ``ab`` (terms k = m..n) at ``x``."""
    r = ab[m, n]
    for k in range(n - 1, m - 1, -1):
        r = r * x + ab[m, k]
    return r


@njit(cache=True, inline="always", fastmath={"contract"})
def series_value(a, n, x):
    """The series ``a[0..n]`` at ``x`` (Horner)."""
    v = a[n]
    for k in range(n - 1, -1, -1):
        v = v * x + a[k]
    return v


@njit(cache=True, inline="always", fastmath={"contract"})
def series_slope(a, n, x):
    """The derivative of the series ``a[0..n]`` at ``x`` (Horner)."""
    v = n * a[n]
    for k in range(n - 1, 0, -1):
        v = v * x + k * a[k]
    return v


@njit(cache=True, fastmath={"contract"})
def dense_samples(a, n, out_th, out_w, out_e, k0, k1, out_dt, t, energy):
    """theta, omega and energy at the samples ``k0 <= k < k1`` (times ``k out_dt``, s) of the series
    ``a[0..n]`` of theta about time ``t`` (s): one order-n evaluation per sample.

    Four samples per pass: their Horner chains are independent, so they overlap in the
    pipeline instead of waiting on one chain's latency.
    """
    i = k0
    while i + 4 <= k1:
        x0 = i * out_dt - t
        x1 = x0 + out_dt
        x2 = x1 + out_dt
        x3 = x2 + out_dt
        an = a[n]
        v0 = an
        v1 = an
        v2 = an
        v3 = an
        dn = n * an
        d0 = dn
        d1 = dn
        d2 = dn
        d3 = dn
        for j in range(n - 1, 0, -1):
            aj = a[j]
            jaj = j * aj
            v0 = v0 * x0 + aj
            v1 = v1 * x1 + aj
            v2 = v2 * x2 + aj
            v3 = v3 * x3 + aj
            d0 = d0 * x0 + jaj
            d1 = d1 * x1 + jaj
            d2 = d2 * x2 + jaj
            d3 = d3 * x3 + jaj
        a0 = a[0]
        out_th[i] = v0 * x0 + a0
        out_th[i + 1] = v1 * x1 + a0
        out_th[i + 2] = v2 * x2 + a0
        out_th[i + 3] = v3 * x3 + a0
        out_w[i] = d0
        out_w[i + 1] = d1
        out_w[i + 2] = d2
        out_w[i + 3] = d3
        out_e[i] = energy
        out_e[i + 1] = energy
        out_e[i + 2] = energy
        out_e[i + 3] = energy
        i += 4
    while i < k1:
        x = i * out_dt - t
        out_th[i] = series_value(a, n, x)
        out_w[i] = series_slope(a, n, x)
        out_e[i] = energy
        i += 1
