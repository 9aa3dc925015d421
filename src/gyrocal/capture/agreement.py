"""The device's own calibration against the host's, on the same samples, to float32 precision.

The device reduces each turn with the window accumulator and solves the six turns with the
first-moment estimator (``gyrocal_first_moment``), all in float32. The host repeats both steps
in float64 on the samples it recorded:

1. **window means**: the host's mean of the turn's raw counts against the mean the device sent
   in its turn frame, within the accumulator's rounding bound;
2. **the solve**: the host's first-moment solution from the device's own means and reference
   rates against the device's ``k, b``, within the solver's rounding bound;
3. **corrected samples**: each corrected sample the device sent against ``k (m + b)`` of the raw
   sample with the same sequence number, within the rounding of ``gyrocal_correct``.

Each bound is a first-order float32 rounding bound, ``C_ROUND * eps`` times a componentwise
(Skeel / Oettli-Prager) condition computed from the data: ``C_ROUND = 32`` covers rounding the
inputs (1/2), the backward error of a 6x6 elimination (about 3n = 18), the stop rule (1) and
the final square root and division (2). These are the bounds ``tests/test_firmware.py`` holds
the C library to. A ratio above 1 means the device did not compute what the library computes
on these samples (a corrupted frame that passed its CRC, a firmware bug, another library).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..estimators import FirstMoment
from ..observations import ObservationSet
from .frames import TURN_LABELS, Result, Turn

__all__ = ["C_ROUND", "EPS32", "Agreement", "CorrectedCheck", "accumulator_bound", "check_device", "corrected_bound",
           "solution_bound"]

EPS32 = float(np.finfo(np.float32).eps)
C_ROUND = 32.0


def accumulator_bound(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bounds on the float32 window mean and mean of squares of `x` (n, 3) from the accumulator.

    Compensated sums of deviations ``d = x - x0`` are exact to a few ulps of the sum of
    ``|d|``; the final additions add a few ulps of ``|x0|`` and of the squares.
    """
    x = np.asarray(x, dtype=float)
    d = np.abs(x - x[0])
    mean_tol = C_ROUND * EPS32 * (np.abs(x[0]) + d.mean(axis=0))
    sq_tol = C_ROUND * EPS32 * (x[0] ** 2 + (x * x).mean(axis=0) + (d * d).mean(axis=0))
    return mean_tol, sq_tol


def solution_bound(k, b, S, M, Y) -> np.ndarray:
    """Componentwise float32 bound on (k, b) solving ``sum_j k_j^2 (S_ij + 2 b_j M_ij + b_j^2) = Y_i``.

    ``S`` is the mean of squares (Algorithm 1) or the squared mean (first moment), ``M`` the
    means and ``Y`` the squared reference rates. Each equation's perturbation is bounded by eps
    times the sum of its terms' sizes (Oettli-Prager) and reaches (k, b) through the inverse
    Jacobian.
    """
    k, b = np.asarray(k, float), np.asarray(b, float)
    k2 = k * k
    J = np.concatenate([2 * k * (S + 2 * b * M + b * b), 2 * k2 * (M + b)], axis=1)
    r = (k2 * (np.abs(S) + 2 * np.abs(b * M) + b * b)).sum(axis=1) + np.abs(Y)
    return C_ROUND * EPS32 * (np.abs(np.linalg.inv(J)) @ r)


@dataclass(frozen=True)
class Agreement:
    """The device's calibration next to the host's recomputation of it.

    Attributes
    ----------
    device_k, device_b : ndarray (3,)
        The device's result [rate unit per count], [counts].
    host_k, host_b : ndarray (3,)
        The host's first-moment solution from the device's means and rates.
    params_ratio : float
        Worst ``|device - host| / bound`` over k and b (<= 1: agree to float32 precision).
    means_ratio : float
        Worst ``|device mean - host mean| / bound`` over the six turns and three axes.
    missing : tuple of str
        Turns whose samples the host did not all receive (their means could not be checked).
    corrected_ratio : float
        Worst ``|w - k (m + b)| / bound`` over the corrected samples the device sent (0 when none).
    corrected_n : int
        How many corrected samples were checked.
    """

    device_k: np.ndarray
    device_b: np.ndarray
    host_k: np.ndarray
    host_b: np.ndarray
    params_ratio: float
    means_ratio: float
    missing: tuple[str, ...] = ()
    corrected_ratio: float = 0.0
    corrected_n: int = 0

    @property
    def agrees(self) -> bool:
        return max(self.params_ratio, self.means_ratio, self.corrected_ratio) <= 1.0

    def report(self, unit: str = "deg/s") -> str:
        lines = [f"{'':<4}{'device':>16} {'host, same turns':>17}"]
        for j, a in enumerate("xyz"):
            lines.append(f"k{a:<3}{self.device_k[j]:>16.8g} {self.host_k[j]:>17.8g}  [{unit} per count]")
        for j, a in enumerate("xyz"):
            lines.append(f"b{a:<3}{self.device_b[j]:>16.8g} {self.host_b[j]:>17.8g}  [counts]")
        verdict = "agree" if self.agrees else "DISAGREE"
        lines.append(f"device and host {verdict} to float32 precision: worst difference {self.params_ratio:.2g} of its "
                     f"bound in k, b; {self.means_ratio:.2g} in the turn means"
                     + (f" (means not checked for {', '.join(self.missing)}: samples missing)" if self.missing else "")
                     + (f"; {self.corrected_ratio:.2g} in {self.corrected_n:,} corrected samples" if self.corrected_n
                        else ""))
        return "\n".join(lines)


