"""gyrocal: calibrate triaxial MEMS gyroscopes.

The core depends on numpy and scipy only; the command line, plots and bag readers
are extras imported where they are used.
"""

__version__ = "0.1.0"

from .calibration import Calibration, load_calibration, save_calibration  # noqa: E402
from .errors import GyrocalError  # noqa: E402
from .estimators import Algorithm1, BatchFit, FirstMoment, FitResult, PaperLM, make_estimator  # noqa: E402
from .models import Affine, ScaleBias  # noqa: E402
from .observations import Observation, ObservationSet, observe  # noqa: E402
from .recording import Recording  # noqa: E402

__all__ = [
    "__version__",
    "GyrocalError",
    "ScaleBias",
    "Affine",
    "Observation",
    "ObservationSet",
    "observe",
    "Algorithm1",
    "PaperLM",
    "FirstMoment",
    "FitResult",
    "BatchFit",
    "make_estimator",
    "Recording",
    "Calibration",
    "save_calibration",
    "load_calibration",
]
