"""Noise of an IMU at rest: Allan deviation, the three IEEE Std 952 figures with intervals.

:func:`characterise` checks the log (physical units, no constant axis, at rest: a log that
moves is cut to its longest still stretch with a warning), computes the overlapping Allan
deviation of each gyro and accelerometer axis (``allantools``) and reads the white-noise
density, the bias instability and the random walk of the bias for each axis and for the
sensor, each with a confidence interval from the equivalent degrees of freedom. The report's
file is :mod:`gyrocal.noise.document` (``save_noise``, ``load_noise``, ``noise_density_arg``).

Layer 7 (the methods) of docs/architecture.md: imports the package root and layers 1 to 7 only.
"""

from .allan import ONE_SIGMA, allan_deviation
from .analyse import MotionPolicy, NoiseWarning, characterise, characterise_recording
from .figures import BI_FACTOR, Figure
from .report import FORMAT, VERSION, NoiseReport, SensorNoise

__all__ = [
    "BI_FACTOR",
    "FORMAT",
    "ONE_SIGMA",
    "VERSION",
    "Figure",
    "MotionPolicy",
    "NoiseReport",
    "NoiseWarning",
    "SensorNoise",
    "allan_deviation",
    "characterise",
    "characterise_recording",
]
