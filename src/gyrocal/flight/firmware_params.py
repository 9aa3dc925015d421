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

The accelerometer's change from ``tref`` (:class:`~.curve.AccelDrift`), when the file holds
one, goes the same way into PX4's ``TC_A{i}_*`` (X0 = 0: zero at ``TC_A{i}_TREF``, as PX4's
onboard ``TemperatureCalibrationAccel`` writes it, so an accelerometer calibration made at TREF
stays valid; ``TC_A{i}_ID`` is the accelerometer's own device id) and into ArduPilot's
``INS_TCALn_ACC1..3`` (``correct_accel`` runs the same ``correct_sensor`` with
``INS_ACCn_CALTEMP``, then ``v -= INS_ACCOFFS``): only the change is written, never
``INS_ACCOFFS``, which one orientation cannot give.

Values are written as the shortest decimal that reads back as the same float32 (both
firmwares store float parameters), without exponents.
"""

from __future__ import annotations

import numpy as np

from .._validation import temperature
from .._version import __version__
from ..errors import InputError
from .curve import TemperaturePolynomial
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
    sensors = "gyro" if tb.accel is None else "gyro and accelerometer"
    grid = np.linspace(tb.tmin, tb.tmax, 25)
    out = [f"{firmware} {sensors} thermal compensation written by gyrocal {__version__} from {src}",
           f"bias fitted over {tb.tmin:.2f} to {tb.tmax:.2f} degC, orders x/y/z {'/'.join(map(str, tb.orders))}; "
           f"1-sigma of the curve up to {1e3 * float(tb.std_at(grid).max()):.3g} mrad/s"]
    if tb.accel is not None:
        out.append(f"accelerometer change from {tb.accel.tref:.2f} degC, orders x/y/z "
                   f"{'/'.join(map(str, tb.accel.orders))}; 1-sigma up to "
                   f"{1e3 * float(tb.accel.std_at(grid).max()):.3g} mm/s^2")
    return out + lines


def _device_id(dev, sensor: str, param: str, cal: str):
    if dev is None:
        raise InputError(f"PX4 applies TC_{sensor[0].upper()} parameters only to the {sensor} whose device id is "
                         f"TC_{sensor[0].upper()}i_ID, and this fit records none (it was not read from a ULog)",
                         param=param, hint=f"give the id (the {cal} value) with {{param}}")
    if not 0 <= int(dev) < 2**32:
        raise InputError(f"{{param}} {dev} is not a PX4 device id (a 32-bit unsigned number)", param=param,
                         value=dev, hint=f"give the {cal} value")
    return int(dev)


def _px4_rows(curve: TemperaturePolynomial, letter: str, i: int, dev: int, zero_at_tref: bool) -> list:
    """``TC_{letter}{i}_*`` rows: X0..X3 about TREF (the file's tref to 0.01 degC, as a float32)."""
    tref = float(np.float32(round(curve.tref, 2)))
    coefs = curve.coefficients_about(tref)
    if zero_at_tref:  # a change from tref stays a change from TREF: what the rounding moved is 1e-6 of it
        coefs[:, 0] = 0.0
    rows = [(f"TC_{letter}_ENABLE", "1", 6), (f"TC_{letter}{i}_ID", str(dev), 6),
            (f"TC_{letter}{i}_TMAX", f32(curve.tmax), 9), (f"TC_{letter}{i}_TMIN", f32(curve.tmin), 9),
            (f"TC_{letter}{i}_TREF", f32(tref), 9)]
    return rows + [(f"TC_{letter}{i}_X{n}_{a}", f32(coefs[a, n]), 9) for a in range(3) for n in range(MAX_ORDER + 1)]


def px4_params(tb: ThermalBias, *, instance: int = 0, device_id: int | None = None,
               accel_device_id: int | None = None) -> str:
    """PX4 parameters ``TC_G{instance}_*`` and ``TC_G_ENABLE`` carrying `tb` (and ``TC_A`` for its accelerometer).

    Parameters
    ----------
    tb : ThermalBias
    instance : int
        Calibration slot 0..3 (``TC_G0`` .. ``TC_G3``, and ``TC_A0`` .. ``TC_A3``).
    device_id : int, optional
        The gyro's device id (``TC_G{i}_ID``; PX4 applies the set only to that sensor).
        Default: the id recorded from a ULog; required otherwise.
    accel_device_id : int, optional
        The accelerometer's device id (``TC_A{i}_ID``), when `tb` holds an accelerometer part.
        Default: the id recorded from a ULog; required otherwise.
    """
    if not 0 <= int(instance) <= 3:
        raise InputError(f"{{param}}={instance!r}: PX4 has thermal slots TC_G0..TC_G3 and TC_A0..TC_A3",
                         param="slot", value=instance)
    dev = _device_id(device_id if device_id is not None else tb.source.get("device_id"), "gyro", "device_id",
                     "CAL_GYROn_ID")
    i = int(instance)
    rows = _px4_rows(tb, "G", i, dev, False)
    notes = [
        "offset = X0 + X1 d + X2 d^2 + X3 d^3 [rad/s], d = clip(T, TMIN, TMAX) - TREF, subtracted from sensor_gyro",
        f"the offset is the whole bias: keep CAL_GYRO offsets of device {dev} at 0 (a later gyro calibration "
        "shifts X0)"]
    if tb.accel is not None:
        adev = _device_id(accel_device_id if accel_device_id is not None else tb.source.get("accel_device_id"),
                          "accelerometer", "accel_device_id", "CAL_ACCn_ID")
        rows += _px4_rows(tb.accel, "A", i, adev, True)
        notes += [f"TC_A{i}: the change of the accelerometer offsets from TREF [m/s^2], zero at TREF (X0 = 0), "
                  "subtracted from sensor_accel;",
                  f"CAL_ACC offsets of device {adev} made at TREF stay valid; made elsewhere, calibrate again with "
                  "TC_A_ENABLE = 1"]
    text = [f"# {line}".rstrip() for line in _header(tb, "PX4", [*notes, "", "Vehicle-Id Component-Id Name Value "
                                                                            "Type"])]
    text += [f"1\t1\t{name}\t{value}\t{kind}" for name, value, kind in rows]
    return "\n".join(text) + "\n"


def _ardupilot_names(imu: int) -> tuple[str, str]:
    offs = "INS_GYROFFS" if imu == 1 else f"INS_GYR{imu}OFFS"
    return offs, f"INS_GYR{imu}_CALTEMP"


def _ardupilot_accel_note(tb: ThermalBias, n: int) -> str:
    if tb.accel is None:
        return "accelerometer temperature terms (ACC1..3) are not calibrated by this log: written as 0 (no correction)"
    return (f"ACC1..3: the change of the accelerometer offsets with temperature [m/s^2], applied as v -= P(T - 35) - "
            f"P(INS_ACC{n}_CALTEMP - 35) before INS_ACCOFFS; the offsets themselves are not written (one orientation "
            "cannot give them): keep the accelerometer calibration")


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
    if tb.accel is None:
        rows += [(f"INS_TCAL{n}_ACC{k}_{ax}", "0") for k in range(1, 4) for ax in "XYZ"]
    else:
        acc = tb.accel.coefficients_about(ARDUPILOT_TREF)  # the constant is dropped: the firmware's P has none
        rows += [(f"INS_TCAL{n}_ACC{k}_{ax}", f32(acc[a, k] * ARDUPILOT_SCALE)) for k in range(1, 4)
                 for a, ax in enumerate("XYZ")]
    rows += [(f"INS_TCAL{n}_GYR{k}_{ax}", f32(c35[a, k] * ARDUPILOT_SCALE)) for k in range(1, 4)
             for a, ax in enumerate("XYZ")]
    rows += [(f"{offs}_{ax}", f32(offset[a])) for a, ax in enumerate("XYZ")] + [(caltemp_name, f32(tcal))]
    notes = _header(tb, "ArduPilot", [
        "v -= P(T - 35) - P(Tcal - 35), P(x) = (GYR1 x + GYR2 x^2 + GYR3 x^3) 1e-6 [rad/s], T and Tcal clipped to "
        "[TMIN, TMAX]; then v -= INS_GYROFFS",
        f"{offs} holds the bias at Tcal = {caltemp_name}; ArduPilot recalibrates both at boot unless INS_GYR_CAL = 0",
        _ardupilot_accel_note(tb, n)])
    text = [f"# {line}".rstrip() for line in notes]
    text += [f"{name} {value}" for name, value in rows]
    return "\n".join(text) + "\n"
