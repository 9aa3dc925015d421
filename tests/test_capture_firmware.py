"""The example firmware (examples/firmware), compiled on the host with a fake board layer that plays a
simulated session, and the frames it sends.

Independent references: the simulated session itself (the samples, time stamps and temperatures
fed to the fake board; the true turns and the true gyro of the simulation), the host's float64
recomputation of the device's float32 arithmetic within the rounding bounds of
tests/test_firmware.py, and the first-moment covariance for the statistical check against the truth.
"""

from __future__ import annotations

import ctypes
import math
from pathlib import Path

import numpy as np
import pytest

from gyrocal import firmware
from gyrocal.capture import frames as fr
from gyrocal.capture.agreement import check_device, corrected_bound
from gyrocal.capture.c_device import CDevice
from gyrocal.capture.simulated import simulate_device_session
from gyrocal.estimators import FirstMoment
from gyrocal.models import ScaleBias
from gyrocal.observations import ObservationSet
from gyrocal.simulation import ServoProtocol

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "firmware"
NOISE = 0.01  # rad/s per sample
MODEL = ScaleBias(k=np.array([1.03, 0.97, 1.01]), b=np.radians([1.5, -2.0, 0.8]))


@pytest.fixture(scope="module")
def example(tmp_path_factory):
    """The example firmware with the fake board, as a shared library (host compiler, strict C99)."""
    path = firmware.build_library(tmp_path_factory.mktemp("example"), include_dirs=[EXAMPLE],
                                  extra_sources=[EXAMPLE / "gyrocal_example.c", EXAMPLE / "host_board.c"])
    dll = ctypes.CDLL(str(path))
    dll.example_run.restype = ctypes.c_size_t
    dll.example_run.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_uint32,
                                ctypes.c_float, ctypes.c_float, ctypes.c_uint16, ctypes.c_void_p, ctypes.c_size_t]
    return dll, CDevice(firmware.load_library(path.parent))


def run_example(dll, s) -> bytes:
    raw = np.ascontiguousarray(s.raw, dtype=np.int16)
    acc = None if s.accel is None else np.ascontiguousarray(s.accel, dtype=np.int16)
    t = np.ascontiguousarray(s.t_us, dtype=np.uint32)
    temp = None if s.temp is None else np.ascontiguousarray(np.round(s.temp * 100), dtype=np.int16)
    out = np.zeros(64 * len(raw) + 1024, dtype=np.uint8)
    n = dll.example_run(raw.ctypes.data, None if acc is None else acc.ctypes.data, t.ctypes.data,
                        None if temp is None else temp.ctypes.data, len(raw), s.sample_rate, s.sensitivity,
                        s.accel_sensitivity or 0, out.ctypes.data, len(out))
    assert n > 0
    return out[:n].tobytes()


@pytest.fixture(scope="module")
def session():
    """A wrong turn (+x by 270 deg), then the paper's six turns at 60 deg/s with 3 deg of misalignment."""
    rng = np.random.default_rng(16)
    wrong = ServoProtocol(turns=("+x",), revolutions=0.75, lead_in=1.0, lead_out=1.0, misalignment_deg=3.0)
    return simulate_device_session([wrong, ServoProtocol(lead_in=1.0, misalignment_deg=3.0)], model=MODEL,
                                   noise_std=NOISE, rng=rng)


@pytest.fixture(scope="module")
def sent(example, session):
    dll, _ = example
    return run_example(dll, session)


def by_type(frames, cls):
    return [f for f in frames if isinstance(f, cls)]


def test_virtual_device_sends_the_firmware_bytes(example, session, sent):
    """The Python-driven C session (the virtual device) is the example firmware, byte for byte."""
    _, cdev = example
    assert cdev.firmware_stream(session.raw, session.t_us, session.temp, sample_rate=session.sample_rate,
                                sensitivity=session.sensitivity) == sent


def test_samples_arrive_as_sent(session, sent):
    dec = fr.FrameDecoder()
    frames = dec.feed(sent)
    samples = by_type(frames, fr.Sample)
    assert dec.stats.skipped == dec.stats.crc_errors == dec.stats.lost_samples == 0
    assert [f.seq for f in samples] == list(range(len(session)))
    np.testing.assert_array_equal([f.raw for f in samples], session.raw)
    np.testing.assert_array_equal([f.t_us for f in samples], session.t_us)
    np.testing.assert_allclose([f.temp for f in samples], session.temp, atol=1e-9)
    hello = frames[0]
    assert isinstance(hello, fr.Hello) and hello.sample_rate == 200 and hello.sensitivity == 131 and hello.has_temp


