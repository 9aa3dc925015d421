"""The C library's frame encoder and on-device session, seen from Python through ctypes.

:func:`firmware_stream` sends a session through the same calls, in the same order, as the
example firmware (``examples/firmware/gyrocal_example.c``): a hello frame, then per sample a
sample frame (or a 6-axis frame), the session's turn and result frames with a text line each,
corrected samples once calibrated, and an end frame when the session is over. The virtual
device serves these bytes, and a test checks them byte for byte against the example firmware
compiled on the host.
"""

from __future__ import annotations

import ctypes

import numpy as np

from ..firmware import C_LIBRARY_VERSION, CLibrary, load_library
from .frames import TURN_LABELS

__all__ = ["CDevice", "CStorage", "firmware_stream"]

_F3 = ctypes.c_float * 3
_BUF = ctypes.c_uint8 * 70  # GYROCAL_FRAME_MAX
_REASONS = (" accepted", " ignored: wrong angle", " ignored: off axis", " ignored: too long", " ignored: bad window")


class _Hello(ctypes.Structure):
    _fields_ = [("sample_rate", ctypes.c_float), ("sensitivity", ctypes.c_float), ("rate_unit", ctypes.c_uint8),
                ("flags", ctypes.c_uint8), ("library", ctypes.c_uint16), ("firmware", ctypes.c_char * 16),
                ("accel_sensitivity", ctypes.c_uint16)]


class _Turn(ctypes.Structure):
    _fields_ = [("start", ctypes.c_uint32), ("stop", ctypes.c_uint32), ("rate", ctypes.c_float),
                ("angle", ctypes.c_float), ("mean", _F3), ("slot", ctypes.c_uint8), ("status", ctypes.c_uint8)]


class _Accum(ctypes.Structure):
    _fields_ = [(name, _F3) for name in ("first", "s1", "c1", "s2", "c2")] + [("count", ctypes.c_uint32)]


class _Obs(ctypes.Structure):
    _fields_ = [("mean", _F3), ("mean_sq", _F3), ("rate", ctypes.c_float)]


class _ScaleBias(ctypes.Structure):
    _fields_ = [("k", _F3), ("b", _F3)]


class _Session(ctypes.Structure):
    """gyrocal_session_t, field for field (gyrocal_session.h)."""

    _fields_ = [
        ("sample_rate", ctypes.c_float), ("sensitivity", ctypes.c_float), ("turn_angle", ctypes.c_float),
        ("threshold", ctypes.c_float), ("settle_n", ctypes.c_uint32), ("quiet_n", ctypes.c_uint32),
        ("max_n", ctypes.c_uint32), ("pre_n", ctypes.c_uint32), ("seq", ctypes.c_uint32), ("phase", ctypes.c_uint8),
        ("have", ctypes.c_uint8), ("cur", ctypes.c_uint8), ("still", ctypes.c_uint32), ("run", ctypes.c_uint32),
        ("base", _F3), ("pre_base", _F3 * 2), ("acc", _Accum * 2), ("obs", _Obs * 6), ("turn", _Turn), ("result", _ScaleBias), ("status", ctypes.c_int),
        ("iterations", ctypes.c_int),
    ]


class _SetCal(ctypes.Structure):
    """gyrocal_set_calibration_t (its gyrocal_affine_t flattened: the same layout)."""

    _fields_ = [("seq", ctypes.c_uint32), ("flags", ctypes.c_uint8), ("rate_unit", ctypes.c_uint8),
                ("matrix", _F3 * 3), ("offset", _F3)]


class _Rx(ctypes.Structure):
    _fields_ = [("buf", ctypes.c_uint8 * 70), ("len", ctypes.c_uint8)]


