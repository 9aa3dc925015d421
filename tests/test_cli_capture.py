"""``gyrocal capture`` as a user runs it: the installed entry point in a subprocess, on a virtual device.

Independent references: the simulated session the virtual device sends (its samples and the true
gyro), and, for the signal cases, exactly the frames sent before the device paused. The tests
synchronise on what the command prints ("listening on ..." once the port is open, the guide's
lines) and on the device having been read dry, never on sleeps; every wait has a generous timeout.
"""

from __future__ import annotations

import json
import math
import os
import queue
import signal
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
from cli_runner import refused

from gyrocal.capture import frames as fr
from gyrocal.capture.device import Faults, VirtualDevice, device_bytes
from gyrocal.capture.simulated import simulate_device_session
from gyrocal.io import read_recording
from gyrocal.models import ScaleBias
from gyrocal.simulation import ServoProtocol

GYROCAL = str(Path(sys.executable).with_name("gyrocal"))
WAIT = 120.0  # [s] generous: a loaded 2-core machine
MODEL = ScaleBias(k=np.array([1.02, 0.98, 1.01]), b=np.radians([1.5, -2.0, 0.8]))
HELLO = len(fr.encode(fr.Hello(200.0, 131.0)))
FRAME = fr.OVERHEAD + fr.Sample.FORMAT.size


