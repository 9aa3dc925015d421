"""Noise files for visual-inertial tools: Kalibr, VINS-Mono / VINS-Fusion, imu_utils.

* **Kalibr** ``imu.yaml`` (Kalibr wiki, "IMU Noise Model" and "YAML formats"): continuous-time
  ``gyroscope_noise_density`` [rad/s/sqrt(Hz)] and ``accelerometer_noise_density``
  [m/s^2/sqrt(Hz)], the white-noise strengths; ``gyroscope_random_walk`` [rad/s^2/sqrt(Hz)] and
  ``accelerometer_random_walk`` [m/s^3/sqrt(Hz)], the strengths of the white noise whose
  integral is the bias (Brownian motion), i.e. the +1/2-slope line of the Allan deviation read
  at tau = 3 s; ``update_rate`` [Hz], which Kalibr uses to discretise them; ``rostopic``.
* **VINS** ``acc_n, gyr_n, acc_w, gyr_w``. VINS-Mono's pre-integration
  (``vins_estimator/src/factor/integration_base.h``) puts ``GYR_N^2`` on each of the two samples
  of a mid-point step and grows the bias variance by ``dt^2 GYR_W^2`` per step: both act as
  discrete-time values at the IMU rate (the config calls them the "measurement noise standard
  deviation" and the "bias random work noise standard deviation"; VINS-Mono issues #102 and
  #233 discuss the ambiguity). gyrocal writes the per-sample standard deviation
  ``n = density * sqrt(rate)`` and ``w = random_walk * sqrt(rate)`` (which makes the bias
  variance grow as the continuous model's), with the continuous values as comments. Because
  the pre-integration treats the two samples of each step as independent draws, its angle
  variance grows at half the continuous rate with that ``n``: use ``inflate`` >= sqrt(2) for
  the same growth.
* **imu_utils** ``<name>_imu_param.yaml`` (``src/imu_an.cpp``, ``writeYAML``): per axis and
  ``avg-axis`` (the mean of the three) ``gyr_n``/``acc_n``, the white-noise density at tau = 1 s
  (gyrocal's: the fitted -1/2 line there, with its range in a comment), and ``gyr_w``/``acc_w``,
  the *minimum* of the Allan deviation (``getBiasInstability``: the floor itself, not divided by
  0.664, and not a random walk); an axis whose curve never turns up gets the 95 % upper limit of
  its lowest point, said in a comment.

Kalibr and VINS need the accelerometer: without it in the noise file the values must come
from the caller (never invented). ``inflate`` multiplies every noise value (the safety factor
Kalibr users apply by hand) and is written into the file.
"""

from __future__ import annotations

import math
import re

import numpy as np

from .._version import __version__
from ..errors import InputError
from ..noise import BI_FACTOR, NoiseReport
from ..noise.allan import confidence, edf

__all__ = ["imu_utils_yaml", "kalibr_yaml", "vins_yaml", "vio_values"]

_SENSOR = 3  # row of the sensor figures
#: Kalibr's name -> the parameter that gives it.
_PARAM = {"accelerometer_noise_density": "accel_noise_density", "accelerometer_random_walk": "accel_random_walk",
          "gyroscope_random_walk": "gyro_random_walk"}


def _walk(sensor, name: str, given: float | None, use_bound: bool) -> tuple[float, str]:
    if given is not None:
        return float(given), "given by the user"
    value = float(sensor.random_walk.value[_SENSOR])
    if math.isfinite(value):
        lo, hi = sensor.random_walk.low[_SENSOR], sensor.random_walk.high[_SENSOR]
        return value, f"Allan +1/2 line at tau = {sensor.random_walk.tau[_SENSOR]:.4g} s, interval {lo:.4g}-{hi:.4g}"
    bound = float(sensor.random_walk_bound[_SENSOR])
    if use_bound and math.isfinite(bound):
        return bound, "not seen in the log: its 95 % upper bound from the longest averaging times"
    raise InputError(f"the {sensor.kind} random walk is not seen in this log (the Allan deviation never turns up)",
                     param="use_bound", hint=f"log longer, give it ({{param:{name}}}), or use its 95 % upper bound "
                                             f"{bound:.3g} ({{param}})")