def corrected_bound(k, b, raw) -> np.ndarray:
    """Bound on ``gyrocal_correct``'s float32 ``w = k (m + b)``: one subtraction and one product per axis."""
    k, b = np.abs(np.asarray(k, float)), np.abs(np.asarray(b, float))
    return C_ROUND * EPS32 * k * (np.abs(raw) + b)


class CorrectedCheck:
    """Corrected samples checked as they come (step 3 of the module notes), keeping only the worst ratio.

    Parameters
    ----------
    k, b : array_like (3,)
        The device's result the samples were corrected with [rate unit per count], [counts].
    """

    def __init__(self, k, b):
        self.k, self.b = np.asarray(k, float), np.asarray(b, float)
        self.ratio, self.n = 0.0, 0

    def add(self, raw, w) -> None:
        """Raw samples (n, 3) [counts] and the corrected samples (n, 3) the device sent for them."""
        raw, w = np.asarray(raw, float).reshape(-1, 3), np.asarray(w, float).reshape(-1, 3)
        if len(raw):
            err = np.abs(w - self.k * (raw + self.b)) / corrected_bound(self.k, self.b, raw)
            self.ratio = max(self.ratio, float(np.max(err)))
            self.n += len(raw)


def check_device(turns: dict[int, Turn], result: Result, samples: dict[int, np.ndarray] | None = None,
                 corrected: tuple[np.ndarray, np.ndarray] | CorrectedCheck | None = None) -> Agreement:
    """Recompute the device's calibration on the host (see the module notes).

    Parameters
    ----------
    turns : dict of int to Turn
        The accepted turn behind each of the six slots (the last one the device filed).
    result : Result
        The device's result frame (status 0).
    samples : dict of int to ndarray, optional
        Slot -> the raw samples (n, 3) [counts] of that turn as the host recorded them, when the
        host has every one of them.
    corrected : (ndarray, ndarray) or CorrectedCheck, optional
        Raw samples (n, 3) [counts] and the corrected samples (n, 3) the device sent for them, or
        those already checked as they came.
    """
    slots = range(len(TURN_LABELS))
    mean = np.array([turns[s].mean for s in slots], dtype=float)
    rate = np.array([turns[s].rate for s in slots], dtype=float)
    count = np.array([turns[s].stop - turns[s].start for s in slots], dtype=float)
    obs = ObservationSet(mean, mean * mean, np.zeros_like(mean), rate, count, count, np.zeros(6, bool))
    fit = FirstMoment(noise_std=1.0).fit(obs)  # the noise sets only the covariance, unused here
    bound = solution_bound(fit.model.k, fit.model.b, mean * mean, mean, rate**2)
    dev = np.concatenate([result.k, result.b])
    params_ratio = float(np.max(np.abs(dev - fit.model.params) / bound))
    means_ratio, missing = 0.0, []
    for s in slots:
        x = None if samples is None else samples.get(s)
        if x is None:
            missing.append(TURN_LABELS[s])
            continue
        tol, _ = accumulator_bound(x)
        means_ratio = max(means_ratio, float(np.max(np.abs(mean[s] - x.mean(axis=0)) / tol)))
    if corrected is not None and not isinstance(corrected, CorrectedCheck):
        raw, w = corrected
        corrected = CorrectedCheck(result.k, result.b)
        corrected.add(raw, w)
    ratio, n = (0.0, 0) if corrected is None else (corrected.ratio, corrected.n)
    return Agreement(np.array(result.k), np.array(result.b), fit.model.k, fit.model.b, params_ratio, means_ratio,
                     tuple(missing), ratio, n)
