"""Defects of real time bases: receive-time stamps in bursts, late deliveries and packet gaps.

A sensor samples on its own regular clock; a PC that stamps samples as it *receives* them
sees them in packets. With two samples per packet at 100 Hz the steps alternate about
3 ms (the second read of a packet) and 17 ms (the wait for the next packet), averaging
10 ms. Now and then a packet is late: its samples and the ones queued behind it arrive in a
burst, one long step then short ones, and nothing is lost. A real gap is different: samples
never arrive, and the sensor clock jumps ahead across it.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from .._validation import positive
from ..errors import InputError
from ..recording import Recording

__all__ = ["ReceiveClock", "drop_samples", "receive_times", "rows_after_gaps", "simulate_time_defects",
           "with_time_defects"]


@dataclass(frozen=True)
class ReceiveClock:
    """How a receiving PC stamps samples.

    Parameters
    ----------
    packet : int
        Samples per packet (2 gives steps alternating short and long).
    read_time : float
        Mean time between reading two samples of one packet [s].
    jitter : float
        Uniform extra latency of each packet, ``U(0, jitter)`` [s]; each read inside a packet
        also takes ``read_time + U(-jitter, jitter) / 2``.
    late_per_minute : float
        Late packets per minute (delayed deliveries).
    late_delay : float
        Extra latency of a late packet [s]; the packets queued behind it drain at `read_time` each.
    """

    packet: int = 2
    read_time: float = 0.003
    jitter: float = 0.002
    late_per_minute: float = 0.0
    late_delay: float = 0.1

    def __post_init__(self):
        if int(self.packet) != self.packet or self.packet < 1:
            raise InputError(f"packet must be a whole number >= 1, got {self.packet!r}")
        for name in ("read_time", "jitter", "late_per_minute", "late_delay"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise InputError(f"{name} must be >= 0, got {value!r}")


def receive_times(n: int, sample_rate: float, clock: ReceiveClock, rng: np.random.Generator) -> np.ndarray:
    """Receive-time stamps [s] of `n` samples taken every ``1 / sample_rate`` on the sensor clock.

    A packet arrives when its last sample is taken plus ``U(0, jitter)`` (plus `late_delay` for a
    late one), never before the packet ahead of it has been read; its samples are stamped
    `read_time` apart. The stamps' mean step over the log equals the sensor period.
    """
    fs = positive("sample_rate", sample_rate)
    k = int(clock.packet)
    longest = clock.read_time + clock.jitter / 2  # one read inside a packet, at most [s]
    if longest * k >= k / fs or (k > 1 and clock.jitter / 2 >= clock.read_time):
        raise InputError(f"read_time {clock.read_time:g} s +- jitter/2 does not fit {k} samples per packet "
                         f"at {fs:g} Hz (each read must take between 0 and the sample period)")
    n_packets = -(-n // k)
    done = (np.arange(n_packets) * k + (k - 1)) / fs  # sensor time of each packet's last sample
    arrive = done + rng.uniform(0.0, clock.jitter, n_packets)
    n_late = rng.poisson(clock.late_per_minute * n / fs / 60.0)
    if n_late:
        arrive[rng.integers(0, n_packets, n_late)] += clock.late_delay
    # a packet is read only after the one ahead of it: a'_p = max(a_p, a'_{p-1} + k read_time)
    drain = k * longest
    steps = np.arange(n_packets) * drain
    arrive = np.maximum.accumulate(arrive - steps) + steps
    reads = clock.read_time + rng.uniform(-clock.jitter / 2, clock.jitter / 2, (n_packets, k))
    reads[:, 0] = 0.0
    stamps = (arrive[:, None] + np.cumsum(reads, axis=1)).ravel()[:n]
    return stamps - stamps[0]


def drop_samples(n: int, gaps: int, lost: int, rng: np.random.Generator, *, margin: int = 0) -> np.ndarray:
    """Boolean mask (n,) that keeps every sample but `gaps` runs of `lost` samples at random places,
    at least `margin` samples from either end and from each other."""
    keep = np.ones(n, dtype=bool)
    if gaps <= 0 or lost <= 0:
        return keep
    spacing = lost + max(margin, 1)
    lo, hi = margin, n - margin - lost
    if hi - lo < gaps * spacing:
        raise InputError(f"{gaps} gaps of {lost} samples do not fit in {n} samples")
    starts = np.sort(rng.choice(np.arange(lo, hi, spacing), size=gaps, replace=False))
    for s in starts:
        keep[s:s + lost] = False
    return keep


def with_time_defects(
    rec: Recording,
    rng: np.random.Generator,
    *,
    clock: ReceiveClock | None = None,
    gaps: int = 0,
    gap_length: float = 0.0,
) -> tuple[Recording, dict]:
    """`rec` with receive-time stamps and packet gaps, and the truth about them.

    Parameters
    ----------
    rec : Recording
        A recording on a regular clock (as simulated).
    clock : ReceiveClock, optional
        Stamp the samples as a receiving PC would; None keeps the sensor's stamps.
    gaps : int
        Number of packet gaps (samples never delivered).
    gap_length : float
        Length of each gap [s] (rounded to whole samples).

    Returns
    -------
    recording : Recording
        Stamps from the data (``has_time``), nominal rate left to be measured from them.
    truth : dict
        ``{"receive_clock": {...} or None, "gaps": [[first missing sample, count], ...]}``, sample
        numbers of the original recording.
    """
    fs = rec.sample_rate
    n = len(rec)
    t = rec.t - rec.t[0] if clock is None else receive_times(n, fs, clock, rng)
    lost = int(round(gap_length * fs))
    keep = drop_samples(n, gaps, lost, rng, margin=int(fs))
    runs = np.flatnonzero(np.diff(np.concatenate(([1], keep.view(np.int8)))) == -1)
    truth = {"receive_clock": None if clock is None else dataclasses.asdict(clock),
             "gaps": [[int(s), lost] for s in runs]}
    out = Recording(
        t=(t + rec.t[0])[keep], gyro=rec.gyro[keep], units=rec.units, source_units=rec.source_units,
        sample_rate=0.0, has_time=True,
        temp=None if rec.temp is None else rec.temp[keep],
        table_rate=None if rec.table_rate is None else rec.table_rate[keep],
        axis=None if rec.axis is None else rec.axis[keep],
        extra={k: np.asarray(v)[keep] for k, v in rec.extra.items()}, sensitivity=rec.sensitivity,
        accel=None if rec.accel is None else rec.accel[keep], accel_units=rec.accel_units,
        accel_source_units=rec.accel_source_units, accel_sensitivity=rec.accel_sensitivity,
    )
    return out, truth


def rows_after_gaps(index, gaps) -> np.ndarray:
    """Rows of the recording with gaps that original sample numbers `index` became.

    `gaps` is the truth's ``[[first missing original sample, count], ...]``; a sample inside a
    gap maps to the first row after it.
    """
    idx = np.asarray(index, dtype=np.int64)
    shift = np.zeros_like(idx)
    for start, count in gaps:
        shift += np.clip(idx - start, 0, count)
    return idx - shift


def simulate_time_defects(rec: Recording, facts: dict, rng: np.random.Generator, *, stamps: str = "sensor",
                          late_per_minute: float = 0.0, gaps: int = 0, gap_length: float = 0.17):
    """`rec` with receive-time stamps and packet gaps, its truth `facts` moved to the recording's rows.

    Returns the recording, the facts (``windows`` and ``plateaus`` as rows of the new recording, and
    ``time_base``: the receive clock and the gaps as ``[first missing sample, count]`` of the sensor
    clock) and the settings to record (``gyrocal simulate``'s truth sidecar).
    """
    if stamps not in ("sensor", "receive"):
        raise InputError(f"stamps must be 'sensor' or 'receive', got {stamps!r}", param="stamps", value=stamps)
    if gaps < 0 or not gap_length > 0:
        raise InputError(f"gaps must be >= 0 and gap_length > 0 s, got {gaps} and {gap_length:g}", param="gaps")
    clock = ReceiveClock(late_per_minute=late_per_minute) if stamps == "receive" else None
    out, truth = with_time_defects(rec, rng, clock=clock, gaps=gaps, gap_length=gap_length)
    moved = dict(facts)
    for key in ("windows", "plateaus"):
        if key in moved:
            moved[key] = [{**w, "start": int(rows_after_gaps(w["start"], truth["gaps"])),
                           "stop": int(rows_after_gaps(w["stop"], truth["gaps"]))} for w in moved[key]]
    moved["time_base"] = {**truth, "note": "gaps: [first missing sample of the sensor clock, count]; windows and "
                                           "plateaus are rows of the recording"}
    settings = {"stamps": stamps, "late_per_minute": late_per_minute, "gaps": gaps, "gap_length_s": gap_length}
    return out, moved, settings
