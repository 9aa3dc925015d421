"""Pictures of a verification, like Figs. 7-10 of the servo method of Wang et al.

Figs. 7-8 of the paper overlay the raw readings of the calibrated gyro on the reference's
(the rotating axis shows the servo's vibration, the others the mounting misalignment);
Figs. 9-10 overlay the calibrated readings (they coincide, the biases are gone). Here each
figure has one panel per test axis with the reference turned into the test frame, and a
third figure draws the error before and after calibration.
"""

from __future__ import annotations

import numpy as np

from .._arrays import median
from ..errors import InputError
from .calibration import AXIS_COLORS
from .figure import new_figure, outside_legend

__all__ = ["check_stretch", "default_stretch", "error_figure", "overlay_figure", "plot_errors", "plot_overlay"]

_MAX_POINTS = 40_000  # per line; longer stretches are drawn every k-th sample
MEAN_S = 1.0  # running mean of the error figure [s]: noise averages out, bias and scale errors stay
_AXES = ("x", "y", "z")


def default_stretch(t: np.ndarray, reference: np.ndarray, seconds: float = 60.0) -> tuple[float, float]:
    """The whole log when it is short, else the `seconds` [s] with the most motion."""
    if t[-1] - t[0] <= 2.0 * seconds:
        return float(t[0]), float(t[-1])
    energy = np.concatenate([[0.0], np.cumsum(np.sum(reference * reference, axis=1))])
    ends = np.searchsorted(t, t + seconds)
    i = int(np.argmax(energy[ends] - energy[: len(t)]))
    return float(t[i]), float(t[i] + seconds)


def check_stretch(t: np.ndarray, stretch: tuple[float, float] | None) -> None:
    """Refuse a stretch [s] that holds fewer than 2 of the compared samples `t` (before anything is drawn)."""
    _window(t, stretch)


def _window(t: np.ndarray, stretch: tuple[float, float] | None) -> slice:
    if stretch is None:
        return slice(0, len(t))
    lo, hi = np.searchsorted(t, stretch[0]), np.searchsorted(t, stretch[1], side="right")
    if hi - lo < 2:
        raise InputError(f"the stretch {stretch[0]:g}..{stretch[1]:g} s holds fewer than 2 compared samples; the "
                         f"comparison covers {t[0]:g}..{t[-1]:g} s on the test clock")
    step = max(1, (hi - lo) // _MAX_POINTS)
    return slice(lo, hi, step)


def plot_overlay(ax, t, test, reference, axis: int, *, units: str, label: str = "gyro", stretch=None) -> list:
    """One test axis over the reference on it (Figs. 7-10); returns the two lines.

    Parameters
    ----------
    ax : matplotlib Axes
    t : ndarray, shape (n,)
        Test clock times [s].
    test, reference : ndarray, shape (n, 3)
        The gyro's readings and the reference turned into the test frame [units].
    axis : int
        0, 1 or 2.
    units : str
        Rate unit, for the label.
    label : str
        Legend name of the gyro's readings ("raw", "calibrated").
    stretch : (float, float), optional
        Time span to draw [s].
    """
    w = _window(t, stretch)
    gyro, = ax.plot(t[w], test[w, axis], color=AXIS_COLORS[axis], lw=0.8, label=f"{label} {_AXES[axis]}")
    ref, = ax.plot(t[w], reference[w, axis], color="black", lw=0.8, ls="--", label=f"reference {_AXES[axis]}")
    ax.set_ylabel(f"{_AXES[axis]} [{units}]")
    outside_legend(ax)
    return [gyro, ref]


def _running_mean(t: np.ndarray, y: np.ndarray, seconds: float) -> np.ndarray:
    """Centred running mean of `y` over about `seconds` [s] (edges shortened)."""
    n = max(1, int(round(seconds / max(float(median(np.diff(t))), np.finfo(float).tiny))))
    c = np.concatenate([[0.0], np.cumsum(y)])
    lo = np.clip(np.arange(len(y)) - n // 2, 0, len(y))
    hi = np.clip(np.arange(len(y)) + n - n // 2, 0, len(y))
    return (c[hi] - c[lo]) / (hi - lo)


def plot_errors(ax, t, before, after, axis: int, *, units: str, stretch=None, smooth_s: float = MEAN_S) -> list:
    """Error against the reference before (grey) and after (axis colour) calibration, each with its
    running mean over `smooth_s` seconds drawn bold (the systematic part: bias, scale); returns the lines.

    `before` may be None (raw counts without a sensitivity): only the error after is drawn.
    """
    w = _window(t, stretch)
    drawn = [(err, label, style) for err, label, style in (
        (before, "before calibration", {"color": "0.6", "mean": {"color": "0.15", "ls": "--"}}),
        (after, "after calibration", {"color": AXIS_COLORS[axis], "mean": {"color": "black", "ls": "-"}}))
        if err is not None]
    lines = [ax.plot(t[w], err[w, axis], color=style["color"], lw=0.5, alpha=0.6, label=label)[0]
             for err, label, style in drawn]
    # the means go on top of both noisy traces, so the systematic error before calibration stays visible
    lines += [ax.plot(t[w], _running_mean(t, err[:, axis], smooth_s)[w], lw=1.6, zorder=3,
                      label=f"{label}, {smooth_s:g} s mean", **style["mean"])[0] for err, label, style in drawn]
    ax.axhline(0.0, color="black", lw=0.5)
    ax.set_ylabel(f"error {_AXES[axis]} [{units}]")
    outside_legend(ax, fontsize=7)
    return lines


def overlay_figure(series, *, calibrated: bool, stretch=None):
    """Three panels (x, y, z): raw (Figs. 7-8) or calibrated (Figs. 9-10) readings over the reference.

    Parameters
    ----------
    series : gyrocal.verify.VerifySeries
    calibrated : bool
        Draw the calibrated readings (True) or the raw ones (False).
    stretch : (float, float), optional
        Time span [s]; default :func:`default_stretch`.
    """
    data = series.calibrated if calibrated else series.raw
    if data is None:
        raise InputError("the raw readings are counts without a sensitivity; they cannot be drawn over the reference")
    stretch = stretch or default_stretch(series.t, series.reference)
    fig = new_figure((10.0, 7.0), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    for j, ax in enumerate(axes):
        plot_overlay(ax, series.t, data, series.reference, j, units=series.units,
                     label="calibrated" if calibrated else "raw", stretch=stretch)
    axes[-1].set_xlabel("time on the test clock [s]")
    fig.suptitle(("Calibrated" if calibrated else "Raw") + " gyro readings and the reference")
    return fig


def error_figure(series, *, stretch=None):
    """Three panels (x, y, z): the error against the reference before and after calibration."""
    stretch = stretch or default_stretch(series.t, series.reference)
    before = None if series.raw is None else series.raw - series.reference
    after = series.calibrated - series.reference
    fig = new_figure((10.0, 7.0), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    for j, ax in enumerate(axes):
        plot_errors(ax, series.t, before, after, j, units=series.units, stretch=stretch)
    axes[-1].set_xlabel("time on the test clock [s]")
    fig.suptitle("Error against the reference")
    return fig
