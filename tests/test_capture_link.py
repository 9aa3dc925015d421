"""Capture through pseudo-terminals (and a local socket): both wire formats, every fault, each way a capture ends.

Independent references: the simulated session that the virtual device sends (values, device time
stamps), and the bytes the faults removed or changed, mapped to the frames they sat in by the
encoder's fixed frame size (not by the decoder under test). Nothing waits on a sleep: a session
ends with its end-of-session marker, after which the reader closes the port and the device waits
for that hang-up; a cut stream (the disconnect fault) is closed only once the reader's queue has
stayed empty; and every capture has a silence limit so a broken test fails instead of hanging.
"""

from __future__ import annotations

import numpy as np
import pytest

from gyrocal.capture import frames as fr
from gyrocal.capture.device import Faults, VirtualDevice, damage, device_bytes
from gyrocal.capture.recorder import Capture
from gyrocal.capture.simulated import simulate_device_session
from gyrocal.io import read_recording
from gyrocal.models import ScaleBias
from gyrocal.simulation import ServoProtocol

SAFETY = 30.0  # [s] of silence after which a capture gives up (never reached when things work)
HELLO = len(fr.encode(fr.Hello(200.0, 131.0)))
FRAME = fr.OVERHEAD + fr.Sample.FORMAT.size


@pytest.fixture(scope="module")
def session():
    rng = np.random.default_rng(1616)
    model = ScaleBias(k=np.array([1.02, 0.98, 1.01]), b=np.radians([1.0, -1.5, 0.5]))
    proto = ServoProtocol(turns=("+x", "-y"), lead_in=1.0, lead_out=1.0, wait=1.0)
    return simulate_device_session(proto, model=model, noise_std=0.01, rng=rng)


def capture(tmp_path, data: bytes, faults=None, transport="pty", **kwargs):
    events = []
    with VirtualDevice(data, faults=faults or Faults(), transport=transport) as dev:
        port = dev.start()
        def on_event(kind, payload):
            events.append((kind, payload))
            if kind == "open":
                dev.release()

        cap = Capture(port, tmp_path / "rec.csv", silence=SAFETY, on_event=on_event, **kwargs)
        result = cap.run()
    return result, events


def read_back(result, units="counts"):
    return read_recording(result.path, units=units)


def test_frames_arrive_whole_and_end_with_the_stream(tmp_path, session):
    data = device_bytes(session, "frames", encoder="python")
    result, events = capture(tmp_path, data)
    assert result.ended == "end of session" and result.wire == "frames" and result.sent == len(session)
    rec = read_back(result)
    np.testing.assert_array_equal(rec.gyro, session.raw)
    np.testing.assert_allclose(rec.t, (session.t_us - session.t_us[0]) * 1e-6, atol=5e-7)
    assert result.hello.sensitivity == 131.0 and ("wire", "frames") in events


def test_text_lines_arrive_whole(tmp_path, session):
    result, _ = capture(tmp_path, device_bytes(session, "text"))
    assert result.wire == "text" and result.ended == "end of session"
    rec = read_back(result)
    np.testing.assert_array_equal(rec.gyro, session.raw)
    np.testing.assert_allclose(rec.t, (session.t_us - session.t_us[0]) * 1e-6, atol=5e-7)
    np.testing.assert_allclose(rec.temp, session.temp, atol=1e-9)
    assert result.stats.bad_lines == 0


def test_bad_text_lines_are_skipped_and_counted(tmp_path, session):
    lines = device_bytes(session, "text").split(b"\r\n")
    bad = [b"1234,oops,3", b"\xff\xfe garbage", b"12,13", b"MPU6050 not found?"]
    for i, line in zip((50, 300, 301, 900), bad):
        lines[i] = line  # replaces data lines 49, 299, 300, 899 (line 0 is the header)
    result, _ = capture(tmp_path, b"\r\n".join(lines), wire="text")
    assert result.stats.bad_lines == len(bad)
    expected = np.delete(session.raw, [49, 299, 300, 899], axis=0)
    np.testing.assert_array_equal(read_back(result).gyro, expected)


