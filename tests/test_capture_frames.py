"""gyrocal frames (gyro-only and 6-axis samples, device messages, the end of a session, the write-back's request and
answer): the C encoder against the Python encoder and decoder byte for byte, the CRC, and resynchronisation.

Independent references: the CRC-16/CCITT-FALSE check value 0x29B1 of b"123456789" (the
published parameter catalogue of CRC-16 variants); the values fed to the encoders (what
was sent is what must come back); and, for faults, the exact bytes that were removed or
changed, so the expected losses are counted from the damage itself, not from the decoder.
"""

from __future__ import annotations

import numpy as np
import pytest

from gyrocal import firmware
from gyrocal.capture import frames as fr
from gyrocal.capture.c_device import CDevice


@pytest.fixture(scope="module")
def cdev(tmp_path_factory):
    return CDevice(firmware.load_library(tmp_path_factory.mktemp("c-build")))


def test_crc_check_value_in_python_and_c(cdev):
    assert fr.crc16(b"123456789") == 0x29B1
    assert cdev.crc16(b"123456789") == 0x29B1


def random_frames(rng, n=200):
    """Frames of every type with random field values, as Python objects."""
    out = []
    for i in range(n):
        raw = tuple(int(v) for v in rng.integers(-32768, 32768, 3))
        temp = None if i % 3 == 0 else float(rng.integers(-4000, 8500)) / 100
        out.append(fr.Sample(int(rng.integers(0, 2**32)), int(rng.integers(0, 2**31)), raw, temp))
        w = tuple(float(np.float32(v)) for v in rng.normal(0, 100, 3))
        out.append(fr.Calibrated(i, int(rng.integers(0, 2**31)), w))
        accel = tuple(int(v) for v in rng.integers(-32768, 32768, 3))
        out.append(fr.ImuSample(int(rng.integers(0, 2**32)), int(rng.integers(0, 2**31)), raw, accel, temp))
    mean = tuple(float(np.float32(v)) for v in rng.normal(0, 5000, 3))
    out.append(fr.Turn(10, 1300, float(np.float32(52.6)), float(np.float32(358.2)), mean, 3, 0))
    out.append(fr.Result(0, "first-moment", 2, 6, (float(np.float32(0.0076)),) * 3, (float(np.float32(-12.5)),) * 3,
                         999))
    out.append(fr.Hello(200.0, 131.0, "deg/s", True, 0x0100, "gyrocal-example"))
    out.append(fr.Hello(100.0, 131.0, "deg/s", False, 2, "imu", accel_sensitivity=16384))
    out.append(fr.Text("+x accepted"))
    out.append(fr.End(int(rng.integers(0, 2**32))))
    matrix, offset = rng.normal(0, 0.01, (3, 3)), rng.normal(0, 300, 3)
    out.append(fr.SetCalibration.of(int(rng.integers(0, 2**32)), matrix, offset, "deg/s"))
    sent = fr.SetCalibration.of(7, matrix, offset, "rad/s", flags=0)
    out.append(fr.CalibrationStored(7, sent.matrix, sent.offset, "rad/s", 0, status=2))
    return out


def c_bytes(cdev: CDevice, f) -> bytes:
    temp = -32768 if getattr(f, "temp", None) is None else round(f.temp * 100)
    if isinstance(f, fr.Sample):
        return cdev.sample(f.seq, f.t_us, f.raw, temp)
    if isinstance(f, fr.ImuSample):
        return cdev.imu(f.seq, f.t_us, f.raw, f.accel, temp)
    if isinstance(f, fr.End):
        return cdev.end(f.samples)
    if isinstance(f, fr.Calibrated):
        return cdev.calibrated(f.seq, f.t_us, f.w)
    if isinstance(f, fr.Turn):
        return cdev.turn(f.start, f.stop, f.rate, f.angle, f.mean, f.slot, f.status)
    if isinstance(f, fr.Result):
        return cdev.result(f.status, 0, f.iterations, f.n_turns, f.k, f.b, f.seq)
    if isinstance(f, fr.Hello):
        return cdev.hello(f.sample_rate, f.sensitivity, has_temp=f.has_temp, firmware=f.firmware, library=f.library,
                          accel_sensitivity=f.accel_sensitivity or 0)
    if isinstance(f, fr.SetCalibration | fr.CalibrationStored):
        return cdev.set_calibration(f.seq, f.flags, ("rad/s", "deg/s").index(f.rate_unit), f.matrix, f.offset,
                                    getattr(f, "status", None))
    return cdev.text(f.text)


