"""gyrocal: calibrate triaxial MEMS gyroscopes.

The core depends on numpy and scipy only; the command line, plots and bag readers
are extras imported where they are used. The names below are loaded on first use,
so ``import gyrocal`` (and ``gyrocal --help``) does not pay for numpy.
"""

from __future__ import annotations

from ._lazy import lazy_names
from ._moved import install as _install_moved
from ._version import __version__

_install_moved()

#: Public name -> module that defines it.
_EXPORTS = {
    "GyrocalError": "errors",
    "ScaleBias": "models",
    "Affine": "models",
    "Observation": "observations",
    "ObservationSet": "observations",
    "observe": "observations",
    "Algorithm1": "estimators",
    "PaperLM": "estimators",
    "FirstMoment": "estimators",
    "FitResult": "estimators",
    "BatchFit": "estimators",
    "make_estimator": "estimators",
    "Recording": "recording",
    "Calibration": "results.calibration",
    "ThermalCalibration": "thermal",
    "load": "results.files",
    "save": "results.files",
    "save_calibration": "results.files",
    "load_calibration": "results.files",
    "read_recording": "io",
}

__all__ = ["__version__", *_EXPORTS]


__getattr__, __dir__ = lazy_names(__name__, _EXPORTS, globals())
