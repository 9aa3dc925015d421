"""Firmware support for the C library in ``gyrocal/c/``.

* :mod:`.header`: C headers of calibrations that the library reads directly
  (``Calibration.c_header``, ``ThermalCalibration.c_header``);
* :mod:`.host`: the library built with the host's C compiler and called through ctypes,
  to check it against Python.

Layer 8 (firmware, exports, simulation, figures and the store) of docs/architecture.md: imports the package
root and layers 1 to 8 only.
"""

from .header import C_LIBRARY_VERSION, calibration_header, thermal_header
from .host import C_FLAGS, CCompileError, CLibrary, build_library, c_source_dir, find_c_compiler, load_library

__all__ = [
    "C_FLAGS",
    "C_LIBRARY_VERSION",
    "CCompileError",
    "CLibrary",
    "build_library",
    "c_source_dir",
    "calibration_header",
    "find_c_compiler",
    "load_library",
    "thermal_header",
]
