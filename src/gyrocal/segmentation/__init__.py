"""Automatic segmentation of calibration sessions into rotation and static windows."""

from ._motion import static_level
from ._result import Segmentation, describe_found
from ._segment import segment

__all__ = ["Segmentation", "describe_found", "segment", "static_level"]
