"""gyrocal frames: the binary wire format between a device and ``gyrocal capture``.

A frame is ``A5 5A | type | length L | payload (L bytes) | CRC-16``. The CRC is
CRC-16/CCITT-FALSE (polynomial 0x1021, initial value 0xFFFF, no reflection, no final XOR;
check value 0x29B1 for ``b"123456789"``) over type, length and payload, sent low byte
first; every field is little-endian. ``docs/capture.md`` has the byte tables, and the C
encoder ``gyrocal/c/gyrocal_frame.c`` writes the same bytes (checked in the tests).

:class:`FrameDecoder` takes bytes in any chunks, finds frames, checks their CRC and
resynchronises after corrupt or dropped bytes, counting what it threw away and the
samples missing from the sequence numbers.
"""

from __future__ import annotations

import binascii
import struct
from dataclasses import dataclass, field

import numpy as np

from .write_frames import CalibrationStored, SetCalibration  # the write-back's two frames

__all__ = [
    "MAX_PAYLOAD",
    "OVERHEAD",
    "SYNC",
    "TURN_LABELS",
    "Calibrated",
    "CalibrationStored",
    "DecoderStats",
    "End",
    "Frame",
    "FrameDecoder",
    "Hello",
    "ImuSample",
    "Result",
    "Sample",
    "SetCalibration",
    "Text",
    "Turn",
    "crc16",
    "encode_samples",
]

SYNC = b"\xa5\x5a"
OVERHEAD = 6  # sync (2), type, length, CRC (2)
MAX_PAYLOAD = 64
PROTOCOL = 1
TEMP_NONE = -32768  # temperature field of a device without a thermometer
#: Slots of the six turns (the servo method's order): slot i is TURN_LABELS[i].
TURN_LABELS = ("+x", "-x", "+y", "-y", "+z", "-z")
_UNITS = ("rad/s", "deg/s")
_METHODS = ("first-moment", "algorithm1")
_TURN_REASONS = {1: "wrong angle", 2: "off axis", 3: "too long", 4: "bad window"}
#: gyrocal_status_t (gyrocal_cal.h) by code.
STATUS_NAMES = {0: "GYROCAL_OK", 1: "GYROCAL_E_INPUT", 2: "GYROCAL_E_SINGULAR", 3: "GYROCAL_E_NONPHYSICAL",
                4: "GYROCAL_E_NOCONV", 5: "GYROCAL_E_RANGE"}


def crc16(data: bytes, crc: int = 0xFFFF) -> int:
    """CRC-16/CCITT-FALSE of `data` (``binascii.crc_hqx`` is this CRC from a given start)."""
    return binascii.crc_hqx(data, crc)


def _frame(kind: int, payload: bytes) -> bytes:
    head = bytes((kind, len(payload)))
    return SYNC + head + payload + struct.pack("<H", crc16(head + payload))


@dataclass(frozen=True)
class Hello:
    """What the device is: sample rate [Hz], sensitivity [counts per `rate_unit`], firmware, and the
    accelerometer's sensitivity [counts per g] when it sends 6-axis samples (None without)."""

    TYPE = 0x01
    FORMAT = struct.Struct("<BBBBffHH16s")
    sample_rate: float
    sensitivity: float
    rate_unit: str = "deg/s"
    has_temp: bool = False
    library: int = 2  # GYROCAL_CAL_VERSION
    firmware: str = ""
    protocol: int = PROTOCOL
    accel_sensitivity: int | None = None

    def payload(self) -> bytes:
        flags = int(self.has_temp) | (2 if self.accel_sensitivity else 0)
        return self.FORMAT.pack(self.protocol, flags, _UNITS.index(self.rate_unit), 0, self.sample_rate,
                                self.sensitivity, self.library, self.accel_sensitivity or 0,
                                self.firmware.encode()[:16])

    @classmethod
    def parse(cls, p: bytes) -> Hello:
        proto, flags, unit, _, fs, sens, lib, accel, fw = cls.FORMAT.unpack(p)
        return cls(fs, sens, _UNITS[unit] if unit < len(_UNITS) else f"unit {unit}", bool(flags & 1), lib,
                   fw.split(b"\0")[0].decode("utf-8", "replace"), proto, accel if flags & 2 and accel else None)


