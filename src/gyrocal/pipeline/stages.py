"""The stages :func:`gyrocal.pipeline.calibrate` runs, each a function of what it is given.

request -> windows -> time base -> usable windows -> observations -> fit -> checks -> uncertainty ->
result; the observations and the result are :func:`gyrocal.pipeline.observations` and
:func:`gyrocal.pipeline.result` (next to the window reduction and the sections they call). No stage reads another's options: where one
option matters to several stages, ``calibrate`` passes each what it needs (its docstring says which).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..checks.fit import check_fit, single_turn_warnings, with_common_scale
from ..checks.noise_terms import noise_notes, sigma_covers, with_earth_rate
from ..checks.plausibility import Context, implausible
from ..checks.quality import GoodnessOfFit
from ..choices import Method, values
from ..errors import InputError
from ..estimators import FitResult, make_estimator
from ..observations import Observation, ObservationSet
from ..observations.turn_angle import follow_wander
from ..recording import Recording
from ..recording.timebase import TimeBase
from ..segmentation import Segmentation, given_windows, segment
from ..segmentation.screening import reference_variances, require_constant_rate, screen_breaks, screen_gaps
from ..segmentation.windows import Window
from ..units import input_scale, parse_input_unit, parse_rate_unit

__all__ = ["Request", "Clock", "Usable", "Fitted", "Checked", "request", "windows", "time_base", "usable", "fit", "check", "uncertainty"]


@dataclass(frozen=True)
class Request:
    """The checked question: the reference and its value [rad/s or rad], the method and its noise, the units."""

    reference: str
    value: float
    method: str
    noise_std: object
    input_units: str
    output_units: str


def request(rec: Recording, speed, angle, method: str, noise_std, reference_sd, output_units) -> Request:
    """Owns the arguments: exactly one reference, options the method takes, units known."""
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
    if method not in values(Method):
        raise InputError(f"{{param}}={method!r} is not one of {', '.join(values(Method))}", param="method",
                         value=method)
    input_units = parse_input_unit(rec.source_units, "recording source_units")
    out_units = parse_rate_unit(output_units or ("deg/s" if input_units == "counts" else input_units), "output_units")
    return Request(reference, value, method, noise_std, input_units, out_units)


def windows(rec: Recording, reference: str, value: float, given: Sequence[Window] | None, *,
            screen: bool) -> Segmentation:
    """Owns finding the windows: detected (plateaus or whole turns), or `given` ones with their references;
    `screen` leaves out given turns the others contradict (angle reference)."""
    if given is None:
        return segment(rec, reference=reference, speed=value if reference == "speed" else None, angle=value,
                       require=False)
    return given_windows(rec, given, reference, value if reference == "speed" else None,
                         value if reference == "angle" else None, screen=screen)


@dataclass(frozen=True)
class Clock:
    """The time base (None when not read) and what the window sums take from it."""

    base: TimeBase | None = None
    #: sample times rebuilt on the sensor's clock, for a log with gaps
    times: np.ndarray | None = None
    #: the sensor's regular period, for a log without gaps
    period: float | None = None
    #: whether the time is counted (a sample counter or stamps), as the plausibility checks read it
    counted: bool | None = None


def time_base(rec: Recording, read: bool) -> Clock:
    """Owns the time stamps: when `read`, the sensor clock under them, its gaps and late deliveries."""
    if not read:
        return Clock()
    tb = rec.time_base()
    # without gaps the clock's trapezoid weights are even (a window lasts count x period); only a clock
    # with gaps needs its sample times rebuilt
    return Clock(tb, tb.clock_times() if tb.gaps else None,
                 tb.clock_period if tb.regular_clock and not tb.gaps else None, tb.counted)


@dataclass(frozen=True)
class Usable:
    """The windows after screening, those the method fits, and the relative variance of each one's reference
    rate (a gap's bound, a declared turn accuracy; 0 for static windows)."""

    segmentation: Segmentation
    windows: Sequence[Window]
    rate_rel_var: tuple[float, ...] = ()


def usable(seg: Segmentation, rec: Recording, clock: Clock, reference: str, value: float, method: str, *,
           refuse_varying: bool, turn_sd: float | None) -> Usable:
    """Owns which windows the fit sees: none across a break, turns across a gap bounded or left out, enough
    of them for `method` (static ones for first-moment only), and, `refuse_varying`, no varying rate; and how
    well each one's reference rate is known (a gap's bound, each turn's declared accuracy `turn_sd` [rad])."""
    seg = screen_breaks(seg, rec.breaks if clock.base is None else clock.base.breaks)
    angle_var: dict = {}
    if clock.base is not None:
        seg, angle_var = screen_gaps(seg, rec, clock.base, reference, clock.times)
    uses_static = method == "first-moment"
    seg.require(static_allowed=uses_static, min_rotations=0 if uses_static else 6)
    used = seg.windows if uses_static else seg.rotations
    if refuse_varying:
        require_constant_rate(rec, used, seg.baseline, method)
    return Usable(seg, used, tuple(reference_variances(used, reference, value, turn_sd, angle_var)))


@dataclass(frozen=True)
class Fitted:
    """The estimate: the estimator of the method, the observations it fitted and their set, its fit."""

    estimator: object
    observations: tuple[Observation, ...]
    observation_set: ObservationSet
    result: FitResult


def fit(rec: Recording, clock: Clock, used: Sequence[Window], obs: tuple[Observation, ...], req: Request, *,
        wander: bool) -> Fitted:
    """Owns the estimate: the method's estimator on `obs`; with `wander`, whole turns whose axis wandered get the
    rotation they made, not the integral, and are refitted."""
    obs_set = ObservationSet.from_observations(obs)
    estimator = make_estimator(req.method, **({} if req.noise_std is None else {"noise_std": req.noise_std}))
    result = estimator.fit(obs_set)
    if wander:
        return Fitted(estimator, *follow_wander(rec, rec.t if clock.times is None else clock.times, used, obs,
                                                obs_set, result, estimator))
    return Fitted(estimator, obs, obs_set, result)


@dataclass(frozen=True)
class Checked:
    """A fit after the self-checks: widened or Birge-scaled, with what they found (None, empty when unchecked)."""

    fit: FitResult
    quality: GoodnessOfFit | None = None
    warnings: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    implausible: str | None = None
    #: the file's ``fit`` section (None when unchecked)
    section: dict | None = None


def check(fitted: Fitted, rec: Recording, use: Usable, clock: Clock, req: Request, *, declared: bool,
          noise_given: bool, reference_sd: float | None) -> Checked:
    """Owns the self-checks: goodness of fit, plausibility of k, the warnings and notes for people, and the
    file's ``fit`` section that records them.

    `declared`: the reference is the one given (not a windows file's angles); `noise_given` and
    `reference_sd` only add notes.
    """
    reference, value, used, obs = req.reference, req.value, use.windows, fitted.observations
    ctx = Context(units=req.input_units, counts_scale=rec.units == "counts", reference=reference,
                  declared=value if declared else math.nan, sample_rate=rec.sample_rate, has_time=rec.has_time,
                  sensitivity=rec.sensitivity, counted=clock.counted)
    scale = input_scale(req.input_units, rec.sensitivity, req.output_units)
    result, _, quality, warnings, notes = check_fit(fitted.result, fitted.observation_set, fitted.estimator,
                                                    [_label(w) for w in used], reference=reference, ctx=ctx,
                                                    input_scale=scale)
    warnings[1 if quality.warnings else 0:0] = list(use.segmentation.warnings) + single_turn_warnings(
        [w.axis for w in used if w.kind == "rotation"], reference, value if declared else None)
    notes += noise_notes(obs, reference, noise_given)
    if reference_sd:
        what = ("every turn's angle, {:g} deg" if reference == "angle" else
                "the speed, {:g} deg/s, common to every plateau (the three k move together)")
        notes.append("the 1-sigma includes the declared accuracy of " + what.format(math.degrees(reference_sd)))
    # every warning and note printed goes in the file too: a flagged calibration must not look clean there
    section = {**quality.to_document(), "warnings": list(warnings), "notes": list(notes),
               "sigma_covers": sigma_covers(obs, reference, noise_given)}
    return Checked(result, quality, tuple(warnings), tuple(notes), implausible(result.model.k, ctx), section)


def uncertainty(result: FitResult, *, speed_rel_sd: float | None, earth_rate: bool) -> FitResult:
    """Owns what the covariance adds after the checks: a known speed's relative error `speed_rel_sd`, common to
    every plateau, and (`earth_rate`) the Earth's rate, which sits in every reading and b takes in."""
    if speed_rel_sd:
        result = with_common_scale(result, speed_rel_sd)
    if earth_rate:
        result = with_earth_rate(result)
    return result


def _label(w: Window) -> str:
    if w.kind == "static":
        return "static"
    return w.label or (f"{'+' if w.sign >= 0 else '-'}{w.axis}" if w.axis else "rotation")
