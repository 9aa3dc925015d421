"""The calibration picture: raw signal with its windows, above the corrected signal.

A person should see at a glance whether segmentation found the right turns (shaded,
labelled ``+x``, ``-y``, ... and ``static``) and whether the correction brings every
turn to the reference (each turn is annotated with its corrected angle or rate).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..recording import Recording
from ..results.calibration import Calibration
from ..segmentation.windows import Window
from ..units import RATE_UNITS, from_rad_s
from .figure import new_figure, outside_legend

__all__ = ["calibration_figure", "display_rates", "plot_corrected", "plot_windows"]

AXIS_COLORS = ("tab:red", "tab:green", "tab:blue")
_SPAN_COLORS = {"x": "tab:red", "y": "tab:green", "z": "tab:blue", None: "0.5"}
_MAX_POINTS = 20_000


def _envelope(t: np.ndarray, y: np.ndarray, max_points: int = _MAX_POINTS) -> tuple[np.ndarray, np.ndarray]:
    """Min/max per block, so long recordings draw fast and keep their spikes."""
    n = len(t)
    block = math.ceil(n / (max_points // 2)) if n > max_points else 1
    if block == 1:
        return t, y
    m = (n // block) * block
    yb = y[:m].reshape(-1, block, *y.shape[1:])
    tb = t[:m].reshape(-1, block)
    lo, hi = yb.min(axis=1), yb.max(axis=1)
    tt = np.repeat(tb[:, [0, -1]].mean(axis=1), 2)
    yy = np.stack([lo, hi], axis=1).reshape(-1, *y.shape[1:])
    return tt, yy


def display_rates(rec: Recording, units: str | None = None) -> tuple[np.ndarray, str]:
    """Readings of `rec` in a unit people read, and that unit's name.

    Parameters
    ----------
    rec : Recording
    units : {"rad/s", "deg/s"}, optional
        Default: the unit the data were declared in (raw counts stay counts).
    """
    if rec.units == "counts":
        return np.asarray(rec.gyro), "counts"
    unit = units or (rec.source_units if rec.source_units in RATE_UNITS else "deg/s")
    return from_rad_s(rec.gyro, unit), unit


def _label(w: Window) -> str:
    if w.kind == "static":
        return "static"
    sense = {1: "+", -1: "\u2212"}.get(int(w.sign), "")
    return f"{sense}{w.axis or '?'}"


def _time(rec: Recording) -> np.ndarray:
    """Time since the first sample [s]: epoch stamps (1.7e9 s) would put '+1.7e9' under the axis."""
    return np.asarray(rec.t) - float(rec.t[0])


def _shade(ax, rec: Recording, windows: Sequence[Window], *, text: Sequence[str] | None = None) -> tuple[list, list]:
    """One shaded span per window with a label at the top; returns (spans, texts)."""
    t = _time(rec)
    spans, texts = [], []
    trans = ax.get_xaxis_transform()
    for i, w in enumerate(windows):
        t0, t1 = t[w.start], t[min(w.stop, len(t)) - 1]
        color = _SPAN_COLORS.get(w.axis if w.kind == "rotation" else None, "0.5")
        spans.append(ax.axvspan(t0, t1, color=color, alpha=0.10 if w.kind == "rotation" else 0.07, lw=0))
        label = _label(w) if text is None else text[i]
        texts.append(
            ax.text((t0 + t1) / 2, 0.98, label, transform=trans, ha="center", va="top", fontsize=8,
                    color="0.25" if w.kind == "static" else color, rotation=90 if w.kind == "static" else 0)
        )
    return spans, texts


def _mark_ignored(ax, rec: Recording, ignored) -> tuple[list, list]:
    """Each turn left out as a hatched span, with the reason (up to its first colon) along its foot."""
    t = _time(rec)
    spans, texts = [], []
    trans = ax.get_xaxis_transform()
    for w, why in ignored:
        if w.kind != "rotation":
            continue
        t0, t1 = t[w.start], t[min(w.stop, len(t)) - 1]
        spans.append(ax.axvspan(t0, t1, facecolor="none", edgecolor="0.55", hatch="///", lw=0))
        texts.append(ax.text((t0 + t1) / 2, 0.02, f"ignored: {why.split(':')[0]}", transform=trans, ha="center",
                             va="bottom", fontsize=7, color="0.3", rotation=90))
    return spans, texts


def plot_windows(ax, rec: Recording, windows: Sequence[Window], *, units: str | None = None,
                 ignored=()) -> dict[str, list]:
    """Draw the raw readings with each window shaded and labelled.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    rec : Recording
    windows : sequence of Window
        Rotation windows are tinted by their axis and labelled ``+x``, ``-y``...;
        static windows are grey.
    units : {"rad/s", "deg/s"}, optional
        Display unit (default: the data's own).
    ignored : sequence of (Window, str), optional
        Turns left out and why (``Segmentation.ignored``): hatched and labelled with the reason.

    Returns
    -------
    dict
        ``lines`` (three Line2D), ``spans`` and ``labels`` (one per window), ``ignored`` and
        ``reasons`` (one per turn left out).
    """
    rates, unit = display_rates(rec, units)
    tt, yy = _envelope(_time(rec), rates)
    lines = [ax.plot(tt, yy[:, i], color=AXIS_COLORS[i], lw=0.7, label=f"g{'xyz'[i]}")[0] for i in range(3)]
    spans, texts = _shade(ax, rec, windows)
    hatched, reasons = _mark_ignored(ax, rec, ignored)
    ax.set_ylabel(f"raw [{unit}]")
    outside_legend(ax)
    ax.grid(True, lw=0.3, alpha=0.5)
    return {"lines": lines, "spans": spans, "labels": texts, "ignored": hatched, "reasons": reasons}


def _turn_summary(corrected: np.ndarray, rec: Recording, w: Window, speed: float | None, unit: str) -> str:
    """Corrected angle of a turn [deg], or its rate when the speed is the reference.

    Both come from the norm of the window mean, the quantity the first-moment
    equations fix (``|A (m_mean - o)| = angle / T``), not from the mean of norms,
    which noise and a wandering hand-turn axis inflate.
    """
    rate = float(np.linalg.norm(corrected[w.start:w.stop].mean(axis=0)))
    if speed is not None:
        return f"{rate:.2f}"
    angle = rate * (w.stop - w.start) / rec.sample_rate  # same duration as observe(): count / fs
    return f"{math.degrees(angle) if unit == 'rad/s' else angle:.1f}\u00b0"


def plot_corrected(ax, rec: Recording, cal: Calibration, windows: Sequence[Window] = (), *,
                   speed: float | None = None) -> dict[str, list]:
    """Draw the corrected rates; annotate each turn with what the reference fixes.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    rec : Recording
        In the calibration's internal units.
    cal : Calibration
    windows : sequence of Window
        Rotation windows are annotated with their corrected angle [deg] (or, with
        `speed`, their corrected mean rate), static windows with ``|mean|``, the bias left.
    speed : float, optional
        Known turn rate [rad/s]; drawn as dashed lines at +-speed.

    Returns
    -------
    dict
        ``lines``, ``spans``, ``labels`` and ``reference`` (the +-speed lines, or empty).
    """
    w_out = from_rad_s(cal.model.correct(rec.gyro), cal.output_units)
    unit = cal.output_units
    tt, yy = _envelope(_time(rec), w_out)
    lines = [ax.plot(tt, yy[:, i], color=AXIS_COLORS[i], lw=0.7)[0] for i in range(3)]
    text = [_turn_summary(w_out, rec, w, speed, unit) if w.kind == "rotation"
            else f"{np.linalg.norm(w_out[w.start:w.stop].mean(axis=0)):.2g}" for w in windows]
    spans, texts = _shade(ax, rec, windows, text=text)
    reference = []
    if speed is not None:
        level = float(from_rad_s(speed, unit))
        reference = [ax.axhline(s * level, color="0.3", ls="--", lw=0.8) for s in (1, -1)]
    what = (f"|mean w| per turn [{unit}]" if speed is not None else "|mean w| x duration per turn") + \
        f"; |mean w| at rest [{unit}]"
    ax.set_ylabel(f"corrected [{unit}]")
    ax.set_title(f"corrected ({cal.method}); numbers: {what}", fontsize=9, loc="left")
    ax.grid(True, lw=0.3, alpha=0.5)
    return {"lines": lines, "spans": spans, "labels": texts, "reference": reference}


def calibration_figure(rec: Recording, windows: Sequence[Window], cal: Calibration | None = None, *,
                       fig=None, speed: float | None = None, title: str | None = None, ignored=()):
    """Raw readings with windows on top, corrected readings below (when `cal` is given).

    Parameters
    ----------
    rec : Recording
    windows : sequence of Window
        The windows used.
    cal : Calibration, optional
        Without it, only the raw panel is drawn (what ``gyrocal segments`` shows).
    fig : matplotlib.figure.Figure, optional
        Drawn into; a new headless figure otherwise.
    speed : float, optional
        Known turn rate [rad/s].
    title : str, optional
    ignored : sequence of (Window, str), optional
        Turns left out and why, marked on the raw panel (``gyrocal segments --plot``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    rows = 1 if cal is None else 2
    if fig is None:
        fig = new_figure((11.0, 3.6 * rows + 0.6), layout="constrained")
    axes = fig.subplots(rows, 1, sharex=True, squeeze=False)[:, 0]
    plot_windows(axes[0], rec, windows, ignored=ignored)
    n_rot = sum(w.kind == "rotation" for w in windows)
    axes[0].set_title(f"raw with windows: {n_rot} rotation, {len(windows) - n_rot} static", fontsize=9, loc="left")
    if cal is not None:
        plot_corrected(axes[1], rec, cal, windows, speed=speed)
    axes[-1].set_xlabel("time since the first sample [s]")
    if title:
        fig.suptitle(title, fontsize=10)
    return fig
