"""Noise characterisation of a static recording with the Allan deviation.

The overlapping Allan deviation (computed by ``allantools``) is read the usual way
(IEEE Std 952, annex C):

* angle random walk ``N``: the -1/2 slope line read at ``tau = 1 s``; it equals the
  white-noise density [rad/s/sqrt(Hz)], and ``N * sqrt(fs)`` is the per-sample sigma;
* bias instability ``B``: the flat minimum divided by ``sqrt(2 ln 2 / pi) = 0.664``
  (NaN when the curve still falls at the longest averaging time);
* rate random walk ``K``: the +1/2 slope line read at ``tau = 3 s`` [rad/s/sqrt(s)].

Each line goes through the point whose local log-log slope is closest to the
line's slope, on the short-tau side of the minimum for ``N`` and on the long side for
``K``. ``K`` is NaN when the curve never turns up (record too short to see it).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ._arrays import readonly
from ._jsonfile import check_header, get, get_array, read_json, write_json
from ._validation import finite_array, positive
from .errors import FileFormatError, InputError, MissingDependencyError

__all__ = ["NoiseReport", "allan_deviation", "characterise", "save_noise", "load_noise", "noise_density_arg"]

FORMAT = "gyrocal.noise"
VERSION = 1
#: Flicker-floor factor: the Allan deviation of bias instability B levels at 0.664 B.
BI_FACTOR = math.sqrt(2.0 * math.log(2.0) / math.pi)


@dataclass(frozen=True)
class NoiseReport:
    """Allan-deviation noise figures of a static recording, per axis.

    Attributes
    ----------
    taus : ndarray, shape (m,)
        Averaging times [s].
    adev : ndarray, shape (3, m)
        Overlapping Allan deviation per axis [rad/s].
    arw : ndarray, shape (3,)
        Angle random walk = white-noise density [rad/s/sqrt(Hz)], i.e. [rad/sqrt(s)].
    bias_instability : ndarray, shape (3,)
        Bias instability [rad/s]; NaN where the record is too short to reach the floor.
    bias_instability_tau : ndarray, shape (3,)
        Averaging time of the flat minimum [s]; NaN likewise.
    rrw : ndarray, shape (3,)
        Rate random walk [rad/s/sqrt(s)]; NaN where no +1/2 slope is seen.
    sample_rate : float
        Sampling rate [Hz].
    duration : float
        Record length [s].
    """

    taus: np.ndarray
    adev: np.ndarray
    arw: np.ndarray
    bias_instability: np.ndarray
    bias_instability_tau: np.ndarray
    rrw: np.ndarray
    sample_rate: float
    duration: float

    def __post_init__(self):
        m = np.shape(self.taus)[0]
        for name, shape in (("taus", (m,)), ("adev", (3, m)), ("arw", (3,)), ("bias_instability", (3,)),
                            ("bias_instability_tau", (3,)), ("rrw", (3,))):
            arr = readonly(getattr(self, name), copy=True)
            if arr.shape != shape:
                raise InputError(f"{name} must have shape {shape}, got {arr.shape}")
            object.__setattr__(self, name, arr)

    @property
    def noise_std(self) -> np.ndarray:
        """Per-sample white-noise standard deviation (3,) [rad/s] at this record's rate."""
        return self.arw * math.sqrt(self.sample_rate)

    def to_dict(self) -> dict:
        """JSON-ready document (SI units, recorded in the file)."""
        def vec(a):
            return [None if not np.isfinite(x) else float(x) for x in np.ravel(a)]

        return {
            "format": FORMAT, "version": VERSION,
            "units": {"arw": "rad/s/sqrt(Hz)", "bias_instability": "rad/s", "rrw": "rad/s/sqrt(s)", "taus": "s",
                      "adev": "rad/s"},
            "sample_rate": self.sample_rate, "duration": self.duration,
            "arw": vec(self.arw), "noise_std": vec(self.noise_std),
            "bias_instability": vec(self.bias_instability), "bias_instability_tau": vec(self.bias_instability_tau),
            "rrw": vec(self.rrw),
            "taus": vec(self.taus), "adev": [vec(row) for row in self.adev],
        }


def _require_allantools():
    try:
        import allantools
    except ImportError:
        raise MissingDependencyError("Allan deviation needs allantools: pip install 'gyrocal[noise]'") from None
    return allantools


