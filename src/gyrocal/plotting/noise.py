"""Allan deviation plots with the three noise figures read off them."""

from __future__ import annotations

import math

import numpy as np

from ..units import STANDARD_GRAVITY
from .figure import new_figure, outside_legend

__all__ = ["allan_deviation_plot", "allan_figure"]

#: Factor from internal units to a displayed unit, and its label.
_DISPLAY = {"rad/s": (1.0, "rad/s"), "deg/s": (180.0 / math.pi, "deg/s"), "m/s^2": (1.0, "m/s^2"),
            "g": (1.0 / STANDARD_GRAVITY, "g")}


def allan_deviation_plot(ax, sensor, *, axes: str = "xyz", unit: str | None = None) -> dict:
    """Draw each axis's Allan deviation and the lines its figures were read from.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    sensor : gyrocal.noise.SensorNoise
    axes : str
        Which axes to draw.
    unit : str, optional
        Displayed unit (``rad/s``, ``deg/s`` for a gyro; ``m/s^2``, ``g`` for an
        accelerometer); default: the internal unit.

    Returns
    -------
    dict
        ``{"adev": [...], "density": [...], "random_walk": [...], "bias": [...]}`` lists of Line2D.
    """
    from ..noise import BI_FACTOR

    factor, label = _DISPLAY[unit or sensor.unit]
    art: dict[str, list] = {"adev": [], "density": [], "random_walk": [], "bias": []}
    tau = sensor.taus
    for a in ("xyz".index(c) for c in axes):
        color = f"C{a}"
        (line,) = ax.loglog(tau, sensor.adev[a] * factor, color=color, label=f"{'xyz'[a]}")
        art["adev"].append(line)
        (dens,) = ax.loglog(tau, factor * sensor.density.value[a] / np.sqrt(tau), color=color, linestyle=":",
                            linewidth=0.9)
        art["density"].append(dens)
        if math.isfinite(sensor.random_walk.value[a]):
            (rw,) = ax.loglog(tau, factor * sensor.random_walk.value[a] * np.sqrt(tau / 3.0), color=color,
                              linestyle="--", linewidth=0.9)
            art["random_walk"].append(rw)
        if math.isfinite(sensor.bias_instability.value[a]):
            floor = factor * sensor.bias_instability.value[a] * BI_FACTOR
            (bias,) = ax.loglog([sensor.bias_instability.tau[a]], [floor], marker="o", color=color, linestyle="none")
            art["bias"].append(bias)
    ax.set_xlabel("averaging time tau [s]")
    ax.set_ylabel(f"{sensor.kind} Allan deviation [{label}]")
    ax.grid(True, which="both", alpha=0.3)
    shown = sensor.adev[:3] * factor
    ax.set_ylim(np.nanmin(shown) / 3, np.nanmax(shown) * 3)
    outside_legend(ax, title="dotted: density (-1/2)\ndashed: random walk (+1/2)\ndot: flat minimum", fontsize=7,
                   title_fontsize=7)
    return art


def allan_figure(report, *, title: str = ""):
    """One panel per sensor (gyro, then accelerometer when logged), in the units the data came in."""
    panels = [(report.gyro, report.source.get("gyro_units"))]
    if report.accel is not None:
        panels.append((report.accel, report.source.get("accel_units")))
    fig = new_figure((7.0, 4.2 * len(panels)), layout="constrained")
    for ax, (sensor, unit) in zip(np.atleast_1d(fig.subplots(len(panels), 1)), panels):
        allan_deviation_plot(ax, sensor, unit=unit if unit in _DISPLAY else None)
    fig.suptitle(title, fontsize=10)
    return fig
