"""The noise file (``format: gyrocal.noise``, version 2): document, reading, writing.

Layout (SI units, recorded in ``units``; ``null`` for a figure not seen)::

    {
      "format": "gyrocal.noise", "version": 2, "confidence": 0.6827,
      "units": {"gyroscope": {...}, "accelerometer": {...}, "time": "s"},
      "sample_rate": 200.0, "samples": 720000, "duration": 3600.0,
      "analysed": {"start": 0.0, "stop": 3600.0, "log_duration": 3600.0, "motions_left_out": 0,
                   "temperature": {"min": 24.9, "max": 25.1, "span": 0.2, "unit": "degC"} or null},
      "source": {"file": "static.csv", "gyro_units": "deg/s", "accel_units": "g"},
      "gyroscope": {
        "x": {"density": {"value": .., "low": .., "high": .., "tau": 1.0, "edf": .., "tau_min": .., "tau_max": ..},
              "bias_instability": {...}, "random_walk": {...}, "random_walk_bound_95": null,
              "noise_std": ..},
        "y": {...}, "z": {...}, "sensor": {...},
        "taus": [...], "adev": {"x": [...], "y": [...], "z": [...], "sensor": [...]}
      },
      "accelerometer": null or the same,
      "warnings": [...], "method": "...", "created_by": "gyrocal 0.2.0"
    }

``density.tau_min``/``tau_max`` (the tau range its -1/2 line was fitted over; ``tau`` is 1 s, where
it is read, ``edf`` the fit's effective dof) are optional: files without them load, with NaN.
``analysed.temperature`` (the sensor temperature's range over the analysed stretch, null for a
log without one) is optional too: a version 2 file without it loads.
Version 1 files (gyro only, no intervals) are upgraded by :func:`upgrade_v1`, through
:mod:`gyrocal.results.legacy`. The ``--noise-density`` argument of several commands accepts such a
file (:func:`noise_density_arg`).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from .._jsonfile import check_header, get, read_json
from .._version import __version__
from ..errors import FileFormatError, InputError
from ..results.files import load, save
from .allan import ONE_SIGMA
from .figures import ROWS, Figure
from .report import FORMAT, VERSION, NoiseReport, SensorKind, SensorNoise

__all__ = ["from_document", "load_noise", "noise_density_arg", "save_noise", "to_document", "upgrade_v1"]

UNITS = {
    "gyroscope": {"density": "rad/s/sqrt(Hz)", "bias_instability": "rad/s", "random_walk": "rad/s^2/sqrt(Hz)",
                  "adev": "rad/s", "noise_std": "rad/s", "tau": "s"},
    "accelerometer": {"density": "m/s^2/sqrt(Hz)", "bias_instability": "m/s^2", "random_walk": "m/s^3/sqrt(Hz)",
                      "adev": "m/s^2", "noise_std": "m/s^2", "tau": "s"},
}
FIGURES = ("density", "bias_instability", "random_walk")
METHOD = ("overlapping Allan deviation (allantools.oadev); figures read on the IEEE Std 952 annex C lines, the density "
          "on the -1/2 line fitted over density.tau_min-tau_max and read at tau = 1 s; intervals from the equivalent "
          "degrees of freedom (Greenhall, allantools.edf_greenhall; the density's from its correlated points)")


def _num(x) -> float | None:
    return float(x) if np.isfinite(x) else None


def _sensor_doc(s: SensorNoise, fs: float) -> dict:
    doc: dict = {}
    std = s.noise_std(fs)
    for r, row in enumerate(ROWS):
        entry = {name: {key: _num(getattr(getattr(s, name), key)[r]) for key in ("value", "low", "high", "tau", "edf")}
                 for name in FIGURES}
        entry["density"].update(tau_min=_num(s.density.tau_min[r]), tau_max=_num(s.density.tau_max[r]))
        entry["random_walk_bound_95"] = _num(s.random_walk_bound[r])
        entry["noise_std"] = _num(std[r])
        doc[row] = entry
    doc["taus"] = s.taus.tolist()
    doc["adev"] = {row: s.adev[r].tolist() for r, row in enumerate(ROWS)}
    return doc


def _temperature_doc(report: NoiseReport) -> dict | None:
    if report.temperature is None:
        return None
    low, high = report.temperature
    return {"min": low, "max": high, "span": high - low, "unit": "degC"}


def _temperature_from(doc: dict, path) -> tuple[float, float] | None:
    """The optional ``analysed.temperature`` (absent in the first version 2 files)."""
    if (doc.get("analysed") or {}).get("temperature") is None:
        return None
    low, high = (_value(doc, f"analysed.temperature.{k}", path, positive=False) for k in ("min", "max"))
    if not low <= high:
        raise FileFormatError(f"{path}: field 'analysed.temperature' must hold numbers min <= max, got {low} and {high}",
                              "analysed.temperature")
    return low, high


def to_document(report: NoiseReport) -> dict:
    """The JSON-ready document of `report`."""
    fs = report.sample_rate
    return {
        "format": FORMAT, "version": VERSION, "confidence": report.confidence,
        "units": {"gyroscope": UNITS["gyroscope"], "accelerometer": UNITS["accelerometer"], "time": "s"},
        "sample_rate": fs, "samples": report.samples, "duration": report.duration,
        "analysed": {"start": report.start, "stop": report.stop, "log_duration": report.log_duration,
                     "motions_left_out": report.motions_left_out, "temperature": _temperature_doc(report)},
        "source": dict(report.source),
        "gyroscope": _sensor_doc(report.gyro, fs),
        "accelerometer": None if report.accel is None else _sensor_doc(report.accel, fs),
        "warnings": list(report.warnings),
        "method": METHOD,
        "created_by": f"gyrocal {__version__}",
    }


def _value(doc: dict, dotted: str, path, *, positive: bool = False) -> float:
    raw = get(doc, dotted, path)
    if raw is None and not positive:
        return math.nan
    if isinstance(raw, bool) or not isinstance(raw, (int, float)) or not math.isfinite(raw) or (positive and raw <= 0):
        want = "a number > 0" if positive else "a number or null"
        raise FileFormatError(f"{path}: field '{dotted}' must be {want}, got {raw!r}", dotted)
    return float(raw)


def _sensor_from(doc: dict, key: SensorKind, path) -> SensorNoise:
    taus = np.asarray(get(doc, f"{key}.taus", path), dtype=float)
    figures = {}
    for name in FIGURES:
        cols = [[_value(doc, f"{key}.{row}.{name}.{k}", path, positive=(name == "density" and k == "value"))
                 for k in ("value", "low", "high", "tau", "edf")] for row in ROWS]
        figures[name] = Figure(*np.array(cols).T)
    fitted = [[_value(doc, f"{key}.{row}.density.{k}", path) if k in doc[key][row]["density"] else math.nan
               for k in ("tau_min", "tau_max")] for row in ROWS]  # optional: older files lack them
    d = figures["density"]
    figures["density"] = Figure(d.value, d.low, d.high, d.tau, d.edf, *np.array(fitted).T)
    bound = [_value(doc, f"{key}.{row}.random_walk_bound_95", path) for row in ROWS]
    adev = []
    for row in ROWS:
        curve = np.asarray(get(doc, f"{key}.adev.{row}", path), dtype=float)
        if curve.shape != taus.shape or not np.all(curve > 0):
            raise FileFormatError(f"{path}: field '{key}.adev.{row}' must be {len(taus)} numbers > 0",
                                  f"{key}.adev.{row}")
        adev.append(curve)
    return SensorNoise(key, taus, np.array(adev), figures["density"], figures["bias_instability"],
                       figures["random_walk"], np.array(bound))


def from_document(doc: dict, path="file") -> NoiseReport:
    """Validate a version 2 document and rebuild the report, naming any bad field."""
    check_header(doc, path, FORMAT, (VERSION,))
    analysed = get(doc, "analysed", path)
    try:
        return NoiseReport(
            gyro=_sensor_from(doc, "gyroscope", path),
            accel=None if doc.get("accelerometer") is None else _sensor_from(doc, "accelerometer", path),
            sample_rate=_value(doc, "sample_rate", path, positive=True), samples=int(get(doc, "samples", path)),
            start=float(analysed.get("start", 0.0)), stop=float(analysed.get("stop", math.nan)),
            log_duration=float(analysed.get("log_duration", math.nan)),
            motions_left_out=int(analysed.get("motions_left_out", 0)),
            confidence=_value(doc, "confidence", path, positive=True), source=dict(doc.get("source") or {}),
            warnings=tuple(str(w) for w in doc.get("warnings") or ()), temperature=_temperature_from(doc, path))
    except (InputError, TypeError, ValueError, AttributeError) as exc:
        raise FileFormatError(f"{path}: {exc}") from None


def upgrade_v1(doc: dict, path="file") -> dict:
    """A version 1 document (gyro per axis, no intervals) as version 2.

    Version 1 held ``arw`` (the density), ``bias_instability``, ``bias_instability_tau``,
    ``rrw``, ``taus`` and ``adev`` per axis. The sensor row is the root mean square of the
    axes; intervals and edf are unknown (null).
    """
    check_header(doc, path, FORMAT, (1,))

    def triple(name, allow_null=True):
        value = get(doc, name, path)
        if not isinstance(value, list) or len(value) != 3:
            raise FileFormatError(f"{path}: field '{name}' must be a list of 3 numbers or nulls", name)
        arr = np.array([math.nan if v is None and allow_null else v for v in value], dtype=float)
        return np.append(arr, math.sqrt(np.mean(arr**2)))

    figures = {"density": (triple("arw"), None), "bias_instability": (triple("bias_instability"),
                                                                      triple("bias_instability_tau")),
               "random_walk": (triple("rrw"), None)}
    taus = np.asarray(get(doc, "taus", path), dtype=float)
    adev = np.asarray(get(doc, "adev", path), dtype=float)
    if adev.ndim != 2 or adev.shape != (3, len(taus)):
        raise FileFormatError(f"{path}: field 'adev' must be 3 rows of {len(taus)} numbers", "adev")
    sensor: dict = {"taus": taus.tolist(),
                    "adev": {row: c.tolist() for row, c in zip(ROWS, np.vstack([adev, np.sqrt(np.mean(adev**2, 0))]))}}
    for r, row in enumerate(ROWS):
        sensor[row] = {name: {"value": _num(v[r]), "low": None, "high": None,
                              "tau": None if t is None else _num(t[r]), "edf": None}
                       for name, (v, t) in figures.items()}
        sensor[row]["random_walk_bound_95"] = None
    return {"format": FORMAT, "version": VERSION, "confidence": ONE_SIGMA, "sample_rate": get(doc, "sample_rate", path),
            "samples": int(round(float(get(doc, "duration", path)) * float(get(doc, "sample_rate", path)))),
            "analysed": {"start": 0.0, "stop": get(doc, "duration", path), "log_duration": get(doc, "duration", path)},
            "gyroscope": sensor, "accelerometer": None, "warnings": ["read from a version 1 file: no intervals"]}


_DEG_SUFFIXES = ("deg/s/rthz", "deg/s/sqrt(hz)", "dps/rthz", "deg/s/√hz")




def save_noise(path: str | os.PathLike, report: NoiseReport) -> None:
    """Write a noise report as JSON (atomically)."""
    save(report, path)


def load_noise(path: str | os.PathLike) -> NoiseReport:
    """Read a noise file (version 2, or version 1 upgraded), validating every field.

    Every gyro density must be a number > 0: a zero density would make any
    uncertainty computed from it zero.
    """
    return load(path, NoiseReport)


def _zero_axes(path: str) -> list[str]:
    """The gyro axes whose density a noise file (version 1 or 2) gives as zero or less."""
    doc = read_json(path)
    if doc.get("version") == 1:
        values = doc.get("arw") or []
    else:
        values = [((doc.get("gyroscope") or {}).get(a) or {}).get("density", {}).get("value") for a in "xyz"]
    return [a for a, v in zip("xyz", values) if isinstance(v, (int, float)) and not v > 0]


def noise_density_arg(value: str) -> np.ndarray:
    """Parse a ``--noise-density`` option into a per-axis gyro density (3,) [rad/s/sqrt(Hz)].

    Accepts a number in rad/s/sqrt(Hz), a number followed by ``deg/s/rtHz``, or the
    path of a noise file written by ``gyrocal noise --json``.
    """
    text = str(value).strip()
    if text.lower().endswith(".json") or Path(text).is_file():
        try:
            return load_noise(text).density
        except FileFormatError as exc:
            zero = _zero_axes(text)
            if not zero:
                raise
            raise InputError(f"{{param}} {text} gives a zero noise density on {', '.join(zero)}, which would give a "
                             "zero 1-sigma (a noise file of all-zero or constant data?)", param="noise_density",
                             value=text, hint="measure the noise on a real static log (gyrocal noise)") from exc
    number, factor = text, 1.0
    for suffix in _DEG_SUFFIXES:
        if text.lower().endswith(suffix):
            number, factor = text[: -len(suffix)], math.pi / 180.0
    try:
        density = float(number) * factor
    except ValueError:
        raise InputError(
            f"--noise-density={value!r} is neither a number [rad/s/sqrt(Hz)], 'N deg/s/rtHz', nor a noise JSON file"
        ) from None
    if not density > 0 or not math.isfinite(density):
        raise InputError(f"--noise-density must be finite and > 0, got {value!r}")
    return np.full(3, density)
