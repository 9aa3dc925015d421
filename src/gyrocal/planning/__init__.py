"""Protocol planning: predicted accuracy and time of a servo calibration, before running it.

Predictions are the Cramér–Rao bound of :mod:`gyrocal.planning.design` (the first-moment
estimator reaches it, see ``gyrocal study servo-normal``). :func:`suggest` searches a
grid of speeds and revolutions for the shortest protocol that reaches target standard
deviations of the scale factors and biases. The information matrix, the bound and the G-optimal
design of a list of windows are :mod:`.design`.

Layer 5 (self-checks and planning) of docs/architecture.md: imports the package root and layers 1 to 5 only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence, get_args

import numpy as np

from .._validation import positive
from ..choices import DesignName
from ..errors import InputError
from ..models import ScaleBias
from .design import Design, predicted_std

__all__ = ["DesignName", "DESIGN_NAMES", "Plan", "build_design", "predict", "suggest"]

DESIGN_NAMES: tuple[str, ...] = get_args(DesignName)


@dataclass(frozen=True)
class Plan:
    """Predicted accuracy of one protocol.

    Attributes
    ----------
    design : str
        Design name (see :func:`build_design`).
    speed : float
        Turn speed [rad/s].
    revolutions : float
        Revolutions per turn.
    sample_rate : float
        [Hz].
    noise_density : ndarray, shape (3,)
        White-noise density [rad/s/sqrt(Hz)].
    std : ndarray, shape (6,)
        Cramér–Rao standard deviations of ``[kx, ky, kz, bx, by, bz]`` [-, rad/s].
    total_time : float
        Protocol length, turns, static windows and pauses [s].
    """

    design: str
    speed: float
    revolutions: float
    sample_rate: float
    noise_density: np.ndarray
    std: np.ndarray
    total_time: float

    @property
    def max_scale_std(self) -> float:
        return float(self.std[:3].max())

    @property
    def max_bias_std(self) -> float:
        return float(self.std[3:].max())

    def meets(self, target_scale: float | None = None, target_bias: float | None = None) -> bool:
        """Whether every scale std is at most `target_scale` [-] and every bias std at most `target_bias` [rad/s]."""
        return (target_scale is None or self.max_scale_std <= target_scale) and \
            (target_bias is None or self.max_bias_std <= target_bias)


def build_design(name: DesignName, speed: float, *, revolutions: float = 1.0, static_duration: float = 3.0,
                 pause: float = 3.0) -> Design:
    """A named design at `speed` [rad/s] with `revolutions` per turn.

    ``six``: the servo method of Wang et al., Fig. 1, +-x, +-y, +-z, `pause` [s] between turns (not used).
    ``six-static``: the same with each wait recorded as a static window of `static_duration` [s].
    ``twelve``: one turn about each of the 12 face diagonals of the cube.
    """
    axes = ("+x", "-x", "+y", "-y", "+z", "-z")
    if name == "six":
        return Design.from_axes(axes, speed, revolutions=revolutions, pause=pause, name=name)
    if name == "six-static":
        return Design.from_axes(axes, speed, revolutions=revolutions, static_duration=static_duration, name=name)
    if name == "twelve":
        diagonals = [r.axis for r in Design.face_diagonals(speed).rotations]
        return Design.from_axes(diagonals, speed, revolutions=revolutions, pause=pause, name=name)
    raise InputError(f"design={name!r} is not one of {', '.join(DESIGN_NAMES)}")


def _density(noise_density) -> np.ndarray:
    d = np.broadcast_to(np.asarray(noise_density, dtype=float), (3,))
    if not np.all(np.isfinite(d)) or np.any(d <= 0):
        raise InputError(f"{{param}} must be > 0 [rad/s/sqrt(Hz)], got {d.tolist()}", param="noise_density")
    return d


def predict(design: DesignName = "six", *, speed: float, revolutions: float = 1.0, sample_rate: float = 200.0,
            noise_density, model: ScaleBias | None = None, static_duration: float = 3.0,
            pause: float = 3.0) -> Plan:
    """Predict each parameter's standard deviation and the protocol time.

    Parameters
    ----------
    design : {"six", "six-static", "twelve"}
    speed : float
        Turn speed [rad/s].
    revolutions : float
        Revolutions per turn.
    sample_rate : float
        Sampling rate [Hz].
    noise_density : float or array_like of shape (3,)
        White-noise density [rad/s/sqrt(Hz)] (``gyrocal noise`` measures it).
    model : ScaleBias, optional
        Expected true parameters (``k = 1, b = 0`` by default); the bound scales with k^2.
    static_duration, pause : float
        See :func:`build_design` [s].
    """
    fs = positive("sample_rate", sample_rate)
    dens = _density(noise_density)
    d = build_design(design, positive("speed", speed), revolutions=positive("revolutions", revolutions),
                     static_duration=static_duration, pause=pause)
    std = predicted_std(d, model, None, fs, noise_density=dens)
    return Plan(design, float(speed), float(revolutions), fs, dens, np.asarray(std), float(d.total_time))


def suggest(
    *,
    target_scale: float | None = None,
    target_bias: float | None = None,
    max_speed: float,
    noise_density,
    sample_rate: float = 200.0,
    design: DesignName = "six",
    model: ScaleBias | None = None,
    speeds: Sequence[float] | None = None,
    revolutions: Sequence[float] = tuple(range(1, 21)),
    baseline: Plan | None = None,
    **design_options,
) -> Plan | None:
    """The shortest protocol on a grid whose worst scale and bias std reach the targets.

    Parameters
    ----------
    target_scale : float, optional
        Largest acceptable std of any scale factor [-].
    target_bias : float, optional
        Largest acceptable std of any bias [rad/s].
    max_speed : float
        Fastest speed the servo can hold [rad/s].
    noise_density : float or array_like of shape (3,)
        [rad/s/sqrt(Hz)].
    speeds : sequence of float, optional
        Speeds to try [rad/s]; default 20 steps from ``max_speed / 20`` to ``max_speed``.
    revolutions : sequence of float
        Revolutions per turn to try.
    baseline : Plan, optional
        The protocol the user has in mind. A suggestion is never worse than it on a target that
        was set (its std stays at most the baseline's), and, when the baseline meets every
        target, it is shorter than the baseline.

    Returns
    -------
    Plan or None
        None when no grid point reaches the targets (or, with a `baseline` that meets them,
        when none is shorter without giving up accuracy on a target).
    """
    if target_scale is None and target_bias is None:
        raise InputError("give target_scale and/or target_bias: there is nothing to reach otherwise",
                         param="target_scale")
    for name, value in (("target_scale", target_scale), ("target_bias", target_bias)):
        if value is not None:
            positive(name, value)
    top = positive("max_speed", max_speed)
    if baseline is not None:  # never worse than the user's protocol on what the user asked for
        target_scale = None if target_scale is None else min(target_scale, baseline.max_scale_std)
        target_bias = None if target_bias is None else min(target_bias, baseline.max_bias_std)
    grid = np.linspace(top / 20, top, 20) if speeds is None else np.asarray(speeds, dtype=float)
    best: Plan | None = None
    for rev in sorted(revolutions):
        for speed in grid:
            plan = predict(design, speed=float(speed), revolutions=rev, sample_rate=sample_rate,
                           noise_density=noise_density, model=model, **design_options)
            if plan.meets(target_scale, target_bias) and (best is None or plan.total_time < best.total_time):
                best = plan
    if best is not None and baseline is not None and baseline.meets(target_scale, target_bias) \
            and best.total_time >= baseline.total_time:
        return None  # the user's protocol is already the shortest that keeps its accuracy
    return best
