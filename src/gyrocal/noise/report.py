"""The noise report of a log at rest: each sensor's Allan deviation and figures, and where they came from.

The report's file, ``format: gyrocal.noise``, is read and written by :mod:`gyrocal.noise.document`
(core numerics do not hold file code); :mod:`gyrocal.results.files` knows it by name, so ``load``,
``save`` and ``to_document`` handle it like any kind.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar, Literal

import numpy as np

from ..errors import InputError
from .allan import ONE_SIGMA
from .figures import Figure

__all__ = ["FORMAT", "VERSION", "NoiseReport", "SensorNoise"]

FORMAT = "gyrocal.noise"
VERSION = 2
SensorKind = Literal["gyroscope", "accelerometer"]
UNITS = {"gyroscope": "rad/s", "accelerometer": "m/s^2"}


@dataclass(frozen=True)
class SensorNoise:
    """Allan deviation and noise figures of one triaxial sensor.

    Attributes
    ----------
    kind : {"gyroscope", "accelerometer"}
        Internal units rad/s or m/s^2.
    taus : ndarray, shape (m,)
        Averaging times [s].
    adev : ndarray, shape (4, m)
        Allan deviation of x, y, z and the sensor [rad/s or m/s^2].
    density, bias_instability, random_walk : Figure
        White-noise density [unit/sqrt(Hz)], bias instability [unit], random walk of the bias
        [unit/s/sqrt(Hz)], each for x, y, z and the sensor with its interval.
    random_walk_bound : ndarray, shape (4,)
        95 % upper bound on the random walk where it is not seen, NaN elsewhere.
    """

    kind: SensorKind
    taus: np.ndarray
    adev: np.ndarray
    density: Figure
    bias_instability: Figure
    random_walk: Figure
    random_walk_bound: np.ndarray

    def __post_init__(self):
        if self.kind not in UNITS:
            raise InputError(f"kind must be one of {', '.join(UNITS)}, got {self.kind!r}")
        m = np.shape(self.taus)[0]
        for name, shape in (("taus", (m,)), ("adev", (4, m)), ("random_walk_bound", (4,))):
            arr = np.array(getattr(self, name), dtype=float)
            if arr.shape != shape:
                raise InputError(f"{name} must have shape {shape}, got {arr.shape}")
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    @property
    def unit(self) -> str:
        """Internal unit of the readings."""
        return UNITS[self.kind]

    def noise_std(self, sample_rate: float) -> np.ndarray:
        """Per-sample white-noise sigma (4,) at `sample_rate` [Hz]: density times sqrt(rate)."""
        return self.density.value * math.sqrt(sample_rate)


@dataclass(frozen=True)
class NoiseReport:
    """Noise figures of a log at rest: the gyro's, and the accelerometer's when it was logged.

    Attributes
    ----------
    gyro : SensorNoise
    accel : SensorNoise or None
    sample_rate : float
        Sampling rate [Hz].
    samples : int
        Samples analysed.
    start, stop : float
        The analysed stretch within the log [s from its first sample].
    log_duration : float
        Length of the whole log [s].
    motions_left_out : int
        Motions found in the log outside the analysed stretch.
    confidence : float
        Probability content of every interval (0.683: 1 sigma).
    source : dict
        Where the data came from (file name, declared units), for the record.
    warnings : tuple of str
        What the analysis warned about.
    temperature : (float, float) or None
        Lowest and highest sensor temperature over the analysed stretch [degC] (of block means),
        None for a log without a temperature column.
    """

    gyro: SensorNoise
    accel: SensorNoise | None
    sample_rate: float
    samples: int
    start: float
    stop: float
    log_duration: float
    motions_left_out: int = 0
    confidence: float = ONE_SIGMA
    source: dict = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    temperature: tuple[float, float] | None = None

    FORMAT: ClassVar[str] = FORMAT
    VERSION: ClassVar[int] = VERSION

    @property
    def duration(self) -> float:
        """Length of the analysed stretch [s]."""
        return self.samples / self.sample_rate

    @property
    def temperature_span(self) -> float | None:
        """How far the temperature moved over the analysed stretch [degC]; None without a temperature."""
        return None if self.temperature is None else self.temperature[1] - self.temperature[0]

    @property
    def density(self) -> np.ndarray:
        """Gyro white-noise density per axis (3,) [rad/s/sqrt(Hz)] (what ``--noise-density`` takes)."""
        return self.gyro.density.value[:3]

    @property
    def noise_std(self) -> np.ndarray:
        """Gyro per-sample noise per axis (3,) [rad/s] at this log's rate."""
        return self.gyro.noise_std(self.sample_rate)[:3]