@dataclass(frozen=True)
class Sample:
    """One raw sample: ``seq`` (device sample counter), ``t_us`` (device time [us], unwrapped by
    the decoder), ``raw`` [counts], ``temp`` [degC] or None."""

    TYPE = 0x02
    FORMAT = struct.Struct("<IIhhhh")
    seq: int
    t_us: int
    raw: tuple[int, int, int]
    temp: float | None = None

    def payload(self) -> bytes:
        temp = TEMP_NONE if self.temp is None else round(self.temp * 100)
        return self.FORMAT.pack(self.seq & 0xFFFFFFFF, self.t_us & 0xFFFFFFFF, *self.raw, temp)

    @classmethod
    def parse(cls, p: bytes) -> Sample:
        seq, t_us, gx, gy, gz, temp = cls.FORMAT.unpack(p)
        return cls(seq, t_us, (gx, gy, gz), None if temp == TEMP_NONE else temp / 100.0)


@dataclass(frozen=True)
class ImuSample:
    """One raw 6-axis sample: as :class:`Sample`, with the accelerometer ``accel`` [counts]."""

    TYPE = 0x07
    FORMAT = struct.Struct("<IIhhhhhhh")
    seq: int
    t_us: int
    raw: tuple[int, int, int]
    accel: tuple[int, int, int]
    temp: float | None = None

    def payload(self) -> bytes:
        temp = TEMP_NONE if self.temp is None else round(self.temp * 100)
        return self.FORMAT.pack(self.seq & 0xFFFFFFFF, self.t_us & 0xFFFFFFFF, *self.raw, *self.accel, temp)

    @classmethod
    def parse(cls, p: bytes) -> ImuSample:
        seq, t_us, gx, gy, gz, ax, ay, az, temp = cls.FORMAT.unpack(p)
        return cls(seq, t_us, (gx, gy, gz), (ax, ay, az), None if temp == TEMP_NONE else temp / 100.0)


@dataclass(frozen=True)
class Calibrated:
    """One corrected sample: ``w`` [the hello's rate unit], float32 on the device."""

    TYPE = 0x03
    FORMAT = struct.Struct("<IIfff")
    seq: int
    t_us: int
    w: tuple[float, float, float]

    def payload(self) -> bytes:
        return self.FORMAT.pack(self.seq & 0xFFFFFFFF, self.t_us & 0xFFFFFFFF, *self.w)

    @classmethod
    def parse(cls, p: bytes) -> Calibrated:
        seq, t_us, *w = cls.FORMAT.unpack(p)
        return cls(seq, t_us, tuple(w))


@dataclass(frozen=True)
class Turn:
    """A turn the device saw: samples ``start:stop`` (sequence numbers), reference ``rate``
    [rate unit], integrated ``angle`` [deg], window ``mean`` [counts], its slot and status."""

    TYPE = 0x04
    FORMAT = struct.Struct("<IIfffffBBH")
    start: int
    stop: int
    rate: float
    angle: float
    mean: tuple[float, float, float]
    slot: int
    status: int = 0

    @property
    def label(self) -> str:
        return TURN_LABELS[self.slot] if self.slot < len(TURN_LABELS) else f"slot {self.slot}"

    @property
    def reason(self) -> str | None:
        """None when the device accepted the turn, else why not."""
        return None if self.status == 0 else _TURN_REASONS.get(self.status, f"reason {self.status}")

    def payload(self) -> bytes:
        return self.FORMAT.pack(self.start, self.stop, self.rate, self.angle, *self.mean, self.slot, self.status, 0)

    @classmethod
    def parse(cls, p: bytes) -> Turn:
        start, stop, rate, angle, m0, m1, m2, slot, status, _ = cls.FORMAT.unpack(p)
        return cls(start, stop, rate, angle, (m0, m1, m2), slot, status)


