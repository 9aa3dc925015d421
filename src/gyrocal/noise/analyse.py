"""From readings at rest to a :class:`~.report.NoiseReport`, checking that they are at rest.

Refused: raw counts (no physical unit), an axis whose readings never change (all zero, a
dead or unmapped column), a log without a long enough still stretch, and figures that
come out zero. A log that moves somewhere is cut to its longest still stretch, with a
warning: an Allan deviation needs contiguous samples, and pasting still stretches together
would join different bias levels with steps that read as noise.
"""

from __future__ import annotations

import warnings

import numpy as np

from .._arrays import distinct
from .._validation import finite_array, positive
from ..choices import MotionPolicy, values
from ..errors import GyrocalWarning, InputError, UnitError
from ..recording import Recording
from ..segmentation.stillness import find_motion
from .allan import MIN_SAMPLES, ONE_SIGMA, allan_deviation
from .figures import read_figures
from .report import NoiseReport, SensorNoise

__all__ = ["MotionPolicy", "NoiseWarning", "characterise", "characterise_recording"]

#: The shortest still stretch a log that moves is cut to [s]; shorter ones are refused.
MIN_STILL_S = 10.0
#: Fewer distinct readings than this on an axis: quantisation, not noise, shapes the short-tau curve.
_FEW_LEVELS = 8
#: A temperature span over the analysed stretch above this [degC] puts a thermal drift into the long-tau figures.
TEMP_SPAN_WARN = 2.0
#: A smaller span still warns when the drift is this large [degC] and clearly monotone (|Spearman rho| >= 0.9).
TEMP_TREND_MIN = 0.5
_TEMP_BLOCKS = 100


class NoiseWarning(GyrocalWarning):
    """The noise analysis used part of the log, or its input limits the figures."""


def _check_axes(name: str, x: np.ndarray, labels: tuple[str, ...], found: list[str]) -> None:
    for j, label in enumerate(labels):
        col = x[:, j]
        if col.min() == col.max():
            raise InputError(f"{name} axis {label} reads {float(col[0]):g} in every sample: a constant column holds "
                             "no noise to analyse (a dead sensor, or the wrong column mapped?)")
        levels = len(distinct(col[: 200_000]))
        if levels < _FEW_LEVELS:
            found.append(f"{name} axis {label} takes only {levels} distinct values: quantisation shapes the "
                         "short averaging times, so the density is that of the quantisation steps")


def _temperature(temp, n: int, start: int, stop: int, found: list[str]) -> tuple[float, float] | None:
    """Lowest and highest temperature [degC] over the analysed stretch (of block means, so that reading
    noise does not count), with a warning in `found` when it drifts enough to reach the long-tau figures."""
    if temp is None:
        return None
    t = finite_array("temp", temp, ndim=1)
    if t.shape != (n,):
        raise InputError(f"temp has {len(t)} samples but gyro has {n}")
    means = np.array([b.mean() for b in np.array_split(t[start:stop], min(_TEMP_BLOCKS, stop - start))])
    low, high = float(means.min()), float(means.max())
    span = high - low
    ranks = np.argsort(np.argsort(means, kind="stable"), kind="stable")
    rho = np.corrcoef(ranks, np.arange(len(means)))[0, 1] if span > 0 else 0.0
    if span > TEMP_SPAN_WARN or (span > TEMP_TREND_MIN and abs(rho) >= 0.9):
        how = "rises" if means[-1] > means[0] else "falls"
        found.append(f"the temperature {how} by {span:.1f} degC over the analysed stretch ({means[0]:.1f} to "
                     f"{means[-1]:.1f} degC), so the long-tau figures (bias instability, random walk) include the "
                     "bias's thermal drift: let the board warm up before logging, or cut the log to its stable part")
    return low, high


def _departures(kind: str, lines) -> list[str]:
    """Where an axis's curve leaves the fitted -1/2 line at short tau, one message each."""
    out = []
    for axis, w in zip("xyz", lines):
        if w is not None and np.isfinite(w.depart_tau):
            offs = ", ".join(f"{100 * off:+.0f} % at {tau:.3g} s" for off, tau in w.offsets)
            out.append(f"{kind} axis {axis}: the Allan deviation leaves the -1/2 line below tau = {w.depart_tau:.3g} s "
                       f"({offs}: a filter, quantisation or a short-tau bump); "
                       f"the density is fitted over tau {w.tau_min:.3g}-{w.tau_max:.3g} s and read at 1 s")
    return out


def _sensor(kind, x, fs, level, found: list[str]) -> SensorNoise:
    taus, adev = allan_deviation(x, fs)
    curves, density, bias, walk, bound, lines = read_figures(taus, adev, fs, len(x), level=level)
    if not np.all(density.value > 0):
        bad = "xyz"[int(np.argmin(np.nan_to_num(density.value[:3], nan=0.0) > 0))]
        raise InputError(f"the {kind} has no white-noise (-1/2 slope) region on axis {bad}, so no noise density can "
                         "be read: the data look filtered or oversampled; log the sensor's own output rate")
    found.extend(_departures(kind, lines))
    return SensorNoise(kind, taus, curves, density, bias, walk, bound)


