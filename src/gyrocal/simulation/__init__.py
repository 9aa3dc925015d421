"""Simulation: a virtual gyro and the motions of both papers' protocols.

Readings from :func:`simulate_servo`, :func:`simulate_turntable`, :func:`simulate_profile`
and :func:`simulate_still` (a static log, or a board warming up) are :class:`~gyrocal.recording.Recording` objects, so simulated
and real data travel one path. :func:`paper_observations` (per sample) and
:func:`simulate_observations` (exact fast path) draw the servo method's window statistics.

Layer 8 (firmware, exports, simulation, figures and the store) of docs/architecture.md: imports the package
root and layers 1 to 8 only, and not export, firmware, io, jobs, plotting, store, thermal.
"""

from .fast import simulate_observations
from .gyro import ThermalErrors, VirtualGyro, noise_std_from_density
from .profiles import simulate_profile
from .servo import ServoProtocol, simulate_servo
from .still import BiasDrift, StillAccelerometer, StillProtocol, simulate_still
from .thermal_truth import ThermalTruth
from .turntable import TurntableProtocol, simulate_turntable
from .windows import paper_observations

__all__ = [
    "VirtualGyro", "ThermalErrors", "noise_std_from_density",
    "ServoProtocol", "simulate_servo",
    "ThermalTruth", "TurntableProtocol", "simulate_turntable",
    "simulate_profile", "paper_observations", "simulate_observations",
    "BiasDrift", "StillAccelerometer", "StillProtocol", "simulate_still",
]
