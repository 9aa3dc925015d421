"""Gyro thermal compensation as PX4 and ArduPilot parameter files.

PX4 (``TemperatureCompensation::calc_thermal_offsets_3D`` in
``src/modules/temperature_compensation/TemperatureCompensation.cpp``, and the user guide's
"Thermal Calibration and Compensation"): with ``d = clip(T, TC_Gi_TMIN, TC_Gi_TMAX) -
TC_Gi_TREF``, ``offset = X0 + X1 d + X2 d^2 + X3 d^3`` [rad/s] per axis, subtracted from the
``sensor_gyro`` reading (``calibration::Gyroscope::Correct``: ``data - thermal_offset -
offset``). Parameters ``TC_G{i}_X{n}_{axis}`` (axis 0, 1, 2 = x, y, z), ``TC_G{i}_TREF``,
``TMIN``, ``TMAX``; ``TC_G{i}_ID`` is the device id the set applies to; ``TC_G_ENABLE = 1``.
File syntax of ``Tools/process_sensor_caldata.py`` (QGroundControl): ``1<TAB>1<TAB>NAME<TAB>
VALUE<TAB>TYPE``, type 6 for int32, 9 for float.

ArduPilot (``AP_InertialSensor_TCal::correct_sensor`` in
``libraries/AP_InertialSensor/AP_InertialSensor_tempcal.cpp``): with ``T`` and the gyro
calibration temperature ``Tcal`` (``INS_GYRn_CALTEMP``) both clipped to ``[INS_TCALn_TMIN,
INS_TCALn_TMAX]``, ``v -= P(T - 35) - P(Tcal - 35)``, where ``P(x) = (c1 x + c2 x^2 + c3 x^3)
* 1e-6`` and ``c_k = INS_TCALn_GYRk_{X,Y,Z}`` (a cubic without constant term about a fixed
35 degC, scaled by 1e6 "so params are easy to work with in GUI parameter editors"); then
``v -= INS_GYROFFS`` (``AP_InertialSensor_Backend::_rotate_and_correct_gyro``). gyrocal writes
``P`` from its bias polynomial about 35 degC and the companion ``INS_GYROFFS = bias(Tcal)``, so
the firmware subtracts exactly ``bias(T)``. File syntax of ``Tools/scripts/tempcal_IMU.py``:
``NAME VALUE`` lines.

Values are written as the shortest decimal that reads back as the same float32 (both
firmwares store float parameters), without exponents.
"""

from __future__ import annotations

import numpy as np

from .._validation import temperature
from .._version import __version__
from ..errors import InputError
from .thermal_bias import MAX_ORDER, ThermalBias

__all__ = ["ARDUPILOT_TREF", "ardupilot_params", "f32", "px4_params"]

#: ArduPilot's fixed reference temperature of the TCAL polynomial (TEMP_REFERENCE) [degC].
ARDUPILOT_TREF = 35.0
#: ArduPilot's coefficient scale (SCALE_FACTOR in AP_InertialSensor_tempcal.cpp).
ARDUPILOT_SCALE = 1.0e6


def f32(value: float) -> str:
    """The shortest positional decimal that reads back as the float32 nearest `value`."""
    return np.format_float_positional(np.float32(value), unique=True, trim="0")


def _header(tb: ThermalBias, firmware: str, lines: list[str]) -> list[str]:
    src = tb.source.get("file", "a log")
    out = [f"{firmware} gyro thermal compensation written by gyrocal {__version__} from {src}",
           f"bias fitted over {tb.tmin:.2f} to {tb.tmax:.2f} degC, orders x/y/z {'/'.join(map(str, tb.orders))}; "
           f"1-sigma of the curve up to {1e3 * float(tb.std_at(np.linspace(tb.tmin, tb.tmax, 25)).max()):.3g} mrad/s",
           *lines]
    return out


