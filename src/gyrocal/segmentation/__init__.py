"""Automatic segmentation of calibration sessions into rotation and static windows."""

from ._given import given_windows
from ._measure import measure_turn, standstill_level
from ._result import Segmentation, describe_found
from ._segment import segment

__all__ = ["Segmentation", "describe_found", "given_windows", "measure_turn", "segment", "standstill_level"]
