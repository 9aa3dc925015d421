"""A single-axis, temperature-controlled turntable running the full-temperature-range method's protocol.

At every temperature of Table 1 (after the soak, which is not recorded) the gyro is
mounted with x, y, then z up along the table axis, and the table runs each rate of
Table 2 forward and reverse for one step. At each step start the table rate
approaches its new command with a first-order lag (``table_tau``), which the
analysis removes with its settling time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validation import at_least, positive, temperature
from ..errors import InputError
from ..recording import Recording
from .gyro import VirtualGyro

__all__ = ["TABLE1_TEMPS", "TABLE2_RATES", "TurntableProtocol", "simulate_turntable"]

#: The full-temperature-range method, Table 1 [degC].
TABLE1_TEMPS: tuple[float, ...] = (-40.0, -30.0, -20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0, 50.0)
#: The full-temperature-range method, Table 2 [deg/s], each non-zero rate run forward and reverse.
TABLE2_RATES: tuple[float, ...] = (0.0, 0.1, 1.0, 10.0, 50.0, 100.0, 150.0, 200.0, 250.0, 300.0, 400.0)


@dataclass(frozen=True)
class TurntableProtocol:
    """What the turntable runs.

    Parameters
    ----------
    temps : tuple of float
        Temperature points [degC] (Table 1).
    rates : tuple of float
        Rate magnitudes [deg/s] (Table 2); non-zero ones run forward then reverse.
    axes : tuple of str
        Body axes mounted up along the table, in order.
    step_duration : float
        Length of each step [s] (paper: 60).
    table_tau : float
        First-order settling time of the table at each new rate [s].
    temp_noise : float
        White noise on the temperature readings [degC].
    temp_quantum : float, optional
        Resolution of the temperature readings [degC] (for example 1).
    """

    temps: tuple[float, ...] = TABLE1_TEMPS
    rates: tuple[float, ...] = TABLE2_RATES
    axes: tuple[str, ...] = ("x", "y", "z")
    step_duration: float = 60.0
    table_tau: float = 0.1
    temp_noise: float = 0.0
    temp_quantum: float | None = None

    def __post_init__(self):
        positive("step_duration", self.step_duration)
        if not set(self.axes) <= {"x", "y", "z"} or not self.axes:
            raise InputError(f"axes must be drawn from 'x', 'y', 'z', got {self.axes!r}")
        for name in ("temps", "rates"):
            values = tuple(float(v) for v in getattr(self, name))
            if not values or not all(math.isfinite(v) for v in values):
                raise InputError(f"{{param}} must be one or more finite numbers, got {getattr(self, name)!r}",
                                 param=name)
            object.__setattr__(self, name, values)
        for t in self.temps:
            temperature("temps", t)
        if min(self.rates) < 0:
            raise InputError(f"{{param}} are magnitudes >= 0 deg/s (each runs forward and reverse), got "
                             f"{list(self.rates)}", param="rates", value=self.rates)
        at_least("table_tau", self.table_tau, 0.0, " s")
        at_least("temp_noise", self.temp_noise, 0.0, " degC")
        if self.temp_quantum is not None:
            positive("temp_quantum", self.temp_quantum)

    def signed_rates(self) -> np.ndarray:
        """Commanded rates of one position [rad/s]: each magnitude forward then reverse."""
        out = []
        for r in self.rates:
            out += [r] if r == 0 else [abs(r), -abs(r)]
        return np.radians(out)

    @property
    def steps_per_point(self) -> int:
        return len(self.axes) * len(self.signed_rates())


def simulate_turntable(gyro: VirtualGyro, protocol: TurntableProtocol = TurntableProtocol(), *,
                       sample_rate: float = 200.0, rng: np.random.Generator) -> Recording:
    """Record a whole session: every temperature, position and rate step in sequence.

    Parameters
    ----------
    gyro : VirtualGyro
        The gyro; with ``thermal`` set, its errors follow the true temperature.
    protocol : TurntableProtocol
        Temperatures, rates, positions and timing.
    sample_rate : float
        Sampling rate [Hz].
    rng : numpy.random.Generator
        Source of all noise.

    Returns
    -------
    Recording
        ``t`` [s], ``gyro`` [rad/s], ``temp`` (readings) [degC], ``table_rate``
        (commanded) [rad/s] and ``axis``.
    """
    fs = positive("sample_rate", sample_rate)
    n = round(protocol.step_duration * fs)
    if n < 2:
        raise InputError(f"step_duration * sample_rate gives {n} samples per step; need at least 2")
    rates = protocol.signed_rates()
    cmd = np.tile(rates, len(protocol.axes))  # one position after another
    axis_idx = np.repeat([ "xyz".index(a) for a in protocol.axes], len(rates))
    prev = np.concatenate([[0.0], cmd[:-1]])
    prev[np.flatnonzero(np.diff(axis_idx)) + 1] = 0.0  # the table stops to remount
    tau = protocol.table_tau
    lag = np.exp(-np.arange(n) / (fs * tau)) if tau > 0 else np.zeros(n)
    actual = (cmd[:, None] + (prev - cmd)[:, None] * lag[None, :]).ravel()
    ax = np.repeat(axis_idx, n)
    true_rates = np.zeros((len(actual), 3))
    true_rates[np.arange(len(actual)), ax] = actual
    chunks, temps = [], []
    for temp in protocol.temps:
        chunks.append(gyro.measure(true_rates, fs, rng, temp=np.full(len(actual), float(temp))))
        reading = np.full(len(actual), float(temp)) + protocol.temp_noise * rng.standard_normal(len(actual))
        if protocol.temp_quantum:
            reading = np.round(reading / protocol.temp_quantum) * protocol.temp_quantum
        temps.append(reading)
    m = len(protocol.temps)
    total = m * len(actual)
    return Recording(t=np.arange(total) / fs, gyro=np.concatenate(chunks), units="rad/s", source_units="rad/s",
                     sample_rate=fs, temp=np.concatenate(temps), table_rate=np.tile(np.repeat(cmd, n), m),
                     axis=np.array(["x", "y", "z"])[np.tile(ax, m)])
