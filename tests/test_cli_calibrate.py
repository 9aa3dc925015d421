"""The ``calibrate``, ``segments``, ``apply`` and ``export`` commands, in-process and once as a subprocess.

In-process runs use :mod:`cli_runner` (the real error boundary inside typer's isolation).

References: the simulated truth of each recording (within 4 predicted sigma), a 200-seed Monte Carlo
for the printed 1-sigma, and the files and lines the commands write.
"""

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from cli_runner import invoke, refused  # noqa: E402

from gyrocal import ScaleBias, load_calibration
from gyrocal.simulation import VirtualGyro, noise_std_from_density
from gyrocal.simulation.servo import ServoProtocol, simulate_servo

TRUE = ScaleBias(k=[1.0069, 0.9960, 0.9955], b=[0.0442, -0.0089, 0.0076])


def _simulate(rng, protocol, fs=200.0, noise=0.01):
    gyro = VirtualGyro(model=TRUE, noise_std=noise)
    return simulate_servo(gyro, protocol, sample_rate=fs, rng=rng)


def _write_csv(path: Path, t, g, header="t,gx,gy,gz", fmt="%.6f"):
    data = np.column_stack([t, g]) if t is not None else g
    np.savetxt(path, data, delimiter=",", header=header, comments="", fmt=fmt)
    return path


def _within_4_sigma(cal, truth=TRUE):
    err = cal.model.params - truth.params
    assert np.all(np.abs(err) < 4 * cal.std), (err / cal.std)


@pytest.fixture(scope="module")
def servo_csv(tmp_path_factory):
    """The servo method's protocol at 60 deg/s, 200 Hz, ramps and vibration, 5 deg misaligned, in deg/s."""
    rng = np.random.default_rng(3)
    rec, truth = _simulate(rng, ServoProtocol(misalignment_deg=5.0))
    path = tmp_path_factory.mktemp("servo") / "rec.csv"
    return _write_csv(path, rec.t, np.degrees(rec.gyro)), truth


def test_speed_invocation_recovers_the_truth(servo_csv, tmp_path):
    path, _ = servo_csv
    out = tmp_path / "cal.json"
    code, stdout, err = invoke("calibrate", path, "--units", "deg/s", "--speed", "60", "-o", out)
    assert code == 0, err
    cal = load_calibration(out)
    assert (cal.input_units, cal.output_units, cal.method) == ("deg/s", "deg/s", "first-moment")
    _within_4_sigma(cal)
    assert "1-sigma" in stdout and "kx [1]" in stdout and "bx [deg/s]" in stdout and "offset" in stdout


def test_angle_invocation_and_plot(rng, tmp_path):
    rec, _ = _simulate(rng, ServoProtocol.hand(("+x", "-x", "+y", "-y", "+z", "-z"), wait=2.0), noise=0.02)
    path = _write_csv(tmp_path / "rec.csv", rec.t, np.degrees(rec.gyro))
    out, png = tmp_path / "cal.json", tmp_path / "cal.png"
    code, _, err = invoke("calibrate", path, "--units", "deg/s", "--angle", "360", "-o", out, "--plot", png)
    assert code == 0, err
    _within_4_sigma(load_calibration(out))
    assert png.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("method", ["algorithm1", "lm"])
def test_paper_methods_are_selectable(servo_csv, tmp_path, method):
    path, _ = servo_csv
    out = tmp_path / "cal.json"
    code, stdout, err = invoke("calibrate", path, "--units", "deg/s", "--speed", "60", "--method", method, "-o", out)
    assert code == 0, err
    cal = load_calibration(out)
    assert cal.method == method and stdout.startswith(f"{method}, speed 60 deg/s")
    # their 1-sigma is the spread; their mean-of-squares bias comes on top and is printed:
    # about 3e-3 of k here (1.7e-3 from noise, 1.25e-3 from the 5 % servo vibration)
    assert cal.std is not None and "reads k low by about" in stdout
    assert np.all(np.abs(cal.model.params - TRUE.params) < 4 * cal.std + np.r_[0.004 * TRUE.k, 0, 0, 0])


