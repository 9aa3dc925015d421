"""Reading recordings and windows files, and writing CSV.

Formats: delimited text (pyarrow when installed), Parquet (``arrow`` extra), ROS 1 / ROS 2 /
MCAP bags (``ros`` extra), PX4 ULog (``ulog`` extra) and ArduPilot DataFlash (``dataflash``
extra) logs. Everything comes back as a checked
:class:`~gyrocal.recording.Recording` in internal units.
"""

from .flightlog import read_flight_log
from .reader import read_recording
from .saturation import find_saturation
from .windowsfile import read_windows
from .writer import write_csv

__all__ = ["read_recording", "read_flight_log", "read_windows", "write_csv", "find_saturation"]