def test_c_encoder_writes_the_python_bytes_and_decodes_back(cdev, rng):
    sent = random_frames(rng)
    stream = b""
    for f in sent:
        c = c_bytes(cdev, f)
        assert c == fr.encode(f), type(f).__name__
        stream += c
    dec = fr.FrameDecoder()
    got = dec.feed(stream)
    assert got == sent
    assert dec.stats.skipped == dec.stats.crc_errors == 0


def test_vectorised_sample_encoder_matches_one_by_one(rng):
    n = 50
    seq, t = np.arange(n) + 7, 5000 * np.arange(n)
    raw = rng.integers(-32768, 32768, (n, 3))
    temp = np.round(rng.uniform(-40, 85, n), 2)
    one = b"".join(fr.encode(fr.Sample(int(seq[i]), int(t[i]), tuple(map(int, raw[i])), float(temp[i])))
                   for i in range(n))
    assert fr.encode_samples(seq, t, raw, temp) == one
    accel = rng.integers(-32768, 32768, (n, 3))
    six = b"".join(fr.encode(fr.ImuSample(int(seq[i]), int(t[i]), tuple(map(int, raw[i])), tuple(map(int, accel[i])),
                                          float(temp[i]))) for i in range(n))
    assert fr.encode_samples(seq, t, raw, temp, accel) == six


def test_text_frame_is_cut_at_the_payload_limit(cdev):
    long = "a" * 100
    assert cdev.text(long) == fr.encode(fr.Text("a" * fr.MAX_PAYLOAD))


def samples_stream(n=400):
    raw = np.stack([np.arange(n), -np.arange(n), np.full(n, 7)], axis=1)
    return fr.encode_samples(np.arange(n), 5000 * np.arange(n), raw), raw


@pytest.mark.parametrize("chunk", [1, 7, 64, 100_000])
def test_decoder_takes_any_chunking(chunk):
    data, raw = samples_stream()
    dec = fr.FrameDecoder()
    got = [f for i in range(0, len(data), chunk) for f in dec.feed(data[i: i + chunk])]
    assert [f.raw for f in got] == [tuple(r) for r in raw.tolist()]


