"""Full-temperature-range calibration (the full-temperature-range method), end to end.

Turntable recordings -> steps (:mod:`.session`) -> per-temperature 12-parameter
least squares (:mod:`.fit`) -> a temperature table with 3-node Lagrange
interpolation (:mod:`.lagrange`) and a smooth polynomial alternative
(:mod:`.smooth`) -> compensation and file (:mod:`.model`) -> evaluation against a
reference (:mod:`.evaluate`, :mod:`.report`).

Layer 7 (the methods) of docs/architecture.md: imports the package root and layers 1 to 7 only.
"""

from ._warn import DroppedStepsWarning, SaturatedStepsWarning, ThermalRangeWarning, ThermalWarning
from .calibrate import calibrate_thermal, table_from_fit
from .fit import PointFit, ThermalFit, fit_point, fit_session
from .lagrange import interpolate, lagrange_weights
from .model import ThermalCalibration
from .session import Steps, find_steps, session_steps
from .smooth import SmoothModel, fit_smooth
from .tempfilter import smooth_temperature

__all__ = [
    "DroppedStepsWarning",
    "PointFit",
    "SaturatedStepsWarning",
    "SmoothModel",
    "Steps",
    "ThermalCalibration",
    "ThermalFit",
    "ThermalRangeWarning",
    "ThermalWarning",
    "calibrate_thermal",
    "find_steps",
    "fit_point",
    "fit_session",
    "fit_smooth",
    "interpolate",
    "lagrange_weights",
    "session_steps",
    "smooth_temperature",
    "table_from_fit",
]
