"""Start-up cost of the command line: ``gyrocal --help`` and ``gyrocal calibrate --example``.

Run by hand:  python bench/bench_startup.py [--repeat 5] [--previous-src DIR]

Each command runs in a fresh interpreter (best of `repeat`), next to:

* the bare interpreter (``python -c pass``): the floor no import can beat;
* ``python -c "import numpy"``: the baseline of issue 25 (``calibrate --example`` at most 2.5x it);
* the previous start: the same command after importing what the command line loaded before its
  imports became lazy (numpy and the modules the package root and the command modules imported at
  the top), kept here as the baseline; or, with ``--previous-src``, a checkout of an earlier gyrocal
  itself (``git worktree add /tmp/old c8f2222`` then ``--previous-src /tmp/old/src``).

Prints each time, the share of it that is interpreter start, and previous / now.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

#: What ``import gyrocal.cli`` loaded before the lazy imports: the package root's names and the command
#: modules' top-level imports.
PREVIOUS = ("import numpy; import gyrocal.calibration, gyrocal.estimators, gyrocal.models, gyrocal.observations, "
            "gyrocal.recording, gyrocal.segmentation, gyrocal.units, gyrocal.segmentation.windows; ")
RUN = "import gyrocal.cli, sys; sys.argv = ['gyrocal'] + {argv!r}; gyrocal.cli.main()"


def best(code: str, repeat: int, src: str | None = None) -> float:
    env = None if src is None else dict(os.environ, PYTHONPATH=src)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], capture_output=True, check=False, env=env)
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--previous-src", help="src folder of an earlier gyrocal, run as the baseline")
    args = parser.parse_args()
    floor, numpy_start = best("pass", args.repeat), best("import numpy", args.repeat)
    print(f"interpreter alone: {floor:.3f} s, with numpy imported {numpy_start:.3f} s")
    for argv in (["--help"], ["calibrate", "--example"]):
        now = best(RUN.format(argv=argv), args.repeat)
        before = (best(RUN.format(argv=argv), args.repeat, args.previous_src) if args.previous_src
                  else best(PREVIOUS + RUN.format(argv=argv), args.repeat))
        name = "gyrocal " + " ".join(argv)
        print(f"{name:>28}: now {now:.3f} s ({100 * floor / now:.0f} % interpreter), previous {before:.3f} s; "
              f"previous / now {before / now:.2f}x; now / import numpy {now / numpy_start:.2f}x")


if __name__ == "__main__":
    main()