def _density_note(d, r: int = _SENSOR) -> str:
    """Where a density came from: its fitted range (older files: the point it was read at)."""
    lo, hi = d.tau_min[r], d.tau_max[r]
    where = (f"fitted over tau {lo:.3g}-{hi:.3g} s, read at tau = 1 s" if math.isfinite(lo)
             else f"at tau = {d.tau[r]:.4g} s")
    return f"Allan -1/2 line {where}, interval {d.low[r]:.4g}-{d.high[r]:.4g}"


def vio_values(report: NoiseReport, *, inflate: float = 1.0, accel_noise_density: float | None = None,
               accel_random_walk: float | None = None, gyro_random_walk: float | None = None,
               use_bound: bool = False) -> dict[str, tuple[float, str]]:
    """The four continuous-time noise values [SI] with a note on where each came from.

    Keys: ``gyroscope_noise_density``, ``gyroscope_random_walk``, ``accelerometer_noise_density``,
    ``accelerometer_random_walk`` (Kalibr's names). Sensor figures (the three axes pooled),
    times `inflate`.
    """
    if not (math.isfinite(inflate) and inflate >= 1):
        raise InputError(f"{{param}} must be a factor >= 1, got {inflate!r}", param="inflate", value=inflate)
    a = report.accel
    if a is None and (accel_noise_density is None or accel_random_walk is None):
        raise InputError("the noise file has no accelerometer figures, and VIO tools need them",
                         param="accel_noise_density",
                         hint="run gyrocal noise on a log with ax, ay, az columns (and the accelerometer's unit), or "
                              "give both {param} [m/s^2/sqrt(Hz)] and the random walk [m/s^3/sqrt(Hz)]")
    g = report.gyro
    d = g.density
    out = {"gyroscope_noise_density": (float(d.value[_SENSOR]), _density_note(d)),
           "gyroscope_random_walk": _walk(g, "gyro_random_walk", gyro_random_walk, use_bound)}
    if accel_noise_density is not None:
        out["accelerometer_noise_density"] = (float(accel_noise_density), "given by the user")
    else:
        ad = a.density
        out["accelerometer_noise_density"] = (float(ad.value[_SENSOR]), _density_note(ad))
    out["accelerometer_random_walk"] = _walk(a, "accel_random_walk", accel_random_walk, use_bound)
    for key, (value, note) in out.items():
        if not (math.isfinite(value) and value > 0):
            name = "{param}" if key in _PARAM else key
            raise InputError(f"{name} must be > 0, got {value!r}", param=_PARAM.get(key), value=value)
        out[key] = (value * inflate, note)
    return out


#: A ROS graph resource name (ROS wiki, "Names"): what Kalibr's rostopic must be.
_ROS_NAME = re.compile(r"[~/]?[A-Za-z][A-Za-z0-9_]*(/[A-Za-z][A-Za-z0-9_]*)*")


def _rate(report: NoiseReport, update_rate: float | None) -> float:
    """The IMU rate the values are discretised for [Hz]: `update_rate`, or the log's."""
    rate = report.sample_rate if update_rate is None else float(update_rate)
    if not (math.isfinite(rate) and rate > 0):
        raise InputError(f"{{param}} must be > 0 Hz, got {update_rate!r}", param="update_rate", value=update_rate)
    return rate


def _source_lines(report: NoiseReport, inflate: float) -> list[str]:
    src = report.source.get("file", "a log")
    return [f"# written by gyrocal {__version__} from {src}: {report.duration:.0f} s at rest, "
            f"{report.sample_rate:g} Hz",
            f"# inflate: {inflate:g} (every noise value below is the measured one times this safety factor)"]


def kalibr_yaml(report: NoiseReport, *, rostopic: str = "/imu0", update_rate: float | None = None,
                inflate: float = 1.0, **given) -> str:
    """Kalibr's ``imu.yaml``. `given`: see :func:`vio_values`."""
    v = vio_values(report, inflate=inflate, **given)
    rate = _rate(report, update_rate)
    if not _ROS_NAME.fullmatch(rostopic):
        raise InputError(f"{{param}} {rostopic!r} is not a ROS topic name", param="rostopic", value=rostopic,
                         hint="letters, digits, _ and /, starting with a letter or /, e.g. /imu0")
    units = {"accelerometer_noise_density": "m/s^2/sqrt(Hz)", "accelerometer_random_walk": "m/s^3/sqrt(Hz)",
             "gyroscope_noise_density": "rad/s/sqrt(Hz)", "gyroscope_random_walk": "rad/s^2/sqrt(Hz)"}
    lines = _source_lines(report, inflate)
    for key in units:
        value, note = v[key]
        lines.append(f"{key + ':':29s}{value:.6e}  # [{units[key]}] continuous time; {note}")
    lines.append(f"{'rostopic:':29s}{rostopic}")
    lines.append(f"{'update_rate:':29s}{float(rate)!r}  # [Hz] for the discretisation of the values above")
    return "\n".join(lines) + "\n"


