"""Reading a whitespace-separated recording against the same data as CSV, in the same run.

Run by hand:  python bench/bench_read_spaced.py [--samples 920000] [--repeat 5]

Writes one servo-like recording (bench_read.servo_signal: t, gx, gy, gz in deg/s at 1 kHz) three times: as
CSV, as imu_tk writes its logs (headerless, two spaces before every field: one spacing throughout, read
by pyarrow's CSV parser with a space as delimiter), and in columns aligned by padding (the spacing varies
with each number's width: each line split by pyarrow's compute kernels). Then:

* time: ``read_recording`` of each, taking turns within each of `repeat` rounds in this process;
  the medians of wall and CPU time, and spaced / CSV. The pure-Python reader the spaced file went
  through before (``read_csv_columns(use_pyarrow=False)``) is timed alongside.
* memory: each read once more in a fresh process; the peak resident set above what the imports
  alone take, and spaced / CSV.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from bench_read import servo_signal  # noqa: E402

_COLUMNS = "t=1,gx=2,gy=3,gz=4"


def _read(kind: str, path: Path):
    from gyrocal.io import read_recording
    from gyrocal.io.csvfile import read_csv_columns

    if kind == "csv":
        return read_recording(path, units="deg/s")
    if kind in ("spaced", "aligned"):
        return read_recording(path, units="deg/s", columns=_COLUMNS)
    return read_csv_columns(path, _COLUMNS, use_pyarrow=False)


def _child(kind: str, path: Path) -> None:
    import pyarrow.compute  # noqa: F401
    import pyarrow.csv  # noqa: F401

    import gyrocal.io  # noqa: F401  (the imports' own memory is not the reader's)
    import gyrocal.io.csvfile  # noqa: F401

    base = _vm("VmRSS")
    _read(kind, path)
    print(_vm("VmHWM") - base)


def _vm(field: str) -> float:
    """A figure of /proc/self/status [MiB]; VmHWM is this process's own peak (ru_maxrss keeps the parent's
    across fork and exec)."""
    with open("/proc/self/status") as f:
        return next(float(line.split()[1]) for line in f if line.startswith(field + ":")) / 1024.0


def _peak(kind: str, path: Path) -> float:
    out = subprocess.run([sys.executable, __file__, "--child", kind, str(path)], capture_output=True, text=True,
                         check=True)
    return float(out.stdout.split()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=920_000)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--python", action="store_true", help="also time the pure-Python reader (slow)")
    parser.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        return _child(args.child[0], Path(args.child[1]))

    from gyrocal.io import write_csv

    data = servo_signal(args.samples, 1000.0, np.random.default_rng(1))
    with tempfile.TemporaryDirectory() as tmp:
        paths = {"csv": Path(tmp) / "servo.csv", "spaced": Path(tmp) / "servo.txt", "aligned": Path(tmp) / "aligned.txt"}
        write_csv(paths["csv"], data)
        cols = np.column_stack([data[c] for c in ("t", "gx", "gy", "gz")])
        np.savetxt(paths["spaced"], cols, fmt="  %.6f  %.9g  %.9g  %.9g")
        np.savetxt(paths["aligned"], cols, fmt="%12.6f %16.9g %16.9g %16.9g")
        kinds = ["csv", "spaced", "aligned"] + (["python"] if args.python else [])
        paths["python"] = paths["spaced"]
        times = {k: ([], []) for k in kinds}
        for _ in range(args.repeat):
            for k in kinds:
                w0, c0 = time.perf_counter(), time.process_time()
                _read(k, paths[k])
                times[k][0].append(time.perf_counter() - w0)
                times[k][1].append(time.process_time() - c0)
        wall = {k: statistics.median(v[0]) for k, v in times.items()}
        cpu = {k: statistics.median(v[1]) for k, v in times.items()}
        peak = {k: _peak(k, paths[k]) for k in kinds}
        print(f"{args.samples:,} rows; CSV {paths['csv'].stat().st_size / 1e6:.0f} MB, "
              f"spaced {paths['spaced'].stat().st_size / 1e6:.0f} MB; medians of {args.repeat} paired rounds")
        print(f"{'':24s} {'wall [s]':>9s} {'CPU [s]':>8s} {'peak [MiB]':>11s}   ratios to CSV: wall  CPU  peak")
        for k in kinds:
            print(f"{k:24s} {wall[k]:9.3f} {cpu[k]:8.3f} {peak[k]:11.1f}   "
                  f"{wall[k] / wall['csv']:19.2f} {cpu[k] / cpu['csv']:4.2f} {peak[k] / peak['csv']:5.2f}")


if __name__ == "__main__":
    main()
