"""Command line: ``gyrocal``. Importing this module registers every command."""

from __future__ import annotations

import sys

from .app import app, run
from . import calibrate_cmds, capture_cmds, sim_cmds, thermal_cmds  # noqa: F401  (register commands)

__all__ = ["app", "main"]


def main() -> None:
    """Console-script entry point."""
    sys.exit(run(sys.argv[1:]))
