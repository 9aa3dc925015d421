"""Pictures of a temperature calibration (the full-temperature-range method, Figures 4-9).

* :func:`plot_coefficients`: every Kg element against temperature, with the fitted
  points and their 1-sigma bars, the Lagrange table and the smooth model (Figures 4-6);
* :func:`plot_error_vs_rate`: step error against table rate, one panel per rotating
  axis and gyro axis, one series per compensation (Figures 7-8);
* :func:`plot_error_vs_temperature`: RMS error against test temperature per
  compensation (Figure 9, spread over temperature).
"""

from __future__ import annotations

import warnings

import numpy as np

from ..models import KG_NAMES
from ..units import unit_factor
from .figure import new_figure, outside_legend

__all__ = ["METHOD_STYLE", "plot_coefficients", "plot_error_vs_rate", "plot_error_vs_temperature"]

METHOD_STYLE = {
    "uncompensated": {"color": "0.55", "marker": "x"},
    "traditional": {"color": "tab:orange", "marker": "s"},
    "lagrange": {"color": "tab:blue", "marker": "o"},
    "smooth": {"color": "tab:green", "marker": "^"},
}
_AXES = ("x", "y", "z")


def plot_coefficients(cal, fig=None, *, units: str | None = None, truth=None) -> dict:
    """Kg elements against temperature, 4 x 3 panels in eq. 14 order.

    Parameters
    ----------
    cal : ThermalCalibration
    fig : matplotlib Figure, optional
        Drawn into; a new headless one by default.
    units : {"rad/s", "deg/s"}, optional
        Unit of the biases (default the calibration's output unit).
    truth : callable, optional
        ``truth.kg(temp) -> (N, 12)`` in internal units, drawn dashed (simulations).

    Returns
    -------
    dict
        ``figure``, ``axes`` (12), and lists ``points``, ``lagrange``, ``smooth``, ``truth`` of artists.
    """
    fig = fig if fig is not None else new_figure((13.0, 10.0), layout="constrained")
    unit = units or cal.output_units
    scale = np.ones(12)
    scale[9:] = 1.0 / unit_factor(unit)
    dense = np.linspace(*cal.range, 200)
    lag = cal.kg_at(dense, "lagrange") * scale
    smo = cal.kg_at(dense, "smooth") * scale
    nodes = cal.kg * scale
    err = None if cal.std is None else cal.std * scale
    axes = fig.subplots(4, 3).ravel()
    out = {"figure": fig, "axes": list(axes), "points": [], "lagrange": [], "smooth": [], "truth": []}
    ref = truth.kg(dense) * scale if truth is not None else None
    for j, ax in enumerate(axes):
        out["points"].append(ax.errorbar(cal.temps, nodes[:, j], yerr=None if err is None else err[:, j],
                                         fmt="o", color="k", ms=3, capsize=2, label="fit at each point"))
        out["lagrange"].append(ax.plot(dense, lag[:, j], color="tab:blue", lw=1.2, label="Lagrange")[0])
        out["smooth"].append(ax.plot(dense, smo[:, j], color="tab:green", lw=1.0, ls="--",
                                     label=f"smooth (order {cal.smooth.orders[j]})")[0])
        if ref is not None:
            out["truth"].append(ax.plot(dense, ref[:, j], color="tab:red", lw=0.8, ls=":", label="truth")[0])
        ax.set_title(KG_NAMES[j] + (f" [{unit}]" if j >= 9 else ""), fontsize=9)
        ax.tick_params(labelsize=7)
        ax.ticklabel_format(axis="y", useOffset=False, style="sci", scilimits=(-3, 4))
    for ax in axes[-3:]:
        ax.set_xlabel("temperature [degC]", fontsize=8)
    outside_legend(axes[0], fontsize=7)
    fig.suptitle("Kg elements against temperature (the full-temperature-range method, eq. 14)")
    return out


def plot_error_vs_rate(evaluation, fig=None, *, units: str = "deg/s", methods=None) -> dict:
    """Step error against table rate: rows = rotating axis, columns = gyro axis.

    Returns
    -------
    dict
        ``figure``, ``axes`` (3 x 3 array) and ``series``: {method: [artists]}.
    """
    fig = fig if fig is not None else new_figure((13.0, 10.0), layout="constrained")
    f = unit_factor(units)
    methods = list(methods or evaluation.errors)
    steps = evaluation.steps
    axes = fig.subplots(3, 3, squeeze=False)
    series = {m: [] for m in methods}
    for a in range(3):
        sel = steps.axis == a
        for j in range(3):
            ax = axes[a, j]
            for m in methods:
                st = METHOD_STYLE.get(m, {})
                series[m].append(ax.plot(steps.rate[sel] / f, evaluation.errors[m][sel, j] / f, ls="none", ms=3,
                                         alpha=0.7, label=m, **st)[0])
            ax.set_title(f"{_AXES[j]} gyro error, {_AXES[a]} axis rotating", fontsize=9)
            ax.axhline(0, color="0.8", lw=0.6, zorder=0)
            ax.tick_params(labelsize=7)
            if a == 2:
                ax.set_xlabel(f"table rate [{units}]", fontsize=8)
            if j == 0:
                ax.set_ylabel(f"error [{units}]", fontsize=8)
    outside_legend(axes[0, 0], fontsize=7)
    return {"figure": fig, "axes": axes, "series": series}


def plot_error_vs_temperature(evaluation, ax=None, *, units: str = "deg/s", methods=None, log: bool = True) -> dict:
    """RMS step error (all axes and rates) against test temperature, one line per method.

    Returns
    -------
    dict
        ``figure``, ``ax`` and ``lines``: {method: Line2D}.
    """
    if ax is None:
        fig = new_figure((7.0, 4.5), layout="constrained")
        ax = fig.add_subplot()
    rows = evaluation.by_temperature(units)
    temps = np.array([r["temp"] for r in rows])
    lines = {}
    for m in methods or evaluation.errors:
        y = np.array([r[f"{m}_rms"] for r in rows])
        lines[m] = ax.plot(temps, y, label=m, **METHOD_STYLE.get(m, {}))[0]
    if log:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # zero errors in noise-free data
            ax.set_yscale("log")
    ax.set_xlabel("temperature [degC]")
    ax.set_ylabel(f"RMS error [{units}]")
    ax.set_title("RMS step error against temperature")
    outside_legend(ax, fontsize=8)
    return {"figure": ax.figure, "ax": ax, "lines": lines}
