"""The library's option vocabularies, as ``Literal`` types.

Each option that takes one of a few words is typed here once; the modules that use it
import it from here, and the command line builds its choices from the same types.
This module imports nothing heavy, so ``gyrocal --help`` does not load numpy.
"""

from __future__ import annotations

from typing import Literal, get_args

__all__ = [
    "AccelModel",
    "AccelOutputUnit",
    "AccelUnit",
    "CaptureWire",
    "DesignName",
    "DeviceWire",
    "GuideName",
    "ImuGyroModel",
    "InputUnit",
    "Method",
    "MotionPolicy",
    "OutOfRange",
    "PlanDesign",
    "Protocol",
    "RateUnit",
    "SaturationPolicy",
    "StudyName",
    "TableModel",
    "TimeStamps",
    "values",
]

#: Angular-rate units a user may read or write; inside gyrocal everything is rad/s.
RateUnit = Literal["rad/s", "deg/s"]
#: Units a gyro recording may be in; ``counts`` are raw integers, optionally with a sensitivity.
InputUnit = Literal["rad/s", "deg/s", "counts"]
#: Units of accelerometer columns; inside gyrocal accelerations are m/s^2.
AccelUnit = Literal["m/s^2", "g", "counts"]
#: Estimators of the scale-bias model (see :mod:`gyrocal.estimators`).
Method = Literal["first-moment", "algorithm1", "lm"]
#: What happens to samples stuck at the sensor's full scale.
SaturationPolicy = Literal["error", "drop", "ignore"]
#: Temperatures outside a thermal table's calibrated range.
OutOfRange = Literal["refuse", "clamp", "extrapolate"]
#: How a thermal table is evaluated in temperature ("traditional": the paper's one-temperature baseline).
TableModel = Literal["lagrange", "smooth", "traditional"]
#: Motion sources of ``gyrocal simulate`` (see :mod:`gyrocal.simulation`).
Protocol = Literal["servo", "hand", "turntable", "profile", "static", "multi-position"]
#: What a noise analysis does with a log that moves: analyse its longest still stretch, or refuse it.
MotionPolicy = Literal["restrict", "refuse"]
#: How ``gyrocal simulate`` stamps its samples: on the sensor's clock, or as a PC receiving packets.
TimeStamps = Literal["sensor", "receive"]
#: Monte Carlo studies reproducing the papers (see :mod:`gyrocal.studies`).
StudyName = Literal["servo-normal", "servo-extreme", "servo-speed", "servo-convergence", "thermal-compare"]
#: Wire formats ``gyrocal capture`` reads ("auto": whichever decodes first; see :mod:`gyrocal.capture`).
CaptureWire = Literal["auto", "frames", "text"]
#: Wire formats the virtual device sends (``gyrocal simulate --device``).
DeviceWire = Literal["frames", "text"]
#: Guided sessions of ``gyrocal capture --guide`` (see :mod:`gyrocal.capture.guide` and
#: :mod:`gyrocal.capture.pose_guide`).
GuideName = Literal["servo", "hand", "multi-position"]
#: Experimental designs of the planner (see :mod:`gyrocal.planning`).
DesignName = Literal["six", "six-static", "twelve"]
#: Designs ``gyrocal plan`` predicts: the servo designs, and a hand session of still poses (see
#: :mod:`gyrocal.imu.planning`).
PlanDesign = Literal["six", "six-static", "twelve", "poses"]
#: Accelerometer models of the whole-IMU calibration ("auto": the largest the poses determine;
#: see :mod:`gyrocal.imu.accel`).
AccelModel = Literal["auto", "affine", "triangular", "scale-bias"]
#: Gyro models of the whole-IMU calibration (see :mod:`gyrocal.imu.gyro`).
ImuGyroModel = Literal["auto", "affine", "scale"]
#: Units of corrected accelerations.
AccelOutputUnit = Literal["m/s^2", "g"]


def values(choice) -> tuple[str, ...]:
    """The words a ``Literal`` type admits, in order."""
    return get_args(choice)
