"""The calibrate command's reference and noise flags in the library's units (rad/s, radians).

``--speed`` and ``--speed-sd`` are in the data's rate unit (``--output-units`` for counts), ``--angle``
and ``--angle-sd`` in degrees, ``--noise-std`` in the data's unit.
"""

from __future__ import annotations

import math

from ..errors import InputError

__all__ = ["density_to_internal", "noise_to_internal", "rate_unit_of", "reference_of"]


def rate_unit_of(units: str, output_units: str | None) -> str:
    """The rate unit of user-facing numbers: --speed, corrected rates (deg/s for counts by default)."""
    from ..units import parse_rate_unit

    if output_units is not None:
        return parse_rate_unit(output_units, "output_units")
    return "deg/s" if units == "counts" else units


def reference_of(speed: float | None, angle: float | None, rate_unit: str, *, speed_sd: float | None = None,
                 angle_sd: float | None = None) -> tuple[str, float | None, float | None, float | None]:
    """``(reference, speed [rad/s], angle [rad], reference accuracy [rad/s or rad])`` from the user's flags."""
    from ..units import unit_factor

    if speed is not None and angle is not None:
        raise InputError(f"give --speed or --angle, not both (got --speed {speed:g} and --angle {angle:g})")
    for name, value in (("--speed", speed), ("--angle", angle)):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise InputError(f"{name} must be a positive number, got {value:g}")
    for name, value in (("--speed-sd", speed_sd), ("--angle-sd", angle_sd)):
        if value is not None and not (math.isfinite(value) and value >= 0):
            raise InputError(f"{name} must be a number >= 0, got {value:g}")
    if speed is not None:
        if angle_sd is not None:
            raise InputError("--angle-sd is the accuracy of turn angles; with --speed give --speed-sd")
        return "speed", speed * unit_factor(rate_unit), None, None if speed_sd is None else speed_sd * unit_factor(rate_unit)
    if speed_sd is not None:
        raise InputError("--speed-sd is the accuracy of a known speed (--speed); for turn angles give --angle-sd")
    return "angle", None, math.radians(360.0 if angle is None else angle), \
        None if angle_sd is None else math.radians(angle_sd)


def noise_to_internal(text: str | None, units: str, rate_unit: str, sensitivity: float | None) -> float | None:
    """--noise-std (the data's unit unless a unit is written) in the recording's internal unit."""
    from ..units import unit_factor
    from ._options import in_unit

    if text is None:
        return None
    try:
        noise_std = float(text)
    except ValueError:  # written with its unit
        noise_std = in_unit("--noise-std", text, "rad/s")
        if units == "counts" and sensitivity is None:
            raise InputError(f"--noise-std {text} is a rate; with --units counts give --sensitivity, or the noise "
                             "in counts") from None
        units, sensitivity = "rad/s", None
    if not (math.isfinite(noise_std) and noise_std > 0):
        raise InputError(f"--noise-std must be a positive number, got {noise_std:g}")
    if units != "counts":
        return noise_std * unit_factor(units)
    return noise_std if sensitivity is None else noise_std / sensitivity * unit_factor(rate_unit)


def density_to_internal(noise_density: str, noise_std: float | None, rec):
    """--noise-density (rad/s/sqrt(Hz), per axis) as per-sample noise [rad/s] at the recording's rate."""
    from ..noise.document import noise_density_arg

    if noise_std is not None:
        raise InputError("give --noise-std or --noise-density, not both")
    if rec.units == "counts":
        raise InputError("--noise-density needs physical units; give --sensitivity with --units counts")
    density = noise_density_arg(noise_density)
    if not all(d > 0 for d in density):
        axes = ", ".join(a for a, d in zip("xyz", density) if not d > 0)
        raise InputError(f"{{param}} {noise_density} gives a zero noise density on {axes}, which would give a zero "
                         "1-sigma (a noise file of all-zero or constant data?)", param="noise_density",
                         value=noise_density, hint="measure the noise on a real static log (gyrocal noise), or "
                         "leave {param} out to estimate it from the windows")
    return density * math.sqrt(rec.sample_rate)
