"""The samples of a capture: kept in memory for the guide and the checks, and written to the file as they come.

Rows use gyrocal's column names, ``t, gx, gy, gz[, temp]``, with ``t`` in seconds from the first
sample. A sample whose time does not come after the previous one (a device restart, a
repeated line) is left out and counted, so the file always reads back as a valid recording.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..io.incremental import IncrementalCSV
from ..recording import Recording
from ..units import unit_factor

__all__ = ["SampleStore"]


def _cell(x: float) -> str:
    return str(int(x)) if float(x).is_integer() and abs(x) < 1e15 else repr(float(x))


class _Column:
    """A growable array: appends in amortised constant time, views without copying."""

    def __init__(self, dtype, width: int = 0):
        self._shape = (width,) if width else ()
        self._a = np.empty((1024, *self._shape), dtype=dtype)
        self.n = 0

    def append(self, value) -> None:
        if self.n == len(self._a):
            self._a = np.concatenate([self._a, np.empty_like(self._a)])
        self._a[self.n] = value
        self.n += 1

    def last(self):
        return self._a[self.n - 1]

    @property
    def view(self) -> np.ndarray:
        return self._a[: self.n]


class SampleStore:
    """Samples received so far, and the file they go to.

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
        self._temp = _Column(float)
        self._seq = _Column(np.int64)
        self.has_time = self.has_temp = False
        self.out_of_order = 0
        self.t0: float | None = None
        self._pending: list[list[str]] = []

    def __len__(self) -> int:
        return self._g.n

    def add(self, t: float | None, g, temp: float | None, seq: int | None = None) -> None:
        """One sample: ``t`` [s] on the device's clock or None, ``g`` as received, ``temp`` [degC] or None."""
        if self._writer is None:
            self._open(t is not None, temp is not None)
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
        self._pending.append(row)

    def _open(self, has_time: bool, has_temp: bool) -> None:
        self.has_time, self.has_temp = has_time, has_temp
        columns = (["t"] if has_time else []) + ["gx", "gy", "gz"] + (["temp"] if has_temp else [])
        self._writer = IncrementalCSV(self.path, columns, self._comment())

    def flush(self) -> None:
        if self._writer is not None:
            self._writer.write_rows(self._pending)
            self._pending = []
            self._writer.flush()

    def finish(self) -> Path | None:
        """Write what is left and put the file in place; None when no sample came (no file)."""
        if self._writer is None:
            return None
        self.flush()
        return self._writer.finish()

    # -- views (no copies) -----------------------------------------------------------------------------------

    @property
    def t(self) -> np.ndarray:
        """[s] from the first sample."""
        return self._t.view

    @property
    def gyro(self) -> np.ndarray:
        return self._g.view

    @property
    def seq(self) -> np.ndarray:
        return self._seq.view

    def samples_by_seq(self, start: int, stop: int) -> np.ndarray | None:
        """Samples with sequence numbers ``start:stop`` when every one of them was received, else None."""
        seq = self.seq
        i = int(np.searchsorted(seq, start))
        j = i + (stop - start)
        if j > len(seq) or seq[i] != start or seq[j - 1] != stop - 1:
            return None
        return self.gyro[i:j].copy()

    def recording(self, units: str, sensitivity: float | None, sample_rate: float | None = None) -> Recording:
        """The samples so far as a :class:`Recording` (rad/s when the unit or sensitivity allows)."""
        g = self.gyro.copy()
        if units == "counts":
            factor = None if sensitivity is None else unit_factor("deg/s") / sensitivity
        else:
            factor = unit_factor(units)
        kwargs = {"source_units": units, "sensitivity": sensitivity if units == "counts" else None}
        gyro = g if factor is None else g * factor
        internal = "counts" if factor is None else "rad/s"
        if self.has_time:
            return Recording(t=self.t.copy(), gyro=gyro, units=internal, sample_rate=sample_rate or 0.0, **kwargs)
        return Recording.from_rate(gyro, sample_rate, units=internal, **kwargs)