def test_ground_station_log_without_time_column(rng, tmp_path):
    """30 columns, a blank first line, no time column, 20 Hz, 25 deg/s.

    Noise: an MPU9250's 0.01 deg/s/sqrt(Hz) density read at 20 Hz (about 0.05 deg/s).
    """
    fs = 20.0
    noise = noise_std_from_density(math.radians(0.01), fs)
    rec, _ = _simulate(rng, ServoProtocol(speed=math.radians(25.0), ramp=0.5), fs=fs, noise=noise)
    n = len(rec)
    names = [f"col{i}" for i in range(27)] + ["gyroX", "gyroY", "gyroZ"]
    data = np.column_stack([rng.standard_normal((n, 27)), np.degrees(rec.gyro)])
    path = tmp_path / "log.csv"
    with open(path, "w") as f:
        f.write("\n" + ",".join(names) + "\n")
        np.savetxt(f, data, delimiter=",", fmt="%.6f")
    out = tmp_path / "cal.json"
    code, _, err = invoke("calibrate", path, "--columns", "gx=gyroX,gy=gyroY,gz=gyroZ", "--sample-rate", "20",
                          "--units", "deg/s", "--speed", "25", "-o", out)
    assert code == 0, err
    _within_4_sigma(load_calibration(out))


def test_raw_counts_with_windows_file_and_sensitivity(rng, tmp_path):
    """Counts at 204.8 Hz with a windows list; with and without a known sensitivity."""
    fs, lsb = 204.8, 65.5  # LSB per deg/s
    rec, truth = _simulate(rng, ServoProtocol(), fs=fs, noise=0.02)
    counts = np.round(np.degrees(rec.gyro) * lsb)
    path = _write_csv(tmp_path / "raw.csv", None, counts, header="gyr_x,gyr_y,gyr_z", fmt="%d")
    windows = tmp_path / "list.json"
    windows.write_text(json.dumps([w.to_dict() for w in truth.windows]))
    common = ["--columns", "gx=gyr_x,gy=gyr_y,gz=gyr_z", "--sample-rate", "204.8", "--units", "counts",
              "--output-units", "deg/s", "--angle", "360", "--windows", windows]
    out = tmp_path / "cal.json"
    code, _, err = invoke("calibrate", path, *common, "-o", out)
    assert code == 0, err
    cal = load_calibration(out)
    assert (cal.input_units, cal.output_units, cal.sensitivity) == ("counts", "deg/s", None)
    matrix, offset = cal.correction
    # quantisation (1/65.5 deg/s) is far below the noise. In counts the truth is
    # matrix = k / lsb [deg/s per count] and offset = -b * lsb [counts]; std is internal (rad/s, counts)
    sd_k = cal.std[:3] / math.radians(1.0) * lsb
    assert np.all(np.abs(np.diag(matrix) * lsb - TRUE.k) < 4 * sd_k)
    assert np.all(np.abs(offset + np.degrees(TRUE.b) * lsb) < 4 * cal.std[3:])
    code, _, err = invoke("calibrate", path, *common, "--sensitivity", "65.5", "-o", tmp_path / "cal2.json")
    assert code == 0, err
    cal2 = load_calibration(tmp_path / "cal2.json")
    assert cal2.sensitivity == 65.5
    assert np.allclose(cal2.correction[0], matrix, rtol=1e-6) and np.allclose(cal2.correction[1], offset, rtol=1e-6)


def test_same_output_is_fine_a_different_one_needs_force(servo_csv, tmp_path):
    path, _ = servo_csv
    out = tmp_path / "cal.json"
    args = ["calibrate", path, "--units", "deg/s", "--speed", "60", "-o", out]
    assert invoke(*args)[0] == 0
    assert invoke(*args)[0] == 0  # same content
    before = out.read_text()
    line = refused("calibrate", path, "--units", "deg/s", "--speed", "60", "--method", "lm", "-o", out)
    assert "different calibration" in line and "--force" in line
    assert out.read_text() == before
    code, _, _ = invoke("calibrate", path, "--units", "deg/s", "--speed", "60", "--method", "lm", "-o", out, "--force")
    assert code == 0 and load_calibration(out).method == "lm"


