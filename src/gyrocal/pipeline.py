"""From a recording to a calibration: segment, reduce the windows, fit, attach units.

``calibrate`` is what the ``gyrocal calibrate`` command runs. With a known speed the
rotation windows are the constant-speed plateaus and their reference is the speed; with
a known angle they are whole turns and their reference is ``angle / duration`` (SPEC,
Method S, first-moment form). A windows file overrides detection.

Which windows each method uses:

* ``first-moment``: rotations and static windows (static windows give ``m = -b``).
* ``algorithm1`` and ``lm`` (the servo method's mean-of-squares regression, eq. 4-8): rotations
  only. A static row would read ``y = 0`` against ``k^2 mean(m^2)``, which holds the noise
  power ``k^2 sigma^2``, so static rows would add bias, not information.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .calibration import Calibration
from .errors import InputError
from .estimators import FitResult, make_estimator
from .observations import Observation, ObservationSet, observe
from .recording import Recording
from .segmentation import Segmentation, segment
from .segmentation._motion import static_level
from .units import parse_input_unit, parse_rate_unit, unit_factor
from .windows import Window

__all__ = ["CalibrationRun", "calibrate"]


@dataclass(frozen=True)
class CalibrationRun:
    """Everything one calibration produced.

    Attributes
    ----------
    calibration : Calibration
        The result with its units, covariance and the windows used (ready to save).
    fit : FitResult
        The estimator's own result (internal units).
    segmentation : Segmentation
        The windows found (or given), and what was ignored.
    observations : tuple of Observation
        One per window used, in the order of ``calibration.windows``.
    reference : {"speed", "angle"}
    reference_value : float
        The known speed [rad/s] or angle per turn [rad].
    """

    calibration: Calibration
    fit: FitResult
    segmentation: Segmentation
    observations: tuple[Observation, ...]
    reference: str
    reference_value: float

    def parameters(self) -> list[tuple[str, float, float, str]]:
        """``(name, value, 1-sigma, unit)`` of k and b in user units (sigma NaN if unknown)."""
        cal = self.calibration
        c, d = cal.input_scale, unit_factor(cal.output_units)
        p = cal.model.params
        std = cal.std if cal.std is not None else np.full(len(p), np.nan)
        k_unit = "1" if cal.input_units == cal.output_units else f"{cal.output_units} per {cal.input_units}"
        rows = []
        for j, axis in enumerate("xyz"):
            rows.append((f"k{axis}", p[j] * c / d, std[j] * c / d, k_unit))
        for j, axis in enumerate("xyz"):
            rows.append((f"b{axis}", p[3 + j] / c, std[3 + j] / c, cal.input_units))
        return rows

    def scale_bias_note(self) -> str | None:
        """For the paper's mean-of-squares methods, how low they read k (SPEC); None otherwise."""
        fit = self.fit
        if self.calibration.method == "first-moment" or fit.noise_std is None:
            return None
        rates = np.array([o.rate for o in self.observations if o.kind != "static"])
        # noise power in each window's mean of squares: |k (m + b)|^2 grows by sum_j k_j^2 s_j^2
        low = float(np.mean(np.sum(fit.model.k**2 * fit.noise_std**2) / (2 * rates**2)))
        return (f"{self.calibration.method} reads k low by about {low:.2g} (the noise power in its mean of squares); "
                "its 1-sigma is the spread only; the first-moment method is unbiased")

    def report(self) -> str:
        """Plain-text summary: parameters in user units with 1-sigma, and the correction."""
        cal = self.calibration
        ref = (f"speed {self.reference_value * 180 / math.pi:g} deg/s" if self.reference == "speed"
               else f"angle {math.degrees(self.reference_value):g} deg per turn")
        n_rot = sum(w["kind"] == "rotation" for w in cal.windows)
        lines = [
            (f"gyrocal calibration: method {cal.method}, reference {ref}, "
             f"{n_rot} rotation and {len(cal.windows) - n_rot} static window(s)"),
            f"{'parameter':<10}{'value':>14}{'1-sigma':>12}  unit",
        ]
        for name, value, sigma, unit in self.parameters():
            s = "n/a" if math.isnan(sigma) else f"{sigma:.3g}"
            lines.append(f"{name:<10}{value:>14.6g}{s:>12}  {unit}")
        matrix, offset = cal.correction
        lines.append(f"correction (w_true = matrix @ (raw - offset)), {cal.input_units} -> {cal.output_units}:")
        lines.append("  matrix diag " + "  ".join(f"{v:.6g}" for v in np.diag(matrix)))
        lines.append("  offset      " + "  ".join(f"{v:.6g}" for v in offset))
        if cal.noise_std is not None:
            noise = cal.noise_std / cal.input_scale
            lines.append(f"  noise std per sample [{cal.input_units}]: " + "  ".join(f"{v:.3g}" for v in noise))
        if (note := self.scale_bias_note()) is not None:
            lines.append("  note: " + note)
        return "\n".join(lines)


