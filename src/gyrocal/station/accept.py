"""Acceptance of a result document against limits: one criterion per parameter and axis, with a guard band.

The values come from the result file itself (a calibration, a noise report, a temperature table), in
its internal units, with their 1-sigma; each is compared in the limit's stated unit. A criterion
passes when ``value +- guard * sigma`` lies inside its bounds; the result passes when every
criterion that applies to it passes. Parameters the result does not hold (noise limits on a
calibration) are listed as not applicable; limits of which none applies are refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InputError
from .limits import Bound, Limits

__all__ = ["Acceptance", "Criterion", "accept", "measured"]

_AXES = "xyz"


@dataclass(frozen=True)
class Criterion:
    """One value judged against one bound, in the bound's unit; `parameter` names the limit (k, b, ...)."""

    name: str
    value: float
    sigma: float
    low: float
    high: float
    unit: str
    guard: float
    parameter: str = ""

    @property
    def margin(self) -> float:
        """Distance from the guarded interval to the nearest bound (negative: outside) [unit]."""
        reach = self.guard * self.sigma
        return min(self.value - reach - self.low, self.high - self.value - reach)

    @property
    def passed(self) -> bool:
        return math.isfinite(self.value) and math.isfinite(self.sigma) and self.margin >= 0

    def to_document(self) -> dict:
        def finite(x):
            return x if math.isfinite(x) else None

        return {"name": self.name, "parameter": self.parameter, "value": finite(self.value), "sigma": finite(self.sigma), "low": finite(self.low),
                "high": finite(self.high), "unit": self.unit, "guard": self.guard, "margin": finite(self.margin),
                "verdict": "pass" if self.passed else "fail"}


@dataclass(frozen=True)
class Acceptance:
    """The decision on one result: every criterion, the parameters that did not apply, the verdict."""

    criteria: tuple[Criterion, ...]
    not_applicable: tuple[str, ...]
    limits: Limits

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.criteria)

    @property
    def verdict(self) -> str:
        return "pass" if self.passed else "fail"

    def failures(self) -> list[str]:
        return [c.name for c in self.criteria if not c.passed]

    def to_document(self) -> dict:
        return {"verdict": self.verdict, "guard": self.limits.guard, "limits": self.limits.to_document(),
                "criteria": [c.to_document() for c in self.criteria], "not_applicable": list(self.not_applicable)}


def _calibration_values(doc: dict) -> dict[str, list[tuple[str, float, float]]]:
    """``parameter -> [(name, value, sigma)]`` of a calibration document (internal units)."""
    std = doc.get("std") or {}
    params = doc.get("parameters") or {}
    out: dict[str, list[tuple[str, float, float]]] = {}
    if "scale_bias" in params:
        sb = params["scale_bias"]
        out["k"] = [(f"k{a}", float(sb["k"][i]), float(std.get(f"k{a}", math.nan))) for i, a in enumerate(_AXES)]
        out["b"] = [(f"b{a}", float(sb["b"][i]), float(std.get(f"b{a}", math.nan))) for i, a in enumerate(_AXES)]
    elif "affine" in params:
        K, B = params["affine"]["K"], params["affine"]["B"]
        out["k"] = [(f"k{a}", float(K[i][i]), float(std.get(f"K{a}{a}", math.nan))) for i, a in enumerate(_AXES)]
        out["b"] = [(f"b{a}", float(B[i]), float(std.get(f"B{a}", math.nan))) for i, a in enumerate(_AXES)]
        out["misalignment"] = [(f"K{a}{c}", float(K[i][j]), float(std.get(f"K{a}{c}", math.nan)))
                               for i, a in enumerate(_AXES) for j, c in enumerate(_AXES) if i != j]
    out["sigma_k"] = [(f"sigma_{n}", s, 0.0) for n, _, s in out.get("k", [])]
    out["sigma_b"] = [(f"sigma_{n}", s, 0.0) for n, _, s in out.get("b", [])]
    p = (doc.get("fit") or {}).get("p_value")
    if p is not None:
        out["p_value"] = [("p_value", float(p), 0.0)]
    return out


