"""What a calibration saw of its data, and the check that later data look like the same sensor
in the same unit.

A calibration in deg/s applied to a log in rad/s reads nothing wrong: the numbers are only 57
times too small, and the correction is silently wrong. The calibration file therefore records
its data's quiet noise level and rate range (the ``observed`` section, in input units); data to
correct are compared with them. The noise level is what identifies a unit: it does not depend on
how the sensor moved, and no setting of the same sensor changes it by a factor of 57.

The noise level is the per-sample standard deviation of the quiet stretches (see
:func:`quiet_noise`). A log's quiet parts are the sensor's noise; a standard deviation, unlike
successive differences, is not lowered by a sensor's low-pass filter.
"""

from __future__ import annotations

import math

import numpy as np

from .._arrays import median, percentile
from ..errors import UnitError
from ..units import unit_factor

__all__ = ["QUIET_BLOCK", "quiet_noise", "observe", "observed_section", "check_observed"]

#: Length of the blocks whose standard deviations give the noise level [s].
QUIET_BLOCK = 0.5
#: A change of noise level that no unit explains stays within this factor (filters, rates, sensors).
_SAME = 8.0
#: A measured ratio is read as a unit's factor when within this factor of it.
_NEAR = 3.0
_DEG = math.degrees(1.0)  # deg/s per rad/s


def quiet_noise(raw: np.ndarray, sample_rate: float) -> np.ndarray:
    """Per-axis noise of the quietest stretches of ``raw`` (N, 3) [its units].

    Blocks of :data:`QUIET_BLOCK` seconds (at least 8 samples) whose standard deviation is within
    1.5 times the 10th percentile of all blocks' are the quiet ones; their pooled standard
    deviation is the noise (a white-noise block's scatters by 1/sqrt(2 n), far less than 1.5
    times). With fewer than two blocks, the standard deviation of the whole record.
    """
    raw = np.asarray(raw, dtype=float)
    size = max(8, int(round(QUIET_BLOCK * sample_rate)))
    blocks = len(raw) // size
    if blocks < 2:
        return np.std(raw, axis=0)
    cut = raw[: blocks * size]
    var = np.stack([cut[:, j].reshape(blocks, size).var(axis=1, ddof=1) for j in range(raw.shape[1])], axis=1)
    quiet = var <= (1.5 * np.sqrt(percentile(var, 10, axis=0))) ** 2
    return np.sqrt(np.sum(np.where(quiet, var, 0.0), axis=0) / np.sum(quiet, axis=0))


