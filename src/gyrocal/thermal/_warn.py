"""Warning classes of the thermal method; the command line prints them."""

from __future__ import annotations

from ..errors import GyrocalWarning

__all__ = ["DroppedStepsWarning", "SaturatedStepsWarning", "ThermalRangeWarning", "ThermalWarning"]


class ThermalWarning(GyrocalWarning):
    """Base class of the warnings the thermal method issues."""


class ThermalRangeWarning(ThermalWarning):
    """A temperature outside the calibrated range was clamped or extrapolated."""


class SaturatedStepsWarning(ThermalWarning):
    """Steps with samples at the gyro's full scale were left out of the fit."""


class DroppedStepsWarning(ThermalWarning):
    """Steps too short after settling, or at an unstable temperature, were left out."""
