"""The write-back: send an accepted calibration to the device and wait for what it read back from its storage.

The device answers a :class:`~gyrocal.capture.write_frames.SetCalibration` with a
:class:`~gyrocal.capture.write_frames.CalibrationStored` echoing the request's number and the
correction as its storage holds it; the host accepts only an echo equal to what it sent, float32
bit for bit (the request is already rounded to float32, so nothing else may differ).
"""

from __future__ import annotations

import os
import time

from ..errors import InputError
from .frames import FrameDecoder, encode
from .write_frames import CalibrationStored, SetCalibration

__all__ = ["request_for", "write_back"]


def request_for(cal, rate_unit: str) -> SetCalibration:
    """The request carrying `cal`'s correction in the device's raw units: counts in, its `rate_unit` out (the
    unit its hello frame gives, so that its corrected samples keep their unit)."""
    if cal.input_units != "counts" or cal.sensitivity is None:
        raise InputError("--write-back sends a correction of raw counts; this calibration reads "
                         f"{cal.input_units}{'' if cal.sensitivity else ' without a sensitivity'}",
                         hint="capture with --units counts (gyrocal frames always send counts)")
    from ..units import unit_factor

    matrix, offset = cal.correction
    matrix = matrix * (unit_factor(cal.output_units) / unit_factor(rate_unit))
    seq = int.from_bytes(os.urandom(4), "little")  # a fresh number: an old answer still in flight cannot match
    return SetCalibration.of(seq, matrix, offset, rate_unit)


def write_back(link, request: SetCalibration, timeout: float) -> CalibrationStored:
    """Send `request` on the open `link` (pyserial) and return the device's echo; InputError (one line) when no
    answer comes within `timeout` [s], the link fails, or the echo differs from the request."""
    import serial

    decoder = FrameDecoder()  # its own: the stream goes on, and only the answer matters here
    deadline = time.monotonic() + timeout
    try:
        link.write(encode(request))
        link.flush()
        while time.monotonic() < deadline:
            for frame in decoder.feed(link.read(link.in_waiting or 1)):
                if isinstance(frame, CalibrationStored) and frame.seq == request.seq:
                    return _checked(frame, request)
    except (serial.SerialException, OSError) as exc:
        raise InputError(f"write-back: the link to the device failed ({exc}); the device may not hold the "
                         "calibration") from None
    raise InputError(f"write-back: no answer from the device within {timeout:g} s ({{param}}); it may not hold the "
                     "calibration (does its firmware take set-calibration frames?)", param="write_back_timeout")


def _checked(answer: CalibrationStored, sent: SetCalibration) -> CalibrationStored:
    if answer.status != 0:
        raise InputError(f"write-back: the device did not store the calibration: {answer.status_name}")
    if not answer.echoes(sent):
        raise InputError("write-back: the device read back another calibration than the one sent (its storage, or "
                         "the link, changed it); do not ship this unit before writing it again")
    return answer