_P = ctypes.POINTER
_U8P = _P(ctypes.c_uint8)
_SIGNATURES = {
    "gyrocal_crc16": (ctypes.c_uint16, [_U8P, ctypes.c_size_t, ctypes.c_uint16]),
    "gyrocal_frame_hello": (ctypes.c_size_t, [_U8P, _P(_Hello)]),
    "gyrocal_frame_sample": (ctypes.c_size_t, [_U8P, ctypes.c_uint32, ctypes.c_uint32, _P(ctypes.c_int16),
                                               ctypes.c_int16]),
    "gyrocal_frame_imu": (ctypes.c_size_t, [_U8P, ctypes.c_uint32, ctypes.c_uint32, _P(ctypes.c_int16),
                                            _P(ctypes.c_int16), ctypes.c_int16]),
    "gyrocal_frame_end": (ctypes.c_size_t, [_U8P, ctypes.c_uint32]),
    "gyrocal_frame_calibrated": (ctypes.c_size_t, [_U8P, ctypes.c_uint32, ctypes.c_uint32, _P(ctypes.c_float)]),
    "gyrocal_frame_turn": (ctypes.c_size_t, [_U8P, _P(_Turn)]),
    "gyrocal_frame_result": (ctypes.c_size_t, [_U8P, ctypes.c_int, ctypes.c_uint8, ctypes.c_uint8, ctypes.c_uint8,
                                               _P(_ScaleBias), ctypes.c_uint32]),
    "gyrocal_frame_text": (ctypes.c_size_t, [_U8P, ctypes.c_char_p]),
    "gyrocal_frame_set_calibration": (ctypes.c_size_t, [_U8P, _P(_SetCal)]),
    "gyrocal_frame_calibration_stored": (ctypes.c_size_t, [_U8P, ctypes.c_uint8, _P(_SetCal)]),
    "gyrocal_parse_set_calibration": (ctypes.c_int, [_U8P, ctypes.c_size_t, _P(_SetCal)]),
    "gyrocal_frame_rx_byte": (ctypes.c_uint, [_P(_Rx), ctypes.c_uint8]),
    "gyrocal_session_init": (ctypes.c_int, [_P(_Session), ctypes.c_float, ctypes.c_float, ctypes.c_float]),
    "gyrocal_session_add": (ctypes.c_uint, [_P(_Session), _P(ctypes.c_int16)]),
    "gyrocal_scale_bias_to_affine": (ctypes.c_int, [_P(_ScaleBias), ctypes.c_void_p]),
    "gyrocal_correct": (ctypes.c_int, [ctypes.c_void_p, _P(ctypes.c_float), _P(ctypes.c_float)]),
}