def frames_hit(indices) -> set[int]:
    """Sample frames (by sequence number) that contain any of the byte `indices` of the clean stream."""
    idx = np.asarray(indices)
    idx = idx[idx >= HELLO]
    return set(((idx - HELLO) // FRAME).tolist())


@pytest.mark.parametrize("kind", ["drop", "corrupt"])
def test_damaged_bytes_lose_only_their_frames(tmp_path, session, kind):
    clean = device_bytes(session, "frames", encoder="python")
    faults = Faults(**{kind: 2e-4}, seed=7)
    data, dmg = damage(clean, faults)
    hit = frames_hit(dmg.dropped if kind == "drop" else dmg.corrupted)
    assert hit  # the fault did something
    result, _ = capture(tmp_path, data)
    keep = sorted(set(range(len(session))) - hit)
    np.testing.assert_array_equal(read_back(result).gyro, session.raw[keep])
    st = result.stats
    missing_inside = len([s for s in hit if s < max(keep)])  # a lost tail is not a gap in the sequence
    assert st.lost_samples == missing_inside
    if kind == "corrupt":  # a hit in the sync, type or length bytes hides the frame; others fail its CRC
        idx = dmg.corrupted[dmg.corrupted >= HELLO] - HELLO
        header_hit = set((idx[idx % FRAME < 4] // FRAME).tolist())
        assert st.crc_errors == len(hit - header_hit)


def test_stall_is_reported_and_nothing_is_lost(tmp_path, session):
    data = device_bytes(session, "frames", encoder="python")
    result, events = capture(tmp_path, data, Faults(stall_at=0.5, stall_s=1.5), stall=0.5)
    assert "stall" in [k for k, _ in events] and max(result.stalls) >= 1.0  # a loaded machine may add its own
    np.testing.assert_array_equal(read_back(result).gyro, session.raw)


def test_disconnect_keeps_everything_received(tmp_path, session):
    data = device_bytes(session, "frames", encoder="python")
    cut = 0.4
    result, _ = capture(tmp_path, data, Faults(disconnect_at=cut))
    whole = (int(cut * len(data)) - HELLO) // FRAME  # sample frames complete before the cut
    assert result.ended == "end of stream"
    np.testing.assert_array_equal(read_back(result).gyro, session.raw[:whole])


def test_duration_counts_device_time(tmp_path, session):
    result, _ = capture(tmp_path, device_bytes(session, "frames", encoder="python"), duration=5.0)
    rec = read_back(result)
    assert result.ended == "duration"
    assert len(rec) == int(np.sum(session.t_us - session.t_us[0] < 5_000_000))


def test_sample_count_ends_exactly(tmp_path, session):
    result, _ = capture(tmp_path, device_bytes(session, "text"), samples=1234)
    assert result.ended == "samples"
    np.testing.assert_array_equal(read_back(result).gyro, session.raw[:1234])


def test_socket_url_end_of_session(tmp_path, session):
    result, _ = capture(tmp_path, device_bytes(session, "frames", encoder="python"), transport="tcp")
    assert result.ended == "end of session"
    np.testing.assert_array_equal(read_back(result).gyro, session.raw)


@pytest.mark.parametrize("wire", ["frames", "text"])
def test_a_stream_without_its_end_marker_ends_with_the_link(tmp_path, session, wire):
    """A device that just stops (no end frame, no end line) and closes: every byte it sent is kept."""
    data = device_bytes(session, wire, encoder="python")
    data = data[: data.rindex(b"#")] if wire == "text" else data[: -len(fr.encode(fr.End(0)))]
    result, _ = capture(tmp_path, data)
    assert result.ended == "end of stream" and result.sent is None
    np.testing.assert_array_equal(read_back(result).gyro, session.raw)


def test_stop_request_finishes_the_file(tmp_path, session):
    data = device_bytes(session, "frames", encoder="python")
    with VirtualDevice(data) as dev:
        cap = Capture(dev.start(), tmp_path / "rec.csv", silence=SAFETY, on_event=lambda k, p: dev.release())
        result = cap.run(stop=lambda: len(cap.result.store) >= 500)
    assert result.ended == "stopped"
    rec = read_back(result)
    assert len(rec) >= 500
    np.testing.assert_array_equal(rec.gyro, session.raw[: len(rec)])


def test_the_end_frame_reveals_samples_lost_before_the_first_one(tmp_path, session):
    """Samples lost before the first one received leave no gap in the sequence numbers; the end frame, which
    counts the samples the device sent, shows them in the summary."""
    from gyrocal.capture.report import summary

    data = device_bytes(session, "frames", encoder="python")
    result, _ = capture(tmp_path, data[:HELLO] + data[HELLO + 5 * FRAME:])
    assert result.stats.lost_samples == 0 and result.sent == len(session) == len(result.store) + 5
    assert f"5 of the {len(session):,} samples the device sent, missing at the start or end" in summary(result)[1]


@pytest.fixture(scope="module")
def imu_session():
    """A short multi-position hand session (four poses) of a board with an accelerometer."""
    from gyrocal.capture.pose_guide import guided_directions
    from gyrocal.capture.simulated_imu import simulate_device_imu_session

    return simulate_device_imu_session(guided_directions()[:4], rng=np.random.default_rng(1618))


def test_six_axis_text_lines_arrive_whole(tmp_path, imu_session):
    s = imu_session
    result, _ = capture(tmp_path, device_bytes(s, "text"))
    assert result.wire == "text" and result.ended == "end of session" and result.stats.bad_lines == 0
    rec = read_recording(result.path, units="counts", accel_units="counts")
    np.testing.assert_array_equal(rec.gyro, s.raw)
    np.testing.assert_array_equal(rec.accel, s.accel)


@pytest.mark.parametrize("kind", ["drop", "corrupt"])
def test_six_axis_frames_with_faults_through_a_pty(tmp_path, imu_session, kind):
    """6-axis frames with damaged bytes: exactly the frames that held a damaged byte are missing from the file,
    with the accelerometer of every other one as sent (frames hit are found from the damage and the frame size)."""
    s = imu_session
    clean = device_bytes(s, "frames", encoder="python")
    data, dmg = damage(clean, Faults(**{kind: 1e-4}, seed=9))
    hello = len(fr.encode(fr.Hello(100.0, 131.0)))
    size = fr.OVERHEAD + fr.ImuSample.FORMAT.size
    idx = np.asarray(dmg.dropped if kind == "drop" else dmg.corrupted)
    idx = idx[(idx >= hello) & (idx < hello + size * len(s))]
    hit = set(((idx - hello) // size).tolist())
    assert hit
    result, _ = capture(tmp_path, data)
    keep = sorted(set(range(len(s))) - hit)
    rec = read_recording(result.path, units="counts", accel_units="counts")
    np.testing.assert_array_equal(rec.gyro, s.raw[keep])
    np.testing.assert_array_equal(rec.accel, s.accel[keep])
    assert result.hello.accel_sensitivity == s.accel_sensitivity


def test_memory_holds_only_recent_samples_and_the_file_all(tmp_path):
    """A capture of any length keeps only the recent samples in memory (what the live display, the guide and the
    device check need) while the file gets every one; indices stay absolute. Reference: the samples written."""
    from gyrocal.capture.store import RETAIN_S, SampleStore

    fs, n = 200.0, 40_000  # 200 s of data: more than twice what is kept
    g = np.arange(3 * n).reshape(n, 3) % 30011
    store = SampleStore(tmp_path / "long.csv")
    most = 0
    for i in range(n):
        store.add(1.0 + i / fs, g[i], None, i, g[i] // 2)
        if i % 100 == 0:  # the capture loop flushes and trims twice a second of wall time
            store.flush()
            # a guide that still needs sample 100 keeps it (for the first half), then nobody needs old samples
            store.trim(keep_from=100 if i < n // 2 else None)
            if i < n // 2:
                assert store.first <= 100
            else:
                most = max(most, len(store.gyro))
    assert most <= 2 * RETAIN_S * fs + 4096 and len(store) == n
    assert store.first + len(store.gyro) == n and store.seq[0] == store.first  # absolute indices
    np.testing.assert_array_equal(store.samples_by_seq(n - 10, n), g[n - 10:])
    rec = read_recording(store.finish(), units="counts", accel_units="counts")
    np.testing.assert_array_equal(rec.gyro, g)
    np.testing.assert_array_equal(rec.accel, g // 2)