def _bad_inputs(tmp_path: Path, servo: Path) -> dict[str, tuple[list, str]]:
    """name -> (arguments after 'calibrate', text expected in the message)."""
    text = servo.read_text().splitlines()
    head, rows = text[0], text[1:]

    def variant(name, lines):
        p = tmp_path / f"{name}.csv"
        p.write_text("\n".join([head] + lines) + "\n")
        return p

    non_numeric = rows.copy()
    non_numeric[100] = non_numeric[100].replace(non_numeric[100].split(",")[2], "abc")
    nan_rows = rows.copy()
    nan_rows[200] = "1.0,nan,0,0"
    nan_rows[201] = "1.005,inf,0,0"
    backwards = rows.copy()
    backwards[300], backwards[301] = backwards[301], backwards[300]
    duplicated = rows.copy()
    duplicated[400] = duplicated[401].split(",")[0] + "," + ",".join(duplicated[400].split(",")[1:])
    saturated = rows.copy()
    for i in range(500, 560):
        saturated[i] = saturated[i].split(",")[0] + ",250.0,0.1,0.2"
    few_turns = [r for r in rows if float(r.split(",")[0]) < 20.0]  # +x and -x only
    rad_as_deg = tmp_path / "as_rad.csv"
    rad_as_deg.write_text(servo.read_text())
    existing = tmp_path / "taken.json"
    existing.write_text('{"format": "gyrocal.calibration", "note": "someone else\'s"}\n')
    std = ["--units", "deg/s", "--speed", "60"]
    return {
        "missing file": ([tmp_path / "nope.csv", *std], "nope.csv"),
        "missing column": ([servo, "--columns", "gx=gyroX", *std], "gyroX"),
        "non-numeric cell": ([variant("text", non_numeric), *std], "abc"),
        "nan rows": ([variant("nan", nan_rows), *std], "NaN"),
        "time goes back": ([variant("back", backwards), *std], "time"),
        "duplicated time": ([variant("dup", duplicated), *std], "time"),
        "saturated": ([variant("sat", saturated), *std], "full scale"),
        "too few rotations": ([variant("few", few_turns), *std], "no rotation about y, z"),  # +x, -x kept
        "deg/s declared as rad/s": ([rad_as_deg, "--units", "rad/s", "--speed", "1.047"], "deg/s"),
        "existing different output": ([servo, *std, "-o", existing], "--force"),
        "speed and angle": ([servo, "--units", "deg/s", "--speed", "60", "--angle", "360"], "not both"),
        "no units": ([servo, "--speed", "60"], "--units"),
    }


def test_bad_input_gets_one_line_exit_2_and_no_output(servo_csv, tmp_path):
    servo, _ = servo_csv
    for name, (args, expected) in _bad_inputs(tmp_path, servo).items():
        out = tmp_path / f"out-{name.replace(' ', '_').replace('/', '_')}.json"
        png = out.with_suffix(".png")
        has_o = "-o" in args
        line = refused("calibrate", *args, *([] if has_o else ["-o", out]), "--plot", png)
        assert expected.lower() in line.lower(), (name, line)
        assert not out.exists() and not png.exists(), name
    assert json.loads((tmp_path / "taken.json").read_text())["note"] == "someone else's"
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp") or ".tmp." in p.name]


def test_example_prints_parameters_with_uncertainty_and_truth(tmp_path):
    out, png = tmp_path / "cal.json", tmp_path / "cal.png"
    code, stdout, err = invoke("calibrate", "--example", "-o", out, "--plot", png)
    assert code == 0, err
    assert "truth" in stdout and "/ sigma" in stdout and "1-sigma" in stdout and "at rest" in stdout
    cal = load_calibration(out)
    _within_4_sigma(cal)
    assert len([w for w in cal.windows if w["kind"] == "rotation"]) == 6
    assert png.stat().st_size > 10_000


