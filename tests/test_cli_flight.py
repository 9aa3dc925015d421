"""``noise``, ``thermal-bias`` and the VIO / flight-stack exports through the command line.

References: the simulated truth (``rec.truth.json``), the firmware evaluators of
``firmware_models.py`` (written from the PX4 and ArduPilot sources), and each tool's documented
field names. Every refusal is the one-line contract of ``cli_runner.refused``.
"""

import json

import numpy as np
import pytest
import yaml
from cli_runner import invoke, refused  # noqa: E402
from dataflash_writer import imu_log  # noqa: E402
from firmware_models import ardupilot_correct, parse_ardupilot, parse_px4, px4_offsets  # noqa: E402

from gyrocal.noise import NoiseReport
from gyrocal.results.files import load


@pytest.fixture(scope="module")
def rest(tmp_path_factory):
    """A 20-minute static log of a gyro and an accelerometer, with bias random walks."""
    folder = tmp_path_factory.mktemp("rest")
    rec = folder / "rest.csv"
    code, out, err = invoke("simulate", "-o", rec, "--protocol", "static", "--duration", "1200", "--sample-rate",
                            "100", "--noise", "0.005", "--rrw", "2e-4", "--accel-noise-density", "0.002",
                            "--accel-random-walk", "1e-3", "--units", "rad/s", "--seed", "5")
    assert code == 0, err
    return rec


def test_noise_then_kalibr_vins_imu_utils(rest, tmp_path):
    noise = tmp_path / "noise.json"
    code, out, err = invoke("noise", rest, "--units", "rad/s", "--accel-units", "m/s^2", "--json", noise)
    assert code == 0, err
    assert "accelerometer" in out and "-0.2" in out  # both tables, with intervals
    report = load(noise, NoiseReport)
    # datasheet units: ARW = N [rad/s/sqrt(Hz)] x 180/pi x 60 deg/sqrt(h); 5e-4 -> 1.72
    assert "datasheet" in out and "deg/\u221ah" in out and "deg/h" in out
    assert f"{np.degrees(report.gyro.density.value[3]) * 60:.3g}" in out
    # the simulation's truth: 0.005 rad/s per sample at 100 Hz, 0.002 m/s^2/sqrt(Hz)
    assert report.gyro.density.value[3] == pytest.approx(5e-4, rel=0.01)
    assert report.accel.density.value[3] == pytest.approx(2e-3, rel=0.01)
    out_yaml = tmp_path / "imu.yaml"
    code, out, err = invoke("export", noise, "--format", "kalibr", "-o", out_yaml, "--rostopic", "/mavros/imu/data_raw",
                            "--inflate", "2")
    assert code == 0, err
    doc = yaml.safe_load(out_yaml.read_text())
    assert doc["rostopic"] == "/mavros/imu/data_raw" and doc["update_rate"] == 100.0
    assert doc["gyroscope_noise_density"] == pytest.approx(2 * report.gyro.density.value[3], rel=1e-6)
    assert "inflate: 2" in out_yaml.read_text()
    code, out, err = invoke("export", noise, "--format", "vins", "-o", tmp_path / "vins.yaml")
    assert code == 0 and yaml.safe_load((tmp_path / "vins.yaml").read_text())["gyr_n"] == pytest.approx(
        report.gyro.density.value[3] * 10, rel=1e-6), err
    code, out, err = invoke("export", noise, "--format", "imu_utils", "-o", tmp_path / "imu_param.yaml",
                            "--name", "sim")
    assert code == 0 and "name: sim" in (tmp_path / "imu_param.yaml").read_text(), err
    assert "--prefix does not apply to kalibr export" in refused("export", noise, "--format", "kalibr", "-o",
                                                                 tmp_path / "x.yaml", "--prefix", "p")
    assert "px4 export takes gyrocal.thermal-bias" in refused("export", noise, "--format", "px4", "-o",
                                                              tmp_path / "x.params")


def test_kalibr_without_an_accelerometer_is_refused_or_takes_flags(rest, tmp_path):
    noise = tmp_path / "gyro.json"
    assert invoke("noise", rest, "--units", "rad/s", "--json", noise)[0] == 0
    line = refused("export", noise, "--format", "kalibr", "-o", tmp_path / "imu.yaml")
    assert "no accelerometer figures" in line and "--accel-noise-density" in line
    code, out, err = invoke("export", noise, "--format", "kalibr", "-o", tmp_path / "imu.yaml",
                            "--accel-noise-density", "0.003", "--accel-random-walk", "0.0004")
    assert code == 0, err
    assert yaml.safe_load((tmp_path / "imu.yaml").read_text())["accelerometer_noise_density"] == 0.003