class CDevice:
    """The frame encoders and the session of the C library (built with the host compiler)."""

    def __init__(self, lib: CLibrary | None = None):
        self.lib = lib or load_library()
        self.dll = self.lib.dll
        for name, (restype, argtypes) in _SIGNATURES.items():
            fn = getattr(self.dll, name)
            fn.restype, fn.argtypes = restype, argtypes
        self._buf = _BUF()

    def _out(self, n: int) -> bytes:
        return bytes(self._buf[:n])

    def crc16(self, data: bytes) -> int:
        arr = (ctypes.c_uint8 * max(len(data), 1)).from_buffer_copy(data or b"\0")
        return self.dll.gyrocal_crc16(arr, len(data), 0xFFFF)

    def hello(self, sample_rate: float, sensitivity: float, *, has_temp: bool, firmware: str,
              library: int = C_LIBRARY_VERSION, rate_unit: int = 1, accel_sensitivity: int = 0) -> bytes:
        flags = int(has_temp) | (2 if accel_sensitivity else 0)  # GYROCAL_HELLO_HAS_TEMP, _HAS_ACCEL
        h = _Hello(sample_rate, sensitivity, rate_unit, flags, library, firmware.encode()[:16], accel_sensitivity)
        return self._out(self.dll.gyrocal_frame_hello(self._buf, ctypes.byref(h)))

    def sample(self, seq: int, t_us: int, raw, temp_centi: int) -> bytes:
        r = (ctypes.c_int16 * 3)(*(int(v) for v in raw))
        return self._out(self.dll.gyrocal_frame_sample(self._buf, seq & 0xFFFFFFFF, t_us & 0xFFFFFFFF, r, temp_centi))

    def imu(self, seq: int, t_us: int, raw, accel, temp_centi: int) -> bytes:
        r, a = ((ctypes.c_int16 * 3)(*(int(v) for v in x)) for x in (raw, accel))
        return self._out(self.dll.gyrocal_frame_imu(self._buf, seq & 0xFFFFFFFF, t_us & 0xFFFFFFFF, r, a, temp_centi))

    def end(self, n_samples: int) -> bytes:
        return self._out(self.dll.gyrocal_frame_end(self._buf, n_samples & 0xFFFFFFFF))

    def calibrated(self, seq: int, t_us: int, w) -> bytes:
        return self._out(self.dll.gyrocal_frame_calibrated(self._buf, seq, t_us & 0xFFFFFFFF, _F3(*w)))

    def turn(self, start, stop, rate, angle, mean, slot, status) -> bytes:
        t = _Turn(start, stop, rate, angle, _F3(*mean), slot, status)
        return self._out(self.dll.gyrocal_frame_turn(self._buf, ctypes.byref(t)))

    def result(self, status: int, method: int, iterations: int, n_turns: int, k, b, seq: int) -> bytes:
        sb = _ScaleBias(_F3(*k), _F3(*b))
        return self._out(self.dll.gyrocal_frame_result(self._buf, status, method, iterations, n_turns,
                                                       ctypes.byref(sb), seq))

    def text(self, text: str) -> bytes:
        return self._out(self.dll.gyrocal_frame_text(self._buf, text.encode()))

    def set_calibration(self, seq: int, flags: int, rate_unit: int, matrix, offset, status: int | None = None) -> bytes:
        """A set-calibration frame (`status` None), or with a status the calibration-stored frame echoing it."""
        c = _SetCal(seq & 0xFFFFFFFF, flags, rate_unit, (_F3 * 3)(*(_F3(*row) for row in np.reshape(matrix, (3, 3)))),
                    _F3(*offset))
        if status is None:
            return self._out(self.dll.gyrocal_frame_set_calibration(self._buf, ctypes.byref(c)))
        return self._out(self.dll.gyrocal_frame_calibration_stored(self._buf, status, ctypes.byref(c)))

    def _events(self, s: _Session, events: int) -> bytes:
        out = b""
        if events & 1:
            out += self._out(self.dll.gyrocal_frame_turn(self._buf, ctypes.byref(s.turn)))
            out += self.text(TURN_LABELS[s.turn.slot] + _REASONS[s.turn.status if s.turn.status < 5 else 1])
        if events & 2:
            ok = s.status == 0
            out += self._out(self.dll.gyrocal_frame_result(self._buf, s.status, 0, s.iterations, 6,
                                                           ctypes.byref(s.result) if ok else None, s.seq - 1))
        return out

    def firmware_stream(self, raw, t_us, temp=None, *, sample_rate: float, sensitivity: float,
                        firmware: str = "gyrocal-example", send_calibrated: bool = True, accel=None,
                        accel_sensitivity: int = 0) -> bytes:
        """Every byte the example firmware sends for this session (see the module notes); with `accel`
        [counts] and its `accel_sensitivity` [counts per g], 6-axis frames instead of sample frames."""
        raw = np.asarray(raw, dtype=np.int16)
        acc = None if accel is None else np.asarray(accel, dtype=np.int16)
        temp_c = None if temp is None else np.round(np.asarray(temp, dtype=float) * 100).astype(np.int16)
        parts = [self.hello(sample_rate, sensitivity, has_temp=temp is not None, firmware=firmware,
                            accel_sensitivity=accel_sensitivity if acc is not None else 0)]
        s = _Session()
        self.dll.gyrocal_session_init(ctypes.byref(s), sample_rate, sensitivity, 360.0)
        cal = (ctypes.c_float * 12)()
        calibrated = False
        r = (ctypes.c_int16 * 3)()
        x, w = _F3(), _F3()
        for i in range(len(raw)):
            r[0], r[1], r[2] = (int(v) for v in raw[i])
            t = int(t_us[i])
            tc = -32768 if temp_c is None else int(temp_c[i])
            parts.append(self.sample(i, t, r, tc) if acc is None else self.imu(i, t, r, acc[i], tc))
            events = self.dll.gyrocal_session_add(ctypes.byref(s), r)
            if events:
                parts.append(self._events(s, events))
                if events & 2 and s.status == 0:
                    self.dll.gyrocal_scale_bias_to_affine(ctypes.byref(s.result), cal)
                    calibrated = True
            if send_calibrated and calibrated:
                x[0], x[1], x[2] = r[0], r[1], r[2]
                self.dll.gyrocal_correct(cal, x, w)
                parts.append(self.calibrated(i, t, w))
        parts.append(self.end(len(raw)))
        return b"".join(parts)


