"""From a recording to a calibration: segment, reduce the windows, fit, attach units.

``calibrate`` is what the ``gyrocal calibrate`` command runs. With a known speed the
rotation windows are the constant-speed plateaus and their reference is the speed; with
a known angle they are whole turns and their reference is ``angle / duration`` (docs/core.md,
Estimators, first-moment form). A windows file overrides detection.

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
from .fit_checks import check_fit, single_turn_warnings, with_common_scale
from .noise_terms import noise_notes, sigma_covers, white_floor, with_earth_rate
from .observations import Observation, ObservationSet
from .observed import quiet_noise
from .plausibility import Context, implausible
from .quality import GoodnessOfFit
from .recording import Recording
from .screening import reference_variances, require_constant_rate, screen_breaks, screen_gaps
from .segmentation import Segmentation, given_windows, segment
from .timebase import TimeBase
from .turn_angle import follow_wander
from .units import input_scale, parse_input_unit, parse_rate_unit, unit_factor
from .window_stats import observe_windows
from .windows import Window

__all__ = ["CalibrationRun", "calibrate", "parameter_rows"]


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
    quality : GoodnessOfFit or None
        Goodness of fit (residuals per window in noise units, chi2/dof, p-value, Birge scaling);
        None when the self-checks were off.
    time_base : TimeBase or None
        Facts about the time stamps (rate, jitter, late deliveries, gaps); None when the
        self-checks were off.
    warnings : tuple of str
        What the self-checks found wrong or doubtful (fit quality, plausibility of k).
    notes : tuple of str
        What they found worth saying (the sensitivity counts imply).
    implausible : str or None
        Why the scale factors are not believable (:func:`gyrocal.plausibility.implausible`): the commands
        refuse to write them unless told to accept them; None when plausible or the self-checks were off.
    """

    calibration: Calibration
    fit: FitResult
    segmentation: Segmentation
    observations: tuple[Observation, ...]
    reference: str
    reference_value: float
    quality: GoodnessOfFit | None = None
    time_base: TimeBase | None = None
    warnings: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    implausible: str | None = None

    def parameters(self) -> list[tuple[str, float, float, str]]:
        """``(name, value, 1-sigma, unit)`` of k and b in user units (see :func:`parameter_rows`)."""
        return parameter_rows(self.calibration)

    def scale_bias_note(self) -> str | None:
        """For the paper's mean-of-squares methods, how low they read k (docs/core.md, Accuracy); None otherwise."""
        fit = self.fit
        if self.calibration.method == "first-moment" or fit.noise_std is None:
            return None
        rates = np.array([o.rate for o in self.observations if o.kind != "static"])
        # noise power in each window's mean of squares: |k (m + b)|^2 grows by sum_j k_j^2 s_j^2
        low = float(np.mean(np.sum(fit.model.k**2 * fit.noise_std**2) / (2 * rates**2)))
        return (f"{self.calibration.method} reads k low by about {low:.2g} (the noise power in its mean of squares); "
                "its 1-sigma is the spread only; the first-moment method is unbiased")

    def reference_text(self, speed_unit: str = "deg/s") -> str:
        """The reference in words: the speed, the one declared angle, or the range a windows file gave."""
        if self.reference == "speed":
            from .units import from_rad_s

            return f"speed {from_rad_s(self.reference_value, speed_unit):g} {speed_unit}"
        angles = {round(math.degrees(w.angle), 6) for w in self.segmentation.rotations}
        if len(angles) > 1:
            return f"angles of the windows file, {min(angles):g}-{max(angles):g} deg"
        return f"angle {angles.pop() if angles else math.degrees(self.reference_value):g} deg per turn"

    def report(self) -> str:
        """Plain-text summary: parameters in user units with 1-sigma, and the correction."""
        cal = self.calibration
        ref = self.reference_text()
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
        if self.quality is not None:
            lines.append(self.quality.summary())
        lines += [f"note: {n}" for n in self.notes] + [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)


def parameter_rows(cal: Calibration) -> list[tuple[str, float, float, str]]:
    """``(name, value, 1-sigma, unit)`` of k and b (Wang et al., eq. 1) in user units (sigma NaN if unknown).

    k and b are what the file stores (``parameters``), in the user's units: with counts and a
    sensitivity, k is relative to that sensitivity (1 = as declared) and b is in the output unit,
    as the counts were converted before the fit; with counts alone, k absorbs the sensitivity
    (output unit per count) and b is in counts.
    """
    p = cal.model.params
    std = cal.std if cal.std is not None else np.full(len(p), np.nan)
    d = unit_factor(cal.output_units)
    if cal.input_units == "counts" and cal.sensitivity is not None:
        k_scale, b_scale, k_unit, b_unit = 1.0, 1.0 / d, "1", cal.output_units
    else:
        c = cal.input_scale
        k_scale, b_scale, b_unit = c / d, 1.0 / c, cal.input_units
        per = "count" if cal.input_units == "counts" else cal.input_units
        k_unit = "1" if cal.input_units == cal.output_units else f"{cal.output_units} per {per}"
    rows = [(f"k{axis}", p[j] * k_scale, std[j] * k_scale, k_unit) for j, axis in enumerate("xyz")]
    return rows + [(f"b{axis}", p[3 + j] * b_scale, std[3 + j] * b_scale, b_unit) for j, axis in enumerate("xyz")]