def allan_deviation(rates, sample_rate: float, *, points_per_decade: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """Overlapping Allan deviation of each axis.

    Parameters
    ----------
    rates : array_like, shape (N, 3)
        Static readings [rad/s].
    sample_rate : float
        Sampling rate [Hz].
    points_per_decade : int
        Log-spaced averaging times per decade.

    Returns
    -------
    taus : ndarray, shape (m,)
        Averaging times [s], from one sample to a ninth of the record.
    adev : ndarray, shape (3, m)
        Allan deviation [rad/s].
    """
    allantools = _require_allantools()
    w = finite_array("rates", rates, shape_tail=(3,), ndim=2)
    fs = positive("sample_rate", sample_rate)
    if len(w) < 100:
        raise InputError(f"a noise analysis needs at least 100 static samples, got {len(w)}")
    top = math.log10(len(w) / 9.0)
    m = np.unique(np.round(np.logspace(0, top, int(top * points_per_decade) + 1)).astype(int))
    taus = m / fs
    out = []
    for axis in range(3):
        t, ad, _, _ = allantools.oadev(w[:, axis], rate=fs, data_type="freq", taus=taus)
        if len(t) != len(taus):
            raise InputError("allantools dropped averaging times; the record is too short for a noise analysis")
        out.append(ad)
    return np.asarray(taus), np.asarray(out)


def _line_value(taus, adev, slope: float, at: float, side: np.ndarray) -> float:
    """Value at ``tau = at`` of the line of `slope` through the best-matching point on `side`."""
    lt, la = np.log(taus), np.log(adev)
    local = np.gradient(la, lt)
    if not side.any():
        return math.nan
    idx = np.flatnonzero(side)[np.argmin(np.abs(local[side] - slope))]
    if abs(local[idx] - slope) > 0.25:
        return math.nan
    return float(np.exp(la[idx] + slope * (math.log(at) - lt[idx])))


def characterise(rates, sample_rate: float, *, points_per_decade: int = 12) -> NoiseReport:
    """Allan deviation and the three noise figures of a static record.

    Parameters
    ----------
    rates : array_like, shape (N, 3)
        Readings of a gyro at rest [rad/s]; the Earth rate and the bias are
        constants and do not affect the Allan deviation.
    sample_rate : float
        Sampling rate [Hz].
    """
    taus, adev = allan_deviation(rates, sample_rate, points_per_decade=points_per_decade)
    arw, bi, bi_tau, rrw = (np.full(3, math.nan) for _ in range(4))
    for a in range(3):
        i_min = int(np.argmin(adev[a]))
        idx = np.arange(len(taus))
        arw[a] = _line_value(taus, adev[a], -0.5, 1.0, idx <= max(i_min, 1))
        if i_min < len(taus) - 2:  # a minimum at the record's end is not a flat floor yet
            bi[a], bi_tau[a] = adev[a, i_min] / BI_FACTOR, taus[i_min]
        rrw[a] = _line_value(taus, adev[a], 0.5, 3.0, idx >= i_min) if i_min < len(taus) - 2 else math.nan
    duration = len(np.asarray(rates)) / float(sample_rate)
    return NoiseReport(taus, adev, arw, bi, bi_tau, rrw, float(sample_rate), duration)


def save_noise(path: str | os.PathLike, report: NoiseReport) -> None:
    """Write a noise report as JSON (atomically)."""
    write_json(path, report.to_dict())


def load_noise(path: str | os.PathLike) -> NoiseReport:
    """Read a noise report written by :func:`save_noise`, validating every field."""
    doc = read_json(path)
    check_header(doc, path, FORMAT, (VERSION,))
    def maybe(name: str) -> np.ndarray:
        value = doc.get(name)
        if not isinstance(value, list) or len(value) != 3:
            raise FileFormatError(f"{path}: field '{name}' must be a list of 3 numbers or nulls", name)
        return np.array([math.nan if x is None else x for x in value], dtype=float)

    m = len(doc.get("taus") or [])
    return NoiseReport(
        taus=get_array(doc, "taus", (m,), path), adev=get_array(doc, "adev", (3, m), path),
        arw=get_array(doc, "arw", (3,), path), bias_instability=maybe("bias_instability"),
        bias_instability_tau=maybe("bias_instability_tau"), rrw=maybe("rrw"),
        sample_rate=float(get(doc, "sample_rate", path)), duration=float(get(doc, "duration", path)),
    )


_DEG_SUFFIXES = ("deg/s/rthz", "deg/s/sqrt(hz)", "dps/rthz", "deg/s/√hz")


def noise_density_arg(value: str) -> np.ndarray:
    """Parse a ``--noise-density`` option into a per-axis density (3,) [rad/s/sqrt(Hz)].

    Accepts a number in rad/s/sqrt(Hz), a number followed by ``deg/s/rtHz``, or the
    path of a noise JSON written by ``gyrocal noise --json``.
    """
    text = str(value).strip()
    if text.lower().endswith(".json") or Path(text).is_file():
        return load_noise(text).arw
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
