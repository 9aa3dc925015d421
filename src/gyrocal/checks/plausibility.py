"""Is a calibration plausible? Scale factors far from 1 usually mean a declared fact was wrong.

A MEMS gyro's scale is trimmed at the factory to a few per cent (MPU-9250: +-3 % at 25 degC),
so in deg/s or rad/s a k more than 5 % from 1 is either a poor part or a mistake: a declared
angle or speed that was not what the robot did, a sample rate or time unit that is not the
log's, a rate unit that is not the data's. When all three axes move by one factor the cause
is common to them, and the factor says which (for example 1.25 = a 20 Hz log declared 25 Hz).

For raw counts without a sensitivity, k *is* the sensitivity; it is printed in LSB per deg/s
with the nearest standard full-scale setting of the common vendors, so a person can check it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Context", "STANDARD_SENSITIVITIES", "check_plausibility", "far_scale", "implausible", "nearest_setting",
           "still_units"]

#: |k - 1| beyond this for physical units raises a warning: the MPU-9250's trim (+-3 %) with room for noise
#: and temperature. At 10 % hand tilts of 48 deg declared 45 (k 6 % low) passed without a word.
K_TOLERANCE = 0.05
#: Axes within this of their common factor share one cause.
COMMON_SPREAD = 0.05
#: An implied sensitivity within this of a standard setting matches it (datasheet tolerance +-3 %).
SETTING_TOLERANCE = 0.05

#: The commands refuse (unless --accept-implausible) a k this far from 1 in physical units, or an implied
#: sensitivity this far from every vendor's setting.
K_REFUSE = 0.2
#: Output data rates of common gyros [Hz]: a common factor that lands the declared rate on one names the cause.
STANDARD_RATES = (10, 12.5, 20, 25, 50, 100, 104, 200, 208, 250, 400, 416, 500, 800, 833, 1000, 1600, 1666, 2000,
                  3200, 3333, 4000, 6664, 8000)
_DEG = 180 / math.pi

#: Standard gyro sensitivities [LSB per deg/s] by full scale [+-deg/s], from the datasheets:
#: InvenSense MPU-9250 (PS-MPU-9250A-01 rev 1.0, Table 1; the same for MPU-6050 and ICM-20602),
#: ST LSM6DSO (DS12140 rev 2, Table 2: 4.375 / 8.75 / 17.5 / 35 / 70 mdps/LSB),
#: Bosch BMI160 (BST-BMI160-DS000-07 rev 0.8, Table 2).
STANDARD_SENSITIVITIES: tuple[tuple[str, float, float], ...] = (
    ("InvenSense", 250, 131.0), ("InvenSense", 500, 65.5), ("InvenSense", 1000, 32.8), ("InvenSense", 2000, 16.4),
    ("ST", 125, 1000 / 4.375), ("ST", 250, 1000 / 8.75), ("ST", 500, 1000 / 17.5), ("ST", 1000, 1000 / 35.0),
    ("ST", 2000, 1000 / 70.0),
    ("Bosch", 125, 262.4), ("Bosch", 250, 131.2), ("Bosch", 500, 65.6), ("Bosch", 1000, 32.8), ("Bosch", 2000, 16.4),
    # Analog Devices iSensor: ADIS16405 0.05 deg/s per LSB, ADIS16448 0.04, ADIS16470 0.1 (16-bit output)
    ("ADI", 300, 20.0), ("ADI", 1000, 25.0), ("ADI", 2000, 10.0),
)


@dataclass(frozen=True)
class Context:
    """What a calibration was told, to judge its result against.

    Attributes
    ----------
    units : {"rad/s", "deg/s", "counts"}
        Unit of the data as declared.
    counts_scale : bool
        True when k holds the sensitivity (counts without one): k is [rad/s per count].
    reference : {"speed", "angle"}
    declared : float
        Declared speed [rad/s] or angle per turn [rad]; NaN when windows carried their own angles.
    sample_rate : float
        Nominal rate [Hz].
    has_time : bool
        Whether the time came from a time column (else from a declared sample rate).
    sensitivity : float or None
        Declared sensitivity [LSB per output unit], for counts.
    counted : bool
        Whether the time is a count of samples at a nominal rate (no time column, or stamps a sample
        counter made: :attr:`gyrocal.recording.timebase.TimeBase.counted`), not a clock's reading.
    """

    units: str
    counts_scale: bool
    reference: str
    declared: float
    sample_rate: float
    has_time: bool
    sensitivity: float | None = None
    counted: bool = False


def nearest_setting(lsb_per_dps: float) -> tuple[float, list[tuple[str, float, float]]]:
    """Relative distance to the nearest standard sensitivity and the settings there (all vendors)."""
    ratio = [abs(math.log(lsb_per_dps / s)) for _, _, s in STANDARD_SENSITIVITIES]
    best = min(ratio)
    near = [row for row, r in zip(STANDARD_SENSITIVITIES, ratio) if r <= best + 0.02]
    return math.expm1(best), near


def _settings_text(rows) -> str:
    by_scale: dict[tuple[float, float], list[str]] = {}
    for vendor, scale, s in rows:
        by_scale.setdefault((scale, round(s, 2)), []).append(vendor)
    return "; ".join(f"+-{scale:g} deg/s = {s:g} LSB/(deg/s) ({', '.join(v)})" for (scale, s), v in by_scale.items())


def _counts(k: np.ndarray) -> tuple[list[str], list[str]]:
    """Notes (and a warning when no standard setting fits) for counts without a sensitivity."""
    lsb = math.pi / 180.0 / k  # k [rad/s per count] -> counts per deg/s
    mean = float(np.exp(np.mean(np.log(lsb))))
    off, rows = nearest_setting(mean)
    per_axis = ", ".join(f"{a} {v:.4g}" for a, v in zip("xyz", lsb))
    note = (f"the scale factors imply a sensitivity of {mean:.4g} LSB per deg/s ({per_axis}); nearest standard "
            f"setting: {_settings_text(rows)}, {100 * off:.1f} % away")
    if off <= SETTING_TOLERANCE:
        return [], [note]
    return [note + f": no standard setting within {100 * SETTING_TOLERANCE:.0f} %; check the declared angle or "
            "speed, or give the sensitivity"], []


def _common_cause(c: float, ctx: Context, k: np.ndarray) -> str:
    ks = "/".join(f"{v:.4g}" for v in k)
    if ctx.reference == "angle":
        how = "short" if c > 1 else "long"
        ang = math.degrees(ctx.declared) if math.isfinite(ctx.declared) else None
        time = ("is the sample rate {:.3g} Hz rather than {:.4g} Hz, or the time column in other units?"
                if ctx.has_time else "is the sample rate {:.3g} Hz rather than the {:.4g} Hz declared?")
        text = (f"every turn reads {100 * abs(1 - 1 / c):.0f} % {how} (k = {ks}, a common factor {c:.4g}): if the "
                f"turns were as declared, the time base is off: " + time.format(ctx.sample_rate / c, ctx.sample_rate))
        if ang is not None:
            text += f" Otherwise the turns were {ang / c:.0f} deg, not {ang:g} deg"
        return text
    how = "slow" if c > 1 else "fast"
    text = (f"every plateau reads {100 * abs(1 - 1 / c):.0f} % {how} against the declared speed (k = {ks}, a common "
            f"factor {c:.4g}): is the speed {math.degrees(ctx.declared / c):.4g} deg/s rather than "
            f"{math.degrees(ctx.declared):.4g} deg/s?")
    if abs(math.log(c) - math.log(math.pi / 180)) < 0.05 or abs(math.log(c) - math.log(180 / math.pi)) < 0.05:
        text += " A factor of 57.3 is a deg/s against rad/s mix-up: check the units"
    elif ctx.sensitivity is not None:
        text += " Or the sensitivity is off by that factor"
    return text


def check_plausibility(k, ctx: Context) -> tuple[list[str], list[str]]:
    """Warnings and notes on fitted scale factors `k` (3,).

    Returns
    -------
    warnings, notes : list of str
    """
    k = np.abs(np.asarray(k, dtype=float))
    clock = [_counted_time(ctx)] if ctx.reference == "angle" and ctx.counted else []
    if ctx.counts_scale:
        warnings, notes = _counts(k)
        return warnings + clock, notes
    c = float(np.exp(np.mean(np.log(k))))
    common = bool(np.all(np.abs(np.log(k / c)) <= math.log1p(COMMON_SPREAD)))
    if common and abs(c - 1) > K_TOLERANCE:
        return [_common_cause(c, ctx, k)], []
    unit = "counts with the declared sensitivity" if ctx.units == "counts" else ctx.units
    what = "angle" if ctx.reference == "angle" else "speed"
    warnings = [
        f"k{a} = {v:.4g} is {100 * abs(v - 1):.0f} % from 1 for data in {unit}: a MEMS gyro is trimmed to a few "
        f"per cent, so the {a} turns may not be the declared {what} (see their measured sizes), or the gyro is poor"
        for a, v in zip("xyz", k) if abs(v - 1) > K_TOLERANCE
    ]
    return warnings + clock, []


def _counted_time(ctx: Context) -> str:
    """The warning for turn angles integrated on a time that counts samples at a nominal rate."""
    what = ("there is no time column: the rate is the declared one" if not ctx.has_time else
            f"the time column steps by exactly {1e3 / ctx.sample_rate:.6g} ms, a sample counter times the nominal rate")
    return (f"{what} ({ctx.sample_rate:.6g} Hz), and the turns' angles, so every k, are only as good as it: a MEMS chip's "
            "own oscillator runs off its nominal rate by a fraction of a per cent or more, far beyond k's 1-sigma, and "
            "a clock 0.5 % fast reads every k 0.5 % low. Stamp the samples with a PC's clock as they arrive (or measure "
            "the rate), or calibrate with a known speed (--speed), which does not depend on the time base")


def _lsb(k: np.ndarray) -> tuple[float, str]:
    lsb = math.pi / 180.0 / k  # k [rad/s per count] -> counts per deg/s
    return float(np.exp(np.mean(np.log(lsb)))), ", ".join(f"{a} {v:.4g}" for a, v in zip("xyz", lsb))


def _standard_rate(ctx: Context, c: float) -> bool:
    """Whether the rate a common factor `c` implies is a standard one (the declared rate was wrong)."""
    if ctx.reference != "angle" or (ctx.has_time and not ctx.counted):
        return False
    return any(abs(ctx.sample_rate / c / r - 1) < 0.005 for r in STANDARD_RATES)


def implausible(k, ctx: Context) -> str | None:
    """Why the commands refuse scale factors `k` (3,), or None: |k - 1| beyond :data:`K_REFUSE` for physical
    units, a common factor that lands the declared rate on a standard one, or (counts alone) a sensitivity
    farther than :data:`K_REFUSE` from every vendor's setting."""
    k = np.abs(np.asarray(k, dtype=float))
    if ctx.counts_scale:
        mean, per_axis = _lsb(k)
        off, rows = nearest_setting(mean)
        if off <= K_REFUSE:
            return None
        return (f"the scale factors imply a sensitivity of {mean:.4g} LSB per deg/s ({per_axis}), {100 * off:.0f} % from "
                f"the nearest vendor setting ({_settings_text(rows)}): no gyro is set so; check the declared angle or "
                "speed and the sample rate, or give the sensitivity")
    c = float(np.exp(np.mean(np.log(k))))
    common = bool(np.all(np.abs(np.log(k / c)) <= math.log1p(COMMON_SPREAD)))
    if common and abs(c - 1) > K_TOLERANCE and (abs(c - 1) > K_REFUSE or _standard_rate(ctx, c)):
        return _common_cause(c, ctx, k)
    unit = "counts with the declared sensitivity" if ctx.units == "counts" else ctx.units
    return far_scale(k, unit, "the {} turns were not the declared " + ("angle" if ctx.reference == "angle" else "speed"))


