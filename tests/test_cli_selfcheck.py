"""The self-checks through the command line: what ``calibrate`` and ``segments`` print and write.

References: the simulator's truth (true sample clock, true turn angles) for every figure
checked here; the one-line refusal contract of ``cli_runner.refused`` for every refusal.
"""

import json
import math
import re

import numpy as np
import pytest
from cli_runner import invoke, refused

from gyrocal.io import write_recording
from gyrocal.models import ScaleBias
from gyrocal.recording import Recording
from gyrocal.simulation import VirtualGyro
from gyrocal.simulation.servo import ServoProtocol, simulate_servo
from gyrocal.simulation.timestamps import ReceiveClock, with_time_defects

K = np.array([1.0069, 0.9960, 0.9955])  # the servo method of Wang et al., Table III (MPU9250)
B = np.array([0.0442, -0.0089, 0.0076])
GYRO = VirtualGyro(ScaleBias(K, B), noise_std=0.01)


@pytest.fixture
def bursty_csv(tmp_path, rng):
    rec, _ = simulate_servo(GYRO, ServoProtocol(misalignment_deg=3), sample_rate=100, rng=rng)
    bursty, _ = with_time_defects(rec, rng, clock=ReceiveClock(packet=2, read_time=0.0035, jitter=0.003))
    path = tmp_path / "bursty.csv"
    write_recording(path, bursty, units="deg/s")
    return path


def test_segments_prints_the_time_base_and_measured_angles(bursty_csv):
    code, out, err = invoke("segments", bursty_csv, "--units", "deg/s", "--angle", "360")
    assert code == 0, err
    rate = re.search(r"time base: ([\d.]+) Hz nominal .* median 5(\.\d+)? ms", out)
    assert rate and abs(float(rate.group(1)) - 100) < 0.01  # the simulator's sensor clock: 100 Hz
    assert "steps are bursty" in out and "declared angle 360 deg" in out
    # every turn's measured angle: 360 / k, not the declared 360 (k = 1.0069, 0.996, 0.9955)
    angles = [float(a) for a in re.findall(r"rotation\s*│\s*[+-][xyz]\s*│.*?│\s*(\d+\.\d)\s*│", out)]
    assert len(angles) == 6
    expected = np.repeat(360 / K, 2)
    # sd of a measured angle: white noise 0.01 rad/s over ~660 samples of 10 ms (0.15 deg) and the standstill
    # level's error over the turn (0.08 deg): 0.17 deg; 4 sigma
    assert np.all(np.abs(np.array(angles) - expected) < 4 * 0.17), angles


def test_calibrate_prints_fit_quality_and_writes_the_sections(bursty_csv, tmp_path):
    out_file = tmp_path / "cal.json"
    code, out, err = invoke("calibrate", bursty_csv, "--units", "deg/s", "--angle", "360", "-o", out_file)
    assert code == 0, err
    assert re.search(r"fit quality: chi2/dof [\d.]+/21 = [\d.]+, p = [\d.e-]+", out)
    assert "largest residuals [noise sigma]: window" in out
    doc = json.loads(out_file.read_text())
    assert doc["fit"]["dof"] == 21 and len(doc["fit"]["residuals"]) == 13
    assert doc["observed"]["time_base"]["median_step"] < 0.006 < doc["observed"]["time_base"]["mean_step"]
    assert doc["observed"]["units"] == "deg/s" and len(doc["observed"]["max_abs_rate"]) == 3
    from gyrocal.results.files import load

    assert load(out_file).fit["dof"] == 21  # the file loads back with its sections


def test_a_wrong_sample_rate_is_named_in_a_warning(tmp_path, rng):
    rec, _ = simulate_servo(GYRO, ServoProtocol(speed=math.radians(25)), sample_rate=20, rng=rng)
    path = tmp_path / "log.csv"
    write_recording(path, Recording.from_rate(rec.gyro, 20.0), units="deg/s")
    np.savetxt(path, np.degrees(rec.gyro), delimiter=",", header="gx,gy,gz", comments="")  # no time column
    out_file = tmp_path / "cal.json"
    line = refused("calibrate", path, "--units", "deg/s", "--sample-rate", "25", "--angle", "360", "-o", out_file)
    assert re.search(r"every turn reads 20 % short .* is the sample rate 20 Hz rather than the 25 Hz declared\\?", line)
    assert not out_file.exists()
    # the same data accepted as they are: exit 0, the diagnosis printed and in the file
    code, out, err = invoke("calibrate", path, "--units", "deg/s", "--sample-rate", "25", "--angle", "360", "-o",
                            out_file, "--accept-implausible")
    assert code == 0
    assert re.search(r"warning: every turn reads 20 % short .* is the sample rate 20 Hz rather than the 25 Hz "
                     "declared\\?", err.replace("\n", " "))
    assert any("--accept-implausible" in w for w in json.loads(out_file.read_text())["fit"]["warnings"])