def _baseline(rec: Recording, windows: Sequence[Window]) -> np.ndarray:
    statics = [w for w in windows if w.kind == "static"]
    if statics:
        return np.mean(np.concatenate([rec.gyro[w.start:w.stop] for w in statics]), axis=0)
    return static_level(rec.gyro, max(8, int(round(0.25 * rec.sample_rate))))[0]


#: A given window's first or last tenth may turn this much slower than its middle (--speed only).
_SPEED_SPREAD = 0.1


def _require_constant_speed(samples: np.ndarray, w: Window, i: int) -> None:
    """Refuse a window with ramps: the speed reference holds only on the constant-speed part."""
    tenths = np.linalg.norm([part.mean(axis=0) for part in np.array_split(samples, min(10, len(samples)))], axis=1)
    middle = float(np.median(tenths))
    worst = float(min(tenths[0], tenths[-1]))
    if worst < (1 - _SPEED_SPREAD) * middle:
        raise InputError(
            f"rotation window {i} ({w.label or f'{w.start}:{w.stop}'}) is not at constant speed: an end of it turns "
            f"at {100 * worst / middle:.0f} % of its middle (a ramp); with a known speed the windows must cover only "
            "the constant-speed part: trim them, or use the angle reference (--angle) with whole turns"
        )


def _given_windows(rec: Recording, windows: Sequence[Window], reference: str, speed, angle) -> Segmentation:
    """A :class:`Segmentation` from user windows: axis and sense filled in, references attached."""
    windows = list(windows)
    if not windows:
        raise InputError("windows is empty; give rotation and static windows, or None to detect them")
    n, fs = len(rec), rec.sample_rate
    for w in windows:
        if not isinstance(w, Window):
            raise InputError(f"windows must hold gyrocal.windows.Window objects, got {type(w).__name__}")
        if w.stop > n:
            raise InputError(f"window {w.label or ''} {w.start}:{w.stop} ends after the recording ({n} samples)")
    base = _baseline(rec, windows)
    out = []
    for i, w in enumerate(windows):
        if w.kind == "static":
            out.append(dataclasses.replace(w, rate=0.0))
            continue
        if w.axis is None or w.sign == 0:
            v = rec.gyro[w.start:w.stop].mean(axis=0) - base
            j = int(np.abs(v).argmax())
            w = dataclasses.replace(w, axis="xyz"[j], sign=1 if v[j] >= 0 else -1)
        if reference == "speed":
            _require_constant_speed(rec.gyro[w.start:w.stop] - base, w, i)
            w = dataclasses.replace(w, angle=speed * len(w) / fs, rate=speed)
        else:
            a = w.angle if math.isfinite(w.angle) else angle
            if a is None:
                raise InputError(f"rotation window {i} ({w.label or f'{w.start}:{w.stop}'}) has no angle; give angle")
            a = abs(float(a))
            w = dataclasses.replace(w, angle=a, rate=a * fs / len(w))
        out.append(w)
    noise = np.full(3, np.nan)
    return Segmentation(tuple(out), (), "file", fs, base, noise)