def test_noise_refuses_what_it_cannot_analyse(tmp_path, rng):
    servo = tmp_path / "servo.csv"
    assert invoke("simulate", "-o", servo)[0] == 0  # six turns, 3 s apart
    assert "the log moves" in refused("noise", servo, "--units", "deg/s")
    zeros = tmp_path / "zeros.csv"
    zeros.write_text("t,gx,gy,gz\n" + "".join(f"{i / 100},0,0,0\n" for i in range(2000)))
    assert "reads 0 in every sample" in refused("noise", zeros, "--units", "rad/s")
    tiny = tmp_path / "tiny.csv"  # three rows: one line saying so, not quantisation warnings first
    tiny.write_text("t,gx,gy,gz\n0,0.1,0.2,0.3\n0.01,0.2,0.1,0.3\n0.02,0.1,0.3,0.2\n")
    assert "needs at least 100 samples at rest, got 3" in refused("noise", tiny, "--units", "rad/s")
    counts = tmp_path / "counts.csv"
    np.savetxt(counts, np.column_stack([np.arange(3000) / 100, np.round(rng.standard_normal((3000, 3)) * 20)]),
               delimiter=",", header="t,gx,gy,gz", comments="", fmt="%g")
    assert "--sensitivity" in refused("noise", counts, "--units", "counts")
    code, out, err = invoke("noise", counts, "--units", "counts", "--sensitivity", "131")
    assert code == 0 and "deg/s" in out, err


def test_a_bad_plot_path_fails_before_the_json_is_written(rest, tmp_path):
    noise = tmp_path / "noise.json"
    assert "must end in .png, .pdf or .svg" in refused("noise", rest, "--units", "rad/s", "--json", noise,
                                                       "--plot", tmp_path / "allan.jpg")
    assert not noise.exists()
    assert "its own file name" in refused("noise", rest, "--units", "rad/s", "--json", tmp_path / "a.png",
                                            "--plot", tmp_path / "a.png")


def test_motion_refuse_names_the_flag(tmp_path, rng):
    knock = tmp_path / "knock.csv"
    g = rng.standard_normal((30_000, 3)) * 0.005
    g[15_000:15_050] += 0.5
    np.savetxt(knock, np.column_stack([np.arange(30_000) / 100, g]), delimiter=",", header="t,gx,gy,gz",
               comments="")
    assert "--motion restrict" in refused("noise", knock, "--units", "rad/s", "--motion", "refuse")
    code, out, err = invoke("noise", knock, "--units", "rad/s")
    assert code == 0 and "warning: the log moves (1 motion, at 149" in err, err


@pytest.fixture(scope="module")
def warm(tmp_path_factory):
    """A board warming from -5 to 50 degC, still, temperature in whole degrees."""
    folder = tmp_path_factory.mktemp("warm")
    rec = folder / "warm.csv"
    code, out, err = invoke("simulate", "-o", rec, "--protocol", "static", "--duration", "2400", "--sample-rate", "50",
                            "--noise", "0.005", "--temp-start", "-5", "--temp-end", "50", "--warmup-tau", "500",
                            "--temp-quantum", "1", "--bias-tempco", "2e-4,-1e-4,5e-5;-3e-6,0,2e-6;5e-8,0,0",
                            "--seed", "3")
    assert code == 0, err
    return rec


def test_noise_on_a_warming_board_warns_and_records_the_temperature_span(warm, rest, tmp_path):
    """Reference: the simulator's warm-up in closed form, T(t) = 50 - 55 exp(-t / 500 s), which spans
    -5 to 49.5 degC over the 2400-s log (recorded as block means of whole degrees, so within 1.5 degC);
    the ``rest`` log is at a constant 25 degC: no warning, a span of 0."""
    noise = tmp_path / "warm_noise.json"
    code, out, err = invoke("noise", warm, "--units", "deg/s", "--json", noise)
    assert code == 0, err
    lines = [line for line in err.splitlines() if "thermal drift" in line]
    assert len(lines) == 1 and lines[0].startswith("warning: the temperature rises by 5"), err
    assert "let the board warm up before logging, or cut the log to its stable part" in lines[0]
    temperature = json.loads(noise.read_text())["analysed"]["temperature"]
    assert temperature["min"] == pytest.approx(-5.0, abs=1.5) and temperature["max"] == pytest.approx(49.5, abs=1.5)
    assert temperature["span"] == pytest.approx(temperature["max"] - temperature["min"]) and temperature["unit"] == "degC"
    assert load(noise, NoiseReport).warnings[-1] == lines[0].removeprefix("warning: ")
    flat = tmp_path / "rest_noise.json"
    code, out, err = invoke("noise", rest, "--units", "rad/s", "--json", flat)
    assert code == 0 and "warning" not in err, err
    assert json.loads(flat.read_text())["analysed"]["temperature"]["span"] == 0.0


def _truth(rec) -> tuple[np.ndarray, float]:
    still = json.loads(rec.with_name(rec.stem + ".truth.json").read_text())["still"]["bias_tempco"]
    return np.array(still["coefs"]), still["ref_temp_degC"]