def characterise(gyro, sample_rate: float, *, accel=None, temp=None, motion: MotionPolicy = "restrict",
                 level: float = ONE_SIGMA, source: dict | None = None) -> NoiseReport:
    """Allan deviation and noise figures, with intervals, of a log at rest.

    Parameters
    ----------
    gyro : array_like, shape (N, 3)
        Gyro readings [rad/s]; constant biases and the Earth rate do not matter.
    sample_rate : float
        Sampling rate [Hz].
    accel : array_like, shape (N, 3), optional
        Accelerometer readings [m/s^2]; gravity is a constant and does not matter.
    temp : array_like, shape (N,), optional
        Sensor temperature [degC]: its range over the analysed stretch is recorded, and a drift
        (over 2 degC, or over 0.5 degC and monotone) gives a :class:`NoiseWarning`.
    motion : {"restrict", "refuse"}
        What to do when the log moves: analyse its longest still stretch (with a
        :class:`NoiseWarning`), or raise.
    level : float
        Confidence of every interval (default 1 sigma, 0.683).
    source : dict, optional
        Where the data came from, recorded in the report.

    Raises
    ------
    InputError
        Constant axes, no still stretch of at least 100 samples, or no white-noise region.
    """
    g = finite_array("gyro", gyro, shape_tail=(3,), ndim=2)
    a = None if accel is None else finite_array("accel", accel, shape_tail=(3,), ndim=2)
    if a is not None and len(a) != len(g):
        raise InputError(f"accel has {len(a)} samples but gyro has {len(g)}")
    fs = positive("sample_rate", sample_rate)
    if motion not in values(MotionPolicy):
        raise InputError(f"{{param}}={motion!r} is not one of {', '.join(values(MotionPolicy))}", param="motion",
                         value=motion)
    if len(g) < MIN_SAMPLES:  # before any warning about the few samples there are
        raise InputError(f"a noise analysis needs at least {MIN_SAMPLES} samples at rest, got {len(g)}")
    found: list[str] = []
    _check_axes("gyro", g, ("x", "y", "z"), found)
    if a is not None:
        _check_axes("accelerometer", a, ("x", "y", "z"), found)
    still = find_motion([g] if a is None else [g, a], fs)
    start, stop = 0, len(g)
    if not still.still:
        start, stop = still.longest_still()
        what = f"the log moves ({still.describe(fs)})"
        longest = f"its longest still stretch is {(stop - start) / fs:.1f} s"
        if stop - start < max(MIN_SAMPLES, MIN_STILL_S * fs):
            raise InputError(f"{what}; {longest}, and a noise analysis needs the sensor at rest for at least "
                             f"{MIN_STILL_S:g} s: record it lying still, untouched")
        if motion == "refuse":
            raise InputError(f"{what}: record the sensor lying still, untouched, or analyse only the longest "
                             f"still stretch, {(stop - start) / fs:.1f} s ({{param}} restrict)", param="motion")
        found.append(f"{what}: analysed the longest still stretch, {start / fs:.1f}-{stop / fs:.1f} s "
                     f"({(stop - start) / fs:.1f} s of {len(g) / fs:.1f} s)")
    temperature = _temperature(temp, len(g), start, stop, found)
    gyro_noise = _sensor("gyroscope", g[start:stop], fs, level, found)
    accel_noise = None if a is None else _sensor("accelerometer", a[start:stop], fs, level, found)
    for message in found:
        warnings.warn(message, NoiseWarning, stacklevel=2)
    return NoiseReport(gyro_noise, accel_noise, fs, stop - start, start / fs, stop / fs, len(g) / fs,
                       motions_left_out=len(still.spans), confidence=level, source=dict(source or {}),
                       warnings=tuple(found), temperature=temperature)


def characterise_recording(rec: Recording, *, motion: MotionPolicy = "restrict", level: float = ONE_SIGMA,
                           source: dict | None = None) -> NoiseReport:
    """:func:`characterise` of a recording (its gyro, and its accelerometer when it has one).

    Raw counts are refused: noise figures need a physical unit (give the sensitivity).
    """
    if rec.units != "rad/s":
        raise UnitError("noise figures need physical units, but the gyro is in raw counts", param="sensitivity",
                        hint="give {param} (LSB per output unit) so the counts become a rate")
    accel = getattr(rec, "accel", None)
    info = {"gyro_units": rec.source_units, **(source or {})}
    if accel is not None:
        info["accel_units"] = getattr(rec, "accel_source_units", None)
    fs = rec.sample_rate
    if rec.has_time and len(rec) > 1:
        fs = (len(rec) - 1) / float(rec.t[-1] - rec.t[0])  # mean rate: bursty stamps average out
    return characterise(rec.gyro, fs, accel=accel, temp=rec.temp, motion=motion, level=level, source=info)