def test_turns_cover_the_true_turns_and_the_wrong_one_is_refused(session, sent):
    frames = fr.FrameDecoder().feed(sent)
    turns = by_type(frames, fr.Turn)
    truth = session.turns
    assert [t.label for t in turns] == [w.label for w in truth]
    for t, w in zip(turns, truth):
        assert t.start <= w.start and t.stop >= w.stop, (t, w)  # the whole turn is inside the window
        assert t.stop - w.stop <= 0.55 * session.sample_rate  # ... with at most the quiet time after it
        assert abs(t.angle - math.degrees(w.angle)) < 0.1 * math.degrees(w.angle)
    assert turns[0].reason == "wrong angle" and all(t.reason is None for t in turns[1:])
    texts = [f.text for f in by_type(frames, fr.Text)]
    assert texts[0] == "+x ignored: wrong angle" and texts[1] == "+x accepted"


def test_device_result_agrees_with_the_host_and_the_truth(session, sent):
    frames = fr.FrameDecoder().feed(sent)
    (result,) = by_type(frames, fr.Result)
    assert result.status == 0 and result.n_turns == 6
    latest = {t.slot: t for t in by_type(frames, fr.Turn) if t.status == 0}
    samples = {s: session.raw[t.start: t.stop].astype(float) for s, t in latest.items()}
    agreement = check_device(latest, result, samples)
    assert agreement.agrees, agreement.report()
    # Against the truth, within 4 sigma of the first-moment covariance at the simulated noise.
    mean = np.array([latest[s].mean for s in range(6)], float)
    count = np.array([latest[s].stop - latest[s].start for s in range(6)], float)
    rate = np.array([latest[s].rate for s in range(6)], float)
    noise_counts = math.degrees(NOISE) * session.sensitivity
    fit = FirstMoment(noise_std=noise_counts).fit(
        ObservationSet(mean, mean**2, np.zeros((6, 3)), rate, count, count / 200, np.zeros(6, bool)))
    sigma = np.sqrt(np.diag(fit.covariance))
    err = np.concatenate([result.k, result.b]) - np.concatenate([session.device_k, session.device_b])
    assert np.all(np.abs(err) <= 4 * sigma), err / sigma


def test_calibrated_samples_are_the_device_correction(session, sent):
    frames = fr.FrameDecoder().feed(sent)
    (result,) = by_type(frames, fr.Result)
    cal = by_type(frames, fr.Calibrated)
    assert [c.seq for c in cal] == list(range(result.seq, len(session)))
    k, b = np.array(result.k, float), np.array(result.b, float)
    m = session.raw[result.seq:].astype(float)
    w = np.array([c.w for c in cal])
    # gyrocal_correct: one subtraction and one product per axis, in float32
    assert np.all(np.abs(w - k * (m + b)) <= corrected_bound(k, b, m))
    # the check can fail: a correction off by a thousandth of a count on one axis
    assert not check_device({t.slot: t for t in by_type(frames, fr.Turn) if t.status == 0}, result, None,
                            (m, w + np.array([0.0, 0.0, k[2] * 1e-3]))).agrees


def test_a_device_that_computes_otherwise_is_caught(session, sent):
    """The check can fail: k off by 1e-5 relative, or one turn mean off by a tenth of a count, is far beyond
    float32 rounding (about 1e-7 relative), so the device no longer agrees with the host."""
    import dataclasses

    frames = fr.FrameDecoder().feed(sent)
    (result,) = by_type(frames, fr.Result)
    latest = {t.slot: t for t in by_type(frames, fr.Turn) if t.status == 0}
    samples = {s: session.raw[t.start: t.stop].astype(float) for s, t in latest.items()}
    k = (result.k[0] * (1 + 1e-5), *result.k[1:])
    assert not check_device(latest, dataclasses.replace(result, k=k), samples).agrees
    moved = dict(latest)
    moved[2] = dataclasses.replace(latest[2], mean=(latest[2].mean[0] + 0.1, *latest[2].mean[1:]))
    agreement = check_device(moved, result, samples)
    assert agreement.means_ratio > 1 and not agreement.agrees


def test_six_axis_firmware_sends_the_accelerometer(example):
    """With an accelerometer sensitivity the example firmware sends 6-axis frames: every sample decodes to what
    the fake board read (gyro, accelerometer, stamp), the hello carries the sensitivity, the end frame the count,
    and the virtual device's C-driven stream is the firmware's, byte for byte."""
    from gyrocal.capture.pose_guide import guided_directions
    from gyrocal.capture.simulated_imu import simulate_device_imu_session

    dll, cdev = example
    s = simulate_device_imu_session(guided_directions()[:4], rng=np.random.default_rng(1606))
    sent = run_example(dll, s)
    assert cdev.firmware_stream(s.raw, s.t_us, s.temp, sample_rate=s.sample_rate, sensitivity=s.sensitivity,
                                accel=s.accel, accel_sensitivity=s.accel_sensitivity) == sent
    frames = fr.FrameDecoder().feed(sent)
    six = by_type(frames, fr.ImuSample)
    assert not by_type(frames, fr.Sample) and [f.seq for f in six] == list(range(len(s)))
    np.testing.assert_array_equal([f.raw for f in six], s.raw)
    np.testing.assert_array_equal([f.accel for f in six], s.accel)
    np.testing.assert_array_equal([f.t_us for f in six], s.t_us)
    assert frames[0].accel_sensitivity == 16384 and frames[-1] == fr.End(len(s))