def test_thermal_bias_then_px4_and_ardupilot_hold_the_truth(warm, tmp_path, rng):
    bias = tmp_path / "bias.json"
    code, out, err = invoke("thermal-bias", warm, "--units", "deg/s", "-o", bias)
    assert code == 0, err
    tb = load(bias)
    coefs, ref = _truth(warm)
    temps = np.linspace(tb.tmin, tb.tmax, 7)
    truth = np.vander(temps - ref, coefs.shape[1], increasing=True) @ coefs.T
    assert "--device-id" in refused("export", bias, "--format", "px4", "-o", tmp_path / "tc.params")
    assert invoke("export", bias, "--format", "px4", "-o", tmp_path / "tc.params", "--device-id", "7", "--slot",
                  "2")[0] == 0
    params = parse_px4((tmp_path / "tc.params").read_text())
    assert params["TC_G2_ID"] == 7
    reading = truth + rng.standard_normal(truth.shape) * 0.01  # what the gyro reads at rest at those temperatures
    px4 = reading - px4_offsets(params, 2, temps)
    ardupilot_file = tmp_path / "tc.parm"
    assert invoke("export", bias, "--format", "ardupilot", "-o", ardupilot_file, "--caltemp", "30")[0] == 0
    ap = ardupilot_correct(parse_ardupilot(ardupilot_file.read_text()), 1, temps, reading)
    # both firmwares leave only the fit's error: within 4 of its reported 1-sigma (plus float32 rounding)
    for corrected in (px4, ap):
        assert np.all(np.abs(corrected - (reading - truth)) < 4 * tb.std_at(temps) + 1e-6), corrected


def test_thermal_bias_refusals(warm, tmp_path):
    short = tmp_path / "short.csv"
    assert invoke("simulate", "-o", short, "--protocol", "static", "--duration", "300", "--sample-rate", "50",
                  "--temp-start", "30", "--temp-end", "36", "--warmup-tau", "100")[0] == 0
    assert "spans only" in refused("thermal-bias", short, "--units", "deg/s")
    servo = tmp_path / "servo.csv"
    assert invoke("simulate", "-o", servo)[0] == 0
    assert "no temperature column" in refused("thermal-bias", servo, "--units", "deg/s")
    assert "--max-order must be 0..3" in refused("thermal-bias", warm, "--units", "deg/s", "--max-order", "5")


def test_thermal_bias_from_a_dataflash_log(tmp_path, rng):
    """A warming board logged by ArduPilot (IMU messages at 25 Hz, two IMUs); the fit holds the truth."""
    n = 25 * 1200
    t = np.arange(n) / 25.0
    temp = 50 - 55 * np.exp(-t / 300.0)
    truth = np.stack([1e-3 + 2e-4 * (temp - 25) - 2e-6 * (temp - 25) ** 2, -1e-4 * (temp - 25),
                      5e-4 + 0 * temp], axis=1)
    raw = truth + rng.standard_normal((n, 3)) * 0.004
    w = imu_log()
    w.write("PARM", 0, "INS_GYROFFS_X", 0.002)
    for k in range(n):
        for inst in (0, 1):
            w.write("IMU", 10_000 + 40_000 * k, inst, *(raw[k] - [0.002, 0, 0]), 0.0, 0.0, 9.81, 0, 0, temp[k],
                    1, 1, 25, 25)
    log = tmp_path / "00000042.BIN"
    log.write_bytes(bytes(w))
    assert "--imu N" in refused("thermal-bias", log, "-o", tmp_path / "b.json")
    code, out, err = invoke("thermal-bias", log, "--imu", "0", "-o", tmp_path / "b.json")
    assert code == 0, err
    tb = load(tmp_path / "b.json")
    assert tb.source["imu_number"] == 1 and tb.source["undone"] == ["INS_GYROFFS"]
    temps = np.linspace(tb.tmin, tb.tmax, 5)
    want = np.stack([1e-3 + 2e-4 * (temps - 25) - 2e-6 * (temps - 25) ** 2, -1e-4 * (temps - 25),
                     np.full(5, 5e-4)], axis=1)
    assert np.all(np.abs(tb.bias_at(temps) - want) < 4 * tb.std_at(temps)), (tb.bias_at(temps) - want)
    # the range is that of the 5-s block means
    assert temp[-125:].min() <= tb.tmax <= temp.max() and temp.min() <= tb.tmin <= temp[125], (tb.tmin, tb.tmax)


def test_turntable_file_exports_its_bias_with_a_warning(tmp_path):
    from test_firmware_params import _turntable

    from gyrocal.results.files import save

    thermal = tmp_path / "thermal.json"
    save(_turntable(), thermal)
    code, out, err = invoke("export", thermal, "--format", "ardupilot", "-o", tmp_path / "tc.parm")
    assert code == 0, err
    assert "warning: scale factors and misalignment change with temperature" in err
    assert "INS_TCAL1_GYR1_X" in (tmp_path / "tc.parm").read_text()
