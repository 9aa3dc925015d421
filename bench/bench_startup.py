"""Start-up cost of the command line: ``gyrocal --help`` and ``gyrocal calibrate --example``.

Run by hand:  python bench/bench_startup.py [--repeat 9] [--previous-src DIR]

Each command runs in a fresh interpreter, `repeat` times, interleaved with its baselines (so load on a
shared machine reaches all alike); the figures are medians, and the ratios medians of the paired ratios.
The baselines:

* the bare interpreter (``python -c pass``): the floor no import can beat;
* ``python -c "import numpy"``: the baseline of issue 25 (``calibrate --example`` at most 2.5x it);
* the previous start: the same command after importing what the command line loaded before its
  imports became lazy (numpy and the modules the package root and the command modules imported at
  the top), kept here as the baseline; or, with ``--previous-src``, a checkout of an earlier gyrocal
  itself (``git worktree add /tmp/old c8f2222`` then ``--previous-src /tmp/old/src``).

Runs with Python's bytecode cache on (``PYTHONDONTWRITEBYTECODE`` removed from the children's environment,
after a warm-up round), as an installed gyrocal runs from its second start; without it every start compiles
gyrocal's modules again (about 90 ms more on the 2-core machine).

Prints each time, the share of it that is interpreter start, previous / now and now / import numpy.
The command line imports only the module of the command it runs (``gyrocal.cli.app``); the previous
start without ``--previous-src`` imports every command module first (``gyrocal.cli.app.load_all``).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time

#: What ``import gyrocal.cli`` loaded before the lazy imports: the package root's names and the command
#: modules' top-level imports.
PREVIOUS = ("import numpy; import gyrocal.results.calibration, gyrocal.estimators, gyrocal.models, gyrocal.observations, "
            "gyrocal.recording, gyrocal.segmentation, gyrocal.units, gyrocal.segmentation.windows; "
            "from gyrocal.cli.app import load_all; load_all(); ")
RUN = "import gyrocal.cli, sys; sys.argv = ['gyrocal'] + {argv!r}; gyrocal.cli.main()"


def once(code: str, src: str | None = None) -> float:
    # as a user's machine runs it: Python caches the modules' bytecode (a warm-up round writes it first)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    if src is not None:
        env["PYTHONPATH"] = src
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], capture_output=True, check=True, env=env)
    return time.perf_counter() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=9)
    parser.add_argument("--previous-src", help="src folder of an earlier gyrocal, run as the baseline")
    args = parser.parse_args()
    runs = {"floor": ("pass", None), "numpy": ("import numpy", None)}
    for argv in (["--help"], ["calibrate", "--example"]):
        name = "gyrocal " + " ".join(argv)
        runs[name] = (RUN.format(argv=argv), None)
        runs[name + " previous"] = ((RUN.format(argv=argv), args.previous_src) if args.previous_src
                                    else (PREVIOUS + RUN.format(argv=argv), None))
    times = {k: [] for k in runs}
    for code, src in runs.values():  # warm-up: bytecode written, files in the page cache
        once(code, src)
    for _ in range(args.repeat):
        for k, (code, src) in runs.items():
            times[k].append(once(code, src))
    med = {k: statistics.median(v) for k, v in times.items()}

    def paired(a: str, b: str) -> float:
        return statistics.median(x / y for x, y in zip(times[a], times[b]))

    print(f"interpreter alone: {med['floor']:.3f} s, with numpy imported {med['numpy']:.3f} s "
          f"(medians of {args.repeat}, interleaved)")
    for name in ("gyrocal --help", "gyrocal calibrate --example"):
        print(f"{name:>28}: now {med[name]:.3f} s ({100 * med['floor'] / med[name]:.0f} % interpreter), previous "
              f"{med[name + ' previous']:.3f} s; previous / now {paired(name + ' previous', name):.2f}x; "
              f"now / import numpy {paired(name, 'numpy'):.2f}x")


if __name__ == "__main__":
    main()
