"""Into the tools people already use: flight-stack thermal parameters and VIO noise files.

* :func:`fit_thermal_bias`: gyro bias against temperature from a still log of a warming board
  (what PX4 and ArduPilot calibrate), order by leave-one-temperature-segment-out error, with
  its uncertainty; :func:`bias_from_thermal` takes the bias part of a turntable calibration.
* :func:`px4_params`, :func:`ardupilot_params`: the parameter files those firmwares load,
  written so that they evaluate exactly gyrocal's bias polynomial.
* :func:`kalibr_yaml`, :func:`vins_yaml`, :func:`imu_utils_yaml`: noise files from a
  :class:`~gyrocal.noise.NoiseReport`.

The thermal-bias file is :mod:`gyrocal.flight.thermal_bias_document`; the exporters are registered by
:mod:`gyrocal.export.flight`.

Layer 7 (the methods) of docs/architecture.md: imports the package root and layers 1 to 7 only.
"""

from .firmware_params import ardupilot_params, px4_params
from .from_table import ScaleNotCarriedWarning, bias_from_thermal
from .temperature import TemperatureCourse, temperature_course
from .thermal_bias import MAX_ORDER, AccelDrift, ThermalBias, ThermalBiasWarning, fit_thermal_bias
from .vio import imu_utils_yaml, kalibr_yaml, vins_yaml, vio_values

__all__ = [
    "MAX_ORDER",
    "AccelDrift",
    "ScaleNotCarriedWarning",
    "TemperatureCourse",
    "ThermalBias",
    "ThermalBiasWarning",
    "ardupilot_params",
    "bias_from_thermal",
    "fit_thermal_bias",
    "imu_utils_yaml",
    "kalibr_yaml",
    "px4_params",
    "temperature_course",
    "vins_yaml",
    "vio_values",
]
