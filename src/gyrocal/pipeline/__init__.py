"""From a recording to a calibration: segment, reduce the windows, fit, attach units.

``calibrate`` is what the ``gyrocal calibrate`` command runs. With a known speed the
rotation windows are the constant-speed plateaus and their reference is the speed; with
a known angle they are whole turns and their reference is ``angle / duration`` (docs/core.md,
Estimators, first-moment form). A windows file overrides detection.

The stages themselves are :mod:`.stages` (docs/architecture.md, the flow of ``calibrate``).

Which windows each method uses:

* ``first-moment``: rotations and static windows (static windows give ``m = -b``).
* ``algorithm1`` and ``lm`` (the servo method's mean-of-squares regression, eq. 4-8): rotations
  only. A static row would read ``y = 0`` against ``k^2 mean(m^2)``, which holds the noise
  power ``k^2 sigma^2``, so static rows would add bias, not information.

Layer 7 (the methods) of docs/architecture.md: imports the package root and layers 1 to 7 only.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..checks.quality import GoodnessOfFit
from ..estimators import FitResult
from ..observations import Observation
from ..observations.observed import observed_section
from ..observations.window_stats import observe_windows, white_floor
from ..recording import Recording
from ..recording.timebase import TimeBase
from ..results.calibration import Calibration, used_windows
from ..segmentation import Segmentation
from ..segmentation.windows import Window
from ..units import input_scale, unit_factor
from . import stages

__all__ = ["CalibrationRun", "calibrate", "observations", "parameter_rows", "result"]


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
        Why the scale factors are not believable (:func:`gyrocal.checks.plausibility.implausible`): the commands
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
            from ..units import from_rad_s

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

    Notes
    -----
    The stages (:mod:`gyrocal.pipeline.stages`) run in order: request, windows, time base, usable windows,
    observations, fit, checks, uncertainty, :func:`result`. The options that reach more than one:

    * `checks`: screens given windows (windows), reads the time base (so turns across gaps are
      bounded), refuses varying rates for the paper's methods (usable windows), follows a wandering
      axis on whole turns (fit, first-moment), runs the checks, adds the Earth's rate (uncertainty)
      and writes the file's sections (result).
    * `method`: which windows are usable (static ones for first-moment only), and the long-run
      observations and wander following are first-moment only.
    * `reference_sd`: per turn for an angle (observations), common to every plateau for a speed
      (uncertainty), and a note (checks).
    * `noise_std`: the estimator's noise, a floor on the observations' white level, and notes.
    """
    req = stages.request(rec, speed, angle, method, noise_std, reference_sd, output_units)
    reference, value, first_moment = req.reference, req.value, method == "first-moment"
    seg = stages.windows(rec, reference, value, windows, screen=checks)
    clock = stages.time_base(rec, read=checks)
    use = stages.usable(seg, rec, clock, reference, value, method, refuse_varying=checks and not first_moment,
                        turn_sd=reference_sd if reference == "angle" else None)
    obs, seen = observations(rec, use, reference, value, clock, long_run=long_run and first_moment,
                             noise_std=noise_std, observed=checks, input_units=req.input_units,
                             output_units=req.output_units)
    fitted = stages.fit(rec, clock, use.windows, obs, req, wander=checks and first_moment and reference == "angle")
    checked = stages.Checked(fitted.result)
    if checks:
        checked = stages.check(fitted, rec, use, clock, req, declared=windows is None or reference == "speed",
                               noise_given=noise_std is not None, reference_sd=reference_sd)
    fit = stages.uncertainty(checked.fit, earth_rate=checks,
                             speed_rel_sd=reference_sd / value if reference == "speed" and reference_sd else None)
    return result(rec, req, use, fitted.observations, fit, checked, clock.base, seen)


def observations(rec: Recording, use: stages.Usable, reference: str, value: float, clock: stages.Clock, *,
                 long_run: bool, noise_std, observed: bool, input_units: str, output_units: str
                 ) -> tuple[tuple[Observation, ...], dict | None]:
    """Owns reducing the recording: each window to an observation (its mean reading and reference rate with
    variances) and, `observed`, what the data looked like (the file's ``observed`` section, less the noise
    behind the fit, which the result adds).

    `long_run`: ripple regressed out and mean variances from the long-run variance (else white);
    `noise_std`: a floor on the white level.
    """
    obs = observe_windows(rec, use.windows, reference, value, long_run=long_run, ripple=long_run,
                          times=clock.times, period=clock.period)
    if noise_std is not None:  # the given white level is a floor; the data's long-run correlation still counts
        obs = white_floor(obs, noise_std)
    # turns across a time-stamp gap (their rate known within its bound), and each turn's declared accuracy
    obs = tuple(dataclasses.replace(o, rate_var=v * o.rate**2) if v else o for v, o in zip(use.rate_rel_var, obs))
    if not observed:
        return obs, None
    scale = input_scale(input_units, rec.sensitivity if input_units == "counts" else None, output_units)
    return obs, observed_section(rec, clock.base, scale, input_units, _spread_blocks(rec.gyro, rec.sample_rate))


def result(rec: Recording, req: stages.Request, use: stages.Usable, obs: tuple[Observation, ...], fit: FitResult,
           checked: stages.Checked, tb: TimeBase | None, seen: dict | None) -> CalibrationRun:
    """Owns the run's result: the calibration in user units with the windows used, and, when checked
    (`checked.section` not None), the file's ``fit`` and ``observed`` sections (built once: freezing thousands
    of residuals costs)."""
    input_units = req.input_units
    cal = Calibration(
        model=fit.model,
        input_units=input_units,
        output_units=req.output_units,
        sensitivity=rec.sensitivity if input_units == "counts" else None,
        method=req.method,
        covariance=fit.covariance,
        noise_std=fit.noise_std,
        windows=used_windows(use.windows, [o.rate for o in obs]),
    )
    if checked.section is not None:
        seen = {**seen, "noise_std": (np.asarray(fit.noise_std, dtype=float) / cal.input_scale).tolist()}
        cal = dataclasses.replace(cal, fit=checked.section, observed=seen)
    return CalibrationRun(cal, fit, use.segmentation, obs, req.reference, req.value, checked.quality, tb,
                          checked.warnings, checked.notes, checked.implausible)


def _spread_blocks(gyro: np.ndarray, sample_rate: float, most: int = 200) -> np.ndarray:
    """Up to `most` whole blocks of :data:`gyrocal.observations.observed.QUIET_BLOCK` seconds, evenly spread over `gyro`.

    The quiet-noise level is a pooled standard deviation of quiet blocks: two hundred of them
    give it to a fraction of a per cent, for a fraction of the work on a long log.
    """
    from ..observations.observed import QUIET_BLOCK

    size = max(8, int(round(QUIET_BLOCK * sample_rate)))
    blocks = len(gyro) // size
    if blocks <= most:
        return gyro
    pick = np.linspace(0, blocks - 1, most).astype(np.intp)
    if gyro.flags.f_contiguous:  # as read: each axis's blocks are contiguous, and so are the result's columns
        return np.array([c[: blocks * size].reshape(blocks, size)[pick].ravel() for c in gyro.T]).T
    return gyro[: blocks * size].reshape(blocks, size, gyro.shape[1])[pick].reshape(-1, gyro.shape[1])

