"""Allan deviation plot with the three noise figures read off it."""

from __future__ import annotations

import math

import numpy as np

from .figure import new_figure

__all__ = ["allan_deviation_plot", "allan_figure"]


def allan_deviation_plot(ax, report, *, axes: str = "xyz") -> dict:
    """Draw each axis's Allan deviation and the lines its figures were read from.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    report : gyrocal.noise.NoiseReport
    axes : str
        Which axes to draw.

    Returns
    -------
    dict
        ``{"adev": [...], "arw": [...], "rrw": [...], "bias": [...]}`` lists of Line2D.
    """
    from ..noise import BI_FACTOR

    art: dict[str, list] = {"adev": [], "arw": [], "rrw": [], "bias": []}
    tau = report.taus
    for a in ("xyz".index(c) for c in axes):
        color = f"C{a}"
        (line,) = ax.loglog(tau, report.adev[a], color=color, label=f"{'xyz'[a]}")
        art["adev"].append(line)
        (arw,) = ax.loglog(tau, report.arw[a] / np.sqrt(tau), color=color, linestyle=":", linewidth=0.9)
        art["arw"].append(arw)
        if math.isfinite(report.rrw[a]):
            (rrw,) = ax.loglog(tau, report.rrw[a] * np.sqrt(tau / 3.0), color=color, linestyle="--", linewidth=0.9)
            art["rrw"].append(rrw)
        if math.isfinite(report.bias_instability[a]):
            (bias,) = ax.loglog([report.bias_instability_tau[a]], [report.bias_instability[a] * BI_FACTOR],
                                marker="o", color=color, linestyle="none")
            art["bias"].append(bias)
    ax.set_xlabel("averaging time tau [s]")
    ax.set_ylabel("Allan deviation [rad/s]")
    ax.grid(True, which="both", alpha=0.3)
    ax.set_ylim(np.nanmin(report.adev) / 3, np.nanmax(report.adev) * 3)
    ax.legend(title="dotted: ARW (-1/2), dashed: RRW (+1/2), dot: flat minimum", fontsize=7, title_fontsize=7)
    return art


def allan_figure(report, *, title: str = ""):
    """A one-panel figure of :func:`allan_deviation_plot`."""
    fig = new_figure((7.0, 4.8), layout="constrained")
    allan_deviation_plot(fig.subplots(), report)
    fig.suptitle(title, fontsize=10)
    return fig
