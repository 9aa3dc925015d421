"""Simulation: a virtual gyro and the motions of both papers' protocols.

Readings from :func:`simulate_servo`, :func:`simulate_turntable`, :func:`simulate_profile`
and :func:`simulate_still` (a static log, or a board warming up) are :class:`~gyrocal.recording.Recording` objects, so simulated
and real data travel one path. :func:`paper_observations` (per sample) and
:func:`simulate_observations` (exact fast path) draw the servo method's window statistics.

Layer 8 (firmware, exports, simulation, figures and the store) of docs/architecture.md: imports the package
root and layers 1 to 8 only, and not export, firmware, io, jobs, plotting, store, thermal.
"""

from .._lazy import lazy_names

#: Public name -> module of this package that defines it; loaded on first use, so that importing one
#: simulator (``gyrocal.simulation.truth`` for the bundled example) does not import them all.
_EXPORTS = {
    "simulate_observations": "fast", "ThermalErrors": "gyro", "VirtualGyro": "gyro",
    "noise_std_from_density": "gyro", "simulate_profile": "profiles", "ServoProtocol": "servo",
    "simulate_servo": "servo", "BiasDrift": "still", "StillAccelerometer": "still", "StillProtocol": "still",
    "simulate_still": "still", "ThermalTruth": "thermal_truth", "TurntableProtocol": "turntable",
    "simulate_turntable": "turntable", "paper_observations": "windows",
}

__all__ = [
    "VirtualGyro", "ThermalErrors", "noise_std_from_density",
    "ServoProtocol", "simulate_servo",
    "ThermalTruth", "TurntableProtocol", "simulate_turntable",
    "simulate_profile", "paper_observations", "simulate_observations",
    "BiasDrift", "StillAccelerometer", "StillProtocol", "simulate_still",
]


__getattr__, __dir__ = lazy_names(__name__, _EXPORTS, globals())