@dataclass(frozen=True)
class Result:
    """The device's calibration (servo method of Wang et al., eq. 1, ``g = diag(k) (m + b)``):
    ``k`` [rate unit per count], ``b`` [counts], the C status, method and iterations."""

    TYPE = 0x05
    FORMAT = struct.Struct("<BBBBffffffI")
    status: int
    method: str
    iterations: int
    n_turns: int
    k: tuple[float, float, float]
    b: tuple[float, float, float]
    seq: int = 0

    @property
    def status_name(self) -> str:
        return STATUS_NAMES.get(self.status, f"status {self.status}")

    def payload(self) -> bytes:
        return self.FORMAT.pack(self.status, _METHODS.index(self.method), self.iterations, self.n_turns, *self.k,
                                *self.b, self.seq)

    @classmethod
    def parse(cls, p: bytes) -> Result:
        status, method, it, n, *rest = cls.FORMAT.unpack(p)
        name = _METHODS[method] if method < len(_METHODS) else f"method {method}"
        return cls(status, name, it, n, tuple(rest[:3]), tuple(rest[3:6]), rest[6])


@dataclass(frozen=True)
class Text:
    """A message from the device for the person at the host."""

    TYPE = 0x06
    text: str

    def payload(self) -> bytes:
        return self.text.encode()[:MAX_PAYLOAD]

    @classmethod
    def parse(cls, p: bytes) -> Text:
        return cls(p.decode("utf-8", "replace"))


@dataclass(frozen=True)
class End:
    """The session is over (a recorded or simulated device; a live board never ends): ``samples``
    sample frames were sent in all. Whoever reads it has everything the device sent."""

    TYPE = 0x08
    FORMAT = struct.Struct("<I")
    samples: int | None  # None: the text line's end, which carries no count

    def payload(self) -> bytes:
        return self.FORMAT.pack((self.samples or 0) & 0xFFFFFFFF)

    @classmethod
    def parse(cls, p: bytes) -> End:
        return cls(cls.FORMAT.unpack(p)[0])


Frame = Hello | Sample | ImuSample | Calibrated | Turn | Result | Text | End | SetCalibration | CalibrationStored
_FIXED = (Hello, Sample, ImuSample, Calibrated, Turn, Result, End, SetCalibration, CalibrationStored)
_KINDS = {cls.TYPE: cls for cls in (*_FIXED, Text)}
#: Fixed payload length per type (TEXT: any length up to MAX_PAYLOAD).
_LENGTHS = {cls.TYPE: cls.FORMAT.size for cls in _FIXED}


def encode(frame: Frame) -> bytes:
    """The bytes of one frame."""
    return _frame(frame.TYPE, frame.payload())


def encode_samples(seq, t_us, raw, temp=None, accel=None) -> bytes:
    """Sample frames for many samples at once: seq (N,), t_us (N,) [us], raw (N, 3) [counts],
    temp (N,) [degC] or None; with accel (N, 3) [counts], 6-axis (IMU) frames."""
    n = len(seq)
    kind = Sample if accel is None else ImuSample
    fields = [("sync", "u1", 2), ("type", "u1"), ("len", "u1"), ("seq", "<u4"), ("t", "<u4"), ("g", "<i2", 3)]
    fields += [] if accel is None else [("a", "<i2", 3)]
    rec = np.zeros(n, dtype=[*fields, ("temp", "<i2"), ("crc", "<u2")])
    rec["sync"] = tuple(SYNC)
    rec["type"], rec["len"] = kind.TYPE, kind.FORMAT.size
    rec["seq"] = np.asarray(seq, dtype=np.int64) & 0xFFFFFFFF
    rec["t"] = np.asarray(t_us, dtype=np.int64) & 0xFFFFFFFF
    rec["g"] = raw
    if accel is not None:
        rec["a"] = accel
    rec["temp"] = TEMP_NONE if temp is None else np.round(np.asarray(temp, dtype=float) * 100)
    view = rec.view(np.uint8).reshape(n, -1)
    rec["crc"] = [crc16(row[2:-2].tobytes()) for row in view]
    return rec.tobytes()


