"""A whole-IMU calibration of a recording, as a calibration file holds it.

:func:`calibrate_recording` runs :func:`~gyrocal.imu.session.calibrate_imu` on a
:class:`~gyrocal.recording.Recording` (on the sensor's own clock when its stamps are receive
times, leaving out pose pairs across lost samples) and builds the
:class:`~gyrocal.results.calibration.Calibration`: ``correction`` and ``parameters`` are the gyro's, in
the conventions of the other methods (``w_true = matrix @ (raw - offset)``), and the
``accelerometer`` section holds the accelerometer's correction, its parameters with their
covariance, how well they fit, the poses, and the gyro's g-sensitivity when it was fitted. A log
whose temperature column spans several points (a chamber's plateaus) is calibrated at each point
(:mod:`gyrocal.imu.thermal`): the correction is then the point nearest 25 degC, and
``accelerometer.thermal`` holds both sensors at every point, their Lagrange and smooth models in
temperature with 1-sigma, the frame they write in, and ``internal``: the units of their parameters.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .._arrays import median
from ..errors import InputError
from ..models import KG_INDEX, Affine, ScaleBias
from ..observations.observed import observe
from ..recording import Recording
from ..recording.timebase import TimeBase
from ..results.calibration import Calibration
from ..units import STANDARD_GRAVITY, accel_scale, parse_rate_unit
from .filedoc import accelerometer_section, gyro_fit_section
from .session import ImuCalibrationResult, calibrate_imu
from .thermal import ImuThermalResult, calibrate_imu_thermal

__all__ = ["ImuRun", "accel_scale", "calibrate_recording", "implausible", "plausibility"]

ACCEL_OUTPUT_UNITS = ("m/s^2", "g")
#: A gap of at most this many lost samples is integrated across (its trapezoid error is third order in
#: its length, below the noise of a hand move); a pose pair across a longer one is left out.
MAX_LOST = 2
#: A temperature column spanning more than this is taken as a chamber log of several temperature points [degC].
THERMAL_SPAN = 5.0


@dataclass(frozen=True)
class ImuRun:
    """A recording's whole-IMU calibration.

    Attributes
    ----------
    result : ImuCalibrationResult
        The fits (internal units: gyro rad/s or counts, accelerometer m/s^2 or counts).
    calibration : Calibration
        The calibration file's content.
    time_base : TimeBase
    thermal : ImuThermalResult or None
        Both sensors across temperature, when the log holds poses at 3 or more temperature points.
    """

    result: ImuCalibrationResult
    calibration: Calibration
    time_base: TimeBase
    thermal: ImuThermalResult | None = None

    @property
    def warnings(self) -> tuple[str, ...]:
        """The fits' warnings, and scale factors far from 1 in physical units (a declared unit that is wrong)."""
        return self.result.warnings + plausibility(self.calibration)


#: Scale factors in physical units further than this from 1 point to a declared unit that is wrong.
SCALE_PLAUSIBLE = 0.2


def plausibility(cal: Calibration) -> tuple[str, ...]:
    """Warnings for scale factors far from 1 when both ends are physical units (a wrong --units or --accel-units)."""
    out = []
    if cal.input_units != "counts":
        k = np.abs(np.diag(np.asarray(cal.model.matrix, dtype=float)))  # internal (rad/s per rad/s as read)
        if np.any(np.abs(k - 1) > SCALE_PLAUSIBLE):
            out.append(f"the gyro's scale factors are {', '.join(f'{v:.4g}' for v in k)} (rad/s per rad/s as read), far "
                       f"from 1: is --units {cal.input_units} right?{_unit_hint(k, 180 / np.pi, 'rad/s', 'deg/s')}")
    part = cal.accelerometer
    if part is not None and part["units"]["input"] != "counts":
        units = part["units"]
        k = np.abs(np.diag(np.asarray(part["parameters"]["matrix"], dtype=float)))  # m/s^2 per m/s^2 as read
        if np.any(np.abs(k - 1) > SCALE_PLAUSIBLE):
            out.append(f"the accelerometer's scale factors are {', '.join(f'{v:.4g}' for v in k)}, far from 1: is "
                       f"--accel-units {units['input']} right?{_unit_hint(k, STANDARD_GRAVITY, 'g', 'm/s^2')}")
    return tuple(out)


