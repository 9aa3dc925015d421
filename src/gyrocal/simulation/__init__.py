"""Simulation: a virtual gyro and the motions of both papers' protocols."""

from .gyro import ThermalErrors, VirtualGyro, noise_std_from_density

__all__ = ["VirtualGyro", "ThermalErrors", "noise_std_from_density"]
