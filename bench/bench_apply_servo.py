"""``gyrocal apply`` of a servo calibration to a long log, against pyarrow read + numpy correction + write.

Run by hand:  python bench/bench_apply_servo.py [--samples 10000000] [--repeat 3]

The log is bench/bench_read.py's servo recording (t, gx, gy, gz in deg/s, 1 kHz); the calibration comes
from ``gyrocal calibrate`` of its first 200 k rows. Each stage runs in a fresh process, first on a short
log (so imports and first-call costs are paid) and then on the long one, so its peak memory above that
is what the long log costs:

* ``pyarrow``: ``pyarrow.csv.read_csv`` with the four columns declared float64, the correction
  ``matrix @ (m - offset)`` column by column in numpy, ``pyarrow.csv.write_csv``: the floor;
* ``apply``: ``gyrocal apply cal.json log.csv -o out.csv`` run through its command line in-process.

Prints the medians over `repeat` paired rounds of seconds and of peak memory above the short run as a
multiple of the numbers (rows x 4 float64), and the median of the paired ratios apply / pyarrow.
The two outputs are compared on their first 100 k rows.
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

NAMES = ("t", "gx", "gy", "gz")


def _peak_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _pyarrow(log: Path, out: Path, cal: Path) -> None:
    import pyarrow as pa
    import pyarrow.csv as pcsv

    from gyrocal.results.files import load_calibration

    matrix, offset = load_calibration(cal).correction
    types = pcsv.ConvertOptions(column_types=dict.fromkeys(NAMES, pa.float64()))
    table = pcsv.read_csv(log, read_options=pcsv.ReadOptions(skip_rows=1, column_names=list(NAMES)),
                          convert_options=types)
    m = [table.column(n).to_numpy() - offset[i] for i, n in enumerate(NAMES[1:])]
    g = [matrix[i, 0] * m[0] + matrix[i, 1] * m[1] + matrix[i, 2] * m[2] for i in range(3)]
    del m
    pcsv.write_csv(pa.table({"t": table.column("t"), "gx": g[0], "gy": g[1], "gz": g[2]}), out)


def _apply(log: Path, out: Path, cal: Path) -> None:
    import gyrocal.cli

    sys.argv = ["gyrocal", "apply", str(cal), str(log), "-o", str(out), "--force"]
    try:
        gyrocal.cli.main()
    except SystemExit as exc:
        if exc.code:
            raise


def stage(name: str, work: Path) -> dict:
    run = {"pyarrow": _pyarrow, "apply": _apply}[name]
    run(work / "short.csv", work / f"short-{name}.csv", work / "cal.json")
    before = _peak_mib()
    t0 = time.perf_counter()
    run(work / "log.csv", work / f"out-{name}.csv", work / "cal.json")
    return {"seconds": time.perf_counter() - t0, "peak_mib": _peak_mib() - before}


def _prepare(work: Path, n: int) -> None:
    sys.path.insert(0, str(Path(__file__).parent))
    from bench_read import servo_signal

    from gyrocal.io import write_csv

    signal = servo_signal(n, 1000.0, np.random.default_rng(1))
    write_csv(work / "log.csv", signal)
    write_csv(work / "short.csv", {k: v[:200_000] for k, v in signal.items()})
    subprocess.run([sys.executable, "-m", "gyrocal", "calibrate", str(work / "short.csv"), "--units", "deg/s",
                    "--speed", "60deg/s", "-o", str(work / "cal.json")], check=True, capture_output=True)


def _run(name: str, work: Path) -> dict:
    out = subprocess.run([sys.executable, __file__, "--stage", name, "--keep", str(work)],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _same_output(work: Path) -> float:
    """Largest difference of the two outputs' first 100 k rows, relative to the largest rate."""
    a, b = (np.loadtxt(work / f"out-{k}.csv", delimiter=",", skiprows=skip, max_rows=100_000)
            for k, skip in (("apply", 2), ("pyarrow", 1)))
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b[:, 1:])))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=10_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--keep", type=Path, help="work folder to keep (default: a temporary one)")
    parser.add_argument("--stage", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.stage == "prepare":
        _prepare(args.keep, args.samples)
        return
    if args.stage:
        print(json.dumps(stage(args.stage, args.keep)))
        return
    with tempfile.TemporaryDirectory() as tmp:
        work = args.keep or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        # a child inherits its parent's peak memory: the log is made in a process of its own too
        subprocess.run([sys.executable, __file__, "--stage", "prepare", "--keep", str(work), "--samples",
                        str(args.samples)], check=True)
        numbers = args.samples * 4 * 8 / 2**20
        print(f"log: {args.samples:,} rows, {(work / 'log.csv').stat().st_size / 2**20:.0f} MiB of CSV, "
              f"{numbers:.0f} MiB of numbers")
        runs: dict[str, list] = {"pyarrow": [], "apply": []}
        for _ in range(args.repeat):  # the stages take turns: a busy machine slows them alike
            for name in runs:
                runs[name].append(_run(name, work))
        for name, rs in runs.items():
            print(f"{name:>8}: {statistics.median(r['seconds'] for r in rs):7.2f} s, peak "
                  f"{statistics.median(r['peak_mib'] for r in rs) / numbers:.2f}x the numbers")
        pairs = list(zip(runs["apply"], runs["pyarrow"]))
        print(f"apply / pyarrow (median of paired ratios): "
              f"{statistics.median(a['seconds'] / p['seconds'] for a, p in pairs):.2f}x time, "
              f"{statistics.median(a['peak_mib'] / p['peak_mib'] for a, p in pairs):.2f}x peak memory")
        print(f"outputs agree to {_same_output(work):.1e} of the largest rate")


if __name__ == "__main__":
    main()
