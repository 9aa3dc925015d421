"""Independent evaluators of the flight stacks' thermal compensation, written from the firmware sources.

* PX4 ``TemperatureCompensation::calc_thermal_offsets_3D`` (src/modules/temperature_compensation):
  float32; ``d`` is the temperature clipped to [TMIN, TMAX] minus TREF;
  ``offset = x0 + x1 d + x2 d^2 + x3 d^3`` with ``d2 = d d``, ``d3 = d2 d``; the sensor reading
  minus the offset is the corrected rate (``calibration::Gyroscope::Correct``).
* ArduPilot ``AP_InertialSensor_TCal::correct_sensor`` (libraries/AP_InertialSensor/
  AP_InertialSensor_tempcal.cpp): float32; T and the calibration temperature both clipped to
  [TMIN, TMAX]; ``v -= P(T - 35) - P(Tcal - 35)``, ``P(x) = (c1 + (c2 + c3 x) x) x 1e-6``; then the
  backend subtracts ``INS_GYROFFS`` (``_rotate_and_correct_gyro``).
* The accelerometer goes the same ways: PX4's ``TC_A{i}`` set through the same
  ``calc_thermal_offsets_3D``; ArduPilot's ``correct_accel`` is ``correct_sensor`` with the
  ``ACC1..3`` coefficients and ``INS_ACCn_CALTEMP``, then ``accel -= INS_ACCOFFS`` and
  ``accel *= INS_ACCSCAL`` (``_rotate_and_correct_accel``).

Used by the exporter tests and by the DataFlash test, which writes logs corrected this way.
"""

import numpy as np

F32 = np.float32


def parse_px4(text: str) -> dict:
    assert "# Vehicle-Id Component-Id Name Value Type" in text
    params = {}
    for line in text.splitlines():
        if line.startswith("#"):
            continue
        vehicle, component, name, value, kind = line.split("\t")
        assert (vehicle, component) == ("1", "1") and kind in ("6", "9")
        params[name] = int(value) if kind == "6" else float(value)
    return params


def px4_offsets(params: dict, i: int, temp: np.ndarray, sensor: str = "G") -> np.ndarray:
    """calc_thermal_offsets_3D of PX4, in float32, for the TC_G (gyro) or TC_A (accelerometer) set."""
    tmin, tmax, tref = (F32(params[f"TC_{sensor}{i}_{k}"]) for k in ("TMIN", "TMAX", "TREF"))
    out = np.empty((len(temp), 3), dtype=np.float32)
    for j, t in enumerate(temp.astype(np.float32)):
        if t > tmax:
            d = F32(tmax - tref)
        elif t < tmin:
            d = F32(tmin - tref)
        else:
            d = F32(t - tref)
        d2 = F32(d * d)
        d3 = F32(d2 * d)
        for a in range(3):
            x = [F32(params[f"TC_{sensor}{i}_X{n}_{a}"]) for n in range(4)]
            out[j, a] = x[0] + x[1] * d + x[2] * d2 + x[3] * d3
    return out


def parse_ardupilot(text: str) -> dict:
    params = {}
    for line in text.splitlines():
        if line.startswith("#"):
            continue
        name, value = line.split(" ")
        params[name] = float(value)
        assert "e" not in value.lower()  # parameter editors read plain decimals
    return params


def ardupilot_correct(params: dict, n: int, temp: np.ndarray, gyro: np.ndarray, sensor: str = "GYR") -> np.ndarray:
    """correct_sensor of AP_InertialSensor_TCal, then the constant offsets (and for ACC the scale), in float32."""
    tmin, tmax = F32(params[f"INS_TCAL{n}_TMIN"]), F32(params[f"INS_TCAL{n}_TMAX"])
    c = np.array([[params[f"INS_TCAL{n}_{sensor}{k}_{ax}"] for ax in "XYZ"] for k in (1, 2, 3)], dtype=np.float32)
    offs = f"INS_{sensor}OFFS" if n == 1 else f"INS_{sensor}{n}OFFS"
    offset = np.array([params[f"{offs}_{ax}"] for ax in "XYZ"], dtype=np.float32)
    scal = "INS_ACCSCAL" if n == 1 else f"INS_ACC{n}SCAL"
    scale = np.array([params.get(f"{scal}_{ax}", 1.0) if sensor == "ACC" else 1.0 for ax in "XYZ"], np.float32)

    def poly(tdiff):
        return (c[0] + (c[1] + c[2] * tdiff) * tdiff) * tdiff * F32(1e-6)

    t = np.clip(temp.astype(np.float32), tmin, tmax)[:, None]
    cal = np.clip(F32(params[f"INS_{sensor}{n}_CALTEMP"]), tmin, tmax)
    v = gyro.astype(np.float32) - poly(t - F32(35.0)) + poly(cal - F32(35.0))
    return (v - offset) * scale


