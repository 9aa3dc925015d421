"""The servo method of Wang et al., Fig. 4: mean squared error of every parameter against servo speed.

Speeds 0.3 to 3 rad/s in steps of 0.1, both noise levels, ``gyros x reps``
calibrations per point (paper: 30 x 500 = 15,000), all by the fast path and batch
estimators. The MSE is eq. 9; the Cramér–Rao variance averaged over the gyros is
drawn dashed.
"""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

from ..simulation.fast import simulate_observations
from ._common import METHOD_LABELS, PARAM_NAMES, Progress, ServoSettings, StudyOutput, draw_truth, fit_errors
from ._crb import crb_std
from ._tables import write_table

#: The servo method of Wang et al., section III-B: 0.3 to 3 rad/s in steps of 0.1 (28 speeds).
PAPER_SPEEDS = tuple(np.round(np.arange(0.3, 3.0 + 1e-9, 0.1), 10))


def run(
    out: Path,
    *,
    gyros: int = 30,
    reps: int = 500,
    seed: int = 0,
    speeds: Sequence[float] = PAPER_SPEEDS,
    methods: Sequence[str] = ("algorithm1",),
    settings: ServoSettings = ServoSettings(),
    progress: Progress | None = None,
    plot: bool = True,
) -> StudyOutput:
    """Run the study; write ``mse.png``, ``mse.csv`` and ``mse.md`` under `out`.

    Parameters
    ----------
    out : Path
        Output folder.
    gyros, reps : int
        Gyros and calibrations of each per speed and noise level.
    seed : int
        Seed of the random generator.
    speeds : sequence of float
        Servo speeds [rad/s].
    methods : sequence of str
        Estimators (``algorithm1``, ``lm``, ``first-moment``); the paper's figure is Algorithm 1.
    """
    rng = np.random.default_rng(seed)
    speeds = np.asarray(speeds, dtype=float)
    k_g, b_g = draw_truth("normal", gyros, rng)
    k, b = np.repeat(k_g, reps, axis=0), np.repeat(b_g, reps, axis=0)
    mse = {(noise, m): np.empty((len(speeds), 6)) for noise in settings.noise_levels for m in methods}
    crb = {noise: np.empty((len(speeds), 6)) for noise in settings.noise_levels}
    for noise in settings.noise_levels:
        for i, speed in enumerate(speeds):
            obs = simulate_observations(k, b, speed=speed, sample_rate=settings.sample_rate, noise_std=noise,
                                        jitter=settings.jitter, misalignment=settings.misalignment, rng=rng)
            for m in methods:
                mse[noise, m][i] = np.mean(fit_errors(m, obs, k, b) ** 2, axis=0)  # the servo method of Wang et al., eq. 9
            crb[noise][i] = np.mean(crb_std(k_g, b_g, speed=speed, noise_std=noise,
                                            sample_rate=settings.sample_rate) ** 2, axis=0)
            if progress:
                progress(1, f"noise {noise:g}, speed {speed:.1f} rad/s")
    out.mkdir(parents=True, exist_ok=True)
    header = ["noise [rad/s]", "method", "speed [rad/s]"] + [f"MSE {p}" for p in PARAM_NAMES] + \
        [f"CRB var {p}" for p in PARAM_NAMES]
    rows = [[noise, METHOD_LABELS[m], float(s), *map(float, mse[noise, m][i]), *map(float, crb[noise][i])]
            for (noise, m) in mse for i, s in enumerate(speeds)]
    files = list(write_table(out / "mse", header, rows))
    if plot:
        from ..plotting import save_figure
        from ..plotting.studies import mse_speed_figure

        fig = mse_speed_figure(speeds, mse, crb, title=f"the servo method of Wang et al., Fig. 4 ({gyros} gyros x {reps} reps per point)")
        save_figure(fig, out / "mse.png")
        files.append(out / "mse.png")
    lines = []
    for (noise, m), v in mse.items():
        ratio = v / crb[noise]
        lines.append(f"{METHOD_LABELS[m]}, noise {noise:g}: MSE/CRB "
                     f"k {ratio[:, :3].min():.2f}-{ratio[:, :3].max():.2f}, "
                     f"b {ratio[:, 3:].min():.2f}-{ratio[:, 3:].max():.2f}")
    return StudyOutput("servo-speed", tuple(files), "\n".join(lines))


def work_units(speeds: Sequence[float] = PAPER_SPEEDS, settings: ServoSettings = ServoSettings()) -> int:
    """Progress units this study reports."""
    return len(speeds) * len(settings.noise_levels)