def implausible(cal: Calibration) -> str | None:
    """Why the commands refuse this calibration (None: plausible): the scale factors of :func:`plausibility`
    (more than 20 % from 1 in physical units), or gyro counts whose sensitivity no vendor's setting comes near."""
    out = list(plausibility(cal))
    if cal.input_units == "counts" and cal.sensitivity is None:
        from ..checks.plausibility import Context
        from ..checks.plausibility import implausible as judge

        ctx = Context(units="counts", counts_scale=True, reference="angle", declared=float("nan"), sample_rate=1.0,
                      has_time=True)
        out.append(judge(np.diag(np.asarray(cal.model.matrix, dtype=float)), ctx))
    return "; ".join(t for t in out if t) or None


def _unit_hint(k: np.ndarray, factor: float, big: str, small: str) -> str:
    """Which unit mix-up a common factor near `factor` (or its inverse) points to: ``big`` is `factor` times
    ``small`` (rad/s = 57.3 deg/s, g = 9.81 m/s^2)."""
    ratio = float(median(k))
    if abs(ratio / factor - 1) < 0.2:
        return f" (a factor {factor:.3g}: data in {big} read as {small})"
    if abs(ratio * factor - 1) < 0.2:
        return f" (a factor 1/{factor:.3g}: data in {small} read as {big})"
    return ""


def calibrate_recording(rec: Recording, *, windows=None, gravity: float = STANDARD_GRAVITY, accel_model="auto",
                        gyro_model="auto", g_sensitivity: bool = False, min_static: float = 1.0,
                        output_units: str | None = None, accel_output_units: str = "m/s^2",
                        threshold: float | None = None, sensor_lag: float | None = None) -> ImuRun:
    """Calibrate the gyro and the accelerometer of a hand session.

    Parameters
    ----------
    rec : Recording
        With accelerometer columns (``rec.accel``).
    windows : sequence of Window, optional
        Still poses and turns chosen by hand (imucal's section list makes a Ferraris session).
    gravity : float
        Local gravity [m/s^2] (it is also one ``g`` for readings and output in g).
    accel_model, gyro_model, g_sensitivity, min_static, threshold :
        See :func:`gyrocal.imu.session.calibrate_imu`.
    output_units : {"rad/s", "deg/s"}, optional
        Of the corrected rates; default the data's, deg/s for counts.
    accel_output_units : {"m/s^2", "g"}
        Of the corrected accelerations.
    sensor_lag : float, optional
        A chamber log's temperature sensor lags the die by this time constant [s]
        (:func:`~gyrocal.imu.thermal_limits.lag_corrected`).
    """
    if rec.accel is None:
        raise InputError("the recording has no accelerometer columns; a whole-IMU calibration needs them",
                         param="accel_units", hint="give {param} (m/s^2, g or counts) and map ax, ay, az if their "
                         "names are not found (--columns ax=...)")
    if accel_output_units not in ACCEL_OUTPUT_UNITS:
        raise InputError(f"{{param}} must be m/s^2 or g, got {accel_output_units!r}", param="accel_output_units",
                         value=accel_output_units)
    out_units = parse_rate_unit(output_units or ("deg/s" if rec.source_units == "counts" else rec.source_units),
                                "output_units")
    tb = rec.time_base()
    clock = tb.clock_times()
    kw = {"gravity": gravity, "accel_model": accel_model, "gyro_model": gyro_model, "min_static": min_static,
          "gaps": [g.index for g in tb.gaps if g.lost > MAX_LOST], "breaks": tb.breaks, "threshold": threshold}
    t = rec.t if clock is None else clock
    thermal, result = _thermal(rec, t, kw, sensor_lag) if windows is None and not g_sensitivity else (None, None)
    if result is None:
        result = calibrate_imu(t, rec.gyro, rec.accel, windows=windows, g_sensitivity=g_sensitivity, **kw)
    cal = _calibration(result, rec, tb, out_units, accel_output_units, gravity)
    if thermal is not None:
        part = {**cal.accelerometer, "thermal": {**thermal.to_dict(), "internal": {
            "accelerometer": rec.accel_units, "gyro": "counts" if rec.source_units == "counts" else "rad/s"}}}
        cal = replace(cal, accelerometer=part)
    return ImuRun(result, cal, tb, thermal)


