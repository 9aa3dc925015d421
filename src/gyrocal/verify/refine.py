"""Joint least-squares refinement of clock offset, clock drift and mounting rotation.

Model: the test gyro reads ``w_test(t) = R w_ref(tau(t)) + e`` where ``w_ref`` is the
reference log linearly interpolated at its own clock time ``tau``, ``R`` the mounting
rotation (reference frame to test frame) and ``e`` the residual. The clocks are related by
``t = tau (1 + drift) + offset``. Internally the time map is written around the test
log's centre ``tc``: ``tau(t) = a + (t - tc) / (1 + drift)``, so the ``a`` and drift columns
of the Jacobian are uncorrelated; the rotation is updated as ``R <- R Exp(theta)``.

The time columns of the Jacobian need the reference's slope. The slope of the
interpolating line is the difference of two noisy samples, whose noise, divided by the
sample period, can exceed the motion's own slope (a servo plateau has none); it would both
steer the fit and inflate its information. The slope is therefore taken from a
Savitzky-Golay derivative of the reference (about 50 ms wide), and the fit solves the
normal equations ``J~^T e = 0`` of that smoothed Jacobian ``J~``. Its noise is odd about
each sample, so it does not correlate with the interpolated noise in ``e``, and the
equations stay unbiased where a plain least-squares fit would drift toward the phases
at which interpolation averages the reference noise down.

The five-parameter problem is solved by Gauss-Newton with step halving. Its normal
equations are accumulated chunk by chunk, so a ten-million-sample log never holds its full
Jacobian (which a general solver such as ``scipy.optimize.least_squares`` would build).
The covariance is that of the residuals' own scatter, ``s^2 A^-1 (J~^T J~) A^-T`` with
``A = J~^T J`` the derivative of the equations. Where the residuals are correlated, as
when a calibration leaves a systematic error, a parameter's variance is raised to its
sandwich (batch-means) value ``A^-1 S A^-T``, ``S`` summed over blocks of consecutive
samples, when that is significantly larger.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ConvergenceError
from ..quaternion import rotvec_matrix
from ._signal import savgol_slope
from .bootstrap import optimal_block_length

__all__ = ["Refined", "interpolate", "refine", "smooth_slope"]

PPM = 1e-6
_CHUNK = 1 << 18  # samples per pass of the normal equations: a (n, 3, 5) Jacobian of 31 MB
_MAX_ITER = 50
#: Width of the derivative filter behind the time columns of the Jacobian [s].
SLOPE_WIDTH_S = 0.05
_MIN_BLOCKS = 30
_MAX_SCORES = 1 << 20


@dataclass(frozen=True)
class Refined:
    """Result of :func:`refine` (internal parameterisation).

    Attributes
    ----------
    a : float
        Reference clock time at the test log's centre ``tc`` [s].
    drift_ppm : float
        Clock drift [ppm].
    rotation : ndarray, shape (3, 3)
        Reference frame to test frame.
    covariance : ndarray, shape (5, 5)
        Covariance of ``(a [s], drift [ppm], theta [rad] x3)``, ``theta`` a right
        perturbation of the rotation (reference frame); see the module docstring.
    covariance_white : ndarray, shape (5, 5)
        The same from the residual scatter alone, valid for white residuals.
    residual_rms : ndarray, shape (3,)
        RMS residual per test axis [rad/s].
    block : int
        Batch length of the sandwich [samples].
    iterations : int
    """

    a: float
    drift_ppm: float
    rotation: np.ndarray
    covariance: np.ndarray
    covariance_white: np.ndarray
    residual_rms: np.ndarray
    block: int
    iterations: int


def interpolate(t_ref: np.ndarray, w_ref: np.ndarray, tau: np.ndarray,
                slope: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Reference at clock times `tau`: value (n, 3), slope (n, 3) [per s] and fractional position (n,).

    The fractional position ``f`` of each time between its two reference samples sets the
    weights ``(1 - f, f)`` of linear interpolation. The slope is that of the interpolating
    line, or `slope` (M, 3) [per s] given at the reference samples, interpolated likewise.
    """
    k = np.clip(np.searchsorted(t_ref, tau, side="right") - 1, 0, len(t_ref) - 2)
    h = t_ref[k + 1] - t_ref[k]
    f = (tau - t_ref[k]) / h
    step = w_ref[k + 1] - w_ref[k]
    if slope is None:
        rate = step / h[:, None]
    else:
        rate = slope[k] + f[:, None] * (slope[k + 1] - slope[k])
    return w_ref[k] + f[:, None] * step, rate, f