def far_scale(k, unit: str, cause: str) -> str | None:
    """The diagnosis for scale factors `k` (3,) more than :data:`K_REFUSE` from 1 in physical `unit`, or None.
    `cause` says what else may be wrong, ``{}`` standing for the axes."""
    k = np.abs(np.asarray(k, dtype=float))
    far = [(a, v) for a, v in zip("xyz", k) if abs(v - 1) > K_REFUSE]
    if not far:
        return None
    ks = ", ".join(f"k{a} = {v:.4g}" for a, v in far)
    c = float(np.exp(np.mean(np.log(k))))
    hint = ""
    if abs(math.log(c / _DEG)) < 0.05 or abs(math.log(c * _DEG)) < 0.05:
        hint = f" (a common factor {c:.4g}: a deg/s against rad/s mix-up, check the units)"
    return (f"{ks}: more than {100 * K_REFUSE:.0f} % from 1 for data in {unit}, which no MEMS gyro's trim comes near; "
            f"{cause.format(', '.join(a for a, _ in far))}, or the unit is wrong{hint}")


def still_units(bias, density, unit: str) -> str | None:
    """The diagnosis for a still log whose bias [deg/s] or white-noise density [deg/s/sqrt(Hz)] (3,), read as
    declared in `unit`, no MEMS gyro shows, or None: a zero-rate offset beyond 50 deg/s or a density beyond
    0.5 (deg/s read as rad/s), or a density below 2e-4 on every axis (rad/s read as deg/s: the quietest MEMS
    gyros, ADIS16495-class, reach 0.0015, and a chip's filter lowers the estimate by a few times at most)."""
    bias, density = np.abs(np.asarray(bias, dtype=float)), np.asarray(density, dtype=float)
    shown = (f"its bias reads {', '.join(f'{v:.3g}' for v in bias)} deg/s and its noise density "
             f"{', '.join(f'{v:.3g}' for v in density)} deg/s/sqrt(Hz) as declared in {unit}")
    if np.any(bias > 50) or np.any(density > 0.5):
        return (f"a still MEMS gyro's zero-rate offset stays within about 20 deg/s and its noise density below 0.1 "
                f"deg/s/sqrt(Hz), but {shown}: is the unit right (deg/s data declared rad/s read 57.3 times large)?")
    if np.all((density > 0) & (density < 2e-4)):
        return (f"no MEMS gyro is quieter than about 0.0015 deg/s/sqrt(Hz), but {shown}: is the unit right (rad/s "
                "data declared deg/s read 57.3 times small)?")
    return None