def _gap_times(rec: Recording, w: Window) -> np.ndarray | None:
    """The window's sample times when the log dropped samples inside it, else None (evenly spaced).

    Without a time column ``t`` is still exact: rows dropped for saturation leave their gaps in it.
    """
    if len(w) < 2:
        return None
    t = rec.t[w.start:w.stop]
    return t if (t[-1] - t[0]) * rec.sample_rate > len(w) - 0.5 else None


def _observe(rec: Recording, w: Window, reference: str, speed) -> Observation:
    # Column-major windows make the per-axis reductions contiguous (about 4x faster than C order):
    # readers give column-major recordings; others are copied window by window, not whole.
    samples = rec.gyro[w.start:w.stop]
    if not rec.gyro.flags.f_contiguous:
        samples = np.asfortranarray(samples)
    fs = rec.sample_rate
    if w.kind == "static":
        return observe(samples, fs, "static")
    if reference == "speed":
        return observe(samples, fs, "speed", speed=speed)
    return observe(samples, fs, "angle", angle=w.angle, t=_gap_times(rec, w))


def calibrate(
    rec: Recording,
    *,
    speed: float | None = None,
    angle: float | None = None,
    method: str = "first-moment",
    windows: Sequence[Window] | None = None,
    noise_std=None,
    output_units: str | None = None,
) -> CalibrationRun:
    """Calibrate a gyro from one recording of a servo, gimbal, robot or hand session.

    Parameters
    ----------
    rec : Recording
        The session (readings in rad/s, or raw counts).
    speed : float, optional
        Known constant speed of every turn [rad/s].
    angle : float, optional
        Known angle of every turn [rad] (for example ``2 pi``). Give exactly one of
        `speed` and `angle`.
    method : {"first-moment", "algorithm1", "lm"}
        Estimator (see the module notes for the windows each uses).
    windows : sequence of Window, optional
        Windows from a windows file; they override detection. Rotation windows without
        an angle of their own use `angle`.
    noise_std : float or array_like of shape (3,), optional
        Known per-sample noise [internal units: rad/s, or counts]; first-moment only.
        Estimated from the windows when omitted.
    output_units : {"rad/s", "deg/s"}, optional
        Unit of corrected rates; default the recording's unit, or deg/s for counts. For
        counts with a sensitivity it must be the unit the sensitivity refers to.

    Raises
    ------
    SegmentationError
        When the windows the method needs are not there; the message lists what was found.
    """
    if (speed is None) == (angle is None):
        raise InputError(f"give exactly one of speed [rad/s] or angle [rad], got speed={speed!r}, angle={angle!r}")
    reference = "speed" if speed is not None else "angle"
    value = abs(float(speed if speed is not None else angle))
    if not (math.isfinite(value) and value > 0):
        raise InputError(f"{reference} must be a finite non-zero number, got {value!r}")
    if noise_std is not None and method != "first-moment":
        raise InputError(f"noise_std applies to method 'first-moment' only, got method={method!r}")
    estimator = make_estimator(method, **({} if noise_std is None else {"noise_std": noise_std}))
    input_units = parse_input_unit(rec.source_units, "recording source_units")
    out_units = parse_rate_unit(output_units or ("deg/s" if input_units == "counts" else input_units), "output_units")
    if windows is None:
        seg = segment(rec, reference=reference, speed=speed, angle=value, require=False)
    else:
        seg = _given_windows(rec, windows, reference, value if reference == "speed" else None,
                             value if reference == "angle" else None)
    uses_static = method == "first-moment"
    seg.require(static_allowed=uses_static, min_rotations=0 if uses_static else 6)
    used = seg.windows if uses_static else seg.rotations
    observations = tuple(_observe(rec, w, reference, value) for w in used)
    fit = estimator.fit(ObservationSet.from_observations(observations))
    cal = Calibration(
        model=fit.model,
        input_units=input_units,
        output_units=out_units,
        sensitivity=rec.sensitivity if input_units == "counts" else None,
        method=method,
        covariance=fit.covariance,
        noise_std=fit.noise_std,
        windows=tuple({**w.to_dict(), "rate": o.rate} for w, o in zip(used, observations)),
    )
    return CalibrationRun(cal, fit, seg, observations, reference, value)