def test_refusals_are_one_line(tmp_path, rng):
    zero = tmp_path / "zero.csv"
    np.savetxt(zero, np.c_[np.arange(2000) / 100, np.zeros((2000, 3))], delimiter=",", header="t,gx,gy,gz",
               comments="")
    for command in ("calibrate", "segments"):
        assert "every reading is the same (0, 0, 0 on x, y, z)" in refused(command, zero, "--units", "deg/s")
    rec, _ = simulate_servo(GYRO, ServoProtocol(), rng=rng)
    path = tmp_path / "rec.csv"
    write_recording(path, rec, units="deg/s")
    line = refused("calibrate", path, "--units", "deg/s", "--angle", "360", "--method", "lm")
    assert "its rate varies" in line and "use the default method (--method first-moment)" in line
    noise = tmp_path / "noise.json"
    noise.write_text(json.dumps({"format": "gyrocal.noise", "version": 1, "taus": [1.0], "adev": [[0.0]] * 3,
                                 "arw": [0.0, 0.0, 0.0], "bias_instability": [None] * 3,
                                 "bias_instability_tau": [None] * 3, "rrw": [None] * 3, "sample_rate": 200.0,
                                 "duration": 10.0, "units": {}}))
    line = refused("calibrate", path, "--units", "deg/s", "--angle", "360", "--noise-density", noise)
    assert "--noise-density" in line and "zero noise density on x, y, z" in line


def test_simulate_writes_each_defect_with_its_truth(tmp_path):
    """``simulate`` with receive-time stamps, gaps, ripple and per-turn angles: the truth sidecar says what was
    done, and its windows are rows of the written recording (checked against the recording itself)."""
    out = tmp_path / "defects.csv"
    code, _, err = invoke("simulate", "-o", out, "--stamps", "receive", "--late-per-minute", "6", "--gaps", "2",
                          "--ripple", "0.05", "--vibration", "0", "--revolutions", "1,1,0.5,0.5,0.75,0.75",
                          "--sample-rate", "100", "--seed", "3")
    assert code == 0, err
    truth = json.loads((tmp_path / "defects.truth.json").read_text())
    assert truth["settings"]["stamps"] == "receive" and truth["settings"]["ripple"] == 0.05
    assert truth["settings"]["revolutions"] == [1, 1, 0.5, 0.5, 0.75, 0.75]
    assert [c for _, c in truth["time_base"]["gaps"]] == [17, 17]
    data = np.loadtxt(out, delimiter=",", skiprows=2)
    t, gyro = data[:, 0], np.radians(data[:, 1:])
    assert np.median(np.diff(t)) < 0.006  # bursty stamps
    # each true turn, as rows of the recording, integrates to its angle (k = 1, b = 0): within 4 sigma of the
    # white noise (0.035 rad/s over ~700 samples of 10 ms: 0.5 deg) unless a gap took up to 17 samples
    # (at most 17 x 10 ms x 60 deg/s x 1.05 = 11 deg) out of it
    from gyrocal.simulation.timestamps import rows_after_gaps

    rows = [int(rows_after_gaps(start, truth["time_base"]["gaps"])) for start, _ in truth["time_base"]["gaps"]]
    for w in (w for w in truth["windows"] if w["kind"] == "rotation"):
        angle = math.degrees(np.linalg.norm(np.sum(gyro[w["start"]:w["stop"]], axis=0)) / 100)  # 10 ms a sample
        gap = any(w["start"] < r < w["stop"] for r in rows)
        assert -11 - 2 < angle - w["angle_deg"] < 2 if gap else abs(angle - w["angle_deg"]) < 2
    line = refused("simulate", "-o", tmp_path / "x.csv", "--late-per-minute", "3")
    assert "--late-per-minute is for --stamps receive" in line


def test_simulated_angle_errors_and_their_declared_accuracy(tmp_path):
    """``simulate --angle-error 0.5``: the truth file's turn sizes differ from 360 by draws of sd 0.5 deg (24
    draws over 4 seeds: their sd / 0.5 within [0.5, 1.6], where a chi2 with 24 dof falls outside [6, 61] with
    probability below 1e-3); its windows hold those sizes; ``calibrate --angle 360 --angle-sd 0.5`` says the
    1-sigma carries it; a turntable and a negative sd are refused."""
    sizes = []
    for seed in range(4):
        out = tmp_path / f"r{seed}.csv"
        assert invoke("simulate", "-o", out, "--angle-error", "0.5", "--seed", str(seed), "--force")[0] == 0
        truth = json.loads((tmp_path / f"r{seed}.truth.json").read_text())
        assert truth["settings"]["angle_error_deg"] == 0.5
        sizes += [360 * r - 360 for r in truth["settings"]["revolutions"]]
        turns = [w["angle_deg"] for w in truth["windows"] if w["kind"] == "rotation"]
        np.testing.assert_allclose(turns, [360 * r for r in truth["settings"]["revolutions"]], rtol=1e-12)
    assert 0.5 <= np.std(sizes) / 0.5 <= 1.6
    code, out, err = invoke("calibrate", tmp_path / "r0.csv", "--units", "deg/s", "--angle", "360", "--angle-sd", "0.5")
    assert code == 0, err
    assert "declared accuracy of every turn's angle, 0.5 deg" in out
    assert "does not apply to --protocol turntable" in refused("simulate", "-o", tmp_path / "t.csv", "--protocol",
                                                                "turntable", "--angle-error", "1")
    assert "--angle-error must be a number of degrees >= 0" in refused("simulate", "-o", tmp_path / "n.csv",
                                                                        "--angle-error", "-1")
