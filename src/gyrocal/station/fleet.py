"""Fleet statistics: how the units calibrated so far are distributed, how capable the process is, how it drifts.

Pure functions on store records (anything with ``serial``, ``created``, ``station``, ``verdict`` and
``document``) and on calibration documents. Each parameter's value is taken in the unit of its limit
(the ``--limits`` file's, else the records' own acceptance sections'), else in the document's
internal unit. The affine model's diagonal ``Kxx``/``Bx`` are named ``kx``/``bx``, as acceptance does.

References (each formula is written where it is used):

* Montgomery, *Introduction to Statistical Quality Control*, 6th ed. (Wiley 2009): Cp and Cpk
  (section 8.3), the chi-square interval of Cp (eq. 8.19), the individuals and moving-range chart
  (section 6.4, d2 = 1.128 for moving ranges of two).
* Bissell, "How reliable is your capability index?", Applied Statistics 39(3), 331-340 (1990): the
  normal approximation to the sampling distribution of Cpk.
* Wilson, "Probable inference, the law of succession, and statistical inference", JASA 22, 209-212
  (1927): the score interval of a proportion.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InputError
from .asfound import parameter_values
from .limits import PARAMETERS, UNITS, Limits

__all__ = ["D2", "Spec", "capability", "drift_ranking", "fleet_statistics", "imr_limits", "newest_first",
           "spec_limits", "unit_values", "wilson"]

#: d2 of moving ranges of two consecutive points: E|X1 - X2| = d2 sigma = (2 / sqrt(pi)) sigma = 1.128 sigma.
D2 = 1.128
_AXES = "xyz"


@dataclass(frozen=True)
class Spec:
    """A parameter's specification limits [low, high] in `unit` (+-inf where unset); `scale` internal per unit."""

    low: float
    high: float
    unit: str
    scale: float


def _family(name: str) -> str:
    """The limits' parameter that judges value `name` (kx -> k, bz -> b, Kyx -> misalignment)."""
    return name[0] if len(name) == 2 and name[0] in "kb" else "misalignment"


def unit_values(doc: dict) -> dict[str, tuple[float, float]]:
    """``name -> (value, 1-sigma)`` of a calibration document (internal units), affine diagonal as kx/bx."""
    out = {}
    for name, pair in parameter_values(doc).items():
        if len(name) == 3 and name[0] == "K" and name[1] == name[2]:
            name = f"k{name[1]}"
        elif len(name) == 2 and name[0] == "B":
            name = f"b{name[1]}"
        out[name] = pair
    return out


def newest_first(records) -> list:
    """`records` ordered newest first (by creation time, then id), as the store orders a history."""
    return sorted(records, key=lambda r: (r.created, r.id), reverse=True)


def spec_limits(records, limits: Limits | None = None) -> dict[str, Spec]:
    """Each value's limits: from `limits` when given, else from the newest record's acceptance that judged it."""
    names = sorted({n for r in records for n in unit_values(r.document)})
    if limits is not None:
        bounds = {b.parameter: b for b in limits.bounds}
        out = {}
        for n in names:
            b = bounds.get(_family(n))
            if b is not None:
                out[n] = Spec(*b.interval(), b.unit, b.scale)
        return out
    out = {}
    for r in newest_first(records):
        for c in (r.document.get("acceptance") or {}).get("criteria") or []:
            name, unit = c.get("name"), c.get("unit")
            if name not in names or name in out or unit is None:
                continue
            scale = UNITS[PARAMETERS[_family(name)][0]].get(unit)
            if scale is not None:
                low, high = c.get("low"), c.get("high")
                out[name] = Spec(-math.inf if low is None else low, math.inf if high is None else high, unit, scale)
    return out