class CStorage:
    """A device's answer to the host's set-calibration frames, in the C library, as the example firmware gives it:
    bytes received one at a time (``gyrocal_frame_rx_byte``), the request parsed, its frame written to a RAM
    "flash" page, the page read back and parsed again, and what it holds echoed in a calibration-stored frame.

    Call it with the bytes the host sent; it returns the bytes to send back. ``page`` is the flash page,
    ``applied`` the correction in use (a ``gyrocal_affine_t`` as 12 floats) once a request asked for it.
    """

    SET, APPLY = 0x09, 1  # GYROCAL_FRAME_SET_CALIBRATION, GYROCAL_SETCAL_APPLY

    def __init__(self, device: CDevice | None = None):
        self.dev = device or CDevice()
        self._rx = _Rx()
        self.page = b""
        self.applied: tuple[float, ...] | None = None

    def __call__(self, data: bytes) -> bytes:
        out = b""
        for byte in data:
            if self.dev.dll.gyrocal_frame_rx_byte(ctypes.byref(self._rx), byte) == self.SET:
                out += self._store(bytes(self._rx.buf[4:4 + self._rx.buf[3]]))
        return out

    def _parse(self, payload: bytes) -> _SetCal | None:
        got = _SetCal()
        buf = (ctypes.c_uint8 * len(payload)).from_buffer_copy(payload)
        return got if self.dev.dll.gyrocal_parse_set_calibration(buf, len(payload), ctypes.byref(got)) == 0 else None

    def _store(self, payload: bytes) -> bytes:
        dll, buf = self.dev.dll, self.dev._buf
        req = self._parse(payload)
        if req is None:
            return self.dev._out(dll.gyrocal_frame_calibration_stored(buf, 1, None))  # GYROCAL_STORED_INVALID
        self.page = self.dev._out(dll.gyrocal_frame_set_calibration(buf, ctypes.byref(req)))
        rx = _Rx()  # the read-back goes through the receiver too: the page's CRC checks it
        back = None
        for byte in self.page:
            if dll.gyrocal_frame_rx_byte(ctypes.byref(rx), byte) == self.SET:
                back = self._parse(bytes(rx.buf[4:4 + rx.buf[3]]))
        if back is None:
            return self.dev._out(dll.gyrocal_frame_calibration_stored(buf, 2, None))  # GYROCAL_STORED_FAILED
        if back.flags & self.APPLY:
            self.applied = (*(v for row in back.matrix for v in row), *back.offset)
        return self.dev._out(dll.gyrocal_frame_calibration_stored(buf, 0, ctypes.byref(back)))


def firmware_stream(raw, t_us, temp=None, *, sample_rate: float, sensitivity: float, **kwargs) -> bytes:
    """:meth:`CDevice.firmware_stream` with the library built in the default cache."""
    return CDevice().firmware_stream(raw, t_us, temp, sample_rate=sample_rate, sensitivity=sensitivity, **kwargs)
