"""Proof on the bench: a calibration checked against a reference gyro.

The servo method of Wang et al. validates its calibration by mounting the calibrated gyro
beside a high-grade reference (Tables IV-V, Figs. 7-10). Two sensors, two clocks:

* :func:`align` finds the clock offset and drift and the mounting rotation between two
  logs of one motion, with their 1-sigma;
* :func:`verify_calibration` (and :func:`verify_rates` on arrays) compares calibrated and raw
  readings with the aligned reference:
  MSE as in the paper's Table V, RMSE, 99th percentile and reduction per axis, with
  block-bootstrap 1-sigma and the reference's own noise floor;
* :func:`compare_calibrations` compares calibrations of one unit parameter by parameter.

Numerics only: no files, no command line.

Layer 7 (the methods) of docs/architecture.md: imports the package root and layers 1 to 7 only.
"""

from .alignment import Alignment, AlignmentError, align
from .metrics import FIGURES, Metrics, error_metrics
from .report import VerifyReport
from .run import VerifySeries, verify_calibration, verify_rates

__all__ = ["FIGURES", "Alignment", "AlignmentError", "Metrics", "VerifyReport", "VerifySeries", "align", "error_metrics",
           "verify_calibration", "verify_rates"]