def _thermal(rec: Recording, t, kw, sensor_lag=None) -> tuple[ImuThermalResult | None, ImuCalibrationResult | None]:
    """Both sensors across temperature when the temperature column spans several points, and the result at the
    point nearest 25 degC (the file's correction); a span that gives no model is said in that result's warnings."""
    if rec.temp is None or np.ptp(rec.temp) <= THERMAL_SPAN:
        return None, None
    from .ramp import calibrate_ramp, is_ramp
    from .thermal_limits import die_temperature

    ramp = is_ramp(t, rec.temp, kw["breaks"])
    try:
        if ramp:  # each pose at its own temperature: the lagging readings moved to the die's, sample by sample
            temp = rec.temp if not sensor_lag else die_temperature(t, rec.temp, sensor_lag)
            thermal = calibrate_ramp(t, rec.gyro, rec.accel, temp, **kw)
        else:
            thermal = calibrate_imu_thermal(t, rec.gyro, rec.accel, rec.temp, sensor_lag=sensor_lag, **kw)
    except InputError as exc:
        result = calibrate_imu(t, rec.gyro, rec.accel, **kw)
        why = (f"the temperature column spans {np.ptp(rec.temp):.1f} degC but no model in temperature was fitted "
               f"({exc}); the correction is one fit over all the poses")
        return None, replace(result, warnings=result.warnings + (why,))
    ref = thermal.points[thermal.reference]
    result = max(ref.results, key=lambda r: len(r.statics))
    what = _what(thermal, ref, ramp)
    return thermal, replace(result, warnings=result.warnings + thermal.notes + (what,))


def _what(thermal: ImuThermalResult, ref, ramp: bool) -> str:
    """The line that says how the log was read across temperature: a ramp or plateaus, the points, the correction."""
    temps = ", ".join(f"{p.temperature:.1f}" for p in thermal.points)
    if not ramp:
        return (f"temperature plateaus: {len(thermal.points)} temperature points ({temps} degC): the correction is "
                f"the point at {ref.temperature:.1f} degC, accelerometer.thermal holds both sensors at every point and "
                "their models in temperature")
    return (f"a temperature ramp ({thermal.ramp['poses']} poses, each at its own temperature; the accelerometer fitted "
            f"across them, the gyro in {len(thermal.points)} temperature bins at {temps} degC): the correction is the "
            f"bin at {ref.temperature:.1f} degC, whose accelerometer fit also holds the drift across the bin (its "
            "residuals above the noise); accelerometer.thermal holds both sensors' models in temperature")


def _gyro_model(result: ImuCalibrationResult):
    """The gyro model and its covariance in that model's parameter order (internal units)."""
    fit = result.gyro
    cov = fit.covariance[:12, :12] if fit.model == "affine" else fit.covariance[:6, :6]
    if fit.model == "scale":
        model = ScaleBias(k=np.diag(fit.matrix), b=-fit.offset)  # Wang et al., eq. 1: b = -offset
        jac = np.diag([1.0, 1.0, 1.0, -1.0, -1.0, -1.0])
        return model, jac @ cov @ jac.T
    model = Affine.from_canonical(fit.matrix, fit.offset)
    k = model.K
    jac = np.zeros((12, 12))
    for row, (r, c) in enumerate(KG_INDEX):  # dK = -K dA K, with A row-major in the fit
        jac[row, :9] = -np.outer(k[r, :], k[:, c]).ravel()
    jac[9:, 9:] = np.eye(3)
    return model, jac @ cov @ jac.T


def _calibration(result, rec: Recording, tb: TimeBase, out_units: str, accel_out: str, gravity: float) -> Calibration:
    model, cov = _gyro_model(result)
    input_units = rec.source_units
    sensitivity = rec.sensitivity if input_units == "counts" else None
    cal = Calibration(model=model, input_units=input_units, output_units=out_units, sensitivity=sensitivity,
                      method="ferraris" if result.kind == "ferraris" else "multi-position", covariance=cov)
    noise = np.sqrt(np.mean([s.gyro_std**2 for s in result.statics], axis=0))
    windows = [{"start": s.start, "stop": s.stop, "kind": "static", "label": s.label or f"pose {i + 1}"}
               for i, s in enumerate(result.statics)]
    windows += [{"start": t.start, "stop": t.stop, "kind": "rotation", "label": t.label,
                 "angle_deg": float(np.degrees(t.angle))} for t in result.turns]
    observed = {**observe(rec.gyro / cal.input_scale, rec.sample_rate, input_units),
                "noise_std": (noise / cal.input_scale).tolist(), "time_base": tb.to_document()}
    return replace(cal, noise_std=noise, windows=tuple(windows), observed=observed, fit=gyro_fit_section(result),
                   accelerometer=accelerometer_section(result, rec, cal, accel_out, gravity))
