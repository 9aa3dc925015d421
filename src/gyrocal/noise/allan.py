"""Overlapping Allan deviation and its confidence intervals, both from ``allantools``.

The confidence interval of an Allan deviation estimate comes from its equivalent degrees
of freedom (edf), which depend on the noise type at that averaging time: Greenhall's
algorithm (``allantools.edf_greenhall``, overlapping estimator) gives the edf and the
chi-squared interval follows (``allantools.confidence_interval``, NIST SP 1065 eq. 45).
Noise types are named by the power-law exponent alpha of the rate (frequency) spectrum:
0 white noise (angle random walk), -1 flicker (bias instability), -2 random walk (rate
random walk), the three lines an IMU noise analysis reads (IEEE Std 952, annex C).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .._arrays import distinct
from .._validation import finite_array, positive
from ..errors import InputError, MissingDependencyError

__all__ = ["ONE_SIGMA", "allan_deviation", "confidence", "edf"]

#: Probability content of a 1-sigma interval, the default confidence of every interval.
ONE_SIGMA = math.erf(1.0 / math.sqrt(2.0))
#: The fewest samples an Allan analysis is run on.
MIN_SAMPLES = 100


def _allantools():
    try:
        import allantools
    except ImportError:
        raise MissingDependencyError("Allan deviation needs allantools: pip install 'gyrocal[noise]'") from None
    return allantools


def allan_deviation(rates, sample_rate: float, *, points_per_decade: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """Overlapping Allan deviation of each column.

    Parameters
    ----------
    rates : array_like, shape (N, k)
        Readings at rest [any rate or acceleration unit].
    sample_rate : float
        Sampling rate [Hz].
    points_per_decade : int
        Log-spaced averaging times per decade.

    Returns
    -------
    taus : ndarray, shape (m,)
        Averaging times [s], from one sample to a ninth of the record.
    adev : ndarray, shape (k, m)
        Allan deviation [units of `rates`].
    """
    allantools = _allantools()
    w = finite_array("rates", rates, ndim=2)
    fs = positive("sample_rate", sample_rate)
    if len(w) < MIN_SAMPLES:
        raise InputError(f"a noise analysis needs at least {MIN_SAMPLES} samples at rest, got {len(w)}")
    top = math.log10(len(w) / 9.0)
    m = distinct(np.round(np.logspace(0, top, int(top * points_per_decade) + 1)).astype(int))
    taus = m / fs
    out = []
    for col in w.T:
        t, ad, _, _ = allantools.oadev(col, rate=fs, data_type="freq", taus=taus)
        if len(t) != len(taus):
            raise InputError("allantools dropped averaging times; the record is too short for a noise analysis")
        out.append(ad)
    return np.asarray(taus), np.asarray(out)


@functools.lru_cache(maxsize=4096)  # the density fit asks for every point, four rows alike
def _edf(alpha: int, m: int, n: int) -> float:
    return float(_allantools().edf_greenhall(alpha=alpha, d=2, m=m, N=n + 1, overlapping=True))


def edf(alpha: int, m: int, n: int) -> float:
    """Equivalent degrees of freedom of an overlapping Allan variance.

    Parameters
    ----------
    alpha : {0, -1, -2}
        Power-law exponent of the noise that dominates at this averaging time.
    m : int
        Averaging factor (samples per cluster).
    n : int
        Samples in the record.
    """
    # Greenhall counts phase points: n rate samples integrate to n + 1 of them.
    return _edf(int(alpha), int(m), int(n))


def confidence(dev: float, dof: float, level: float = ONE_SIGMA) -> tuple[float, float]:
    """Two-sided interval ``(low, high)`` of an Allan deviation with `dof` degrees of freedom."""
    low, high = _allantools().confidence_interval(dev, dof, ci=level)
    return float(low), float(high)
