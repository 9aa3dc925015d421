"""Reading recordings and windows files, and writing CSV.

Formats: delimited text (pyarrow when installed), Parquet (``arrow`` extra), ROS 1 / ROS 2 /
MCAP bags (``ros`` extra), PX4 ULog (``ulog`` extra) and ArduPilot DataFlash (``dataflash``
extra) logs. Everything comes back as a checked
:class:`~gyrocal.recording.Recording` in internal units.

Layer 3 (reading files and observations) of docs/architecture.md: imports the package root and layers 1 to 3
only.
"""

from ..recording.saturation import find_saturation
from .accel_log import attach_accelerometer
from .flightlog import read_flight_log
from .profile import read_profile
from .reader import read_header_comment, read_recording
from .session import read_session
from .windowsfile import read_windows
from .writer import check_csv_name, recording_columns, write_csv, write_recording

__all__ = ["attach_accelerometer", "check_csv_name", "find_saturation", "read_flight_log", "read_header_comment", "read_profile", "read_recording", "read_session",
           "read_windows", "recording_columns", "write_csv", "write_recording"]
