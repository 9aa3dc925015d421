"""Figures of the simulation studies (the servo method of Wang et al., Fig. 2, 4, 5 and Table I; the full-temperature-range method, Tables 3-4).

Functions that draw on one ``Axes`` return the artists they made; the ``*_figure``
helpers build a headless ``Figure`` from them.
"""

from __future__ import annotations

from typing import Mapping

import numpy as np

from .figure import new_figure, outside_legend

__all__ = ["error_boxes", "error_box_figure", "mse_vs_speed", "mse_speed_figure", "convergence", "convergence_figure",
           "rms_by_temperature", "rms_by_temperature_figure"]

PARAMS = ("kx", "ky", "kz", "bx", "by", "bz")
_LABELS = {"algorithm1": "Algorithm 1", "lm": "LM", "first-moment": "first moment"}


def _label(ax, xlabel: str, ylabel: str, title: str) -> None:
    """Axis labels, a small title and a log-friendly grid."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=9)
    ax.grid(True, which="both", alpha=0.3)


def error_boxes(ax, errors: np.ndarray, crb_std: np.ndarray | None = None, *, title: str = "") -> dict:
    """Box plot of estimation errors (B, 6), one box per parameter, with +-2 sigma CRB marks.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    errors : ndarray, shape (B, 6)
        ``estimate - truth`` in ``(kx, ky, kz, bx, by, bz)`` order [-, rad/s].
    crb_std : ndarray, shape (6,), optional
        Cramér–Rao standard deviations; drawn as short bars at +-2 sigma.

    Returns
    -------
    dict
        matplotlib's boxplot artists, plus ``"crb"`` (list of Line2D) when drawn.
    """
    art = ax.boxplot(np.asarray(errors), showfliers=False, tick_labels=list(PARAMS))
    art["crb"] = []
    if crb_std is not None:
        x = np.arange(1, 7)
        for sign in (-2.0, 2.0):
            (line,) = ax.plot(x, sign * np.asarray(crb_std), linestyle="none", marker="_", markersize=18,
                              color="tab:red", label="CRB +-2 sigma" if sign > 0 else None)
            art["crb"].append(line)
    ax.axhline(0.0, color="0.6", linewidth=0.8)
    ax.set_title(title, fontsize=9)
    ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
    return art


def error_box_figure(errors: Mapping[tuple[float, str], np.ndarray], crb: Mapping[float, np.ndarray] | None = None,
                     *, title: str = ""):
    """Grid of :func:`error_boxes`: rows are noise levels, columns methods (the servo method of Wang et al., Fig. 2 / 5)."""
    noises = sorted({n for n, _ in errors})
    methods = list(dict.fromkeys(m for _, m in errors))
    fig = new_figure((3.6 * len(methods), 3.0 * len(noises)), layout="constrained")
    axes = np.atleast_2d(fig.subplots(len(noises), len(methods), squeeze=False))
    for i, noise in enumerate(noises):
        for j, method in enumerate(methods):
            error_boxes(axes[i, j], errors[noise, method], None if crb is None else crb.get(noise),
                        title=f"{_LABELS.get(method, method)}, noise {noise:g} rad/s")
        axes[i, 0].set_ylabel("estimate - truth")
    if crb is not None:
        outside_legend(axes[0, -1], fontsize=7)
    fig.suptitle(title, fontsize=10)
    return fig


def mse_vs_speed(ax, speeds, mse: np.ndarray, crb_var: np.ndarray | None = None, *, title: str = "") -> list:
    """MSE of each parameter against servo speed (the servo method of Wang et al., eq. 9, Fig. 4), with the CRB dashed.

    Parameters
    ----------
    speeds : array_like, shape (S,)
        Servo speeds [rad/s].
    mse : ndarray, shape (S, 6)
        Mean squared errors [-, (rad/s)^2].
    crb_var : ndarray, shape (S, 6), optional
        Cramér–Rao variances, drawn dashed in the same colours.
    """
    lines = []
    for j, name in enumerate(PARAMS):
        (line,) = ax.semilogy(speeds, mse[:, j], marker=".", color=f"C{j}", label=name)
        lines.append(line)
        if crb_var is not None:
            (bound,) = ax.semilogy(speeds, crb_var[:, j], linestyle="--", color=f"C{j}", linewidth=0.9)
            lines.append(bound)
    _label(ax, "speed [rad/s]", "MSE", title)
    return lines


def mse_speed_figure(speeds, mse: Mapping[tuple[float, str], np.ndarray], crb: Mapping[float, np.ndarray] | None = None,
                     *, title: str = ""):
    """Rows: methods; columns: noise levels (the servo method of Wang et al., Fig. 4 (a) and (b)); CRB dashed."""
    noises = sorted({n for n, _ in mse})
    methods = list(dict.fromkeys(m for _, m in mse))
    fig = new_figure((5.0 * len(noises), 3.4 * len(methods)), layout="constrained")
    axes = fig.subplots(len(methods), len(noises), squeeze=False)
    for i, method in enumerate(methods):
        for j, noise in enumerate(noises):
            mse_vs_speed(axes[i, j], speeds, mse[noise, method], None if crb is None else crb.get(noise),
                         title=f"{_LABELS.get(method, method)}, noise {noise:g} rad/s")
    outside_legend(axes[0, -1], fontsize=7, ncol=2, title="dashed: CRB" if crb is not None else None, title_fontsize=7)
    fig.suptitle(title, fontsize=10)
    return fig


def convergence(ax, history: np.ndarray, truth: np.ndarray, *, title: str = "") -> list:
    """``|estimate - truth|`` of each parameter against iteration (the servo method of Wang et al., Table I).

    Parameters
    ----------
    history : ndarray, shape (iterations + 1, 6)
        Estimates after each iteration, initial estimate first.
    truth : ndarray, shape (6,)
    """
    err = np.abs(np.asarray(history) - np.asarray(truth))
    lines = []
    for j, name in enumerate(PARAMS):
        (line,) = ax.semilogy(np.arange(len(err)), np.maximum(err[:, j], 1e-12), marker="o", color=f"C{j}",
                              label=name)
        lines.append(line)
    _label(ax, "iteration (0 = initial estimate, beta0 = 0)", "|estimate - truth|", title)
    return lines


def convergence_figure(cases: Mapping[str, tuple[np.ndarray, np.ndarray]], *, title: str = ""):
    """One :func:`convergence` panel per case (``name -> (history, truth)``)."""
    fig = new_figure((4.2 * len(cases), 3.2), layout="constrained")
    axes = fig.subplots(1, len(cases), squeeze=False)[0]
    for ax, (name, (history, truth)) in zip(axes, cases.items()):
        convergence(ax, history, truth, title=name)
    outside_legend(axes[-1], fontsize=7, ncol=2)
    fig.suptitle(title, fontsize=10)
    return fig


def rms_by_temperature(ax, temps, rms: Mapping[str, "np.ndarray"], *, floor: float | None = None,
                       title: str = "") -> list:
    """RMS compensation error against test temperature, one line per method (the full-temperature-range method, Tables 3-4).

    Parameters
    ----------
    temps : array_like, shape (T,)
        Test temperatures [degC].
    rms : mapping of str to array_like, shape (T,)
        RMS error per method [deg/s].
    floor : float, optional
        Noise floor of a test step mean [deg/s], drawn dashed: the study's bound.
    """
    lines = []
    for i, (method, values) in enumerate(rms.items()):
        (line,) = ax.semilogy(temps, values, marker="o", color=f"C{i}", label=method)
        lines.append(line)
    if floor is not None:
        # On top of the lines: the best methods sit right on it.
        lines.append(ax.axhline(floor, linestyle="--", color="k", linewidth=1.0, zorder=3,
                                label=f"noise floor of a step mean, \u03c3/\u221an = {floor:.3g} deg/s"))
    _label(ax, "test temperature [degC]", "RMS step error [deg/s]", title)
    outside_legend(ax, fontsize=7)
    return lines


def rms_by_temperature_figure(temps, rms: Mapping[str, "np.ndarray"], *, floor: float | None = None,
                              title: str = ""):
    """A one-panel figure of :func:`rms_by_temperature`."""
    fig = new_figure((6.5, 4.2), layout="constrained")
    rms_by_temperature(fig.subplots(), temps, rms, floor=floor, title=title)
    return fig
