"""Verification of a calibration against a reference gyro: alignment, errors, report.

This is the check of the servo method of Wang et al. (Tables IV-V, Figs. 7-10): the
calibrated gyro and a high-grade reference record the same motion; the reference,
interpolated at the test log's own sample times and turned into the test frame, is the
truth that the readings are compared with, before and after calibration.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import finite_array
from ..errors import InputError, UnitError
from ..recording import Recording
from ..units import RateUnit, parse_rate_unit, unit_factor
from .alignment import align
from .metrics import error_metrics
from .report import AXES, VerifyReport
from .whitenoise import second_difference_noise

__all__ = ["VerifySeries", "verify_calibration", "verify_rates"]

OVERLAP_WARNING = 0.9  # fraction of the test log the reference should cover
FIT_WARNING = 3.0  # residual RMS over the noise of both sensors
FLOOR_WARNING = 0.5  # share of the MSE after calibration that the reference's noise makes up
WORSE_WARNING_PCT = 1.0  # MSE increase [%] that is worth a warning (when also beyond 2 sigma)
UNRESOLVED_WARNING = 0.02  # share of it that motion too fast for the reference may add


@dataclass(frozen=True)
class VerifySeries:
    """The compared series at the test samples inside the reference log (for figures).

    Attributes
    ----------
    t : ndarray, shape (n,)
        Test clock times [s].
    raw : ndarray, shape (n, 3), or None
        Raw test readings [units]; None for raw counts without a sensitivity.
    calibrated : ndarray, shape (n, 3)
        Calibrated test readings [units].
    reference : ndarray, shape (n, 3)
        Reference interpolated at `t` and turned into the test frame [units].
    units : str
    """

    t: np.ndarray
    raw: np.ndarray | None
    calibrated: np.ndarray
    reference: np.ndarray
    units: str


def _floor(alignment, frac: np.ndarray, noise: np.ndarray, noise_std: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """MSE [units^2] the reference noise adds on each test axis, and its 1-sigma.

    Linear interpolation with weights ``(1 - f, f)`` keeps ``(1 - f)**2 + f**2`` of the
    white-noise variance; the rotation mixes the reference axes into each test axis.
    """
    keep = float(np.mean((1.0 - frac) ** 2 + frac**2))
    r2 = alignment.mounting_rotation**2
    floor = keep * r2 @ noise**2
    floor_std = np.sqrt((keep * r2 * 2.0 * noise) ** 2 @ np.nan_to_num(noise_std) ** 2)
    return floor, floor_std


def _warnings(alignment, t_test, metrics, unresolved: np.ndarray, units: str) -> list[str]:
    out = []
    covered = alignment.overlap_s / max(t_test[-1] - t_test[0], np.finfo(float).tiny)
    if covered < OVERLAP_WARNING:
        out.append(f"the reference covers only {100 * covered:.0f} % of the test log; the figures describe that part")
    expected = np.sqrt(alignment.noise_test**2 + (alignment.mounting_rotation**2) @ alignment.noise_ref**2)
    ratio = alignment.residual_rms / np.maximum(expected, np.finfo(float).tiny)
    for ax, r in zip(AXES, ratio):
        if r > FIT_WARNING:
            out.append(f"after calibration the {ax} axis differs from the reference by {r:.1f}x the noise of both "
                       "sensors: the calibration leaves a systematic error there (see the figures)")
    worse = [ax for ax, red, sd in zip(AXES, metrics.values["reduction_pct"], metrics.std["reduction_pct"])
             if red < min(-2.0 * sd, -WORSE_WARNING_PCT)]
    if worse:
        out.append(f"calibration made axis {', '.join(worse)} worse against the reference (by more than "
                   f"{WORSE_WARNING_PCT:g} % of the MSE and 2 sigma)")
    share = metrics.values["reference_floor"] / np.maximum(metrics.values["mse_after"], np.finfo(float).tiny)
    for ax, s in zip(AXES, share):
        if s > FLOOR_WARNING:
            out.append(f"the reference's own noise makes up {100 * s:.0f} % of the MSE after calibration on the {ax} "
                       "axis: a quieter reference (or a slower comparison) is needed to judge that axis")
    if np.any(unresolved > UNRESOLVED_WARNING * metrics.values["mse_after"]):
        sizes = ", ".join(f"{x:.2g}" for x in unresolved)
        out.append(
            f"the reference holds motion faster than its sample rate follows (vibration); interpolating it at the "
            f"test times adds an error of its own to every MSE, of the order of {sizes} ({units})^2 on x, y, z "
            "(seen in the reference's own second differences; the true share can be larger). Read the figures as "
            "upper bounds, or compare with a faster reference")
    return out


def verify_rates(t_test, raw, calibrated, t_ref, w_ref, *, units: RateUnit, seed: int = 0, fit_drift: bool = True,
                 replicates: int = 1000, inputs: dict | None = None) -> tuple[VerifyReport, VerifySeries]:
    """Verify calibrated readings against a reference log.

    Parameters
    ----------
    t_test : array_like, shape (N,)
        Test sample times [s].
    raw : array_like, shape (N, 3), or None
        Raw test readings [rad/s]; None when they are raw counts without a sensitivity.
    calibrated : array_like, shape (N, 3)
        The same readings with the calibration applied [rad/s].
    t_ref, w_ref : array_like, shape (M,), (M, 3)
        Reference log [s], [rad/s].
    units : {"rad/s", "deg/s"}
        Unit of the reported figures (the calibration's output unit).
    seed : int
        Seed of the bootstrap.
    fit_drift : bool
        False holds the clock drift at zero.
    replicates : int
        Bootstrap replicates.
    inputs : dict, optional
        Provenance recorded in the report.

    Returns
    -------
    report : VerifyReport
    series : VerifySeries
    """
    units = parse_rate_unit(units, "units")
    t_test = finite_array("t_test", t_test, ndim=1)
    cal = finite_array("calibrated", calibrated, shape_tail=(3,), ndim=2)
    t_ref = finite_array("t_ref", t_ref, ndim=1)
    w_ref = finite_array("w_ref", w_ref, shape_tail=(3,), ndim=2)
    raw = None if raw is None else finite_array("raw", raw, shape_tail=(3,), ndim=2)
    if len(cal) != len(t_test) or (raw is not None and len(raw) != len(t_test)):
        raise InputError(f"t_test, raw and calibrated must have one row per sample, got {len(t_test)}, "
                         f"{None if raw is None else len(raw)} and {len(cal)}")
    alignment = align(t_test, cal, t_ref, w_ref, fit_drift=fit_drift)
    ref, inside, frac = alignment.reference_at(t_test, t_ref, w_ref)
    u = unit_factor(units)
    ref_noise = second_difference_noise(t_ref, w_ref)
    noise, noise_std = ref_noise.std / u, ref_noise.std_err / u
    floor, floor_std = _floor(alignment, frac, noise, noise_std)
    unresolved = _floor(alignment, frac, np.sqrt(np.maximum(ref_noise.rms**2 - ref_noise.std**2, 0.0)) / u,
                        np.zeros(3))[0]
    series = VerifySeries(t=t_test[inside], raw=None if raw is None else raw[inside] / u, calibrated=cal[inside] / u,
                          reference=ref / u, units=units)
    err_before = None if series.raw is None else series.raw - series.reference
    metrics = error_metrics(err_before, series.calibrated - series.reference, floor, floor_std,
                            rng=np.random.default_rng(seed), replicates=replicates)
    report = VerifyReport(alignment=alignment, metrics=metrics, units=units, reference_noise=noise,
                          reference_noise_std=noise_std, test_noise=alignment.noise_test / u, seed=int(seed),
                          inputs=dict(inputs or {}),
                          warnings=tuple(_warnings(alignment, t_test, metrics, unresolved, units)))
    return report, series


def verify_calibration(calibration, test: Recording, reference: Recording, *, seed: int = 0, fit_drift: bool = True,
                       replicates: int = 1000, inputs: dict | None = None, **apply_options,
                       ) -> tuple[VerifyReport, VerifySeries]:
    """Verify a calibration (any kind with ``apply``) on a test log against a reference log.

    Parameters
    ----------
    calibration : Calibration or ThermalCalibration
        Applied to `test` with `apply_options` (thermal: ``model``, ``out_of_range``); a
        thermal table needs a ``temp`` column in the test log.
    test : Recording
        The calibrated gyro's log, read in the calibration's input units.
    reference : Recording
        The reference gyro's log, in rates (not raw counts).
    seed, fit_drift, replicates, inputs
        As for :func:`verify_rates`.

    Returns
    -------
    report : VerifyReport
        Figures in the calibration's output unit.
    series : VerifySeries
    """
    if reference.units != "rad/s":
        raise UnitError("the reference log is in raw counts without a sensitivity; its rates are needed",
                        param="reference", hint="give the reference's sensitivity in LSB per unit")
    corrected = calibration.apply(test, **apply_options)
    raw = np.asarray(test.gyro) if test.units == "rad/s" else None  # counts without a sensitivity: no raw rates
    return verify_rates(test.t, raw, corrected.gyro, reference.t, reference.gyro, units=calibration.output_units,
                        seed=seed, fit_drift=fit_drift, replicates=replicates, inputs=inputs)
