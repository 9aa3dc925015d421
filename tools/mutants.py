"""Mutation check of the statistical core: does the test suite notice when the 1-sigma code is wrong?

Each mutation below changes one line of a module that computes an estimate or its 1-sigma (a term
dropped, a constant off by about 1 %, a factor not squared, an off-by-one). For each, a copy of the
tracked tree is mutated and the whole suite is run there, stopping at the first failure (the test
files most likely to fail go first, so a killed mutant costs seconds; a survivor costs one full
run). A mutant that no test fails *survives*: the suite cannot tell that code from the real one.

Run by hand, not in CI (a survivor costs a full suite run)::

    python tools/mutants.py                 # every mutation, one worker
    python tools/mutants.py -j 2 -k excess  # the mutations whose name contains "excess", two workers
    python tools/mutants.py --list
    python tools/mutants.py -k ramp --hints-only  # only each mutation's own test files, not the whole suite

With ``--hints-only`` a mutant that its own test files do not kill is reported as ``survived the
hints`` without the whole-suite run (cheap on a shared machine; a full run decides it).

It exits 1 when any mutant survives, 2 when a mutation no longer matches its module (the list is stale).
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

from mutations import MUTATIONS, Mutation

ROOT = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class Outcome:
    mutation: Mutation
    killed: bool
    by: str  # the first failing test, or what the run ended with
    seconds: float


def _tracked_copy(dest: Path) -> None:
    """The tracked files of the repository (as they are in the working tree) under `dest`."""
    files = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, check=True, capture_output=True).stdout
    for name in filter(None, files.decode().split("\0")):
        src = ROOT / name
        if src.is_file():
            (dest / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / name)


def check_stale(mutations: list[Mutation]) -> list[str]:
    """Mutations whose text is not found exactly once in their file."""
    bad = []
    for m in mutations:
        count = (ROOT / m.path).read_text().count(m.old)
        if count != 1:
            bad.append(f"{m.name}: {m.path} holds its text {count} times (expected once)")
    return bad


def _first_failure(output: str) -> str:
    for line in output.splitlines():
        if line.startswith(("FAILED ", "ERROR ")):
            return line.split(" ", 1)[1].split(" - ")[0]
    tail = [line for line in output.splitlines() if line.strip()]
    return tail[-1] if tail else "no output"


def run_one(m: Mutation, python: str, hints_only: bool = False) -> Outcome:
    """Mutate a fresh copy of the tree and run the suite there, the likely killers first (only them with
    `hints_only`, when the mutation names any)."""
    with tempfile.TemporaryDirectory(prefix="gyrocal-mutant-") as tmp:
        tree = Path(tmp)
        _tracked_copy(tree)
        target = tree / m.path
        target.write_text(target.read_text().replace(m.old, m.new, 1))
        env = dict(os.environ, PYTHONPATH=str(tree / "src"), PYTHONDONTWRITEBYTECODE="1")
        cmd = [python, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider"]
        start = time.perf_counter()
        # pytest orders one run's files by folder, so the likely killers get a run of their own first
        # tests that signal a process at a moment in time check no statistics, and a loaded machine upsets them
        everything = ["tests", "-k", "not ctrl_c and not sigterm"]
        selections = ([*m.tests],) if m.tests and hints_only else ([*m.tests], everything) if m.tests else (everything,)
        for selection in selections:
            proc = subprocess.run(cmd + selection, cwd=tree, env=env, capture_output=True, text=True)
            if proc.returncode:
                break
        seconds = time.perf_counter() - start
    out = proc.stdout + proc.stderr
    survived = "survived the hints" if m.tests and hints_only else "survived"
    return Outcome(m, proc.returncode != 0, _first_failure(out) if proc.returncode else survived, seconds)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("-k", dest="match", default="", help="only mutations whose name contains this")
    parser.add_argument("-j", dest="jobs", type=int, default=1, help="mutants run at once")
    parser.add_argument("--list", action="store_true", help="print the mutations and stop")
    parser.add_argument("--hints-only", action="store_true",
                        help="run only each mutation's own test files, not the whole suite after them")
    parser.add_argument("--python", default=sys.executable, help="the interpreter that has the test extras")
    args = parser.parse_args(argv)
    chosen = [m for m in MUTATIONS if args.match in m.name]
    stale = check_stale(chosen)
    if stale:
        print("\n".join(stale), file=sys.stderr)
        return 2
    if args.list:
        for m in chosen:
            print(f"{m.name:32s} {m.path}: {m.why}")
        return 0
    print(f"{len(chosen)} mutations, {args.jobs} at a time")
    with ThreadPoolExecutor(args.jobs) as pool:
        outcomes = []
        for o in pool.map(lambda m: run_one(m, args.python, args.hints_only), chosen):
            outcomes.append(o)
            print(f"{'killed  ' if o.killed else 'SURVIVED'} {o.mutation.name:32s} {o.seconds:6.0f} s  {o.by}",
                  flush=True)
    survivors = [o for o in outcomes if not o.killed]
    modules = sorted({m.path for m in chosen})
    print(f"\n{len(outcomes) - len(survivors)} of {len(outcomes)} killed over {len(modules)} modules; "
          f"{len(survivors)} survived" + (": " + ", ".join(o.mutation.name for o in survivors) if survivors else ""))
    return 1 if survivors else 0


if __name__ == "__main__":
    sys.exit(main())