def test_segments_lists_windows_and_what_was_ignored(tmp_path):
    from importlib import resources

    session = Path(str(resources.files("gyrocal") / "data" / "imucal_ferraris" / "example_ferraris_session.csv"))
    png = tmp_path / "seg.png"
    code, stdout, err = invoke("segments", session, "--units", "deg/s", "--sample-rate", "102.4", "--angle", "360",
                               "--plot", png)
    assert code == 0, err
    assert stdout.count("rotation") == 3 and "ignored" in stdout and "wrong angle" in stdout
    assert png.read_bytes()[:4] == b"\x89PNG"
    code, stdout, _ = invoke("segments", session, "--units", "deg/s", "--sample-rate", "102.4", "--windows",
                             session.with_name("example_ferraris_session_list.json"))
    assert code == 0 and "9 windows from" in stdout and "nothing ignored" in stdout


def test_apply_corrects_and_passes_other_columns_through(servo_csv, tmp_path):
    path, _ = servo_csv
    cal_path = tmp_path / "cal.json"
    assert invoke("calibrate", path, "--units", "deg/s", "--speed", "60", "-o", cal_path)[0] == 0
    # add an unrelated column that must pass through
    lines = path.read_text().splitlines()
    src = tmp_path / "with_extra.csv"
    src.write_text("\n".join([lines[0] + ",note"] + [f"{ln},n{i}" for i, ln in enumerate(lines[1:])]) + "\n")
    out = tmp_path / "corrected.csv"
    code, _, err = invoke("apply", cal_path, src, "-o", out)
    assert code == 0, err
    from gyrocal.io import read_recording

    corrected = read_recording(out, units="deg/s")
    raw = read_recording(src, units="deg/s")
    cal = load_calibration(cal_path)
    assert np.allclose(corrected.gyro, cal.model.correct(raw.gyro), atol=1e-12)
    assert np.array_equal(corrected.t, raw.t)
    assert list(corrected.extra["note"][:3]) == ["n0", "n1", "n2"]
    # another rate unit is converted, so the reader's own unit check speaks; counts never mix with rates
    line = refused("apply", cal_path, src, "--units", "rad/s", "-o", tmp_path / "x.csv")
    assert "the data are almost surely in deg/s" in line
    line = refused("apply", cal_path, src, "--units", "counts", "-o", tmp_path / "x.csv")
    assert "--units counts does not match the calibration's input units deg/s" in line
    assert not (tmp_path / "x.csv").exists()


def test_export_json_and_yaml(servo_csv, tmp_path):
    path, _ = servo_csv
    cal_path = tmp_path / "cal.json"
    assert invoke("calibrate", path, "--units", "deg/s", "--speed", "60", "-o", cal_path)[0] == 0
    assert invoke("export", cal_path, "--format", "json", "-o", tmp_path / "c.json")[0] == 0
    assert json.loads((tmp_path / "c.json").read_text()) == json.loads(cal_path.read_text())
    import yaml

    assert invoke("export", cal_path, "--format", "yaml", "-o", tmp_path / "c.yaml")[0] == 0
    assert yaml.safe_load((tmp_path / "c.yaml").read_text()) == json.loads(cal_path.read_text())


