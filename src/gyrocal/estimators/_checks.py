"""Checks shared by the estimators: enough observations, a non-degenerate design."""

from __future__ import annotations

import numpy as np

from ..errors import ConvergenceError, DegenerateDesignError, NonPhysicalEstimateError

N_PARAMS = 6


def require_count(n_equations: int, what: str) -> None:
    if n_equations < N_PARAMS:
        raise DegenerateDesignError(
            f"{what} give {n_equations} equation(s) for {N_PARAMS} parameters; "
            "add rotations (the paper's design turns +x, -x, +y, -y, +z, -z) or static windows"
        )


def require_full_rank(J: np.ndarray, names: tuple[str, ...], what: str, rtol: float = 1e-9) -> None:
    """Refuse a Jacobian (m, P) whose column-scaled singular values fall below `rtol`."""
    norms = np.linalg.norm(J, axis=0)
    if np.any(norms == 0):
        lost = [n for n, c in zip(names, norms) if c == 0]
        raise DegenerateDesignError(f"{what} carry no information on {', '.join(lost)}; rotate about every axis")
    s = np.linalg.svd(J / norms, compute_uv=False)
    if s[-1] < rtol * s[0]:
        _, _, vt = np.linalg.svd(J / norms)
        worst = names[int(np.argmax(np.abs(vt[-1])))]
        raise DegenerateDesignError(
            f"{what} cannot separate the parameters (most affected: {worst}); "
            "rotate about all three axes, in both senses, or add static windows"
        )


def require_positive_k2(k2: np.ndarray, method: str) -> None:
    bad = ~(k2 > 0)
    if np.any(bad):
        idx = np.argwhere(bad)[0]
        raise NonPhysicalEstimateError(
            f"{method} estimated k^2 = {float(k2[tuple(idx)]):.4g} <= 0 (batch item {idx[0]}, axis {'xyz'[idx[-1]]}); "
            "check the reference speed or angle and the units of the readings"
        )


def require_converged(converged: np.ndarray, iterations: np.ndarray, method: str) -> None:
    if not np.all(converged):
        i = int(np.argmin(converged))
        raise ConvergenceError(
            f"{method} did not converge after {int(iterations[i])} iterations (batch item {i}); "
            "check the windows and the reference, or raise max_iter",
            iterations=int(iterations[i]),
        )


def require_every_axis(mean: np.ndarray, static: np.ndarray) -> np.ndarray:
    """Refuse a design with no rotation about some axis; return each window's dominant axis.

    `mean` is one gyro's window means (n, 3); the dominant axis of a window is the one
    with the largest mean reading. Without a turn about an axis its scale factor is
    invisible (a small misalignment makes the problem ill-posed rather than singular).
    """
    dominant = np.abs(mean).argmax(axis=-1)
    for j in range(3):
        if not np.any((dominant == j) & ~static):
            raise DegenerateDesignError(
                f"no rotation about the {'xyz'[j]} axis; k{'xyz'[j]} cannot be observed. Turn about every axis"
            )
    return dominant