def vins_yaml(report: NoiseReport, *, update_rate: float | None = None, inflate: float = 1.0, **given) -> str:
    """The ``acc_n, gyr_n, acc_w, gyr_w`` block of a VINS-Mono / VINS-Fusion config."""
    v = vio_values(report, inflate=inflate, **given)
    rate = _rate(report, update_rate)
    root = math.sqrt(rate)
    lines = _source_lines(report, inflate) + [
        f"# discrete-time values at {rate:g} Hz, as VINS-Mono's integration_base.h uses them: the continuous",
        "# density and random walk (Kalibr's) times sqrt(rate); paste into the config's imu parameters"]
    for key, name in (("accelerometer_noise_density", "acc_n"), ("gyroscope_noise_density", "gyr_n"),
                      ("accelerometer_random_walk", "acc_w"), ("gyroscope_random_walk", "gyr_w")):
        value, _ = v[key]
        lines.append(f"{name}: {value * root:.6e}  # continuous {key} {value:.6e}")
    return "\n".join(lines) + "\n"


def _floor_bound(sensor, i: int, report: NoiseReport) -> float:
    """95 % upper limit of an axis's lowest Allan deviation point: its floor lies lower still."""
    j = int(np.argmin(sensor.adev[i]))
    dof = edf(-1, round(sensor.taus[j] * report.sample_rate), report.samples)
    return confidence(float(sensor.adev[i, j]), dof, 0.95)[1]


def _imu_utils_block(sensor, short: str, unit: str, inflate: float, report: NoiseReport) -> list[str]:
    d = sensor.density
    n = d.value[:3] * inflate
    w = sensor.bias_instability.value[:3] * BI_FACTOR * inflate  # the floor itself, as imu_utils writes it
    notes = [f"# {ax}-axis {short}_n: {_density_note(d, i)}" for i, ax in enumerate("xyz")]
    for i, ax in enumerate("xyz"):
        if not math.isfinite(w[i]):
            w[i] = _floor_bound(sensor, i, report) * inflate
            notes.append(f"# {ax}-axis {short}_w: the curve never turns up (still falls at tau = {sensor.taus[-1]:.4g} "
                         "s): 95 % upper bound of its lowest point, the floor is lower")
    rows = [("avg-axis", n.mean(), w.mean())] + [(f"{ax}-axis", n[i], w[i]) for i, ax in enumerate("xyz")]
    out = [f"{short.capitalize()}:", *notes, f'   unit: " {unit}"']
    for name, nv, wv in rows:
        out += [f"   {name}:", f"      {short}_n: {nv:.16e}", f"      {short}_w: {wv:.16e}"]
    return out


def imu_utils_yaml(report: NoiseReport, *, name: str = "imu", inflate: float = 1.0) -> str:
    """imu_utils' ``<name>_imu_param.yaml`` layout (``Acc`` left out when the log has no accelerometer)."""
    if not (math.isfinite(inflate) and inflate >= 1):
        raise InputError(f"{{param}} must be a factor >= 1, got {inflate!r}", param="inflate", value=inflate)
    lines = ["%YAML:1.0", *_source_lines(report, inflate),
             "# *_n: white-noise density, the -1/2 line fitted to the Allan deviation and read at tau = 1 s; "
             "*_w: minimum of the Allan deviation",
             "---", "type: IMU", f"name: {name}"]
    lines += _imu_utils_block(report.gyro, "gyr", "rad/s", inflate, report)
    if report.accel is None:
        lines.append("# no accelerometer in the log: no Acc block")
    else:
        lines += _imu_utils_block(report.accel, "acc", "m/s^2", inflate, report)
    return "\n".join(lines) + "\n"
