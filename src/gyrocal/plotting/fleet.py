"""Fleet figures: a parameter's distribution across units with its limits, and its control charts per station."""

from __future__ import annotations

from datetime import datetime

from .figure import new_figure, outside_legend

__all__ = ["control_figure", "histogram_figure"]


def _label(p: dict) -> str:
    return p["name"] if p["unit"] in ("internal", "1") else f"{p['name']} [{p['unit']}]"


def histogram_figure(p: dict):
    """Histogram of one parameter's values (each unit's newest calibration), its mean and its limits.

    `p` is one entry of :func:`gyrocal.station.fleet.fleet_statistics`'s ``parameters``.
    """
    fig = new_figure((7.0, 4.0), layout="constrained")
    ax = fig.subplots()
    ax.hist(p["values"], bins=max(5, min(30, len(p["values"]) // 2)), color="C0", alpha=0.75,
            label=f"{p['n']} unit(s)")
    ax.axvline(p["mean"], color="k", linewidth=1.0, label="mean")
    for key, text in (("low", "LSL"), ("high", "USL")):
        if p[key] is not None:
            ax.axvline(p[key], color="C3", linestyle="--", linewidth=1.2, label=f"{text} {p[key]:g}")
    cp, cpk = p["cp"], p["cpk"]
    ax.set_title(f"{p['name']}: Cp {'-' if cp is None else f'{cp:.2f}'}, "
                 f"Cpk {'-' if cpk is None else f'{cpk:.2f}'}", fontsize=10, loc="left")
    ax.set_xlabel(_label(p))
    ax.set_ylabel("units")
    outside_legend(ax)
    return fig


def control_figure(p: dict):
    """Individuals chart of one parameter per station: values over time, centre line, mean -+ 3 MR_bar / d2."""
    stations = list(p["control"].items())
    fig = new_figure((8.0, 2.6 * len(stations) + 0.6), layout="constrained")
    axes = fig.subplots(len(stations), 1, squeeze=False, sharex=True)[:, 0]
    for ax, (station, chart) in zip(axes, stations):
        times = [datetime.fromisoformat(t.replace("Z", "+00:00")) for t in chart["times"]]
        ax.plot(times, chart["values"], marker="o", markersize=3, linewidth=0.8, color="C0", label="value")
        ax.axhline(chart["centre"], color="k", linewidth=1.0, label="centre (mean)")
        if chart["ucl"] is not None:
            for key in ("lcl", "ucl"):
                ax.axhline(chart[key], color="C3", linestyle="--", linewidth=1.0,
                           label="mean -+ 3 MR/1.128" if key == "ucl" else None)
            out = chart["out"]
            ax.plot([times[i] for i in out], [chart["values"][i] for i in out], "o", color="C3", markersize=6,
                    fillstyle="none", label="outside" if out else None)
        ax.set_title(f"station {station}: {len(times)} calibration(s)", fontsize=9, loc="left")
        ax.set_ylabel(_label(p))
        ax.grid(True, alpha=0.3)
        outside_legend(ax)
    fig.autofmt_xdate()
    return fig
