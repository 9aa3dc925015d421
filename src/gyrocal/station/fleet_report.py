"""The fleet report: figures per parameter and ``fleet.md``, all written or none (:func:`write_report`)."""

from __future__ import annotations

from pathlib import Path

__all__ = ["SUMMARY", "markdown", "write_report"]

#: The summary's file name inside the report folder.
SUMMARY = "fleet.md"


def _num(x, fmt: str = ".4g") -> str:
    return "-" if x is None else format(x, fmt)


def _ci(value, ci, fmt: str = ".3g") -> str:
    return "-" if value is None else f"{value:{fmt}} [{ci[0]:{fmt}}, {ci[1]:{fmt}}]"


def _yield(y: dict) -> str:
    return "-" if y["n"] == 0 else f"{y['passed']}/{y['n']} = {_ci(y['yield'], y['ci'], '.3f')}"


def _parameter_table(stats: dict) -> list[str]:
    lines = ["| parameter | unit | LSL | USL | n | mean | sd | Cp | Cpk | yield |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for p in stats["parameters"]:
        lines.append(f"| {p['name']} | {p['unit']} | {_num(p['low'])} | {_num(p['high'])} | {p['n']} | "
                     f"{_num(p['mean'], '.6g')} | {_num(p['sd'], '.3g')} | {_ci(p['cp'], p['cp_ci'])} | "
                     f"{_ci(p['cpk'], p['cpk_ci'])} | {_yield(p['yield'])} |")
    return lines


def _drift_table(stats: dict) -> list[str]:
    if not stats["drift"]:
        return ["No unit has two calibrations."]
    lines = ["| unit | parameter | change [sigma] | latest | previous |", "|---|---|---|---|---|"]
    lines += [f"| {d['serial']} | {d['parameter']} | {d['z']:+.2f} | {d['new']} | {d['old']} |" for d in stats["drift"]]
    return lines


def markdown(stats: dict, figures: dict[str, tuple[str, str]]) -> str:
    """The summary: yields, the parameter table, the drifted units, and links to the figures."""
    level = f"{100 * stats['confidence']:g}%"
    y = stats["yield"]
    out = ["# Fleet report", "",
           f"{stats['units']} unit(s), {stats['records']} calibration record(s); each unit's newest calibration "
           f"for the distributions. Limits: {stats['limits'] or 'none'}. Intervals: {level} (Cp chi-square, Cpk "
           "Bissell, yield Wilson score).", "", "## Yield (records with a verdict)", "",
           "| station | yield |", "|---|---|", f"| all | {_yield(y['overall'])} |"]
    out += [f"| {s} | {_yield(v)} |" for s, v in y["stations"].items()]
    out += ["", "## Parameters", "", *_parameter_table(stats), "",
            "## Largest drift between a unit's two latest calibrations", "", *_drift_table(stats), "", "## Figures", ""]
    for name, (hist, control) in figures.items():
        out += [f"### {name}", "", f"![{name} distribution]({hist})", "", f"![{name} control chart]({control})", ""]
    return "\n".join(out)


def write_report(stats: dict, folder: str | Path) -> list[Path]:
    """Write each parameter's histogram and control chart (PNG) and :data:`SUMMARY` into `folder`.

    Everything is drawn into a temporary folder first, so a failure leaves `folder` as it was.
    Returns the paths written.
    """
    from .._atomic import atomic_folder
    from ..plotting.figure import save_figure
    from ..plotting.fleet import control_figure, histogram_figure

    figures = {}
    with atomic_folder(folder) as tmp:
        for p in stats["parameters"]:
            names = (f"fleet_{p['name']}_histogram.png", f"fleet_{p['name']}_control.png")
            save_figure(histogram_figure(p), tmp / names[0])
            save_figure(control_figure(p), tmp / names[1])
            figures[p["name"]] = names
        (tmp / SUMMARY).write_text(markdown(stats, figures) + "\n", encoding="utf-8")
        written = sorted(p.name for p in tmp.iterdir())
    return [Path(folder) / name for name in written]
