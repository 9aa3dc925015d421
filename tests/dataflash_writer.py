"""A minimal ArduPilot DataFlash (``.bin``) writer for tests, from the documented format.

ArduPilot's ``libraries/AP_Logger/LogStructure.h``: every message starts with the header bytes
0xA3 0x95 and a message type; type 128 (``FMT``) describes a type: ``type`` (uint8),
``length`` of the whole message (uint8), ``name`` char[4], ``format`` char[16], ``labels``
char[64]. Format characters used here: Q uint64, B uint8, I uint32, H uint16, f float,
N char[16]. The ``IMU`` message is ``QBffffffIIfBBHH`` with labels
``TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz`` (AP_InertialSensor's
LOG_STRUCTURE_FROM_INERTIALSENSOR); ``PARM`` is ``QNf`` (``TimeUS,Name,Value``).
"""

import struct

HEAD = b"\xa3\x95"
_STRUCT = {"Q": "Q", "B": "B", "I": "I", "H": "H", "f": "f", "N": "16s", "n": "4s", "Z": "64s"}


class DataFlashWriter:
    """Append FMT-described messages to a bytes buffer; ``bytes(writer)`` is the log."""

    def __init__(self):
        self.buf = bytearray()
        self.types = {}
        self.define(128, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns")

    def define(self, msg_type: int, name: str, fmt: str, labels: str) -> None:
        layout = "<" + "".join(_STRUCT[c] for c in fmt)
        length = 3 + struct.calcsize(layout)
        self.types[name] = (msg_type, layout)
        self.buf += HEAD + bytes([128]) + struct.pack("<BB4s16s64s", msg_type, length, name.encode(), fmt.encode(),
                                                       labels.encode())

    def write(self, name: str, *values) -> None:
        msg_type, layout = self.types[name]
        packed = [v.encode() if isinstance(v, str) else v for v in values]
        self.buf += HEAD + bytes([msg_type]) + struct.pack(layout, *packed)

    def __bytes__(self) -> bytes:
        return bytes(self.buf)


def imu_log() -> DataFlashWriter:
    """A writer with the PARM and IMU formats of current ArduPilot."""
    w = DataFlashWriter()
    w.define(64, "PARM", "QNf", "TimeUS,Name,Value")
    w.define(65, "IMU", "QBffffffIIfBBHH", "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz")
    return w