class Running:
    """A ``gyrocal capture`` subprocess whose output lines can be waited for."""

    def __init__(self, *args):
        env = {**os.environ, "PYTHONUNBUFFERED": "1", "COLUMNS": "200"}
        self.proc = subprocess.Popen([GYROCAL, "capture", *map(str, args)], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        self.lines: queue.Queue = queue.Queue()
        self.seen: list[str] = []
        self.err: list[str] = []
        self._threads = [threading.Thread(target=self._pump, daemon=True),
                         threading.Thread(target=lambda: self.err.extend(self.proc.stderr), daemon=True)]
        for t in self._threads:
            t.start()

    def _pump(self):
        for line in self.proc.stdout:
            self.lines.put(line.rstrip("\n"))
        self.lines.put(None)

    def wait_for(self, text: str) -> str:
        while True:
            line = self.lines.get(timeout=WAIT)
            assert line is not None, f"capture ended before printing {text!r}: {self.seen}"
            self.seen.append(line)
            if text in line:
                return line

    def finish(self) -> tuple[int, str, str]:
        self.proc.stdin.close()
        self.proc.wait(timeout=WAIT)
        for t in self._threads:
            t.join(WAIT)
        self.proc.stdout.close()
        self.proc.stderr.close()
        rest = []
        while not self.lines.empty():
            line = self.lines.get()
            if line is not None:
                rest.append(line)
        return self.proc.returncode, "\n".join(self.seen + rest), "".join(self.err)


def start(dev: VirtualDevice, *args) -> Running:
    port = dev.start()
    run = Running("--port", port, *args)
    run.wait_for("listening on")
    dev.release()
    return run


@pytest.fixture(scope="module")
def servo():
    rng = np.random.default_rng(1601)
    wrong = ServoProtocol(turns=("+x",), revolutions=0.75, lead_in=3.0, lead_out=1.0)
    return simulate_device_session([wrong, ServoProtocol(lead_in=1.0)], model=MODEL, noise_std=0.01, rng=rng)


def within_4_sigma(cal_path: Path) -> np.ndarray:
    doc = json.loads(cal_path.read_text())
    p = doc["parameters"]
    params = np.r_[p[next(iter(p))]["k"], p[next(iter(p))]["b"]]
    sd = np.sqrt(np.diag(doc["covariance"]))
    z = (params - MODEL.params) / sd
    assert np.all(np.abs(z) <= 4), z
    return z


def test_guided_servo_session_with_the_device_answer(tmp_path, servo):
    out = tmp_path / "rec.csv"
    with VirtualDevice(device_bytes(servo, "frames", encoder="c")) as dev:
        run = start(dev, "-o", out, "--guide", "servo")
        code, stdout, err = run.finish()
    assert code == 0, err
    assert "NO: +x: refused: wrong angle" in stdout and "every step accepted" in stdout
    assert "device and host agree to float32 precision" in stdout
    rec = read_recording(out, units="counts")
    np.testing.assert_array_equal(rec.gyro, servo.raw[: len(rec)])  # the file holds what was sent, in order
    within_4_sigma(out.with_suffix(".cal.json"))


def test_guided_hand_session_with_a_redo(tmp_path):
    rng = np.random.default_rng(1602)
    proto = ServoProtocol.hand(turns=("+x", "+y", "+y", "+z"), lead_in=3.0, wait=4.0, lead_out=4.0)
    s = simulate_device_session(proto, model=MODEL, noise_std=0.01, rng=rng)
    data = device_bytes(s, "frames", encoder="python")
    pause = s.turns[1].stop + int(2.0 * s.sample_rate)  # 2 s into the stillness after the first +y
    with VirtualDevice(data, faults=Faults(stall_at=(HELLO + pause * FRAME) / len(data), stall_s=WAIT)) as dev:
        run = start(dev, "-o", tmp_path / "rec.csv", "--guide", "hand")
        run.wait_for("ok: +y: accepted")
        run.proc.stdin.write("r\n")
        run.proc.stdin.flush()
        run.wait_for("redo step 4")
        dev.resume()
        code, stdout, err = run.finish()
    assert code == 0, err
    assert [ln.split(": ")[2] for ln in stdout.splitlines() if ln.startswith("guide: ok:")] == [
        "still for 2 s", "+x", "still for 2 s", "+y", "+y", "still for 2 s", "+z", "still for 2 s"]
    within_4_sigma(tmp_path / "rec.cal.json")


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_signal_ends_the_capture_with_everything_received(tmp_path, servo, sig):
    data = device_bytes(servo, "frames", encoder="python")
    pause = 0.5
    with VirtualDevice(data, faults=Faults(stall_at=pause, stall_s=WAIT)) as dev:
        run = start(dev, "-o", tmp_path / "rec.csv")
        assert dev.paused.wait(WAIT)  # the capture has read every byte sent before the pause
        run.proc.send_signal(sig)
        code, stdout, err = run.finish()
    assert code == 0, err
    assert "capture ended (stopped)" in stdout
    whole = (int(pause * len(data)) - HELLO) // FRAME
    rec = read_recording(tmp_path / "rec.csv", units="counts")
    np.testing.assert_array_equal(rec.gyro, servo.raw[:whole])
    assert not list(tmp_path.glob(".*.part"))  # no temporary file left behind


def test_disconnect_through_the_cli(tmp_path, servo):
    data = device_bytes(servo, "text")
    with VirtualDevice(data, faults=Faults(disconnect_at=0.3)) as dev:
        run = start(dev, "-o", tmp_path / "rec.csv", "--samples", 100_000)
        code, stdout, err = run.finish()
    assert code == 0, err
    assert "capture ended (end of stream)" in stdout
    lines = data[: int(0.3 * len(data))].split(b"\r\n")[1:-1]  # complete lines after the header
    rec = read_recording(tmp_path / "rec.csv", units="counts")
    np.testing.assert_array_equal(rec.gyro, servo.raw[: len(lines)])


def test_refusals_are_one_line(tmp_path):
    assert "cannot open" in refused("capture", "--port", tmp_path / "no-such-port", "-o", tmp_path / "r.csv")
    (tmp_path / "r.csv").write_text("keep me")
    assert "--force" in refused("capture", "--port", "x", "-o", tmp_path / "r.csv")
    assert (tmp_path / "r.csv").read_text() == "keep me"
    assert "--wire" in refused("capture", "--port", "x", "-o", tmp_path / "s.csv", "--wire", "morse")


def test_nothing_received_is_an_error_and_writes_nothing(tmp_path):
    with VirtualDevice(b"") as dev:
        code, _out, err = start(dev, "-o", tmp_path / "r.csv").finish()
    assert code == 2 and "no samples received" in err
    assert not (tmp_path / "r.csv").exists() and not list(tmp_path.glob(".*"))


def test_guide_without_a_sensitivity_is_refused_but_keeps_the_recording(tmp_path, servo):
    with VirtualDevice(device_bytes(servo, "text")) as dev:
        run = start(dev, "-o", tmp_path / "r.csv", "--guide", "servo")
        code, _out, err = run.finish()
    assert code == 2 and "--sensitivity" in err and "Traceback" not in err
    rec = read_recording(tmp_path / "r.csv", units="counts")
    np.testing.assert_array_equal(rec.gyro, servo.raw[: len(rec)])
    assert math.isfinite(rec.t[-1])


def test_simulate_device_serves_capture(tmp_path):
    """Two real processes, as a person would run them: the virtual device and the capture.

    The device repeats its hello until the capture has opened the port (pyserial empties the queue
    on opening), then sends the session and its end frame, which says how many samples it sent:
    the capture must have every one of them, the first ones included.
    """
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    sim = subprocess.Popen([GYROCAL, "simulate", "--device", "--pace", "0", "--seed", "3", "--misalignment", "2"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        first = sim.stdout.readline()
        port = first.split(" on ")[1].split(":")[0]
        cap = subprocess.run([GYROCAL, "capture", "--port", port, "-o", tmp_path / "rec.csv"], capture_output=True,
                             text=True, timeout=WAIT, env=env)
        sim_out, sim_err = sim.communicate(timeout=WAIT)
    finally:
        sim.kill()
    assert cap.returncode == 0 and sim.returncode == 0, (cap.stderr, sim_err)
    assert "capture ended (end of session)" in cap.stdout and "the device closed the link" in sim_out
    assert "device and host agree to float32 precision" in cap.stdout
    assert "link: nothing lost" in cap.stdout
    assert len(read_recording(tmp_path / "rec.csv", units="counts")) > 10_000


def test_simulate_device_flags_need_device(tmp_path):
    assert "--device" in refused("simulate", "-o", tmp_path / "r.csv", "--faults", "drop=0.1")
    assert "not understood" in refused("simulate", "--device", "--faults", "melt=1")
    assert "guide's poses" in refused("simulate", "--device", "--protocol", "multi-position", "--tilt", "45")
    assert "--device serves servo, hand or multi-position" in refused("simulate", "--device", "--protocol", "static")


def test_capture_warns_when_the_device_result_is_off(tmp_path, servo):
    """A RESULT frame with k off by 1e-5 (a valid CRC: a firmware bug, not a line fault) is flagged."""
    import dataclasses

    data = device_bytes(servo, "frames", encoder="c")
    frames = fr.FrameDecoder().feed(data)
    (result,) = [f for f in frames if isinstance(f, fr.Result)]
    bad = dataclasses.replace(result, k=(result.k[0] * (1 + 1e-5), *result.k[1:]))
    data = data.replace(fr.encode(result), fr.encode(bad))
    with VirtualDevice(data) as dev:
        code, stdout, err = start(dev, "-o", tmp_path / "rec.csv").finish()
    assert code == 0 and "device and host DISAGREE" in stdout
    assert "warning: the device's calibration differs" in err


def imu_z_scores(cal_path: Path, s) -> np.ndarray:
    """(calibration file - simulator truth) / the file's own 1-sigma: accelerometer (9) and gyro (12) parameters."""
    from gyrocal.results.files import load_calibration

    cal = load_calibration(cal_path)
    part = cal.accelerometer["parameters"]
    xyz = "xyz".index
    truth = [s.truth["accel_matrix"][xyz(n[2]), xyz(n[3])] if n[0] == "A" else s.truth["accel_offset"][xyz(n[2])]
             for n in part["names"]]
    std = [cal.accelerometer["std"][n] for n in part["names"]]
    za = (np.array(part["values"]) - truth) / std
    zg = (cal.model.params - s.model.params) / np.sqrt(np.diag(cal.covariance))
    return np.r_[za, zg]


def test_guided_multi_position_session_with_a_redo(tmp_path):
    """The whole IMU through the example firmware's 6-axis frames: a person follows the guide, takes pose 4 back
    (r + Enter) and holds it again; the calibration file (gyro and accelerometer) finds the simulator's truth
    within 4 sigma of its own covariance."""
    from gyrocal.capture.pose_guide import guided_directions
    from gyrocal.capture.simulated_imu import simulate_device_imu_session

    d = guided_directions(12)
    s = simulate_device_imu_session([*d[:4], d[3], *d[4:]], rng=np.random.default_rng(1603), aim_deg=1.5)
    data = device_bytes(s, "frames", encoder="c")
    k = s.windows[3].start + int(2.5 * s.sample_rate)  # 2.5 s into pose 4: accepted by then, still held
    at = data.index(fr.encode(fr.ImuSample(k, int(s.t_us[k]), tuple(s.raw[k]), tuple(s.accel[k]), float(s.temp[k]))))
    out = tmp_path / "imu.csv"
    with VirtualDevice(data, faults=Faults(stall_at=at / len(data), stall_s=WAIT)) as dev:
        run = start(dev, "-o", out, "--guide", "multi-position")
        run.wait_for("ok: pose 4: accepted")
        run.proc.stdin.write("r\n")
        run.proc.stdin.flush()
        run.wait_for("redo pose 4")
        dev.resume()
        code, stdout, err = run.finish()
    assert code == 0, err
    accepted = [ln.split(": ")[2] for ln in stdout.splitlines() if ln.startswith("guide: ok:")]
    assert accepted == [f"pose {i}" for i in (1, 2, 3, 4, 4, *range(5, 13))]
    assert "enough poses, covering the sphere" in stdout and "accelerometer:" in stdout
    rec = read_recording(out, units="counts", accel_units="counts")
    np.testing.assert_array_equal(rec.accel, s.accel[: len(rec)])  # ax, ay, az as the device sent them
    z = imu_z_scores(out.with_suffix(".cal.json"), s)
    assert np.all(np.abs(z) <= 4), z


def test_capture_without_pyserial_names_the_extra(tmp_path, monkeypatch):
    """The quick start installs no pyserial: capture must say which extra to install, in one line (exit 2), and
    leave nothing behind. Reference: the contract of README's extras (a command that needs one says which)."""
    monkeypatch.setitem(sys.modules, "serial", None)  # import serial now raises ImportError
    line = refused("capture", "--port", "/dev/ttyACM0", "-o", tmp_path / "rec.csv", "--guide", "servo")
    assert "needs pyserial" in line and "gyrocal[serial]" in line
    assert not any(tmp_path.iterdir())


def test_station_capture_accepts_stores_and_asks_for_the_next_unit(tmp_path, servo):
    """A guided servo capture with --unit, --limits and --store: the calibration is judged and stored, the verdict is
    the last line a test engineer reads; with --next the serial prompt ends on an empty line. Reference: the
    virtual device's true k (1.02, 0.98, 1.01), inside limits of +-3 % and outside +-1.5 % for kx."""
    from gyrocal.store import open_store

    limits = tmp_path / "limits.toml"
    limits.write_text("guard = 2\n[limits.k]\nmin = 0.97\nmax = 1.03\n")
    store = tmp_path / "station.db"
    with VirtualDevice(device_bytes(servo, "frames", encoder="c")) as dev:
        run = start(dev, "-o", tmp_path / "{serial}.csv", "--guide", "servo", "--unit", "SN-7", "--limits", limits,
                    "--store", store, "--next")
        run.wait_for("next unit: scan or type its serial")
        run.proc.stdin.write("\n")
        code, stdout, err = run.finish()
    assert code == 0, err
    assert "SN-7: PASS" in stdout and "stored as record 1" in stdout
    doc = json.loads((tmp_path / "SN-7.cal.json").read_text())
    assert doc["unit"]["serial"] == "SN-7" and doc["acceptance"]["verdict"] == "pass"
    with open_store(store) as st:
        (record,) = st.history("SN-7")
    assert record.verdict == "pass" and record.document == doc
    assert "{serial}" in refused("capture", "--port", "x", "-o", tmp_path / "a.csv", "--guide", "servo", "--unit", "A",
                                 "--next")


def _station_run(tmp_path, servo, *extra, answer=None, limits="min = 0.97\nmax = 1.03\n"):
    lim = tmp_path / "limits.toml"
    lim.write_text(f"guard = 2\n[limits.k]\n{limits}")
    with VirtualDevice(device_bytes(servo, "frames", encoder="c"), answer=answer) as dev:
        run = start(dev, "-o", tmp_path / "rec.csv", "--guide", "servo", "--unit", "SN-7", "--limits", lim,
                    "--store", tmp_path / "station.db", "--write-back", "--quiet", *extra)
        return (*run.finish(), json.loads((tmp_path / "rec.cal.json").read_text()))


def test_write_back_after_a_pass_is_stored_and_read_back_by_the_device(tmp_path, servo):
    """--write-back after a pass: the virtual device receives the set-calibration frame with the C library's receiver,
    writes it to its RAM flash page, reads it back and echoes it. References: the calibration file's own correction
    rounded to float32 (what was sent), and the C side's page, parsed again in Python."""
    from gyrocal.capture.c_device import CStorage

    storage = CStorage()
    code, stdout, err, doc = _station_run(tmp_path, servo, answer=storage)
    assert code == 0, err
    assert "SN-7: written to the device and read back" in stdout and stdout.rstrip().endswith("SN-7: PASS")
    sent = np.asarray(doc["correction"]["matrix"], dtype=np.float32)
    device = doc["device"]
    assert doc["units"]["output"] == "deg/s" and device["rate_unit"] == "deg/s"  # the hello's unit, as the file
    assert device["written_back"] is True and device["applied"] is True
    np.testing.assert_array_equal(np.asarray(device["matrix"], np.float32), sent)
    (page,) = fr.FrameDecoder().feed(storage.page)
    np.testing.assert_array_equal(np.asarray(page.matrix, np.float32).reshape(3, 3), sent)
    np.testing.assert_array_equal(np.float32(page.offset), np.float32(doc["correction"]["offset"]))
    assert storage.applied == (*page.matrix, *page.offset)


def test_a_failed_unit_is_never_written_back(tmp_path, servo):
    from gyrocal.capture.c_device import CStorage

    storage = CStorage()
    code, stdout, err, doc = _station_run(tmp_path, servo, answer=storage, limits="min = 0.99\nmax = 1.01\n")
    assert code == 1 and "SN-7: FAIL" in stdout, err
    assert storage.page == b"" and "written to the device" not in stdout and "device" not in doc


def test_write_back_to_a_device_that_never_answers_is_refused_in_one_line(tmp_path, servo):
    """No answer within --write-back-timeout: exit 2 with one line; the file and the record say it was not written."""
    code, stdout, err, doc = _station_run(tmp_path, servo, "--write-back-timeout", "0.5")
    assert code == 2 and len(err.strip().splitlines()) == 1 and "no answer from the device within 0.5 s" in err
    assert "--write-back-timeout" in err
    assert doc["device"]["written_back"] is False


def test_write_back_refuses_an_echo_that_differs(tmp_path, servo):
    from gyrocal.capture.c_device import CStorage

    storage = CStorage()

    def flip(data: bytes) -> bytes:  # a storage that loses one bit of the matrix
        out = bytearray(storage(data))
        if out:
            out[20] ^= 1
            out[-2:] = fr.crc16(bytes(out[2:-2])).to_bytes(2, "little")
        return bytes(out)

    code, stdout, err, doc = _station_run(tmp_path, servo, answer=flip)
    assert code == 2 and "read back another calibration" in err and len(err.strip().splitlines()) == 1
    assert doc["device"]["written_back"] is False