def capability(values, low: float, high: float, confidence: float = 0.95) -> dict:
    """n, mean, sd (sample, n - 1) and Cp, Cpk with two-sided intervals at `confidence`.

    Cp = (USL - LSL) / (6 s) needs both limits; Cpk = min(USL - mean, mean - LSL) / (3 s) takes the
    limits that are set. Intervals (normal data):

    * Cp (Montgomery eq. 8.19): (n-1) s^2 / sigma^2 is chi-square with n-1 degrees of freedom, so
      Cp_hat sqrt(chi2_{a/2, n-1} / (n-1)) <= Cp <= Cp_hat sqrt(chi2_{1-a/2, n-1} / (n-1)).
    * Cpk (Bissell 1990): Cpk_hat is approximately normal with standard error
      sqrt(1 / (9 n) + Cpk_hat^2 / (2 (n - 1))), so Cpk_hat -+ z_{1-a/2} times that.
    """
    import numpy as np
    from scipy import stats

    x = np.asarray(values, dtype=float)
    n = int(x.size)
    mean = float(x.mean()) if n else math.nan
    sd = float(x.std(ddof=1)) if n > 1 else math.nan
    out = {"n": n, "mean": mean, "sd": sd, "cp": None, "cp_ci": None, "cpk": None, "cpk_ci": None}
    if n < 2 or not sd > 0:
        return out
    alpha = 1.0 - confidence
    if math.isfinite(low) and math.isfinite(high):
        cp = (high - low) / (6.0 * sd)
        chi = stats.chi2.ppf([alpha / 2, 1 - alpha / 2], n - 1)
        out["cp"], out["cp_ci"] = cp, [float(cp * math.sqrt(q / (n - 1))) for q in chi]
    sides = [d for d in (high - mean, mean - low) if math.isfinite(d)]
    if sides:
        cpk = min(sides) / (3.0 * sd)
        half = float(stats.norm.ppf(1 - alpha / 2)) * math.sqrt(1 / (9 * n) + cpk ** 2 / (2 * (n - 1)))
        out["cpk"], out["cpk_ci"] = cpk, [cpk - half, cpk + half]
    return out


def wilson(passed: int, n: int, confidence: float = 0.95) -> dict:
    """Yield passed / n with Wilson's score interval (Wilson 1927):
    (p + z^2/(2n) -+ z sqrt(p (1 - p) / n + z^2 / (4 n^2))) / (1 + z^2 / n)."""
    from scipy import stats

    if n == 0:
        return {"passed": 0, "n": 0, "yield": None, "ci": None}
    z = float(stats.norm.ppf(0.5 + confidence / 2))
    p = passed / n
    centre, den = p + z * z / (2 * n), 1 + z * z / n
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return {"passed": passed, "n": n, "yield": p, "ci": [(centre - half) / den, (centre + half) / den]}


def imr_limits(values) -> dict:
    """Individuals chart (Montgomery section 6.4): centre line the mean, limits mean -+ 3 MR_bar / d2,
    MR_bar the mean moving range |x_i - x_{i-1}| and d2 = 1.128 (ranges of two points)."""
    x = [float(v) for v in values]
    mr = [abs(b - a) for a, b in zip(x, x[1:])]
    centre = sum(x) / len(x) if x else math.nan
    if not mr:
        return {"centre": centre, "mr_bar": None, "lcl": None, "ucl": None, "out": []}
    mr_bar = sum(mr) / len(mr)
    lcl, ucl = centre - 3 * mr_bar / D2, centre + 3 * mr_bar / D2
    return {"centre": centre, "mr_bar": mr_bar, "lcl": lcl, "ucl": ucl,
            "out": [i for i, v in enumerate(x) if v < lcl or v > ucl]}


def drift_ranking(records, top: int = 10) -> list[dict]:
    """The units whose parameters changed most between their two latest calibrations, in the 1-sigma of
    the change: z = (new - old) / sqrt(sigma_new^2 + sigma_old^2); a unit ranks by its largest |z|."""
    by_unit: dict[str, list] = {}
    for r in newest_first(records):
        by_unit.setdefault(r.serial, []).append(r)
    rows = []
    for serial, recs in by_unit.items():
        if len(recs) < 2:
            continue
        new, old = unit_values(recs[0].document), unit_values(recs[1].document)
        z = {n: (new[n][0] - old[n][0]) / math.hypot(new[n][1], old[n][1]) for n in new
             if n in old and math.hypot(new[n][1], old[n][1]) > 0}
        z = {n: v for n, v in z.items() if math.isfinite(v)}
        if z:
            worst = max(z, key=lambda n: abs(z[n]))
            rows.append({"serial": serial, "parameter": worst, "z": z[worst], "changes": z,
                         "new": _stamp(recs[0]), "old": _stamp(recs[1])})
    rows.sort(key=lambda row: -abs(row["z"]))
    return rows[:top]


