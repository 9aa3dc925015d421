"""Command line: ``gyrocal``. Importing this module registers every command.

Each command group lives in its own module (``*_cmds``); they never import each other,
and shared pieces live in the ``_*`` helper modules. :data:`HELP_ORDER` is the one
place that sets the order of ``gyrocal --help``.

Layer 10 (the command line) of docs/architecture.md: imports the package root and layers 1 to 10 only.
"""

from __future__ import annotations

import importlib
import sys

from . import app as _app_module
from .app import app, run

__all__ = ["COMMAND_MODULES", "HELP_ORDER", "app", "main"]

#: Modules that register commands (add yours here).
COMMAND_MODULES = ("calibrate_cmds", "imu_cmds", "apply_cmds", "export_cmds", "thermal_cmds", "noise_cmds",
                   "flight_cmds", "sim_cmds", "plan_cmds", "study_cmds", "capture_cmds", "verify_cmds",
                   "station_cmds", "store_cmds", "batch_cmds", "fleet_cmds")
#: Order of the commands in ``gyrocal --help``; commands not listed follow by name.
HELP_ORDER = ("calibrate", "segments", "apply", "export", "imu", "verify", "compare", "thermal", "thermal-report",
              "noise", "thermal-bias", "simulate", "plan", "study", "capture", "batch", "accept", "certificate", "store",
              "fleet")

for _name in COMMAND_MODULES:
    importlib.import_module(f"{__name__}.{_name}")
_app_module.HELP_ORDER[:] = HELP_ORDER


def main() -> None:
    """Console-script entry point."""
    sys.exit(run(sys.argv[1:]))
