"""The samples of a capture: written to the file as they come, and the recent ones kept in memory.

Rows use gyrocal's column names, ``t, gx, gy, gz[, temp][, ax, ay, az]`` (the order ``apply``
writes them), with ``t`` in seconds from the first sample. A sample whose time does not come
after the previous one (a device restart, a repeated line) is left out and counted, so the file
always reads back as a valid recording.

Memory stays bounded on a capture of any length: the file has every sample, and the store keeps
only the recent ones (:data:`RETAIN_S` of device time, or :data:`RETAIN_N` samples without time
stamps) plus whatever its user still needs (:meth:`SampleStore.trim`). Indices are absolute:
sample ``i`` is the ``i``-th sample written, whatever was dropped from memory since.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..io.incremental import IncrementalCSV
from ..recording import Recording
from ..units import STANDARD_GRAVITY, unit_factor

__all__ = ["RETAIN_N", "RETAIN_S", "SampleStore"]

#: Device time kept in memory [s]: the longest turn the on-device session files (60 s) and its quiet
#: end, so the host still holds a turn's samples when the device reports it.
RETAIN_S = 75.0
#: Samples kept in memory when they carry no time stamps.
RETAIN_N = 1 << 16


def _cell(x: float) -> str:
    return str(int(x)) if float(x).is_integer() and abs(x) < 1e15 else repr(float(x))


class _Column:
    """A growable array: appends in amortised constant time, views without copying, drops its oldest rows."""

    def __init__(self, dtype, width: int = 0):
        self._shape = (width,) if width else ()
        self._a = np.empty((1024, *self._shape), dtype=dtype)
        self.n = 0

    def append(self, value) -> None:
        if self.n == len(self._a):
            self._a = np.concatenate([self._a, np.empty_like(self._a)])
        self._a[self.n] = value
        self.n += 1

    def drop(self, k: int) -> None:
        """Forget the first `k` rows (numpy copies overlapping ranges correctly)."""
        self._a[: self.n - k] = self._a[k: self.n]
        self.n -= k

    def last(self):
        return self._a[self.n - 1]

    @property
    def view(self) -> np.ndarray:
        return self._a[: self.n]


class SampleStore:
    """Samples received so far: every one to the file, the recent ones in memory.

    Parameters
    ----------
    path : path-like
        The output CSV (written through a temporary file, put in place by :meth:`finish`).
    header_comment : callable returning str
        Called when the first sample arrives (the device's hello is known by then).
    """

    def __init__(self, path, header_comment=lambda: ""):
        self.path = Path(path)
        self._comment = header_comment
        self._writer: IncrementalCSV | None = None
        self._t = _Column(float)
        self._g = _Column(float, 3)
        self._a = _Column(float, 3)
        self._temp = _Column(float)
        self._seq = _Column(np.int64)
        self.has_time = self.has_temp = self.has_accel = False
        self.out_of_order = 0
        self.missing_accel = 0  # samples without the accelerometer in a recording that has it (left out)
        self.t0: float | None = None
        self.first = 0  # absolute index of the first sample kept in memory
        self._pending: list[list[str]] = []

    def __len__(self) -> int:
        """Samples written (all of them, not only those kept in memory)."""
        return self.first + self._g.n

    def add(self, t: float | None, g, temp: float | None, seq: int | None = None, accel=None) -> None:
        """One sample: ``t`` [s] on the device's clock or None, ``g`` and ``accel`` as received (accel None
        without an accelerometer), ``temp`` [degC] or None."""
        if self._writer is None:
            self._open(t is not None, temp is not None, accel is not None)
        if self.has_accel and accel is None:
            self.missing_accel += 1
            return
        row = []
        if self.has_time:
            if self.t0 is None and t is not None:
                self.t0 = t
            if t is None or (self._t.n and t - self.t0 <= self._t.last()):
                self.out_of_order += 1
                return
            self._t.append(t - self.t0)
            row.append(f"{t - self.t0:.6f}")  # device clocks tick in microseconds
        if self.has_temp:
            temp = float(self._temp.last()) if temp is None else temp  # a lost reading keeps the last one
            self._temp.append(temp)
        self._seq.append(len(self) if seq is None else seq)
        self._g.append(g)
        row += [_cell(v) for v in g]
        if self.has_temp:
            row.append(f"{temp:.2f}")
        if self.has_accel:
            self._a.append(accel)
            row += [_cell(v) for v in accel]
        self._pending.append(row)

    def _open(self, has_time: bool, has_temp: bool, has_accel: bool) -> None:
        self.has_time, self.has_temp, self.has_accel = has_time, has_temp, has_accel
        columns = (["t"] if has_time else []) + ["gx", "gy", "gz"] + (["temp"] if has_temp else [])
        columns += ["ax", "ay", "az"] if has_accel else []
        self._writer = IncrementalCSV(self.path, columns, self._comment())

    def flush(self) -> None:
        if self._writer is not None:
            self._writer.write_rows(self._pending)
            self._pending = []
            self._writer.flush()

    def trim(self, keep_from: int | None = None) -> None:
        """Forget samples before the recent ones (:data:`RETAIN_S`, :data:`RETAIN_N`), but none from
        `keep_from` (an absolute index) on. Drops in large steps, so the cost per sample stays constant."""
        n = self._g.n
        if not n:
            return
        if self.has_time:
            cut = int(np.searchsorted(self.t, self.t[-1] - RETAIN_S))
        else:
            cut = max(0, n - RETAIN_N)
        if keep_from is not None:
            cut = min(cut, max(0, keep_from - self.first))
        if cut < max(4096, n // 2):
            return
        for col in (self._t, self._g, self._a, self._temp, self._seq):
            if col.n:
                col.drop(cut)
        self.first += cut

    def finish(self) -> Path | None:
        """Write what is left and put the file in place; None when no sample came (no file)."""
        if self._writer is None:
            return None
        self.flush()
        return self._writer.finish()

    # -- views of the samples in memory (no copies) ----------------------------------------------------------

    @property
    def t(self) -> np.ndarray:
        """[s] from the first sample."""
        return self._t.view

    @property
    def gyro(self) -> np.ndarray:
        return self._g.view

    @property
    def accel(self) -> np.ndarray | None:
        return self._a.view if self.has_accel else None

    @property
    def seq(self) -> np.ndarray:
        return self._seq.view

    def samples_by_seq(self, start: int, stop: int) -> np.ndarray | None:
        """Samples with sequence numbers ``start:stop`` when every one of them is here, else None."""
        seq = self.seq
        i = int(np.searchsorted(seq, start))
        j = i + (stop - start)
        if j > len(seq) or i >= len(seq) or seq[i] != start or seq[j - 1] != stop - 1:
            return None
        return self.gyro[i:j].copy()

    def recording(self, units: str, sensitivity: float | None, sample_rate: float | None = None, *,
                  start: int | None = None, accel_sensitivity: float | None = None,
                  gravity: float = STANDARD_GRAVITY) -> Recording:
        """Samples from absolute index `start` (default: all in memory) as a :class:`Recording`: rad/s when
        the unit or sensitivity allows, the accelerometer in m/s^2 with a sensitivity, else in counts."""
        i = 0 if start is None else max(0, start - self.first)
        g = self.gyro[i:].copy()
        if units == "counts":
            factor = None if sensitivity is None else unit_factor("deg/s") / sensitivity
        else:
            factor = unit_factor(units)
        kwargs = {"source_units": units, "sensitivity": sensitivity if units == "counts" else None}
        if self.has_accel:
            a = self.accel[i:].copy()
            kwargs.update(accel=a if accel_sensitivity is None else a * (gravity / accel_sensitivity),
                          accel_units="counts" if accel_sensitivity is None else "m/s^2", accel_source_units="counts",
                          accel_sensitivity=accel_sensitivity)
        gyro = g if factor is None else g * factor
        internal = "counts" if factor is None else "rad/s"
        if self.has_time:
            return Recording(t=self.t[i:].copy(), gyro=gyro, units=internal, sample_rate=sample_rate or 0.0, **kwargs)
        return Recording.from_rate(gyro, sample_rate, units=internal, **kwargs)
