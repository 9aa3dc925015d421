"""Settings, truth draws and outputs shared by the studies of the servo method of Wang et al."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Literal

import numpy as np

from ..estimators import make_estimator
from ..observations import ObservationSet

#: ``progress(advance, label)``: called after each unit of work with how many units it was.
Progress = Callable[[int, str], None]

#: The servo method of Wang et al., section III-A: 200 Hz, 60 deg/s, 5 % jitter, misalignment up to 0.10, two noise levels.
PAPER_SPEED = math.pi / 3.0
PAPER_NOISE = (0.035, 0.2)
PARAM_NAMES = ("kx", "ky", "kz", "bx", "by", "bz")
METHOD_LABELS = {"algorithm1": "Algorithm 1", "lm": "LM", "first-moment": "first moment"}
Condition = Literal["normal", "extreme"]


@dataclass(frozen=True)
class ServoSettings:
    """Simulation settings of the servo method of Wang et al., section III [SI units]."""

    speed: float = PAPER_SPEED
    sample_rate: float = 200.0
    jitter: float = 0.05
    misalignment: float = 0.10
    noise_levels: tuple[float, ...] = PAPER_NOISE


@dataclass(frozen=True)
class StudyOutput:
    """What a study wrote and its headline numbers.

    Attributes
    ----------
    name : str
    files : tuple of Path
        Figures (PNG) and tables (CSV, Markdown) written.
    summary : str
        A few lines for the terminal.
    """

    name: str
    files: tuple[Path, ...]
    summary: str = field(default="")


def draw_truth(condition: Condition, gyros: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """True ``(k, b)``, each (gyros, 3), from the servo method's ranges.

    ``normal`` (III-A): k ~ U(0.8, 1.2), b ~ U(-0.1, 0.1) rad/s.
    ``extreme`` (III-C): k ~ U(1.2, 2.0), |b| ~ U(0.1, 0.2) rad/s with a random sign.
    """
    if condition == "normal":
        return rng.uniform(0.8, 1.2, (gyros, 3)), rng.uniform(-0.1, 0.1, (gyros, 3))
    sign = rng.choice([-1.0, 1.0], (gyros, 3))
    return rng.uniform(1.2, 2.0, (gyros, 3)), sign * rng.uniform(0.1, 0.2, (gyros, 3))


def fit_errors(method: str, obs: ObservationSet, k: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Estimation errors ``estimate - truth`` (B, 6) of one method on a batch."""
    fit = make_estimator(method).fit_batch(obs)
    return fit.params - np.concatenate([k, b], axis=1)


def noise_label(noise: float) -> str:
    return f"noise {noise:g} rad/s"