def calibrate(
    rec: Recording,
    *,
    speed: float | None = None,
    angle: float | None = None,
    method: str = "first-moment",
    windows: Sequence[Window] | None = None,
    noise_std=None,
    output_units: str | None = None,
    checks: bool = True,
    long_run: bool = True,
    reference_sd: float | None = None,
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
        Known per-sample noise [internal units: rad/s, or counts], > 0; first-moment only.
        Estimated from the windows when omitted.
    output_units : {"rad/s", "deg/s"}, optional
        Unit of corrected rates; default the recording's unit, or deg/s for counts. For
        counts with a sensitivity it must be the unit the sensitivity refers to.
    checks : bool
        Run the self-checks (default): the time base read from the stamps (the sensor clock
        rebuilt under receive-time stamps; turns across real gaps bounded or left out), the
        paper's methods refusing varying rates, goodness of fit with Birge scaling of the
        covariance, plausibility of k, and the ``fit`` and ``observed`` sections of the file.
    long_run : bool
        First-moment only (default): each plateau's periodic speed ripple regressed out of its
        level, and every plateau's and static window's mean variance from the long-run variance
        of the data (correlated noise, what ripple is left), not sigma / sqrt(n).
        ``checks=False, long_run=False`` is the plain estimate on the stamps as they are, with a
        white-noise covariance (benchmarks and tests compare them).
    reference_sd : float, optional
        First-moment only: the accuracy (1-sigma) of each turn's angle [rad], independent from turn to turn
        (a robot's repeatability), or of the one known speed [rad/s], common to every plateau; in the 1-sigma.

    Raises
    ------
    SegmentationError
        When the windows the method needs are not there; the message lists what was found.
    InputError
        For Algorithm 1 and LM, a rotation window whose rate varies (ramps, hand turns).
    """
    # long function: the pipeline's steps in the order they run (references, segmentation, time base,
    # observations, fit, checks, file sections), each already a call of its own
    if (speed is None) == (angle is None):
        raise InputError(f"give exactly one of speed [rad/s] or angle [rad], got speed={speed!r}, angle={angle!r}")
    reference = "speed" if speed is not None else "angle"
    value = abs(float(speed if speed is not None else angle))
    if not (math.isfinite(value) and value > 0):
        raise InputError(f"{reference} must be a finite non-zero number, got {value!r}")
    for name, given in (("noise_std", noise_std), ("reference_sd", reference_sd)):
        if given is not None and method != "first-moment":
            raise InputError(f"{{param}} applies to method 'first-moment' only, got method={method!r}", param=name)
    if noise_std is not None and not np.all(np.asarray(noise_std, dtype=float) > 0):
        raise InputError(f"{{param}} must be > 0 on every axis, got {noise_std!r}: a zero noise would give a zero "
                         "1-sigma", param="noise_std", value=noise_std,
                         hint="measure it (gyrocal noise) or leave {param} out to estimate it from the windows")
    estimator = make_estimator(method, **({} if noise_std is None else {"noise_std": noise_std}))
    input_units = parse_input_unit(rec.source_units, "recording source_units")
    out_units = parse_rate_unit(output_units or ("deg/s" if input_units == "counts" else input_units), "output_units")
    if windows is None:
        seg = segment(rec, reference=reference, speed=speed, angle=value, require=False)
    else:
        seg = given_windows(rec, windows, reference, value if reference == "speed" else None,
                            value if reference == "angle" else None, screen=checks)
    tb = rec.time_base() if checks else None
    angle_var: dict = {}
    # the sensor's clock under receive-time stamps: without gaps its trapezoid weights are even (a window
    # lasts count x period), so only a clock with gaps needs its sample times rebuilt
    period = tb.clock_period if tb is not None and tb.regular_clock and not tb.gaps else None
    times = tb.clock_times() if tb is not None and tb.gaps else None
    seg = screen_breaks(seg, rec.breaks if tb is None else tb.breaks)
    if tb is not None:
        seg, angle_var = screen_gaps(seg, rec, tb, reference, times)
    uses_static = method == "first-moment"
    seg.require(static_allowed=uses_static, min_rotations=0 if uses_static else 6)
    used = seg.windows if uses_static else seg.rotations
    if checks and not uses_static:
        require_constant_rate(rec, used, seg.baseline, method)
    observations = observe_windows(rec, used, reference, value, long_run=long_run and uses_static,
                                   ripple=long_run and uses_static, times=times, period=period)
    if noise_std is not None:  # the given white level is a floor; the data's long-run correlation still counts
        observations = white_floor(observations, noise_std)
    # turns across a time-stamp gap (their rate known within its bound), and the reference's declared accuracy
    rel_var = reference_variances(used, reference, value, reference_sd if reference == "angle" else None, angle_var)
    observations = tuple(dataclasses.replace(o, rate_var=v * o.rate**2) if v else o
                         for v, o in zip(rel_var, observations))
    obs_set = ObservationSet.from_observations(observations)
    fit = estimator.fit(obs_set)
    if checks and uses_static and reference == "angle":  # a wandering axis: the integral is not the rotation
        observations, obs_set, fit = follow_wander(rec, rec.t if times is None else times, used, observations,
                                                   obs_set, fit, estimator)
    quality, warnings, notes, refusal = None, [], [], None
    if checks:
        ctx = Context(units=input_units, counts_scale=rec.units == "counts", reference=reference,
                      declared=value if windows is None or reference == "speed" else math.nan,
                      sample_rate=rec.sample_rate, has_time=rec.has_time, sensitivity=rec.sensitivity,
                      counted=tb.counted)
        scale = input_scale(input_units, rec.sensitivity, out_units)
        fit, obs_set, quality, warnings, notes = check_fit(fit, obs_set, estimator, [_label(w) for w in used],
                                                           reference=reference, ctx=ctx, input_scale=scale)
        refusal = implausible(fit.model.k, ctx)
        warnings[1 if quality.warnings else 0:0] = list(seg.warnings) + single_turn_warnings(
            [w.axis for w in used if w.kind == "rotation"], reference, None if windows and reference == "angle" else value)
        notes += noise_notes(observations, reference, noise_std is not None)
        if reference_sd:
            what = ("every turn's angle, {:g} deg" if reference == "angle" else
                    "the speed, {:g} deg/s, common to every plateau (the three k move together)")
            notes.append("the 1-sigma includes the declared accuracy of " + what.format(math.degrees(reference_sd)))
    if reference == "speed" and reference_sd:  # one speed, off on every plateau alike
        fit = with_common_scale(fit, reference_sd / value)
    if checks:  # the Earth's rate sits in every reading, and b takes it in
        fit = with_earth_rate(fit)
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
    if checks:  # the file's sections, built once (freezing thousands of residuals costs)
        # every warning and note printed goes in the file too: a flagged calibration must not look clean there
        cal = dataclasses.replace(cal, fit={**quality.to_document(), "warnings": list(warnings), "notes": list(notes),
                                            "sigma_covers": sigma_covers(observations, reference, noise_std is not None)},
                                  observed=_observed(rec, tb, fit.noise_std, cal.input_scale, input_units))
    return CalibrationRun(cal, fit, seg, observations, reference, value, quality, tb, tuple(warnings), tuple(notes),
                          refusal)


def _observed(rec: Recording, tb: TimeBase, noise_std, input_scale: float, input_units: str) -> dict:
    """What the calibration saw (the file's ``observed`` section), rates in the input units.

    `input_scale` is internal units per input unit (:attr:`gyrocal.calibration.Calibration.input_scale`).
    """
    # up to 20 000 evenly spread samples (every 50 ms at 1 kHz: a turn's rate lasts longer); the order of
    # magnitude is what a unit check needs
    sample = np.ascontiguousarray(rec.gyro[:: max(1, len(rec) // 20_000)].T)  # one row per axis, one pass
    peak = np.maximum(sample.max(axis=1), -sample.min(axis=1))
    return {"sample_rate": rec.sample_rate, "units": input_units,
            "noise_std": (np.asarray(noise_std, dtype=float) / input_scale).tolist(),
            "max_abs_rate": (peak / input_scale).tolist(), "time_base": tb.to_document(),
            # the noise of the quiet stretches, measured as apply measures the data it corrects
            "quiet_noise_std": (quiet_noise(_spread_blocks(rec.gyro, rec.sample_rate), rec.sample_rate)
                                / input_scale).tolist()}


def _spread_blocks(gyro: np.ndarray, sample_rate: float, most: int = 200) -> np.ndarray:
    """Up to `most` whole blocks of :data:`gyrocal.observed.QUIET_BLOCK` seconds, evenly spread over `gyro`.

    The quiet-noise level is a pooled standard deviation of quiet blocks: two hundred of them
    give it to a fraction of a per cent, for a fraction of the work on a long log.
    """
    from .observed import QUIET_BLOCK

    size = max(8, int(round(QUIET_BLOCK * sample_rate)))
    blocks = len(gyro) // size
    if blocks <= most:
        return gyro
    pick = np.linspace(0, blocks - 1, most).astype(np.intp)
    if gyro.flags.f_contiguous:  # as read: each axis's blocks are contiguous, and so are the result's columns
        return np.array([c[: blocks * size].reshape(blocks, size)[pick].ravel() for c in gyro.T]).T
    return gyro[: blocks * size].reshape(blocks, size, gyro.shape[1])[pick].reshape(-1, gyro.shape[1])


def _label(w: Window) -> str:
    if w.kind == "static":
        return "static"
    return w.label or (f"{'+' if w.sign >= 0 else '-'}{w.axis}" if w.axis else "rotation")