def px4_params(tb: ThermalBias, *, instance: int = 0, device_id: int | None = None) -> str:
    """PX4 parameters ``TC_G{instance}_*`` and ``TC_G_ENABLE`` carrying `tb`.

    Parameters
    ----------
    tb : ThermalBias
    instance : int
        Calibration slot 0..3 (``TC_G0`` .. ``TC_G3``).
    device_id : int, optional
        The gyro's device id (``TC_G{i}_ID``; PX4 applies the set only to that sensor).
        Default: the id recorded from a ULog; required otherwise.
    """
    if not 0 <= int(instance) <= 3:
        raise InputError(f"{{param}}={instance!r}: PX4 has gyro thermal slots TC_G0..TC_G3", param="slot",
                         value=instance)
    dev = device_id if device_id is not None else tb.source.get("device_id")
    if dev is None:
        raise InputError("PX4 applies TC_G parameters only to the gyro whose device id is TC_Gi_ID, and this fit "
                         "records none (it was not read from a ULog)", param="device_id",
                         hint="give the id (the CAL_GYROn_ID value) with {param}")
    if not 0 <= int(dev) < 2**32:
        raise InputError(f"{{param}} {dev} is not a PX4 device id (a 32-bit unsigned number)", param="device_id",
                         value=dev, hint="give the CAL_GYROn_ID value")
    i = int(instance)
    tref = float(np.float32(round(tb.tref, 2)))
    coefs = tb.coefficients_about(tref)
    rows = [("TC_G_ENABLE", "1", 6), (f"TC_G{i}_ID", str(int(dev)), 6), (f"TC_G{i}_TMAX", f32(tb.tmax), 9),
            (f"TC_G{i}_TMIN", f32(tb.tmin), 9), (f"TC_G{i}_TREF", f32(tref), 9)]
    rows += [(f"TC_G{i}_X{n}_{a}", f32(coefs[a, n]), 9) for a in range(3) for n in range(MAX_ORDER + 1)]
    notes = _header(tb, "PX4", [
        "offset = X0 + X1 d + X2 d^2 + X3 d^3 [rad/s], d = clip(T, TMIN, TMAX) - TREF, subtracted from sensor_gyro",
        f"the offset is the whole bias: keep CAL_GYRO offsets of device {int(dev)} at 0 (a later gyro calibration "
        "shifts X0)",
        "", "Vehicle-Id Component-Id Name Value Type"])
    text = [f"# {line}".rstrip() for line in notes]
    text += [f"1\t1\t{name}\t{value}\t{kind}" for name, value, kind in rows]
    return "\n".join(text) + "\n"


def _ardupilot_names(imu: int) -> tuple[str, str]:
    offs = "INS_GYROFFS" if imu == 1 else f"INS_GYR{imu}OFFS"
    return offs, f"INS_GYR{imu}_CALTEMP"


def ardupilot_params(tb: ThermalBias, *, imu: int = 1, caltemp: float | None = None) -> str:
    """ArduPilot parameters ``INS_TCAL{imu}_*`` with the ``INS_GYROFFS`` companion carrying `tb`.

    Parameters
    ----------
    tb : ThermalBias
    imu : int
        IMU number 1..3 as ArduPilot counts them (``INS_TCAL1`` is the first IMU).
    caltemp : float, optional
        Temperature of the constant gyro offsets [degC] (``INS_GYRn_CALTEMP``); default the
        middle of the fitted range.
    """
    if not 1 <= int(imu) <= 3:
        raise InputError(f"{{param}}={imu!r}: ArduPilot has temperature calibration sets INS_TCAL1..INS_TCAL3",
                         param="slot", value=imu)
    n = int(imu)
    tcal = float(np.float32(tb.tref if caltemp is None else temperature("caltemp", caltemp)))
    c35 = tb.coefficients_about(ARDUPILOT_TREF)
    offset = tb.bias_at([tcal])[0]  # what the firmware's constant offsets must hold at Tcal (clipped like T)
    offs, caltemp_name = _ardupilot_names(n)
    rows = [(f"INS_TCAL{n}_ENABLE", "1"), (f"INS_TCAL{n}_TMIN", f32(tb.tmin)), (f"INS_TCAL{n}_TMAX", f32(tb.tmax))]
    rows += [(f"INS_TCAL{n}_ACC{k}_{ax}", "0") for k in range(1, 4) for ax in "XYZ"]
    rows += [(f"INS_TCAL{n}_GYR{k}_{ax}", f32(c35[a, k] * ARDUPILOT_SCALE)) for k in range(1, 4)
             for a, ax in enumerate("XYZ")]
    rows += [(f"{offs}_{ax}", f32(offset[a])) for a, ax in enumerate("XYZ")] + [(caltemp_name, f32(tcal))]
    notes = _header(tb, "ArduPilot", [
        "v -= P(T - 35) - P(Tcal - 35), P(x) = (GYR1 x + GYR2 x^2 + GYR3 x^3) 1e-6 [rad/s], T and Tcal clipped to "
        "[TMIN, TMAX]; then v -= INS_GYROFFS",
        f"{offs} holds the bias at Tcal = {caltemp_name}; ArduPilot recalibrates both at boot unless INS_GYR_CAL = 0",
        "accelerometer temperature terms (ACC1..3) are not calibrated by this log: written as 0 (no correction)"])
    text = [f"# {line}".rstrip() for line in notes]
    text += [f"{name} {value}" for name, value in rows]
    return "\n".join(text) + "\n"
