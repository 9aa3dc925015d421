"""The servo method of Wang et al., Fig. 2 and Fig. 5: error box plots of three estimators at two noise levels.

``servo-normal`` uses the normal parameter ranges (section III-A), ``servo-extreme``
the extreme ones (section III-C). Each of ``gyros`` random gyros is calibrated
``reps`` times with the six-observation protocol, by the fast path.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._arrays import median, percentile
from ..simulation.fast import simulate_observations
from ._common import METHOD_LABELS, PARAM_NAMES, Condition, Progress, ServoSettings, StudyOutput, draw_truth, fit_errors
from ._crb import crb_std
from ._tables import write_table

METHODS = ("algorithm1", "lm", "first-moment")


def run(
    out: Path,
    condition: Condition = "normal",
    *,
    gyros: int = 30,
    reps: int = 500,
    seed: int = 0,
    settings: ServoSettings = ServoSettings(),
    progress: Progress | None = None,
    plot: bool = True,
) -> StudyOutput:
    """Run the study and write ``errors.png``, ``errors.csv`` and ``errors.md`` under `out`.

    Parameters
    ----------
    out : Path
        Output folder.
    condition : {"normal", "extreme"}
        The servo method's parameter ranges.
    gyros, reps : int
        Simulated gyros, and calibrations of each (paper: 30 x 500).
    seed : int
        Seed of the random generator.
    """
    rng = np.random.default_rng(seed)
    k_g, b_g = draw_truth(condition, gyros, rng)
    k, b = np.repeat(k_g, reps, axis=0), np.repeat(b_g, reps, axis=0)
    errors: dict[tuple[float, str], np.ndarray] = {}
    crb: dict[float, np.ndarray] = {}
    for noise in settings.noise_levels:
        obs = simulate_observations(k, b, speed=settings.speed, sample_rate=settings.sample_rate, noise_std=noise,
                                    jitter=settings.jitter, misalignment=settings.misalignment, rng=rng)
        for method in METHODS:
            errors[noise, method] = fit_errors(method, obs, k, b)
            if progress:
                progress(1, f"{METHOD_LABELS[method]}, noise {noise:g}")
        # The bound varies with k; report its RMS over the simulated gyros.
        crb[noise] = np.sqrt(np.mean(crb_std(k_g, b_g, speed=settings.speed, noise_std=noise,
                                             sample_rate=settings.sample_rate) ** 2, axis=0))
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for (noise, method), e in errors.items():
        lo, hi = percentile(e, [2.5, 97.5], axis=0)
        for j, name in enumerate(PARAM_NAMES):
            rows.append([noise, METHOD_LABELS[method], name, float(e[:, j].mean()), float(median(e[:, j])),
                         float(e[:, j].std()), float(np.sqrt(np.mean(e[:, j] ** 2))), float(lo[j]), float(hi[j]),
                         float(crb[noise][j])])
    header = ["noise [rad/s]", "method", "param", "mean error", "median error", "std", "rms", "p2.5", "p97.5",
              "CRB std"]
    files = list(write_table(out / "errors", header, rows))
    if plot:
        from ..plotting import save_figure
        from ..plotting.studies import error_box_figure

        fig = error_box_figure(errors, crb, title=f"the servo method of Wang et al., Fig. {2 if condition == 'normal' else 5} "
                                                  f"({condition} conditions, {gyros} gyros x {reps} reps)")
        save_figure(fig, out / "errors.png")
        files.append(out / "errors.png")
    summary = "\n".join(
        f"noise {noise:g}: " + ", ".join(
            f"{METHOD_LABELS[m]} rms k {np.sqrt(np.mean(errors[noise, m][:, :3] ** 2)):.2e} "
            f"b {np.sqrt(np.mean(errors[noise, m][:, 3:] ** 2)):.2e}" for m in METHODS)
        + f"; CRB k {np.sqrt(np.mean(crb[noise][:3] ** 2)):.2e} b {np.sqrt(np.mean(crb[noise][3:] ** 2)):.2e}"
        for noise in settings.noise_levels
    )
    return StudyOutput(f"servo-{condition}", tuple(files), summary)


def work_units(settings: ServoSettings = ServoSettings()) -> int:
    """Progress units this study reports."""
    return len(settings.noise_levels) * len(METHODS)