def test_firmware_stores_reads_back_and_applies_a_written_back_calibration(example, session):
    """The host's set-calibration frame, received from sample 100 on: the firmware stores it (the fake board's RAM
    page holds the request's own frame), answers with what it read back, which is the request float32 bit for bit,
    and corrects every later sample with it, its own result coming later notwithstanding; the virtual device's
    C-driven storage (CStorage) answers the same bytes. References: the request, and w = matrix (raw - offset)
    recomputed in float64 within float32 rounding."""
    from gyrocal.capture.c_device import CStorage

    dll, cdev = example
    dll.example_host_input.argtypes = [ctypes.c_char_p, ctypes.c_size_t, ctypes.c_uint32]
    dll.example_page.restype = ctypes.c_size_t
    dll.example_page.argtypes = [ctypes.c_void_p, ctypes.c_size_t]
    matrix = np.diag(MODEL.k / session.sensitivity) + 1e-4 * np.eye(3)[[1, 2, 0]]
    request = fr.SetCalibration.of(42, matrix, -np.degrees(MODEL.b) * session.sensitivity)
    wire = b"\xa5\x00" + fr.encode(request)  # a stray byte first: the receiver finds the frame after it
    dll.example_host_input(wire, len(wire), 100)
    try:
        frames = fr.FrameDecoder().feed(run_example(dll, session))
    finally:
        dll.example_host_input(None, 0, 0)
    page = ctypes.create_string_buffer(256)
    assert dll.example_page(page, 256) == len(fr.encode(request)) and page.raw[:62] == fr.encode(request)
    (echo,) = by_type(frames, fr.CalibrationStored)
    assert echo.echoes(request) and fr.encode(echo) == CStorage(cdev)(wire)
    cal = by_type(frames, fr.Calibrated)
    assert [c.seq for c in cal] == list(range(100, len(session))) and len(by_type(frames, fr.Result)) == 1
    m = np.asarray(request.matrix, float).reshape(3, 3)
    d = session.raw[100:].astype(float) - np.asarray(request.offset)
    bound = 4 * np.finfo(np.float32).eps * (np.abs(d) @ np.abs(m).T + np.abs(np.asarray(request.offset)) @ np.abs(m).T)
    assert np.all(np.abs(np.array([c.w for c in cal]) - d @ m.T) <= bound)


def _device_turns(cdev, s):
    """Feed a session to the C session through ctypes: the accepted turns by slot and the final session."""
    from gyrocal.capture.c_device import _Session

    st, ptr = _Session(), ctypes.POINTER(ctypes.c_int16)
    cdev.dll.gyrocal_session_init(ctypes.byref(st), s.sample_rate, s.sensitivity, 360.0)
    raw = np.ascontiguousarray(s.raw, dtype=np.int16)
    turns = {}
    for i in range(len(raw)):
        if cdev.dll.gyrocal_session_add(ctypes.byref(st), ctypes.cast(raw.ctypes.data + 6 * i, ptr)) & 1:
            if st.turn.status == 0:
                turns[st.turn.slot] = (tuple(st.turn.mean), st.turn.stop - st.turn.start, st.turn.rate)
    return turns, st


def test_slow_ramps_at_1khz_against_the_truth(example):
    """At 1 kHz with 1 s ramps the part of each ramp under the 10 deg/s band lasts 1/6 s; a pre-window of
    32 samples missed most of it and biased k by +2.5e-3 (26 sigma). Reference: the simulation's true
    gyro, and the first-moment covariance of the device's own windows at the simulated noise. Over 8
    seeded sessions (24 z values of k), RMS z within 3/sqrt(2n) of 1 and the mean z within 3/sqrt(n) of 0."""
    _, cdev = example
    z = []
    for seed in range(8):
        s = simulate_device_session(ServoProtocol(lead_in=1.0, ramp=1.0, misalignment_deg=3.0), model=MODEL,
                                    noise_std=NOISE, rng=np.random.default_rng(100 + seed), sample_rate=1000.0)
        turns, st = _device_turns(cdev, s)
        assert st.status == 0 and sorted(turns) == list(range(6))
        mean, count, rate = (np.array([turns[j][i] for j in range(6)], float) for i in range(3))
        fit = FirstMoment(noise_std=math.degrees(NOISE) * s.sensitivity).fit(
            ObservationSet(mean, mean**2, np.zeros((6, 3)), rate, count, count / 1000, np.zeros(6, bool)))
        z.append((np.array(st.result.k) - s.device_k) / np.sqrt(np.diag(fit.covariance))[:3])
    z = np.concatenate(z)
    assert abs(np.sqrt(np.mean(z**2)) - 1) < 3 / np.sqrt(2 * z.size), z
    assert abs(z.mean()) < 3 / np.sqrt(z.size), z
