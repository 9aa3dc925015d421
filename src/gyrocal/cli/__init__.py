"""Command line: ``gyrocal``.

Each command group lives in its own module (``*_cmds``); they never import each other,
and shared pieces live in the ``_*`` helper modules. :data:`HELP_ORDER` is the one
place that sets the order of ``gyrocal --help``; :data:`COMMANDS` names the module of each
command, so that a run imports only the module of the command it runs
(:mod:`gyrocal.cli.app`). Reading :data:`app`'s commands outside a run imports them all.

Layer 10 (the command line) of docs/architecture.md: imports the package root and layers 1 to 10 only.
"""

from __future__ import annotations

import atexit
import os
import sys
import threading

from . import app as _app_module
from .app import app, run

__all__ = ["COMMANDS", "COMMAND_MODULES", "HELP_ORDER", "app", "main"]

#: Modules that register commands (add yours here, and its commands to COMMANDS).
COMMAND_MODULES = ("calibrate_cmds", "imu_cmds", "apply_cmds", "export_cmds", "thermal_cmds", "noise_cmds",
                   "flight_cmds", "sim_cmds", "plan_cmds", "study_cmds", "capture_cmds", "verify_cmds",
                   "station_cmds", "store_cmds", "batch_cmds", "fleet_cmds")
#: Each command (or command group) -> the module that registers it (tests/test_cli_registry.py checks it).
COMMANDS = {"calibrate": "calibrate_cmds", "segments": "calibrate_cmds", "imu": "imu_cmds", "apply": "apply_cmds",
            "export": "export_cmds", "thermal": "thermal_cmds", "thermal-report": "thermal_cmds",
            "noise": "noise_cmds", "thermal-bias": "flight_cmds", "simulate": "sim_cmds", "plan": "plan_cmds",
            "study": "study_cmds", "capture": "capture_cmds", "verify": "verify_cmds", "compare": "verify_cmds",
            "accept": "station_cmds", "certificate": "station_cmds", "batch": "batch_cmds",
            "fleet": "fleet_cmds", "store": "store_cmds"}
#: Order of the commands in ``gyrocal --help``; commands not listed follow by name.
HELP_ORDER = ("calibrate", "segments", "apply", "export", "imu", "verify", "compare", "thermal", "thermal-report",
              "noise", "thermal-bias", "simulate", "plan", "study", "capture", "batch", "accept", "certificate", "store",
              "fleet")

_app_module.HELP_ORDER[:] = HELP_ORDER
_app_module.MODULES[:] = COMMAND_MODULES
_app_module.COMMANDS.update(COMMANDS)


def main() -> None:
    """Console-script entry point."""
    _leave(run(sys.argv[1:]))


def _leave(code: int) -> None:
    """End the process with `code`, skipping the interpreter's teardown of every module (40-55 ms a run).

    What that teardown does of use happens first: the streams are flushed and the atexit handlers
    run (logging's among them). Every file gyrocal writes is closed before its command returns. With
    other threads alive, or a stream that cannot be flushed (a closed pipe), the ordinary exit runs,
    which waits for the threads and reports the stream as Python does.
    """
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except (OSError, ValueError):
        sys.exit(code)
    if threading.active_count() > 1:
        sys.exit(code)
    atexit._run_exitfuncs()
    os._exit(code)
