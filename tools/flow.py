#!/usr/bin/env python3
"""Count the gyrocal modules one recording passes through in ``gyrocal.pipeline.calibrate``.

Runs ``calibrate`` on the bundled example (``gyrocal calibrate --example``: deg/s, speed 60 deg/s)
under ``sys.setprofile`` and keeps the Python call and return events of frames whose module is
``gyrocal`` or below it (``f_globals['__name__']``). A warm-up call first, so imports are not counted.

Printed:

* modules entered: distinct gyrocal modules with a function called during the run;
* climbs back: distinct returns from one module into another (callee -> caller edges),
  each a return to a module the flow had left; with the raw count of such returns beside it;
* depth: the longest chain of distinct module changes on the stack.
* the flow: the modules that :data:`TOP` (``calibrate``'s own module and its stages) call, in order
  (repeats in a row collapsed), and how often it climbs back into a module it had left;
* with ``--list``, that flow and, per function ``calibrate`` calls (a stage), the modules below it.

Usage::

    PYTHONPATH=src python tools/flow.py [--methods first-moment,lm] [--list]
"""

from __future__ import annotations

import argparse
import sys

#: Stage packages whose __init__ itself holds code (a module named like the package is the package).
_PACKAGES = {"gyrocal.recording", "gyrocal.observations", "gyrocal.planning", "gyrocal.export", "gyrocal.segmentation",
             "gyrocal.estimators", "gyrocal.io"}
#: The modules that sequence the run: what they call is the flow.
TOP = {"gyrocal.pipeline", "gyrocal.pipeline.stages"}


def _trace(fn):
    """Run `fn` under a profiler; return the module stacks seen and the cross-module returns."""
    stack: list[str] = []
    entered: set[str] = set()
    returns: dict[tuple[str, str], int] = {}
    calls: dict[tuple[str, str], int] = {}
    depth = [0]
    flow: list[str] = []  # modules the orchestrating modules call, in order, repeats collapsed
    stage = [""]  # the function calibrate called last, and the modules seen under each
    by_stage: dict[str, set[str]] = {}

    def hook(frame, event, _arg):
        if event not in ("call", "return"):
            return
        module = frame.f_globals.get("__name__", "")
        if not module.startswith("gyrocal"):
            return
        if event == "call":
            if stack and stack[-1] != module:
                calls[(stack[-1], module)] = calls.get((stack[-1], module), 0) + 1
                if stack[-1] in TOP and module not in TOP and (not flow or flow[-1] != module):
                    flow.append(module)
            caller = frame.f_back
            if caller is not None and caller.f_code.co_name == "calibrate" and module in TOP:
                stage[0] = frame.f_code.co_name
            stack.append(module)
            entered.add(module)
            if module not in TOP and stage[0]:
                by_stage.setdefault(stage[0], set()).add(module)
            changes = sum(a != b for a, b in zip(stack, stack[1:]))
            depth[0] = max(depth[0], changes)
        elif stack:
            stack.pop()
            if stack and stack[-1] != module:
                returns[(module, stack[-1])] = returns.get((module, stack[-1]), 0) + 1

    sys.setprofile(hook)
    try:
        fn()
    finally:
        sys.setprofile(None)
    return entered, calls, returns, depth[0], flow, by_stage


def _packages(flow: list[str]) -> list[str]:
    """The flow by stage package (``gyrocal.checks.quality`` -> ``checks``), repeats in a row collapsed; the package
    root's vocabulary (units, models) is no stage and is left out."""
    out: list[str] = []
    for module in flow:
        parts = module.split(".")
        if len(parts) == 2 and module not in _PACKAGES:
            continue
        package = parts[1]
        if not out or out[-1] != package:
            out.append(package)
    return out


def main(argv=None) -> int:
    """Print the counts for each method on the bundled example."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--methods", default="first-moment,lm")
    parser.add_argument("--list", action="store_true", help="also list the modules in the order entered")
    args = parser.parse_args(argv)
    import math

    from gyrocal.cli.calibrate_cmds import _example_paths
    from gyrocal.io import read_recording
    from gyrocal.pipeline import calibrate

    path, _ = _example_paths()
    rec = read_recording(path, units="deg/s")
    for method in args.methods.split(","):
        def run(method=method):
            return calibrate(rec, speed=math.radians(60.0), method=method)

        run()  # imports and caches out of the count
        entered, _, returns, depth, flow, by_stage = _trace(run)
        again = sum(m in flow[:i] for i, m in enumerate(flow))
        print(f"{method}: calibrate enters {len(set(flow))} module(s) besides {', '.join(sorted(TOP & entered))} "
              f"and climbs back {again} time(s) ({len(flow)} hand-offs); whole trace: {len(entered)} modules, "
              f"{len(returns)} distinct returns across modules ({sum(returns.values())} in all), depth {depth}")
        stages = _packages(flow)
        back = sum(p in stages[:i] for i, p in enumerate(stages))
        print(f"  by stage package: {' > '.join(stages)} ({len(set(stages))} packages, {len(stages) - 1} hand-offs, "
              f"{back} climb(s) back to a package already left)")
        if args.list:
            print("  " + " > ".join(m.removeprefix("gyrocal.") for m in flow))
            for name, modules in by_stage.items():
                print(f"  stage {name}: {len(modules)} module(s): "
                      + ", ".join(sorted(m.removeprefix("gyrocal.") for m in modules)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
