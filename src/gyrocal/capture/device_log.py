"""What the device said about its own calibration, with what the host needs to check it, in bounded memory.

The check (:mod:`gyrocal.capture.agreement`) needs the raw samples of the six turns behind the
device's result and every corrected sample next to its raw sample. A capture may run for hours,
so nothing here grows with it: each accepted turn's samples are copied when its turn frame
arrives (the store still holds them then), a result keeps the six turns it was computed from,
and corrected samples are checked as they come, keeping only the worst ratio.
"""

from __future__ import annotations

import numpy as np

from .agreement import Agreement, CorrectedCheck, check_device
from .frames import TURN_LABELS, Calibrated, Result, Turn
from .store import SampleStore

__all__ = ["DeviceLog"]


class DeviceLog:
    """Turn, result and corrected-sample frames of one capture, ready for :meth:`check`."""

    def __init__(self, store: SampleStore):
        self.store = store
        self.turns: list[Turn] = []
        self.results: list[Result] = []
        self._slots: dict[int, tuple[Turn, np.ndarray | None]] = {}
        self._basis: tuple[Result, dict[int, tuple[Turn, np.ndarray | None]], CorrectedCheck] | None = None
        self._active: CorrectedCheck | None = None  # the correction the device applies now
        self._pending: list[Calibrated] = []

    def turn(self, t: Turn) -> None:
        self.turns.append(t)
        if t.status == 0:  # filed in its slot: a later turn of the slot replaces it
            self._slots[t.slot] = (t, self.store.samples_by_seq(t.start, t.stop))

    def result(self, r: Result) -> None:
        self.settle()  # corrected samples before this result belong to the previous one
        self.results.append(r)
        self._active = None
        if r.status == 0 and len(self._slots) == len(TURN_LABELS):
            self._active = CorrectedCheck(r.k, r.b)
            self._basis = (r, dict(self._slots), self._active)

    def calibrated(self, c: Calibrated) -> None:
        if self._active is not None:
            self._pending.append(c)

    def settle(self) -> None:
        """Check the corrected samples received so far against their raw samples (those still in memory)."""
        seq = self.store.seq
        if not self._pending or self._active is None or not len(seq):
            self._pending = []
            return
        want = np.array([c.seq for c in self._pending])
        idx = np.minimum(np.searchsorted(seq, want), len(seq) - 1)
        ok = seq[idx] == want
        w = np.array([c.w for c in self._pending], dtype=float).reshape(-1, 3)
        self._active.add(self.store.gyro[idx[ok]], w[ok])
        self._pending = []

    def check(self) -> Agreement | None:
        """The device's last successful result recomputed on the host (None when it sent none)."""
        self.settle()
        if self._basis is None:
            return None
        result, slots, corrected = self._basis
        turns = {s: t for s, (t, _) in slots.items()}
        samples = {s: x for s, (_, x) in slots.items() if x is not None}
        return check_device(turns, result, samples, corrected if corrected.n else None)
