"""Automatic segmentation of calibration sessions into rotation and static windows.

Owns the :class:`~.windows.Window` type (:mod:`.windows`), detection and given windows, the windows a
method must not use as they are (:mod:`.screening`: across a gap or a break, varying rates for the paper's
methods) and whether a log is still (:mod:`.stillness`).

Layer 2 (windows) of docs/architecture.md: imports the package root and layers 1 to 2 only.
"""

from ._given import given_windows
from ._measure import measure_turn, standstill_level
from ._result import Segmentation, describe_found
from ._segment import segment

__all__ = ["Segmentation", "describe_found", "given_windows", "measure_turn", "segment", "standstill_level"]
