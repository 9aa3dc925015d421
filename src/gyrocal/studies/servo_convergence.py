"""The servo method of Wang et al., Table I: Algorithm 1's estimates iteration by iteration, for three gyros.

The true parameters are the paper's own "actual values" of its three cases (high
scale error; high bias; both). Each case is calibrated once, showing every iterate,
and ``reps`` more times to count iterations. The paper's row "1" is our iteration 0,
the linear solve with ``beta0 = 0``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..estimators import Algorithm1
from ..simulation.fast import simulate_observations
from ._common import PARAM_NAMES, Progress, ServoSettings, StudyOutput
from ._tables import write_table

#: The servo method of Wang et al., Table I, "Actual value" rows: (kx, ky, kz, bx, by, bz).
PAPER_CASES = {
    "1. high scale factor error": (1.9074, 1.9529, 1.5635, 0.0827, 0.0265, -0.0805),
    "2. high bias": (1.0979, 1.1052, 0.9851, -0.1046, 0.1995, 0.1565),
    "3. high scale factor error and bias": (1.5044, 1.6494, 1.5282, 0.1483, -0.1282, 0.1794),
}


def run(
    out: Path,
    *,
    reps: int = 1000,
    seed: int = 0,
    noise: float | None = None,
    settings: ServoSettings = ServoSettings(),
    progress: Progress | None = None,
    plot: bool = True,
) -> StudyOutput:
    """Run the study; write ``convergence.{csv,md,png}`` and ``iterations.{csv,md}`` under `out`.

    Parameters
    ----------
    reps : int
        Extra calibrations per case used to count iterations.
    noise : float, optional
        Per-sample white noise [rad/s]; default the first of ``settings.noise_levels``
        (the paper's lower level).
    """
    noise = settings.noise_levels[0] if noise is None else noise
    rng = np.random.default_rng(seed)
    estimator = Algorithm1()
    rows, count_rows, cases = [], [], {}
    for name, truth in PAPER_CASES.items():
        truth = np.asarray(truth)
        k, b = np.tile(truth[:3], (reps + 1, 1)), np.tile(truth[3:], (reps + 1, 1))
        obs = simulate_observations(k, b, speed=settings.speed, sample_rate=settings.sample_rate, noise_std=noise,
                                    jitter=settings.jitter, misalignment=settings.misalignment, rng=rng)
        fit = estimator.fit_batch(obs)
        first = fit.item(0)
        cases[name] = (first.history, truth)
        rows.append([name, "actual value", *map(float, truth)])
        for i, est in enumerate(first.history):
            label = f"{i}" + (" (converged)" if i == first.iterations else "")
            rows.append([name, label, *map(float, est)])
        counts = np.bincount(fit.iterations, minlength=fit.iterations.max() + 1)
        count_rows.append([name, reps + 1, float(fit.iterations.mean()), int(fit.iterations.max()),
                           " ".join(f"{i}:{c}" for i, c in enumerate(counts) if c)])
        if progress:
            progress(1, name)
    out.mkdir(parents=True, exist_ok=True)
    files = list(write_table(out / "convergence", ["case", "iteration", *PARAM_NAMES], rows))
    files += write_table(out / "iterations", ["case", "calibrations", "mean iterations", "max iterations",
                                              "iterations:count"], count_rows)
    if plot:
        from ..plotting import save_figure
        from ..plotting.studies import convergence_figure

        save_figure(convergence_figure(cases, title="the servo method of Wang et al., Table I: Algorithm 1 iterates"), out / "convergence.png")
        files.append(out / "convergence.png")
    summary = "; ".join(f"{r[0]}: mean {r[2]:.2f}, max {r[3]} iterations" for r in count_rows)
    return StudyOutput("servo-convergence", tuple(files), summary)


def work_units() -> int:
    """Progress units this study reports."""
    return len(PAPER_CASES)
