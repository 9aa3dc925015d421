"""Reading a turntable session: the cost of its one-letter ``axis`` column, now and before.

Run by hand:  python bench/bench_session.py [--step 60] [--repeat 3]

Writes the full-temperature-range method's session (7.56 M rows at the paper's 60 s steps) with
``t, gx, gy, gz, temp, table_rate, axis``, then times in one process (best of `repeat`):

* ``read_session``: the whole read (parse, checks, Recording);
* the axis column alone, from the parsed pyarrow column to the Recording's checked letters:
  now (dictionary-encoded in pyarrow, checked on character codes) and previous (kept below: Python
  strings, then numpy's string functions strip, lower and isin).

Prints the times, the axis column's share of the read before and now, and previous / now.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np


def previous_axis(column) -> np.ndarray:
    """Before: every cell a Python string, then strip, lower and a membership test over the strings."""
    labels = np.char.lower(np.char.strip(np.asarray(column.to_numpy(), dtype=str)))
    assert np.isin(labels, ("x", "y", "z")).all()
    return labels


def current_axis(column) -> np.ndarray:
    from gyrocal.io._arrow import text_to_numpy
    from gyrocal.recording import _axis_letters

    return _axis_letters(text_to_numpy(column, dtype=str))


def best(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--step", type=float, default=60.0, help="seconds per rate step (60: the paper's)")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    import pyarrow.csv as pcsv

    from gyrocal.io import read_session, write_recording
    from gyrocal.simulation.thermal_truth import ThermalTruth
    from gyrocal.simulation.turntable import TurntableProtocol, simulate_turntable

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "session.csv"
        rec = simulate_turntable(ThermalTruth().gyro(np.radians(0.05)), TurntableProtocol(step_duration=args.step),
                                 sample_rate=200.0, rng=np.random.default_rng(7))
        write_recording(path, rec, units="deg/s", header_comment="gyrocal simulate --protocol turntable")
        rows = len(rec)
        del rec
        column = pcsv.read_csv(path, read_options=pcsv.ReadOptions(skip_rows=1)).column("axis")
        assert np.array_equal(previous_axis(column), current_axis(column))
        read = best(lambda: read_session(path, units="deg/s", saturation="ignore"), args.repeat)
        now = best(lambda: current_axis(column), args.repeat)
        before = best(lambda: previous_axis(column), args.repeat)
        print(f"session: {rows:,} rows")
        print(f"read_session: {read:.2f} s; axis column now {now:.3f} s ({100 * now / read:.1f} % of the read), "
              f"previous {before:.3f} s ({100 * before / (read - now + before):.0f} % of a read with it)")
        print(f"axis column: previous / now {before / now:.1f}x")


if __name__ == "__main__":
    main()