def smooth_slope(t_ref: np.ndarray, w_ref: np.ndarray, width_s: float = SLOPE_WIDTH_S) -> np.ndarray:
    """Savitzky-Golay derivative (M, 3) [per s] of the reference over about `width_s` seconds.

    A quadratic is fitted over an odd number of samples (at least 5) on the mean sample
    period, which suits the regular clock of a reference-grade sensor.
    """
    dt = (t_ref[-1] - t_ref[0]) / (len(t_ref) - 1)
    n = max(5, 2 * round(width_s / dt / 2) + 1)
    n = min(n, len(t_ref) - (1 - len(t_ref) % 2))
    return savgol_slope(w_ref, n, dt)


def _chunk(p, sl, a: float, drift: float, rot: np.ndarray, jacobian: bool, exact: bool = False):
    """Residuals (n, 3) of a chunk of samples and their smoothed Jacobian J~ (n, 3, 5) when
    asked; with `exact`, the Jacobian of the interpolant itself instead (two-point slopes)."""
    u = p["u"][sl]
    tau = a + u / (1.0 + drift * PPM)
    v, s, _ = interpolate(p["t_ref"], p["w_ref"], tau, None if exact else p["slope"])
    e = p["w"][sl] - v @ rot.T
    if not jacobian:
        return e, None
    rs = s @ rot.T  # d(R v)/dtau
    dtau_ddrift = -u * PPM / (1.0 + drift * PPM) ** 2
    jac = np.empty((len(u), 3, 5))
    jac[:, :, 0] = -rs
    jac[:, :, 1] = -rs * dtau_ddrift[:, None]
    rv = v @ rot.T
    for j in range(3):  # e = w - R (v + theta x v); R (v x e_j) = (R v) x (R e_j)
        jac[:, :, 2 + j] = np.cross(rv, rot[:, j])
    return e, jac


def _normal_equations(p, a, drift, rot, fit_drift: bool):
    """``A = J~^T J~``, ``psi = J~^T e`` and the residual sum of squares; a held drift gets a unit row."""
    n = len(p["u"])
    h, g, cost = np.zeros((5, 5)), np.zeros(5), 0.0
    for i in range(0, n, _CHUNK):
        e, jac = _chunk(p, slice(i, i + _CHUNK), a, drift, rot, True)
        flat = jac.reshape(-1, 5)
        h += flat.T @ flat
        g += flat.T @ e.ravel()
        cost += float(e.ravel() @ e.ravel())
    if not fit_drift:
        h[1, :], h[:, 1], g[1] = 0.0, 0.0, 0.0
        h[1, 1] = 1.0
    return h, g, cost


def _solve(h: np.ndarray, g: np.ndarray) -> np.ndarray:
    """GN step ``-A^-1 psi`` with Jacobi scaling (the columns differ by orders of magnitude)."""
    d = np.sqrt(np.diag(h))
    d = np.where(d > 0, d, 1.0)
    return -np.linalg.solve(h / np.outer(d, d), g / d) / d


def _step(a, drift, rot, delta):
    return a + delta[0], drift + delta[1], rot @ rotvec_matrix(delta[2:])


def _gauss_newton(p, a, drift, rot, fit_drift: bool):
    """Solve ``J~^T e = 0``; the merit is the predicted decrease ``psi^T A^-1 psi`` (0 at the solution)."""
    dof = max(3 * len(p["u"]) - 5, 1)
    h, g, cost = _normal_equations(p, a, drift, rot, fit_drift)
    for it in range(1, _MAX_ITER + 1):
        delta = _solve(h, g)
        merit = float(-g @ delta)
        if merit <= 1e-8 * cost / dof:  # the step is below 1e-4 of the parameters' 1-sigma
            return a, drift, rot, it
        for _ in range(20):  # halve the step until the merit falls
            trial = _step(a, drift, rot, delta)
            h_t, g_t, cost_t = _normal_equations(p, *trial, fit_drift)
            if float(-g_t @ _solve(h_t, g_t)) < merit:
                break
            delta = delta / 2
        else:
            raise ConvergenceError("the alignment stalled: no Gauss-Newton step improves the fit", it)
        (a, drift, rot), h, g, cost = trial, h_t, g_t, cost_t
    raise ConvergenceError(f"the alignment did not converge in {_MAX_ITER} Gauss-Newton iterations", _MAX_ITER)


