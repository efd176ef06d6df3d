"""The fused table's own error, drawn for the validation ensembles.

A table fused from its IMU and the film (:func:`rocklab.tracking.fuse_table_motion`) has an
error the smoother states per sample (``TableMotion.sigma_ax_m_s2``, σ) but whose spectrum
matters as much as its size: a rocking block or column responds to the table's acceleration
below about 10 Hz, and the error is mostly above. White noise of σ per sample, or noise of σ
correlated below a guessed corner, samples the wrong error.

The spectrum sampled is measured on synthetic sessions where the true table is known (the demo's
set-ups rendered at 960×540, 50 fps, H.264, and tracked as ``rocklab run`` tracks them; a
256 Hz table IMU with 5 mg of noise; development sessions only: the 3-block column on its
0.6 s sine pulse, seeds 20 and 21, and B5L under El Centro, seeds 22 and 23). The error
``e = a_fused - a_true`` over the samples where the table moves, divided by σ, filtered into the
bands of :data:`FUSED_ERROR_BANDS_HZ`, has in each band at most the variance of
:data:`FUSED_ERROR_Z_VAR` (the largest of the four sessions: 1.43 in all, the error 1.2 σ RMS;
the sessions' own totals 1.16 and 0.63 on the pulses, 1.03 and 0.80 under El Centro). The drawn
variance sits at 5-40 Hz, 8 % of it below 5 Hz, with peaks at 7-10 Hz (El Centro's, 0.31 σ²) and
14-20 Hz (a pulse's, 0.36 σ²). The largest session's variance, not the mean, is drawn: the kind
of motion is not known to the ensemble, and a mean would draw one kind's error too small, which
is what makes a band too narrow. (Measured with the smoother of
:func:`rocklab.tracking.fuse_table_motion` as it is: its local driving noise and film variance;
the earlier one, without them, left 2.8 σ², peaking at the pulses' start and end.)

:func:`fused_error_draw` draws that error: white noise shaped to the measured band variances
(a piecewise flat spectrum), times σ at every sample.
"""

from __future__ import annotations

import numpy as np

__all__ = ["FUSED_ERROR_BANDS_HZ", "FUSED_ERROR_Z_VAR", "fused_error_draw"]

#: Bands (Hz) of the fused table's error spectrum.
FUSED_ERROR_BANDS_HZ = (
    (0.0, 1.0), (1.0, 2.0), (2.0, 3.5), (3.5, 5.0), (5.0, 7.0), (7.0, 10.0),
    (10.0, 14.0), (14.0, 20.0), (20.0, 40.0), (40.0, 128.0),
)  # fmt: skip
#: Variance of the fused table's error over its σ in each band of :data:`FUSED_ERROR_BANDS_HZ`
#: while the table moves, the largest of the development sessions (see the module doc), -.
FUSED_ERROR_Z_VAR = (1.8e-3, 1.51e-2, 4.74e-2, 5.60e-2, 1.375e-1, 3.124e-1, 1.899e-1, 3.625e-1, 2.276e-1, 7.47e-2)


def fused_error_draw(t_s, sigma_m_s2, rng, gain: float = 1.0) -> np.ndarray:
    """One draw of a fused table's acceleration error at its samples.

    Parameters
    ----------
    t_s : ndarray, (n,)
        The fused table's sample times, s (its IMU's regular grid).
    sigma_m_s2 : ndarray, (n,)
        The smoother's standard deviation of the acceleration at each sample, m/s².
    rng : numpy.random.Generator
    gain : float
        Multiplies the draw (1: the error as measured).

    Returns
    -------
    ndarray, (n,)
        ``gain`` σ(t) z(t), m/s², z Gaussian with the band variances of :data:`FUSED_ERROR_Z_VAR`
        (bands above the samples' Nyquist frequency dropped: the table has no error there).
    """
    t = np.asarray(t_s, float)
    s = np.asarray(sigma_m_s2, float)
    n = t.size
    if n < 2:
        return np.zeros(n)
    fs = 1.0 / float(np.median(np.diff(t)))
    m = 2 * n  # twice as long: the circular shaping's wrap-around falls outside the samples
    f = np.fft.rfftfreq(m, 1.0 / fs)
    psd = np.zeros(f.size)  # one-sided, per Hz
    for (lo, hi), v in zip(FUSED_ERROR_BANDS_HZ, FUSED_ERROR_Z_VAR):
        psd[(f >= lo) & (f < hi)] = v / (hi - lo)
    # unit white noise has the one-sided density 2 / fs: shaping by sqrt(psd fs / 2) gives psd
    z = np.fft.irfft(np.fft.rfft(rng.standard_normal(m)) * np.sqrt(psd * fs / 2.0), m)[:n]
    return gain * s * z