def observed_section(rec, tb, input_scale: float, input_units: str, quiet_sample: np.ndarray) -> dict:
    """What a calibration saw (the file's ``observed`` section), rates in the input units.

    `input_scale` is internal units per input unit; `quiet_sample` the readings the quiet noise is measured
    on (spread blocks of the recording). ``noise_std``, the noise behind the fit, is left as None for the
    result to fill.
    """
    # up to 20 000 evenly spread samples (every 50 ms at 1 kHz: a turn's rate lasts longer); the order of
    # magnitude is what a unit check needs
    sample = np.ascontiguousarray(rec.gyro[:: max(1, len(rec) // 20_000)].T)  # one row per axis, one pass
    peak = np.maximum(sample.max(axis=1), -sample.min(axis=1))
    return {"sample_rate": rec.sample_rate, "units": input_units, "noise_std": None,
            "max_abs_rate": (peak / input_scale).tolist(), "time_base": tb.to_document(),
            # the noise of the quiet stretches, measured as apply measures the data it corrects
            "quiet_noise_std": (quiet_noise(quiet_sample, rec.sample_rate) / input_scale).tolist()}


def observe(raw: np.ndarray, sample_rate: float, units: str) -> dict:
    """The facts :func:`check_observed` compares, from data ``raw`` (N, 3) [input `units`]."""
    raw = np.asarray(raw, dtype=float)
    return {"sample_rate": float(sample_rate), "quiet_noise_std": quiet_noise(raw, sample_rate).tolist(),
            "max_abs_rate": np.max(np.abs(raw), axis=0).tolist(), "units": units}


def _ratio(observed, raw: np.ndarray, sample_rate: float, scale: float) -> tuple[float, np.ndarray, np.ndarray]:
    """Median over axes of the noise ratio (data times `scale` / calibration), and both noise levels."""
    # the calibration's quiet noise, measured as here; else the noise behind its 1-sigma
    then = np.asarray(observed.get("quiet_noise_std") or observed["noise_std"], dtype=float)
    now = quiet_noise(raw, sample_rate) * abs(scale)
    ok = (then > 0) & (now > 0)  # quantised quiet data can read zero: no evidence
    return (float(median(now[ok] / then[ok])) if ok.any() else math.nan), now, then


def _near(ratio: float, factor: float) -> bool:
    return abs(math.log(ratio / factor)) <= math.log(_NEAR)


def check_observed(observed, raw: np.ndarray, sample_rate: float, *, source: str, calibration: str,
                   sensitivity: float | None = None, output_units: str | None = None,
                   scale: float = 1.0) -> str | None:
    """Refuse data that look like another unit than the calibration's; return a warning for data
    whose noise differs from the calibration's by more than a factor 8 without a unit to explain it.

    Parameters
    ----------
    observed : mapping
        The calibration's ``observed`` section: ``quiet_noise_std`` (else ``noise_std``) and
        ``max_abs_rate`` per axis in ``units`` (the calibration's input unit).
    raw : array_like, shape (N, 3)
        The data to correct, as read in the calibration's input unit.
    sample_rate : float
        Their rate [Hz].
    source, calibration : str
        Names of the data and of the calibration file, for the message.
    sensitivity, output_units : optional
        The calibration's sensitivity [LSB per `output_units`], when its input is counts.
    scale : float
        Factor taking `raw` to the calibration's input unit (no scaled copy of a long log is made).

    Returns
    -------
    str or None
        A warning, or None when the data look like the calibration's.

    Raises
    ------
    UnitError
        The noise level (and, for the loud direction, the rate range) points to another unit.
    """
    units = observed["units"]
    raw = np.asarray(raw, dtype=float)
    if len(raw) and np.all(raw == raw[0]):
        return (f"{source}: every reading is the same ({_shown(raw[0] * scale)} {units}): the sensor was not running, "
                "or the columns are not the gyro's; the corrected file holds nothing but the calibration's offsets")
    q, now, then = _ratio(observed, raw, sample_rate, scale)
    if not math.isfinite(q) or 1 / _SAME <= q <= _SAME:
        return None
    if scale != 1.0:
        raw = raw * scale  # a warning or a refusal follows: the copy is worth its cost here
    peak_now = np.max(np.abs(raw), axis=0)
    peak_then = np.asarray(observed["max_abs_rate"], dtype=float)
    r = float(median(peak_now / np.where(peak_then > 0, peak_then, np.nan))) if (peak_then > 0).any() else math.nan
    facts = (f"their noise is {_shown(now)} per sample against {_shown(then)} {units} in the calibration's data "
             f"({q:.3g} times), and they reach {_shown(peak_now)} against {_shown(peak_then)} {units}")
    likely = _likely_unit(units, q, r, integers=bool(np.array_equal(raw, np.round(raw))), sensitivity=sensitivity,
                          output_units=output_units)
    if likely is not None:
        convertible = likely in ("deg/s", "rad/s") and (units != "counts" or sensitivity is not None)
        hint = "give {param} " + likely + " (gyrocal converts them)" if convertible else f"convert them to {units} first"
        raise UnitError(f"{source}: the data look like {likely}, not {units} as {calibration} expects: {facts}",
                        param="units", value=units, hint=hint + ", or {param:check_units} to apply anyway")
    return (f"{source}: the data's noise differs from the calibration's by {q:.3g} times ({facts}); "
            f"are they from the same sensor, in {units}, at the same settings?")


def _shown(values) -> str:
    return ", ".join(f"{v:.3g}" for v in np.asarray(values, dtype=float))


def _likely_unit(units: str, q: float, r: float, *, integers: bool, sensitivity: float | None,
                 output_units: str | None) -> str | None:
    """The unit the data seem to be in, from the noise ratio `q` and the peak ratio `r` (data / calibration)."""
    if units == "deg/s" and q < 1 and _near(q, 1 / _DEG):
        return "rad/s"  # quieter by 57: nothing but the unit does that
    if units == "rad/s" and q > 1 and _near(q, _DEG) and math.isfinite(r) and _near(r, _DEG):
        return "deg/s"  # louder could be motion: the rate range must agree
    if units in ("deg/s", "rad/s") and q > _SAME and integers:
        return "counts"
    if units == "counts" and q < 1 / _SAME:
        if sensitivity is not None and output_units is not None:
            for unit in ("deg/s", "rad/s"):  # one count is unit_factor(out) / sensitivity rad/s
                if _near(q, unit_factor(output_units) / (unit_factor(unit) * sensitivity)):
                    return unit
        return "deg/s or rad/s"
    return None