def _stamp(record) -> str:
    return record.created.strftime("%Y-%m-%dT%H:%M:%SZ")


def _yields(calibrations, confidence: float) -> dict:
    """Yield of the records with a verdict, overall and per station."""
    judged = [r for r in calibrations if r.verdict in ("pass", "fail")]
    stations = sorted({r.station or "-" for r in judged})
    per = {s: wilson(sum(r.verdict == "pass" for r in judged if (r.station or "-") == s),
                     sum((r.station or "-") == s for r in judged), confidence) for s in stations}
    return {"overall": wilson(sum(r.verdict == "pass" for r in judged), len(judged), confidence), "stations": per}


def _criterion_yield(newest, name: str, confidence: float) -> dict:
    verdicts = [c.get("verdict") for r in newest for c in (r.document.get("acceptance") or {}).get("criteria") or []
                if c.get("name") == name and c.get("verdict") in ("pass", "fail")]
    return wilson(verdicts.count("pass"), len(verdicts), confidence)


def _parameter(name: str, calibrations, newest, spec: Spec | None, confidence: float) -> dict:
    """Everything about one parameter: values per unit, capability, yield of its criterion, control charts."""
    scale, unit = (spec.scale, spec.unit) if spec else (1.0, "internal")
    per_unit = [(r.serial, unit_values(r.document)[name][0] / scale) for r in newest if name in unit_values(r.document)]
    low, high = (spec.low, spec.high) if spec else (-math.inf, math.inf)
    charts = {}
    for r in sorted(calibrations, key=lambda r: (r.created, r.id)):
        v = unit_values(r.document).get(name)
        if v is not None:
            charts.setdefault(r.station or "-", {"times": [], "serials": [], "values": []})
            chart = charts[r.station or "-"]
            chart["times"].append(_stamp(r))
            chart["serials"].append(r.serial)
            chart["values"].append(v[0] / scale)
    for chart in charts.values():
        chart.update(imr_limits(chart["values"]))
    return {"name": name, "unit": unit, "low": low if math.isfinite(low) else None,
            "high": high if math.isfinite(high) else None, "serials": [s for s, _ in per_unit],
            "values": [v for _, v in per_unit], **capability([v for _, v in per_unit], low, high, confidence),
            "yield": _criterion_yield(newest, name, confidence), "control": dict(sorted(charts.items()))}


def _order(name: str) -> tuple:
    return ({"k": 0, "b": 1}.get(name[0], 2), name)


def fleet_statistics(records, limits: Limits | None = None, confidence: float = 0.95, top: int = 10) -> dict:
    """The fleet's statistics from calibration `records` (each unit's newest for the distributions).

    Raises :class:`InputError` when no record holds calibration parameters.
    """
    if not 0 < confidence < 1:
        raise InputError(f"the confidence must lie between 0 and 1, got {confidence:g}")
    calibrations = [r for r in records if unit_values(r.document or {})]
    if not calibrations:
        raise InputError("none of the records holds calibration parameters (scale_bias or affine)")
    newest = list({r.serial: r for r in reversed(newest_first(calibrations))}.values())
    newest.sort(key=lambda r: r.serial)
    specs = spec_limits(calibrations, limits)
    names = sorted({n for r in newest for n in unit_values(r.document)}, key=_order)
    return {"confidence": confidence, "records": len(calibrations), "units": len(newest),
            "limits": limits.source if limits is not None else ("records' acceptance" if specs else None),
            "yield": _yields(calibrations, confidence),
            "parameters": [_parameter(n, calibrations, newest, specs.get(n), confidence) for n in names],
            "drift": drift_ranking(calibrations, top)}
