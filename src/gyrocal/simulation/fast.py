"""Exact window statistics without drawing every sample (the fast path).

Inside a constant-speed window the per-sample generator of the servo method's simulation
(:func:`gyrocal.simulation.windows.paper_observations`) produces readings

    m_i = c + j_i d + e_i,        i = 1..n,

with ``c`` the noise-free mean reading, ``d`` the rotation part of the reading
(``speed * axis / k``), ``j_i`` the speed jitter re-centred to zero mean over the
window (the servo turns exactly 360 deg), and ``e_i`` white noise ``N(0, diag(s^2))``.
Writing ``w_i = jitter z_i d + e_i`` (``z_i`` standard normal, iid), the jitter's
re-centring gives ``m_i - mean(m) = w_i - mean(w)`` while ``mean(m) = c + mean(e)``. So:

* the window mean is exactly ``c + N(0, s^2 / n)``: jitter leaves no trace in it;
* the mean of squares is ``mean(m)^2 + S_aa / n`` per axis, where ``S`` is the scatter
  matrix of ``w``, Wishart with ``n - 1`` degrees of freedom and scale
  ``jitter^2 d d^T + diag(s^2)``, independent of the mean;
* the first-difference statistic ``noise_var`` (mean squared difference / 2, see
  :func:`gyrocal.observations.observe`) is ``sum_k lambda_k y_k^2 / (2 (n-1))`` over the
  same ``w``'s DCT coefficients; we draw it from the Wishart law with the same first
  two moments (Satterthwaite, ``nu = 4 (n-1)^2 / (6 n - 8)``), independent of the scatter.
  Only the covariance uses it; the estimates do not.

The three diagonal entries of the Wishart scatter are drawn jointly and exactly from
seven variates per window (see :func:`_wishart_diagonal`), so a calibration of six
windows costs ~100 random numbers instead of ~20,000 per axis.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from ..errors import InputError
from ..observations import ObservationSet
from .windows import PAPER_AXES, _tilted_axes, axis_vector, check_protocol_args, paper_observations

__all__ = ["window_statistics", "noise_var_dof", "simulate_observations"]


def noise_var_dof(count) -> np.ndarray:
    """Degrees of freedom of the chi-square matching the first-difference statistic.

    For ``n`` white samples, ``sum (x_{i+1} - x_i)^2`` has mean ``2 (n-1) s^2`` and
    variance ``2 (6 n - 8) s^4`` (trace of the squared path-graph Laplacian), so
    ``noise_var / s^2`` has the mean and variance of ``chi2_nu / nu`` with this ``nu``.
    """
    n = np.asarray(count, dtype=float)
    return 4.0 * (n - 1.0) ** 2 / (6.0 * n - 8.0)


def _wishart_diagonal(dof, d, jitter: float, sd: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Diagonal (..., 3) of ``W ~ Wishart(dof, jitter^2 d d^T + diag(sd^2))``.

    ``W = sum_k w_k w_k^T`` with ``w_k = jitter z_k d + sd * eta_k``. Per axis,
    ``W_aa = (jitter d_a sqrt(Z) + sd_a g_a)^2 + sd_a^2 R_a`` where ``Z = sum z_k^2``
    (chi2_dof, shared by the axes), ``g_a`` is eta_a projected on ``z`` (standard
    normal) and ``R_a`` the rest (chi2_{dof-1}). Exact, also for non-integer ``dof``.
    """
    shape = d.shape
    dof = np.broadcast_to(dof, shape[:-1])
    Z = rng.chisquare(dof)[..., None]
    g = rng.standard_normal(shape)
    R = rng.chisquare(np.broadcast_to((dof - 1.0)[..., None], shape))
    return (jitter * d * np.sqrt(Z) + sd * g) ** 2 + sd * sd * R


