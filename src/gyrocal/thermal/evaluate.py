"""Evaluation against a reference, like the full-temperature-range method's Tables 3-4 and Figures 7-9.

Each step of a test recording (constant table rate, position and temperature) is
reduced to its mean; each compensation turns that mean into a rate estimate, whose
difference from the reference body rate is the step's error. Working on step means
keeps white noise out of the comparison; the compensation is affine at a fixed
temperature, so compensating the mean equals averaging the compensated samples.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._arrays import distinct
from ..recording import Recording
from ..units import unit_factor
from ._warn import ThermalRangeWarning
from .lagrange import OutOfRange, interpolate, range_policy
from .model import ThermalCalibration
from .session import AXES, Steps, drop_saturated, drop_unstable, find_steps

__all__ = ["METHODS", "Evaluation", "evaluate", "evaluate_steps", "loto_comparison"]

#: Compensations compared; "traditional" is one Kg (nearest the reference temperature) used everywhere.
METHODS = ("uncompensated", "traditional", "lagrange", "smooth")


@dataclass(frozen=True)
class Evaluation:
    """Step errors of every compensation.

    Attributes
    ----------
    steps : Steps
        The test steps.
    errors : dict of str to ndarray (n, 3)
        Compensated step mean minus reference, per method [rad/s].
    """

    steps: Steps
    errors: dict

    def summary(self, units: str = "deg/s") -> list[dict]:
        """Mean and RMS error per rotating axis, gyro axis and method (Tables 3-4), in `units`."""
        f = unit_factor(units)
        rows = []
        for a in range(3):
            sel = self.steps.axis == a
            if not sel.any():
                continue
            for j in range(3):
                row = {"rotating_axis": AXES[a], "gyro_axis": AXES[j], "steps": int(sel.sum())}
                for m, e in self.errors.items():
                    row[f"{m}_mean"] = float(e[sel, j].mean() / f)
                    row[f"{m}_rms"] = float(np.sqrt(np.mean(e[sel, j] ** 2)) / f)
                t, lg = row["traditional_rms"], row["lagrange_rms"]
                row["lagrange_rms_reduction_pct"] = float(100 * (t - lg) / t) if t > 0 else 0.0
                rows.append(row)
        return rows

    def by_temperature(self, units: str = "deg/s", resolution: float = 0.5) -> list[dict]:
        """RMS error over all steps and gyro axes at each test temperature (rounded to `resolution` degC)."""
        f = unit_factor(units)
        key = np.round(self.steps.temp / resolution) * resolution
        rows = []
        for t in distinct(key):
            sel = key == t
            row = {"temp": float(t), "steps": int(sel.sum())}
            for m, e in self.errors.items():
                row[f"{m}_rms"] = float(np.sqrt(np.mean(e[sel] ** 2)) / f)
            rows.append(row)
        return rows

    def step_rows(self, units: str = "deg/s") -> list[dict]:
        """One row per step: temperature, position, rate and each method's error per gyro axis."""
        f = unit_factor(units)
        rows = []
        for i in range(len(self.steps)):
            row = {"temp": float(self.steps.temp[i]), "axis": AXES[self.steps.axis[i]],
                   "table_rate": float(self.steps.rate[i] / f)}
            for m, e in self.errors.items():
                for j in range(3):
                    row[f"{m}_{AXES[j]}"] = float(e[i, j] / f)
            rows.append(row)
        return rows


def evaluate_steps(cal: ThermalCalibration, steps: Steps, out_of_range: OutOfRange = "refuse") -> Evaluation:
    """Errors of every method on reduced steps."""
    ref = steps.reference
    # the range policy once for all methods (one refusal or one warning), then every method on its result
    temp = range_policy(cal.temps, steps.temp, out_of_range)
    errors = {"uncompensated": steps.mean - ref}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ThermalRangeWarning)  # already said above
        for m in METHODS[1:]:
            errors[m] = cal.compensate(steps.mean, temp, m, "extrapolate") - ref
    return Evaluation(steps=steps, errors=errors)


def evaluate(cal: ThermalCalibration, recordings: Sequence[Recording], *, settle: float = 2.0,
             full_scale: float | None = None, temp_tolerance: float = 2.0,
             out_of_range: OutOfRange = "refuse") -> Evaluation:
    """Evaluate `cal` on test recordings with ``temp``, ``table_rate`` and ``axis`` columns.

    Parameters
    ----------
    cal : ThermalCalibration
    recordings : sequence of Recording
    settle : float
        Time dropped at each step start [s].
    full_scale : float, optional
        Gyro range [rad/s]; saturated steps are left out with a warning.
    temp_tolerance : float
        Steps spanning more than this are left out [degC].
    out_of_range : {"refuse", "clamp", "extrapolate"}
        Policy for test temperatures outside the calibrated range.
    """
    steps = Steps.concat([find_steps(r, settle=settle, full_scale=full_scale, source=i)
                          for i, r in enumerate(recordings)])
    steps = drop_saturated(drop_unstable(steps, temp_tolerance))
    return evaluate_steps(cal, steps, out_of_range)


def loto_comparison(cal: ThermalCalibration) -> list[dict]:
    """Leave-one-temperature-out RMS error of Lagrange and of the smooth model, per Kg element.

    Lagrange drops each node in turn and predicts it from the rest (ends by
    extrapolation); the smooth model reports the LOTO error of its chosen order.
    Needs at least 4 points. Values are in internal units (K dimensionless, B rad/s).
    """
    from ..models import KG_NAMES

    n = len(cal.temps)
    if n < 4:
        return []
    pred = np.empty_like(cal.kg)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ThermalRangeWarning)
        for k in range(n):
            keep = np.arange(n) != k
            pred[k] = interpolate(cal.temps[keep], cal.kg[keep], [cal.temps[k]], "extrapolate")[0]
    lag = np.sqrt(np.mean((pred - cal.kg) ** 2, axis=0))
    sm = cal.smooth.loto_rms[cal.smooth.orders, np.arange(12)]
    return [{"element": name, "order": int(cal.smooth.orders[j]), "lagrange_loto_rms": float(lag[j]),
             "smooth_loto_rms": float(sm[j])} for j, name in enumerate(KG_NAMES)]
