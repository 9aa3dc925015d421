"""matplotlib without pyplot: a headless ``Figure`` and an atomic ``savefig``."""

from __future__ import annotations

import os
from pathlib import Path

from .._atomic import atomic_path
from ..errors import InputError, MissingDependencyError

__all__ = ["check_figure_path", "new_figure", "outside_legend", "plain_ticks", "save_figure"]

_HINT = "plots need matplotlib: pip install 'gyrocal[plot]'"
_FORMATS = ("png", "pdf", "svg")


def new_figure(figsize: tuple[float, float] = (11.0, 7.0), **kwargs):
    """A ``matplotlib.figure.Figure`` bound to the Agg canvas (no GUI, no pyplot state).

    Parameters
    ----------
    figsize : tuple of float
        Width and height [inch].
    **kwargs
        Passed to ``Figure`` (for example ``layout="constrained"``).
    """
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError:
        raise MissingDependencyError(_HINT) from None
    fig = Figure(figsize=figsize, **kwargs)
    FigureCanvasAgg(fig)
    return fig


def check_figure_path(path: str | os.PathLike) -> str:
    """The format of a figure path (png, pdf or svg), refusing other suffixes and unwritable folders.

    Commands call it before writing any output, so a bad plot path fails before a JSON
    file is written.
    """
    fmt = Path(path).suffix.lower().lstrip(".")
    if fmt not in _FORMATS:
        got = Path(path).suffix or "no suffix"
        raise InputError(f"plot path {str(path)!r} must end in .png, .pdf or .svg, got {got!r}")
    folder = next((p for p in Path(path).absolute().parents if p.exists()), None)
    if folder is not None and not os.access(folder, os.W_OK | os.X_OK):
        raise InputError(f"plot path {str(path)!r}: cannot write in {folder}; choose another folder")
    return fmt


def outside_legend(ax, **kwargs):
    """A legend beside the axes, right of them, where it cannot cover data."""
    kwargs.setdefault("fontsize", 8)
    return ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, **kwargs)


def plain_ticks(fig) -> None:
    """Tick labels written out in full: no offset or multiplier text ('+1.7e9', '1e-5') above an axis,
    where it would collide with a left-aligned title."""
    from matplotlib.ticker import ScalarFormatter

    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            fmt = axis.get_major_formatter()
            if isinstance(fmt, ScalarFormatter):
                fmt.set_useOffset(False)
                fmt.set_scientific(False)


def save_figure(fig, path: str | os.PathLike, dpi: int = 110) -> None:
    """Write `fig` to `path` atomically; the format follows the suffix (png, pdf or svg).

    Tick labels are written out (:func:`plain_ticks`) and the saved area includes legends
    placed beside the axes (:func:`outside_legend`).
    """
    fmt = check_figure_path(path)
    plain_ticks(fig)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt, dpi=dpi, bbox_inches="tight")
