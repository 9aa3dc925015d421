"""Frames of the write-back: the host's set-calibration request and the device's calibration-stored answer.

Both payloads are ``seq (u32) | flags | rate unit | status | 0 | matrix (9 float32, row by row) |
offset (3 float32)``, little-endian, in a frame as :mod:`gyrocal.capture.frames` writes it (same sync
and CRC); the C side is ``gyrocal_frame_set_calibration`` / ``gyrocal_frame_calibration_stored`` and
``gyrocal_parse_set_calibration`` (``gyrocal/c/gyrocal_frame.h``). The correction is the canonical
``w = matrix (raw - offset)`` with raw and offset in counts.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np

__all__ = ["APPLY", "STORED_STATUS", "CalibrationStored", "SetCalibration"]

APPLY = 1  # GYROCAL_SETCAL_APPLY: correct the samples from now on
#: GYROCAL_STORED_* by code.
STORED_STATUS = {0: "stored", 1: "refused (a value not finite, or an unknown unit)",
                 2: "the storage failed or read back no valid record"}
_UNITS = ("rad/s", "deg/s")
_FORMAT = struct.Struct("<IBBBB12f")


def _f32(values) -> tuple[float, ...]:
    return tuple(float(v) for v in np.asarray(values, dtype=np.float32).ravel())


@dataclass(frozen=True)
class SetCalibration:
    """Host to device: store the correction ``w = matrix (raw - offset)`` [rate unit per count, counts];
    ``seq`` numbers the request, ``flags`` :data:`APPLY` to correct the samples from now on."""

    TYPE = 0x09
    FORMAT = _FORMAT
    seq: int
    matrix: tuple[float, ...]  # 9, row by row, float32 values
    offset: tuple[float, float, float]
    rate_unit: str = "deg/s"
    flags: int = APPLY

    @classmethod
    def of(cls, seq: int, matrix, offset, rate_unit: str = "deg/s", flags: int = APPLY) -> SetCalibration:
        """From any arrays, rounded to float32 (what the device stores)."""
        return cls(seq, _f32(matrix), _f32(offset), rate_unit, flags)

    def payload(self, status: int = 0) -> bytes:
        return self.FORMAT.pack(self.seq & 0xFFFFFFFF, self.flags, _UNITS.index(self.rate_unit), status, 0,
                                *self.matrix, *self.offset)

    @classmethod
    def parse(cls, p: bytes) -> SetCalibration:
        seq, flags, unit, _, _, *v = cls.FORMAT.unpack(p)
        return cls(seq, tuple(v[:9]), tuple(v[9:]), _unit(unit), flags)


@dataclass(frozen=True)
class CalibrationStored:
    """Device to host: the correction as the device read it back from its storage, with the request's
    ``seq`` and a status (0 stored; see :data:`STORED_STATUS`)."""

    TYPE = 0x0A
    FORMAT = _FORMAT
    seq: int
    matrix: tuple[float, ...]
    offset: tuple[float, float, float]
    rate_unit: str = "deg/s"
    flags: int = APPLY
    status: int = 0

    @property
    def status_name(self) -> str:
        return STORED_STATUS.get(self.status, f"status {self.status}")

    def payload(self) -> bytes:
        return SetCalibration(self.seq, self.matrix, self.offset, self.rate_unit, self.flags).payload(self.status)

    @classmethod
    def parse(cls, p: bytes) -> CalibrationStored:
        seq, flags, unit, status, _, *v = cls.FORMAT.unpack(p)
        return cls(seq, tuple(v[:9]), tuple(v[9:]), _unit(unit), flags, status)

    def echoes(self, sent: SetCalibration) -> bool:
        """Whether this answer stored exactly what `sent` asked for (float32 values compared bit for bit)."""
        return (self.status == 0 and self.seq == sent.seq and self.rate_unit == sent.rate_unit
                and self.payload()[4:] == sent.payload()[4:] and self.flags == sent.flags)


def _unit(code: int) -> str:
    return _UNITS[code] if code < len(_UNITS) else f"unit {code}"