def test_dropped_bytes_lose_only_the_frames_they_hit(rng):
    """Each deleted byte destroys the frame it sat in; the decoder resynchronises at the next one."""
    data, raw = samples_stream()
    size = len(data) // len(raw)
    hit = np.sort(rng.choice(len(data), 25, replace=False))
    keep = np.ones(len(data), bool)
    keep[hit] = False
    damaged = bytes(np.frombuffer(data, np.uint8)[keep])
    dec = fr.FrameDecoder()
    got = dec.feed(damaged)
    lost_frames = set((hit // size).tolist())
    assert sorted(f.seq for f in got) == sorted(set(range(len(raw))) - lost_frames)
    assert dec.stats.lost_samples == len(lost_frames)


def test_corrupt_bytes_are_caught_by_the_crc(rng):
    data, raw = samples_stream()
    size = len(data) // len(raw)
    buf = bytearray(data)
    hit = rng.choice(len(raw), 30, replace=False) * size + 4 + rng.integers(0, 16, 30)  # inside payloads
    for i in hit:
        buf[i] ^= 1 << int(rng.integers(0, 8))
    dec = fr.FrameDecoder()
    got = dec.feed(bytes(buf))
    assert sorted(f.seq for f in got) == sorted(set(range(len(raw))) - set((hit // size).tolist()))
    assert dec.stats.crc_errors == len(set((hit // size).tolist()))


def test_garbage_between_frames_is_skipped_and_counted(rng):
    data, _raw = samples_stream(10)
    size = len(data) // 10
    noise = bytes(rng.integers(0, 256, 37, dtype=np.uint8).tolist()).replace(fr.SYNC, b"")
    stream = data[: 5 * size] + noise + data[5 * size:]
    dec = fr.FrameDecoder()
    assert [f.seq for f in dec.feed(stream)] == list(range(10))
    assert dec.stats.skipped == len(noise)


def test_device_clock_wrap_is_unwrapped():
    t = np.array([2**32 - 10_000, 2**32 - 5_000, 0, 5_000]) % 2**32
    data = fr.encode_samples(np.arange(4), t, np.zeros((4, 3), int))
    got = fr.FrameDecoder().feed(data)
    assert np.all(np.diff([f.t_us for f in got]) == 5_000)


@pytest.mark.parametrize("kind", ["drop", "corrupt"])
def test_six_axis_frames_with_faults_lose_only_the_frames_hit(rng, kind):
    """Damage in a stream of 6-axis frames: the frames that held a damaged byte are lost (a corrupted sync,
    type or length byte hides its frame, any other fails the CRC); every other one decodes to what was sent."""
    n = 300
    raw, accel = rng.integers(-32768, 32768, (n, 3)), rng.integers(-32768, 32768, (n, 3))
    data = fr.encode_samples(np.arange(n), 10_000 * np.arange(n), raw, None, accel)
    size = len(data) // n
    hit = np.sort(rng.choice(len(data), 20, replace=False))
    buf = np.frombuffer(data, np.uint8).copy()
    if kind == "drop":
        damaged = np.delete(buf, hit).tobytes()
    else:
        buf[hit] ^= 0x10
        damaged = buf.tobytes()
    dec = fr.FrameDecoder()
    got = dec.feed(damaged)
    lost = set((hit // size).tolist())
    assert [f.seq for f in got] == sorted(set(range(n)) - lost)
    np.testing.assert_array_equal([f.accel for f in got], accel[[f.seq for f in got]])
    np.testing.assert_array_equal([f.raw for f in got], raw[[f.seq for f in got]])
    assert dec.stats.lost_samples == len([s for s in lost if s < max(f.seq for f in got)])
    if kind == "corrupt":  # a flipped sync or length byte hides its frame; a flipped type (0x17, unknown) does not
        hidden = {int(i // size) for i in hit if i % size in (0, 1, 3)}
        assert dec.stats.crc_errors == len(lost - hidden)


def test_write_back_request_through_the_c_receiver_and_echo(cdev, rng):
    """A Python set-calibration request, fed in pieces with noise before it, is received, stored, read back and
    echoed by the C library (CStorage, the example firmware's calls); a NaN is refused. Reference: the request."""
    from gyrocal.capture.c_device import CStorage

    storage = CStorage(cdev)
    sent = fr.SetCalibration.of(0xDEADBEEF, np.eye(3) / 131.0 + rng.normal(0, 1e-4, (3, 3)), rng.normal(0, 50, 3))
    data = b"\x00\xa5\x5a\x07" + fr.encode(sent)  # a false start (a frame too long), then the request
    answer = b"".join(storage(data[i:i + 5]) for i in range(0, len(data), 5))
    (echo,) = fr.FrameDecoder().feed(answer)
    assert isinstance(echo, fr.CalibrationStored) and echo.echoes(sent) and echo.status_name == "stored"
    assert storage.page == fr.encode(sent) and storage.applied == (*sent.matrix, *sent.offset)
    bad = fr.SetCalibration(1, (float("nan"),) + sent.matrix[1:], sent.offset)
    (refused,) = fr.FrameDecoder().feed(storage(fr.encode(bad)))
    assert refused.status == 1 and not refused.echoes(bad) and storage.page == fr.encode(sent)