@dataclass
class DecoderStats:
    """What a decoder saw: frames by type, bytes thrown away, CRC failures, missing samples."""

    bytes: int = 0
    frames: int = 0
    skipped: int = 0        # bytes discarded while looking for a frame
    crc_errors: int = 0     # frames whose CRC did not match
    unknown: int = 0        # well-formed frames of a type this version does not know
    lost_samples: int = 0   # samples missing from the sequence numbers
    gaps: int = 0           # places where samples were missing
    restarts: int = 0       # the sequence went backwards (the device restarted)
    by_type: dict[str, int] = field(default_factory=dict)


class FrameDecoder:
    """Streaming decoder: ``feed(bytes) -> list of frames``; ``stats`` counts the losses."""

    def __init__(self):
        self._buf = bytearray()
        self._next_seq: int | None = None
        self._t_last: int | None = None
        self._t_wraps = 0
        self.stats = DecoderStats()

    def feed(self, data: bytes) -> list[Frame]:
        buf, st = self._buf, self.stats
        buf += data
        st.bytes += len(data)
        out: list[Frame] = []
        pos, end = 0, len(buf)
        while True:
            i = buf.find(SYNC, pos)
            if i < 0:
                keep = 1 if end > pos and buf[-1] == SYNC[0] else 0  # a sync may straddle two chunks
                st.skipped += end - pos - keep
                pos = end - keep
                break
            st.skipped += i - pos
            pos = i
            if end - pos < 4:
                break
            kind, n = buf[pos + 2], buf[pos + 3]
            if n > MAX_PAYLOAD or _LENGTHS.get(kind, n) != n:
                st.skipped += 1  # not a frame start: a sync pattern inside other bytes
                pos += 1
                continue
            if end - pos < n + OVERHEAD:
                break
            body = bytes(buf[pos + 2: pos + 4 + n])
            if crc16(body) != buf[pos + 4 + n] | (buf[pos + 5 + n] << 8):
                st.crc_errors += 1
                st.skipped += 1
                pos += 1
                continue
            pos += n + OVERHEAD
            frame = self._parse(kind, body[2:])
            if frame is not None:
                out.append(frame)
        del buf[:pos]
        return out

    def _parse(self, kind: int, payload: bytes) -> Frame | None:
        st = self.stats
        cls = _KINDS.get(kind)
        if cls is None:
            st.unknown += 1
            return None
        frame = cls.parse(payload)
        st.frames += 1
        st.by_type[cls.__name__] = st.by_type.get(cls.__name__, 0) + 1
        if cls is Sample:
            frame = Sample(frame.seq, self._unwrap(frame.t_us), frame.raw, frame.temp)
            self._track(frame.seq)
        elif cls is ImuSample:
            frame = ImuSample(frame.seq, self._unwrap(frame.t_us), frame.raw, frame.accel, frame.temp)
            self._track(frame.seq)
        return frame

    def _unwrap(self, t_us: int) -> int:
        # the device's 32-bit microsecond clock wraps every 71.6 min
        if self._t_last is not None and t_us < self._t_last and self._t_last - t_us > 1 << 31:
            self._t_wraps += 1
        self._t_last = t_us
        return t_us + (self._t_wraps << 32)

    def _track(self, seq: int) -> None:
        st = self.stats
        if self._next_seq is not None and seq != self._next_seq:
            ahead = (seq - self._next_seq) & 0xFFFFFFFF
            if ahead < 1 << 31:
                st.lost_samples += ahead
                st.gaps += 1
            else:
                st.restarts += 1
        self._next_seq = (seq + 1) & 0xFFFFFFFF
