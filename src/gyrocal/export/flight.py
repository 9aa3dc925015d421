"""Exporters of noise and thermal-bias files into the tools people already use.

``kalibr``, ``vins``, ``imu_utils`` take a noise file (:class:`~gyrocal.noise.NoiseReport`);
``px4`` and ``ardupilot`` take a thermal-bias file (:class:`~.thermal_bias.ThermalBias`) or the
bias part of a turntable calibration (``gyrocal.thermal``, with a warning that scale and
misalignment against temperature are left behind). The text itself comes from
:mod:`gyrocal.flight.vio` and :mod:`gyrocal.flight.firmware_params`.
"""

from __future__ import annotations

from .._validation import refuse_options
from ..flight.firmware_params import ardupilot_params, px4_params
from ..flight.from_table import bias_from_thermal
from ..flight.thermal_bias import ThermalBias
from ..flight.vio import imu_utils_yaml, kalibr_yaml, vins_yaml
from ..noise.report import NoiseReport
from ..thermal.model import ThermalCalibration
from . import register_exporter

__all__ = ["ardupilot", "imu_utils", "kalibr", "px4", "vins"]

_GIVEN = ("inflate", "accel_noise_density", "accel_random_walk", "gyro_random_walk", "use_bound")


def kalibr(report: NoiseReport, **options) -> str:
    """Kalibr's ``imu.yaml`` (see :func:`.vio.kalibr_yaml`)."""
    refuse_options(options, ("rostopic", "update_rate", *_GIVEN), "kalibr export")
    return kalibr_yaml(report, **options)


def vins(report: NoiseReport, **options) -> str:
    """The VINS ``acc_n, gyr_n, acc_w, gyr_w`` block (see :func:`.vio.vins_yaml`)."""
    refuse_options(options, ("update_rate", *_GIVEN), "vins export")
    return vins_yaml(report, **options)


def imu_utils(report: NoiseReport, **options) -> str:
    """imu_utils' parameter file (see :func:`.vio.imu_utils_yaml`)."""
    refuse_options(options, ("name", "inflate"), "imu_utils export")
    return imu_utils_yaml(report, **options)


def _bias(obj) -> ThermalBias:
    return bias_from_thermal(obj) if isinstance(obj, ThermalCalibration) else obj


def px4(obj, *, slot: int | None = None, device_id: int | None = None, accel_device_id: int | None = None,
        **options) -> str:
    """PX4 ``TC_G`` (and ``TC_A``) parameters; `slot` defaults to the log's IMU instance (0 otherwise)."""
    refuse_options(options, (), "px4 export")
    tb = _bias(obj)
    return px4_params(tb, instance=tb.source.get("instance", 0) if slot is None else slot, device_id=device_id,
                      accel_device_id=accel_device_id)


def ardupilot(obj, *, slot: int | None = None, caltemp: float | None = None, **options) -> str:
    """ArduPilot ``INS_TCAL`` parameters; `slot` (1..3) defaults to the log's IMU (1 otherwise)."""
    refuse_options(options, (), "ardupilot export")
    tb = _bias(obj)
    default = tb.source.get("imu_number", tb.source.get("instance", 0) + 1)
    return ardupilot_params(tb, imu=default if slot is None else slot, caltemp=caltemp)


register_exporter("kalibr", (NoiseReport,), kalibr, suffix=".yaml")
register_exporter("vins", (NoiseReport,), vins, suffix=".yaml")
register_exporter("imu_utils", (NoiseReport,), imu_utils, suffix=".yaml")
register_exporter("px4", (ThermalBias, ThermalCalibration), px4, suffix=".params")
register_exporter("ardupilot", (ThermalBias, ThermalCalibration), ardupilot, suffix=".parm")