def test_installed_entry_point_as_a_subprocess(tmp_path):
    out = tmp_path / "cal.json"
    proc = subprocess.run([sys.executable, "-m", "gyrocal", "calibrate", "--example", "-o", str(out)],
                          check=False, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert load_calibration(out).method == "first-moment"
    proc = subprocess.run([sys.executable, "-m", "gyrocal", "calibrate", str(tmp_path / "missing.csv"), "--units",
                           "deg/s", "--speed", "60"], check=False, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_entry_point_exit_keeps_output_handlers_threads_and_codes(tmp_path):
    """The console script ends without the interpreter's teardown (gyrocal.cli._leave). The independent
    reference is what an ordinary ``sys.exit`` guarantees: all output arrives through a pipe, atexit
    handlers run, a running non-daemon thread finishes, and the exit code is the command's."""
    marker = tmp_path / "thread-done"
    code = ("import atexit, sys, threading, time; import gyrocal.cli; "
            "atexit.register(lambda: print('atexit ran')); "
            f"threading.Thread(target=lambda: (time.sleep(0.3), open({str(marker)!r}, 'w').close())).start(); "
            "sys.argv = ['gyrocal'] + sys.argv[1:]; gyrocal.cli.main()")
    proc = subprocess.run([sys.executable, "-c", code, "calibrate", "--help"], check=False, capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "Usage" in proc.stdout and proc.stdout.rstrip().endswith("atexit ran")
    assert marker.exists()
    # without other threads: the short exit, the same output, handlers and code
    code = ("import atexit, sys; import gyrocal.cli; atexit.register(lambda: print('atexit ran')); "
            "sys.argv = ['gyrocal'] + sys.argv[1:]; gyrocal.cli.main()")
    helped = subprocess.run([sys.executable, "-c", code, "calibrate", "--help"], check=False, capture_output=True,
                            text=True, timeout=120)
    assert (helped.returncode, helped.stdout) == (0, proc.stdout)
    refused = subprocess.run([sys.executable, "-c", code, "calibrate", "--speed", "abc"], check=False,
                             capture_output=True, text=True, timeout=120)
    assert refused.returncode == 2 and refused.stdout == "atexit ran\n"
    assert len(refused.stderr.strip().splitlines()) == 1 and "Traceback" not in refused.stderr


def _make_example_module():
    import importlib.util

    path = Path(__file__).resolve().parents[1] / "tools" / "make_example.py"
    spec = importlib.util.spec_from_file_location("make_example", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_bundled_example_is_what_the_tool_generates():
    assert _make_example_module().main(["--check"]) == 0


def test_example_check_tolerates_last_bits_but_not_a_change():
    """--check passes another BLAS kernel's last bits (seen: 3.0000000000000004 against 3.000000000000001,
    and a printed last digit flipping) and fails a real change of a number, a text or a row."""
    same = _make_example_module().same_numbers
    assert same('{"deg": 3.0000000000000004}', '{"deg": 3.000000000000001}')
    assert same("t,gx\n0.005,1.234567\n", "t,gx\n0.005,1.234568\n", fixed_point=True)
    assert not same("t,gx\n0.005,1.234567\n", "t,gx\n0.005,1.234569\n", fixed_point=True)
    assert not same('{"deg": 3.0}', '{"deg": 3.0001}')
    assert not same('{"ramp_s": 0.3}', '{"ramp_s": 0.4}')
    assert not same("t,gx\n", "t,gy\n")
    assert not same("t,gx\n0.005,1.0\n", "t,gx\n0.005,1.0\n0.010,1.0\n")


def test_example_uncertainty_matches_monte_carlo_within_20_percent(tmp_path):
    """The 1-sigma printed for the bundled example against the spread over 200 simulated sessions.

    The Monte Carlo standard deviation of 200 draws is itself uncertain by about
    1/sqrt(2 * 199) = 5 %, so the 20 % target is a 4-sigma test.
    """
    from gyrocal.pipeline import calibrate

    out = tmp_path / "cal.json"
    assert invoke("calibrate", "--example", "-o", out)[0] == 0
    printed = load_calibration(out).std  # internal units: k [1], b [rad/s]
    gyro, protocol, fs = _make_example_module().example_setup()
    estimates = []
    for seed in range(200):
        rec, _ = simulate_servo(gyro, protocol, sample_rate=fs, rng=np.random.default_rng(seed))
        estimates.append(calibrate(rec, speed=protocol.speed).fit.model.params)
    mc = np.std(estimates, axis=0, ddof=1)
    assert np.all(np.abs(printed / mc - 1) < 0.20), printed / mc


@pytest.fixture
def thermal_file(tmp_path):
    """A thermal table whose bias grows 0.01 deg/s per degC, with a 1 % x scale error."""
    from gyrocal.models import Affine
    from gyrocal.results.files import save_thermal
    from gyrocal.thermal import ThermalCalibration, fit_smooth

    temps = np.array([-10.0, 10.0, 30.0, 50.0])
    K = np.diag([1.01, 1.0, 1.0])
    kg = np.array([Affine(K=K, B=np.radians([0.01 * T, 0.0, -0.02 * T])).kg for T in temps])
    tc = ThermalCalibration(temps=temps, kg=kg, smooth=fit_smooth(temps, kg), input_units="deg/s",
                            output_units="deg/s", temp_tau=0.0)
    path = tmp_path / "thermal.json"
    save_thermal(tc, path)
    return path, K


def test_apply_and_export_a_thermal_file(thermal_file, tmp_path):
    path, K = thermal_file
    t = np.arange(400) / 100.0
    temp = np.linspace(0.0, 40.0, len(t))
    true = np.column_stack([np.full_like(t, 30.0), np.zeros_like(t), np.full_like(t, -10.0)])  # deg/s
    raw = true @ K.T + np.column_stack([0.01 * temp, 0 * temp, -0.02 * temp])
    src = _write_csv(tmp_path / "hot.csv", None, np.column_stack([t, raw, temp]), header="t,gx,gy,gz,temp")
    out = tmp_path / "corrected.csv"
    code, _, err = invoke("apply", path, src, "-o", out, "--model", "lagrange")
    assert code == 0, err
    from gyrocal.io import read_recording

    corrected = read_recording(out, units="deg/s")
    assert np.allclose(np.degrees(corrected.gyro), true, atol=1e-9)
    assert np.allclose(corrected.temp, temp)
    src_cold = _write_csv(tmp_path / "cold.csv", None, np.column_stack([t, raw, temp - 40.0]),
                          header="t,gx,gy,gz,temp")
    line = refused("apply", path, src_cold, "-o", tmp_path / "x.csv")
    assert "-10" in line and not (tmp_path / "x.csv").exists()
    assert invoke("apply", path, src_cold, "-o", tmp_path / "x.csv", "--out-of-range", "clamp")[0] == 0
    import yaml

    assert invoke("export", path, "--format", "yaml", "-o", tmp_path / "t.yaml")[0] == 0
    assert yaml.safe_load((tmp_path / "t.yaml").read_text())["format"] == "gyrocal.thermal"
    assert invoke("export", path, "--format", "c-header", "-o", tmp_path / "t.h")[0] == 0
    assert "#" in (tmp_path / "t.h").read_text()


def test_outputs_never_destroy_an_input_or_another_file(servo_csv, tmp_path):
    path, _ = servo_csv
    cal = tmp_path / "cal.json"
    assert invoke("calibrate", path, "--units", "deg/s", "--speed", "60", "-o", cal)[0] == 0
    before = Path(path).read_text()
    assert "also an input" in refused("apply", cal, path, "-o", path, "--force")
    assert "also an input" in refused("calibrate", path, "--units", "deg/s", "--speed", "60", "-o", path, "--force")
    assert Path(path).read_text() == before
    # an earlier apply output may be replaced; a file gyrocal did not write needs --force
    corrected = tmp_path / "corrected.csv"
    assert invoke("apply", cal, path, "-o", corrected)[0] == 0
    assert invoke("apply", cal, path, "-o", corrected)[0] == 0
    notes = tmp_path / "notes.csv"
    notes.write_text("my notes\n")
    assert "--force" in refused("apply", cal, path, "-o", notes)
    assert notes.read_text() == "my notes\n"
    # export: the same text again is fine, something else needs --force
    header = tmp_path / "cal.h"
    assert invoke("export", cal, "--format", "c-header", "-o", header)[0] == 0
    assert invoke("export", cal, "--format", "c-header", "-o", header)[0] == 0
    assert "--force" in refused("export", cal, "--format", "json", "-o", header)
    assert invoke("export", cal, "--format", "json", "-o", header, "--force")[0] == 0


def test_an_output_under_a_file_is_refused_before_anything_is_written(servo_csv, tmp_path):
    path, _ = servo_csv
    (tmp_path / "afile").write_text("x")
    line = refused("calibrate", path, "--units", "deg/s", "--speed", "60", "-o", tmp_path / "afile" / "c.json",
                   "--plot", tmp_path / "p.png")
    assert "is a file, not a folder" in line
    assert not (tmp_path / "p.png").exists()


def test_a_closed_stdout_does_not_cost_the_outputs(tmp_path):
    out, plot = tmp_path / "cal.json", tmp_path / "cal.png"
    proc = subprocess.Popen([sys.executable, "-m", "gyrocal", "calibrate", "--example", "-o", str(out), "--plot", str(plot)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()  # like '| head -0'
    _, err = proc.communicate(timeout=120)
    assert b"Traceback" not in err
    assert load_calibration(out).method == "first-moment" and plot.stat().st_size > 0


def test_declared_reference_accuracy_flags(tmp_path):
    """--speed-sd / --angle-sd: the accuracy enters the 1-sigma and the file says so; mixed with the other
    reference, negative, or with the paper's methods, one line and exit 2. Reference: first-order propagation,
    k is proportional to the speed, so one speed known to 0.1 deg/s in 60 adds exactly (k 0.1 / 60)^2 to each k's
    variance and the same to every pair's covariance."""
    import json

    plain, declared = tmp_path / "plain.json", tmp_path / "declared.json"
    assert invoke("calibrate", "--example", "-o", plain)[0] == 0
    code, out, err = invoke("calibrate", "--example", "--speed-sd", "0.1", "-o", declared)
    assert code == 0, err
    assert "declared accuracy of the speed, 0.1 deg/s, common to every plateau" in out + err
    a, b = json.loads(plain.read_text()), json.loads(declared.read_text())
    k = np.array(b["parameters"]["scale_bias"]["k"])
    sd_a = np.array([a["std"][f"k{c}"] for c in "xyz"])
    sd_b = np.array([b["std"][f"k{c}"] for c in "xyz"])
    np.testing.assert_allclose(sd_b**2, sd_a**2 + (k * 0.1 / 60) ** 2, rtol=1e-6)
    cov_a, cov_b = np.array(a["covariance"]), np.array(b["covariance"])
    np.testing.assert_allclose(cov_b[0, 1] - cov_a[0, 1], k[0] * k[1] * (0.1 / 60) ** 2, rtol=1e-6)
    assert any("declared accuracy" in n for n in b["fit"]["notes"])
    assert "with --speed give --speed-sd" in refused("calibrate", "--example", "--angle-sd", "0.05")
    assert "--speed-sd must be a number >= 0" in refused("calibrate", "--example", "--speed-sd", "-1")
    assert "not --method lm" in refused("calibrate", "--example", "--speed-sd", "0.1", "--method", "lm")
    assert "for turn angles give --angle-sd" in refused("calibrate", "--example", "--angle", "360", "--speed-sd", "1")


def test_a_windows_file_without_turns_is_told_to_add_them(tmp_path):
    """A windows file of static windows only: the refusal points at the file, not at giving one."""
    import json

    assert invoke("simulate", "-o", tmp_path / "s.csv")[0] == 0
    (tmp_path / "w.json").write_text(json.dumps([{"start": 0, "stop": 300, "kind": "static"}]))
    line = refused("calibrate", tmp_path / "s.csv", "--units", "deg/s", "--windows", tmp_path / "w.json")
    assert "add the missing rotation windows to the windows file (--windows)" in line


@pytest.mark.parametrize("speed", ["abc", "60furlongs/s"])
def test_example_with_a_speed_that_is_not_one_is_refused_in_one_line(speed):
    """Reference: the one-line refusal contract (exit 2, no traceback), with the bundled example's own flags."""
    line = refused("calibrate", "--example", "--speed", speed)
    assert "--speed" in line


def test_example_with_a_speed_written_with_its_unit_runs():
    code, out, err = invoke("calibrate", "--example", "--speed", "60deg/s")
    assert code == 0, err
    assert "--speed 60deg/s" in out
