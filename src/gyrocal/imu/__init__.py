"""Whole-IMU calibration from a hand session, no turntable needed.

The board rests in many orientations and is turned by hand in between (the multi-position
method of Tedaldi et al., ICRA 2014), or follows imucal's Ferraris protocol (six faces and
three known-angle turns). :func:`calibrate_imu` finds the still poses, fits the accelerometer
from the gravity they show and the gyro from the turns between them, each with its
covariance and goodness of fit. :mod:`gyrocal.imu.planning` predicts the accuracy of a pose
plan before it is done.

Layer 7 (the methods) of docs/architecture.md: imports the package root and layers 1 to 7 only.
"""

from .accel import ACCEL_MODELS, AccelFit, fit_accelerometer, normal_gravity
from .gyro import GYRO_MODELS, GyroFit, PairCheck, Turn, fit_gyroscope
from .poses import Coverage, coverage, fibonacci_directions, pose_sequence, triangular_frame
from .session import FERRARIS_POSES, ImuCalibrationResult, calibrate_imu
from .statics import Static, StaticDetection, detect_statics

__all__ = [
    "ACCEL_MODELS",
    "FERRARIS_POSES",
    "GYRO_MODELS",
    "AccelFit",
    "Coverage",
    "GyroFit",
    "ImuCalibrationResult",
    "PairCheck",
    "Static",
    "StaticDetection",
    "Turn",
    "calibrate_imu",
    "coverage",
    "detect_statics",
    "fibonacci_directions",
    "fit_accelerometer",
    "fit_gyroscope",
    "normal_gravity",
    "pose_sequence",
    "triangular_frame",
]