def _noise_values(doc: dict) -> dict[str, list[tuple[str, float, float]]]:
    """Density and bias instability of each gyro axis; the 1-sigma is half the reported interval."""
    gyro = doc.get("gyroscope") or {}
    out: dict[str, list[tuple[str, float, float]]] = {}
    for key, name in (("density", "noise_density"), ("bias_instability", "bias_instability")):
        rows = []
        for a in _AXES:
            fig = (gyro.get(a) or {}).get(key) or {}
            value, low, high = (fig.get(f, None) for f in ("value", "low", "high"))
            if value is not None:
                half = (high - low) / 2 if low is not None and high is not None else math.nan
                rows.append((f"{name}_{a}", float(value), float(half)))
        if rows:
            out[name] = rows
    return out


def _thermal_values(doc: dict) -> dict[str, list[tuple[str, float, float]]]:
    rms = [max(p.get("residual_rms") or [math.nan]) for p in doc.get("points") or []]
    return {"thermal_residual": [("thermal_residual", float(max(rms)), 0.0)]} if rms else {}


def _thermal_bias_values(doc: dict) -> dict[str, list[tuple[str, float, float]]]:
    """A bias-versus-temperature fit: its bias at the reference temperature, and its residual.

    ``b`` is the calibration's bias (the reading at rest is its negative, as in [limits.b]), so it is
    minus the fitted bias at ``tref`` (the middle of the logged range), with the 1-sigma of that
    constant term; ``thermal_residual`` is the largest axis's RMS residual of the fit (no 1-sigma, as
    for a temperature table). Scale factors and noise are not in such a file.
    """
    axes = [ax for a in _AXES if isinstance(ax := (doc.get("axes") or {}).get(a), dict)]
    if len(axes) != 3:
        return {}
    b = [(f"b{a}", -float(ax["coefs"][0]), math.sqrt(float(ax["covariance"][0][0]))) for a, ax in zip(_AXES, axes)]
    return {"b": b, "sigma_b": [(f"sigma_{n}", s, 0.0) for n, _, s in b],
            "thermal_residual": [("thermal_residual", max(float(ax["residual_rms"]) for ax in axes), 0.0)]}


_READERS = {"gyrocal.calibration": _calibration_values, "gyrocal.noise": _noise_values,
            "gyrocal.thermal": _thermal_values, "gyrocal.thermal-bias": _thermal_bias_values}


def measured(doc: dict) -> dict[str, list[tuple[str, float, float]]]:
    """What a result document holds that limits can judge: ``parameter -> [(name, value, sigma)]``."""
    reader = _READERS.get(doc.get("format"))
    if reader is None:
        raise InputError(f"a {doc.get('format')!r} file holds nothing limits judge; accept a calibration, noise, "
                         "temperature or thermal-bias file (gyrocal.calibration, gyrocal.noise, gyrocal.thermal, "
                         "gyrocal.thermal-bias)")
    return reader(doc)


def _criterion(bound: Bound, name: str, value: float, sigma: float, guard: float) -> Criterion:
    low, high = bound.interval()
    return Criterion(name, value / bound.scale, sigma / bound.scale, low, high, bound.unit, guard, bound.parameter)


def accept(doc: dict, limits: Limits) -> Acceptance:
    """Judge the result document `doc` against `limits` (values in their 1-sigma, with the guard band)."""
    values = measured(doc)
    internal = (doc.get("units") or {}).get("internal")
    criteria, missing = [], []
    for bound in limits.bounds:
        rows = values.get(bound.parameter)
        if not rows:
            missing.append(bound.parameter)
            continue
        if internal == "counts" and bound.parameter in ("b", "sigma_b"):
            raise InputError(f"the calibration is in raw counts, so its bias cannot be judged in {bound.unit}; "
                             "calibrate with --sensitivity to get rates")
        criteria.extend(_criterion(bound, n, v, s, limits.guard) for n, v, s in rows)
    if not criteria:
        raise InputError(f"none of the limits in {limits.source or 'the limits file'} ({', '.join(missing)}) applies "
                         f"to a {doc.get('format')} file")
    return Acceptance(tuple(criteria), tuple(missing), limits)