def _covariances(p, a, drift, rot, fit_drift: bool):
    """Sandwich and white covariances of the root of ``J~^T e = 0``.

    The bread is the derivative of the equations, ``J~^T J`` with ``J`` the Jacobian of the
    interpolant actually fitted; the meat sums the scores ``J~^T e`` over blocks.
    """
    n = len(p["u"])
    # Scores are summed over `micro` samples (a power of two, so it divides _CHUNK) to bound memory.
    micro = 1 << max(0, math.ceil(math.log2(n / _MAX_SCORES))) if n > _MAX_SCORES else 1
    bread, gram, sq = np.zeros((5, 5)), np.zeros((5, 5)), np.zeros(3)
    scores = np.empty((-(-n // micro), 5))
    for i in range(0, n, _CHUNK):
        sl = slice(i, i + _CHUNK)
        e, jac = _chunk(p, sl, a, drift, rot, True)
        flat = jac.reshape(-1, 5)
        bread += flat.T @ _chunk(p, sl, a, drift, rot, True, exact=True)[1].reshape(-1, 5)
        gram += flat.T @ flat
        part = np.einsum("nip,ni->np", jac, e)
        scores[i // micro:(i + len(e) - 1) // micro + 1] = np.add.reduceat(part, np.arange(0, len(e), micro), axis=0)
        sq += np.sum(e * e, axis=0)
    keep = np.array([0, 1, 2, 3, 4] if fit_drift else [0, 2, 3, 4])
    inv = np.zeros((5, 5))
    inv[np.ix_(keep, keep)] = np.linalg.inv(bread[np.ix_(keep, keep)])
    white = inv @ gram @ inv.T * float(sq.sum()) / max(3 * n - len(keep), 1)
    m = len(scores)
    block = min(max(optimal_block_length(scores[:, 0]), 1), max(m // _MIN_BLOCKS, 1))
    sums = np.add.reduceat(scores, np.arange(0, m, block), axis=0) @ inv.T  # each block's pull on the estimate
    return _inflated(white, sums), white, np.sqrt(sq / n), block * micro


def _inflated(white: np.ndarray, pulls: np.ndarray) -> np.ndarray:
    """`white`, with each parameter's variance raised to the block (sandwich) variance where
    that is significantly larger: correlated residuals, as a calibration's systematic error
    leaves. The block variance of a parameter whose information sits in a few blocks (the
    ramps of a servo session) is noisy, so it replaces the white one only beyond three
    standard deviations of its own scatter, ``1 + 3 sqrt(2 / nu)`` with ``nu`` the effective
    number of blocks."""
    var = np.einsum("bk,bk->k", pulls, pulls)
    nu = var**2 / np.maximum(np.einsum("bk,bk->k", pulls**2, pulls**2), np.finfo(float).tiny)
    w = np.diag(white)
    ratio = np.where(w > 0, var / np.where(w > 0, w, 1.0), 1.0)
    scale = np.sqrt(np.where(ratio > 1.0 + 3.0 * np.sqrt(2.0 / np.maximum(nu, 1.0)), ratio, 1.0))
    return white * np.outer(scale, scale)


def refine(t_test, w_test, t_ref, w_ref, a0: float, drift0: float, rot0: np.ndarray, *,
           fit_drift: bool = True, covariance: bool = True) -> Refined:
    """Least-squares offset, drift and rotation from a starting point.

    Parameters
    ----------
    t_test : ndarray, shape (n,)
        Test sample times [s] that map inside the reference log (the caller trims them).
    w_test : ndarray, shape (n, 3)
        Test rates [rad/s] (calibrated, so they are comparable with the reference).
    t_ref, w_ref : ndarray, shape (M,), (M, 3)
        Reference log [s], [rad/s].
    a0 : float
        Starting reference time at the test centre ``(t_test[0] + t_test[-1]) / 2`` [s].
    drift0 : float
        Starting drift [ppm].
    rot0 : ndarray, shape (3, 3)
        Starting rotation, reference frame to test frame.
    fit_drift : bool
        False holds the drift at `drift0` (a short log cannot measure it).
    covariance : bool
        False skips the covariance (NaN), for a pass whose result only starts another.
    """
    tc = 0.5 * (t_test[0] + t_test[-1])
    p = {"u": t_test - tc, "w": w_test, "t_ref": t_ref, "w_ref": w_ref, "slope": smooth_slope(t_ref, w_ref)}
    a, drift, rot, iterations = _gauss_newton(p, float(a0), float(drift0), np.asarray(rot0, float), fit_drift)
    if not covariance:
        nan = np.full((5, 5), np.nan)
        return Refined(a=a, drift_ppm=drift, rotation=rot, covariance=nan, covariance_white=nan,
                       residual_rms=np.full(3, np.nan), block=0, iterations=iterations)
    sandwich, white, rms, block = _covariances(p, a, drift, rot, fit_drift)
    return Refined(a=a, drift_ppm=drift, rotation=rot, covariance=sandwich, covariance_white=white,
                   residual_rms=rms, block=block, iterations=iterations)