def window_statistics(
    level,
    direction,
    count,
    noise_std,
    jitter: float,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Draw ``(mean, mean_sq, noise_var)`` of constant-speed windows exactly.

    Parameters
    ----------
    level : array_like, shape (..., n, 3)
        Noise-free mean reading ``c`` of each window [rad/s].
    direction : array_like, shape (..., n, 3)
        Rotation part ``d`` of the reading, multiplied by the relative speed jitter
        [rad/s]; zero for static windows.
    count : array_like of int, shape (n,)
        Samples per window.
    noise_std : float or array_like of shape (3,)
        Per-sample white-noise standard deviation [rad/s].
    jitter : float
        Per-sample relative speed jitter (standard deviation, re-centred per window) [-].
    rng : numpy.random.Generator

    Returns
    -------
    mean, mean_sq, noise_var : ndarray, shape (..., n, 3)
        What :func:`gyrocal.observations.observe` returns for the same window, in law.
    """
    c = np.asarray(level, dtype=float)
    d = np.broadcast_to(np.asarray(direction, dtype=float), c.shape)
    n = np.asarray(count, dtype=float)
    if c.ndim < 2 or c.shape[-1] != 3 or n.shape != c.shape[-2:-1]:
        raise InputError(f"level must be (..., n, 3) with n = len(count); got {c.shape} and {n.shape}")
    if np.any(n < 3):
        raise InputError(f"count must be >= 3 samples per window, got {n.min():g}")
    if not jitter >= 0:
        raise InputError(f"jitter must be >= 0, got {jitter!r}")
    sd = np.broadcast_to(np.asarray(noise_std, dtype=float), (3,))
    n3 = n[:, None]
    mean = c + sd * rng.standard_normal(c.shape) / np.sqrt(n3)
    scatter = _wishart_diagonal(n - 1.0, d, jitter, sd, rng)
    mean_sq = mean * mean + scatter / n3
    nu = noise_var_dof(n)
    noise_var = _wishart_diagonal(nu, d, jitter, sd, rng) / nu[:, None]
    return mean, mean_sq, noise_var


def simulate_observations(
    k,
    b,
    *,
    speed: float,
    sample_rate: float = 200.0,
    noise_std=0.035,
    jitter: float = 0.05,
    misalignment: float = 0.10,
    static_duration: float = 0.0,
    axes: Sequence[str] = PAPER_AXES,
    rng: np.random.Generator,
    fast: bool = True,
) -> ObservationSet:
    """The servo method's six-observation protocol for a batch of gyros, by the fast path.

    Same parameters and law as :func:`gyrocal.simulation.windows.paper_observations`
    (the per-sample reference), which is called instead when ``fast`` is False. The
    fast path is exact for that generator's model (Gaussian white noise, re-centred
    Gaussian jitter, one constant tilt per window), so there is no case it must
    decline; models outside it (quantisation, saturation, bias instability, ramps)
    go through :class:`~gyrocal.simulation.VirtualGyro` and the per-sample simulators.

    Parameters
    ----------
    fast : bool
        Draw window statistics from their exact laws (True) or every sample (False).
    """
    if not fast:
        return paper_observations(k, b, speed=speed, sample_rate=sample_rate, noise_std=noise_std, jitter=jitter,
                                  misalignment=misalignment, static_duration=static_duration, axes=axes, rng=rng)
    k, b, speed, fs, sd = check_protocol_args(k, b, speed, sample_rate, noise_std, jitter, misalignment, static_duration)
    n_rot = int(round(2 * np.pi / speed * fs))
    n_sta = int(round(static_duration * fs))
    if n_rot < 3 or (static_duration > 0 and n_sta < 3):
        raise InputError(f"windows need at least 3 samples; speed={speed} rad/s and sample_rate={fs} Hz give {n_rot}")
    B = len(k)
    rot = np.stack([speed * _tilted_axes(axis_vector(a), misalignment, B, rng) for a in axes], axis=1) / k[:, None]
    if n_sta:
        # Each turn is followed by its static window, as in the per-sample generator.
        rot = np.stack([rot, np.zeros_like(rot)], axis=2).reshape(B, -1, 3)
    static = np.tile([False, True], len(axes)) if n_sta else np.zeros(len(axes), dtype=bool)
    count = np.where(static, n_sta, n_rot).astype(float)
    # Static windows carry no jitter: their rotation part d is zero.
    mean, mean_sq, noise_var = window_statistics(rot - b[:, None], rot, count, sd, jitter, rng)
    rate = np.broadcast_to(np.where(static, 0.0, speed), (B, len(count)))
    return ObservationSet(mean, mean_sq, noise_var, rate, count, count / fs, static)
