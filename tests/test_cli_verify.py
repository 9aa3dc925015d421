"""``gyrocal verify``, ``gyrocal compare`` and ``gyrocal simulate --reference`` from the command line.

Independent references: the truth sidecar of the simulated pair (clock offset, drift and
mounting rotation the simulation used), the true parameters of the simulated gyros, and
the one-line exit-2 contract for bad input (``cli_runner.refused``).
"""

import json
import math
import subprocess
import sys

import numpy as np
import pytest
from cli_runner import invoke, refused
from verify_pairs import make_pair

from gyrocal import Calibration, ScaleBias
from gyrocal.io import write_recording
from gyrocal.results.files import load, save
from gyrocal.simulation import VirtualGyro, simulate_profile
from gyrocal.simulation.reference import simulate_reference
from gyrocal.simulation.thermal_truth import ThermalTruth
from gyrocal.simulation.truth import SimulationTruth
from gyrocal.thermal import ThermalCalibration, fit_smooth
from gyrocal.verify import VerifyReport

TRUE = ScaleBias(k=(1.0069, 0.9960, 0.9955), b=(0.0442, -0.0089, 0.0076))  # MPU9250 of the servo paper, Table III


@pytest.fixture(scope="module")
def bench(tmp_path_factory):
    """A simulated servo session of the paper's MPU9250, its reference log and a calibration file."""
    folder = tmp_path_factory.mktemp("bench")
    pair = make_pair(np.random.default_rng(21), motion="servo", fs_test=200.0, fs_ref=100.0, noise_test=0.035,
                     noise_ref=0.0005, offset=-2.3, drift=40.0, mounting_deg=12.0, model=TRUE)
    write_recording(folder / "test.csv", pair.test, units="deg/s")
    write_recording(folder / "ref.csv", pair.ref, units="deg/s")
    save(Calibration(model=TRUE, input_units="deg/s", output_units="deg/s", covariance=np.diag([1e-6] * 3 + [1e-8] * 3)),
         folder / "cal.json")
    return folder, pair


def test_verify_writes_the_report_and_finds_the_clock(bench):
    folder, _pair = bench
    code, out, err = invoke("verify", folder / "cal.json", folder / "test.csv", "--reference", folder / "ref.csv",
                            "--ref-units", "deg/s", "-o", folder / "out", "--replicates", "200")
    assert code == 0, err
    assert "Table V" in out and "time_offset_s" in out
    for name in ("verify.json", "summary.md", "before.png", "after.png", "errors.png"):
        assert (folder / "out" / name).exists()
    report = load(folder / "out" / "verify.json")
    assert isinstance(report, VerifyReport)
    a = report.alignment
    assert abs(a.time_offset_s + 2.3) < 4 * a.std[0] and abs(a.clock_drift_ppm - 40.0) < 4 * a.std[1]
    # the true calibration: after calibration only the gyro's own noise (0.035 rad/s) is left
    mse_after = report.metrics.values["mse_after_net"]
    assert np.all(np.abs(mse_after - math.degrees(0.035) ** 2) < 4 * report.metrics.std["mse_after_net"] + 0.05)
    assert np.all(report.metrics.values["reduction_pct"][0] > 50)  # x carries the largest bias


def test_verify_with_a_thermal_table(tmp_path):
    """A thermal gyro at 30 degC checked with its true table: the error after is its noise."""
    truth = ThermalTruth()
    temps = np.array([0.0, 20.0, 40.0, 60.0])
    kg = truth.kg(temps)
    save(ThermalCalibration(temps=temps, kg=kg, smooth=fit_smooth(temps, kg, 2), input_units="deg/s",
                            output_units="deg/s"), tmp_path / "thermal.json")
    rng = np.random.default_rng(8)
    motion = make_pair(rng, duration=40.0).rates
    t = np.arange(len(motion)) / 200.0
    gyro = VirtualGyro(model=TRUE, thermal=truth, noise_std=0.01)
    test, rates = simulate_profile(gyro, (t, motion), duration=39.9, sample_rate=200.0, rng=rng, temp=30.0)
    ref, _ = simulate_reference(test.t, rates, VirtualGyro(model=ScaleBias((1, 1, 1), (0, 0, 0)), noise_std=5e-4),
                                time_offset_s=0.7, mounting_deg=20.0, rng=rng)
    write_recording(tmp_path / "test.csv", test, units="deg/s")
    write_recording(tmp_path / "ref.csv", ref, units="deg/s")
    code, _out, err = invoke("verify", tmp_path / "thermal.json", tmp_path / "test.csv", "--reference",
                            tmp_path / "ref.csv", "--ref-units", "deg/s", "-o", tmp_path / "out", "--no-figures",
                            "--replicates", "100")
    assert code == 0, err
    report = load(tmp_path / "out" / "verify.json")
    assert np.all(np.sqrt(report.metrics.values["mse_after"]) < 1.5 * math.degrees(0.01))


def test_simulate_writes_a_reference_with_its_truth(tmp_path):
    code, _, err = invoke("simulate", "-o", tmp_path / "rec.csv", "--reference", tmp_path / "ref.csv",
                            "--ref-sample-rate", "50", "--ref-offset", "-1.25", "--ref-drift", "30",
                            "--ref-mounting", "7", "--vibration", "0", "--seed", "2")
    assert code == 0, err
    truth = json.loads((tmp_path / "rec.truth.json").read_text())["reference"]
    assert truth["time_offset_s"] == -1.25 and truth["clock_drift_ppm"] == 30.0 and truth["sample_rate"] == 50.0
    assert truth["mounting_rotation_deg"] == pytest.approx(7.0) and truth["path"] == "ref.csv"
    save(Calibration(model=ScaleBias((1, 1, 1), (0, 0, 0)), input_units="deg/s", output_units="deg/s"),
         tmp_path / "cal.json")
    code, _out, err = invoke("verify", tmp_path / "cal.json", tmp_path / "rec.csv", "--reference", tmp_path / "ref.csv",
                            "--ref-units", "deg/s", "-o", tmp_path / "out", "--no-figures", "--replicates", "100")
    assert code == 0, err
    a = load(tmp_path / "out" / "verify.json").alignment
    assert abs(a.time_offset_s + 1.25) < 4 * a.std[0] and abs(a.rotation_deg - 7.0) < 4 * a.rotation_deg_std


def _verify_args(folder, *extra):
    return ("verify", folder / "cal.json", folder / "test.csv", "--reference", folder / "ref.csv", "-o",
            folder / "bad", *extra)


@pytest.mark.parametrize("extra, words", [
    ((), "--ref-units is required"),
    (("--ref-units", "counts"), "--ref-sensitivity"),
    (("--ref-units", "deg/s", "--units", "counts"), "applies to rates in deg/s, not to raw counts; give --units"),
    (("--ref-units", "deg/s", "--stretch", "5"), "--stretch must be two times"),
    (("--ref-units", "deg/s", "--ref-columns", "gx=nope"), "nope"),
])
def test_bad_verify_input_is_one_line(bench, extra, words):
    folder, _ = bench
    line = refused(*_verify_args(folder, *extra))
    assert words in line
    assert not (folder / "bad" / "verify.json").exists()


def test_verify_refuses_static_logs(bench, tmp_path):
    folder, pair = bench
    save(Calibration(model=TRUE, input_units="deg/s", output_units="deg/s"), tmp_path / "cal.json")
    still = type(pair.ref)(t=pair.ref.t, gyro=1e-4 * np.random.default_rng(1).standard_normal(pair.ref.gyro.shape),
                           sample_rate=100.0)
    write_recording(tmp_path / "ref.csv", still, units="deg/s")
    (tmp_path / "test.csv").write_text((folder / "test.csv").read_text())
    assert "no motion to align on" in refused(*_verify_args(tmp_path, "--ref-units", "deg/s"))


def test_verify_names_the_reference_unit_or_its_short_span_not_the_motion(bench, tmp_path):
    """Reference: the simulated pair's truth. The bench's reference written in rad/s but declared deg/s
    is 57.3 times too small (the deg/rad factor), and its first third covers 33 % of the test log; the
    refusals must name --ref-units rad/s and the short reference, not a repeating motion."""
    folder, pair = bench
    (tmp_path / "test.csv").write_text((folder / "test.csv").read_text())
    save(Calibration(model=TRUE, input_units="deg/s", output_units="deg/s"), tmp_path / "cal.json")
    write_recording(tmp_path / "ref.csv", pair.ref, units="rad/s")
    line = refused(*_verify_args(tmp_path, "--ref-units", "deg/s", "--no-figures"))
    assert "57." in line and "times smaller" in line and "give --ref-units rad/s" in line and "repeats" not in line
    third = type(pair.ref)(t=pair.ref.t[:len(pair.ref.t) // 3], gyro=pair.ref.gyro[:len(pair.ref.t) // 3],
                           sample_rate=100.0)
    write_recording(tmp_path / "ref.csv", third, units="deg/s")
    line = refused(*_verify_args(tmp_path, "--ref-units", "deg/s", "--no-figures"))
    assert "the reference log covers only 33 % of the test log" in line and "repeats" not in line
    assert not (tmp_path / "bad").exists()


def test_a_rerun_replaces_the_whole_report_or_none_of_it(bench, tmp_path, monkeypatch):
    """Reference: the list of files a run writes (``wrote ...``). After a run with figures, a run with
    --no-figures leaves exactly verify.json and summary.md of gyrocal's names (a file of the user's
    stays); a run that fails while drawing leaves the previous report byte for byte, and no temporary."""
    import gyrocal.plotting.verify as drawing
    from gyrocal.errors import InputError

    folder, _ = bench
    out = tmp_path / "out"
    args = ("verify", folder / "cal.json", folder / "test.csv", "--reference", folder / "ref.csv", "--ref-units",
            "deg/s", "-o", out, "--replicates", "50")
    code, stdout, err = invoke(*args)
    assert code == 0 and {p.name for p in out.iterdir()} == {"verify.json", "summary.md", "before.png", "after.png",
                                                             "errors.png"}, err
    (out / "mine.png").write_text("the user's own")
    code, stdout, err = invoke(*args, "--no-figures", "--seed", "1")
    assert code == 0 and f"wrote {out / 'verify.json'}, {out / 'summary.md'}\n" in stdout, err
    assert sorted(p.name for p in out.iterdir()) == ["mine.png", "summary.md", "verify.json"]
    assert invoke(*args)[0] == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}

    def broken(*a, **k):
        raise InputError("a figure that cannot be drawn")

    monkeypatch.setattr(drawing, "error_figure", broken)
    assert "a figure that cannot be drawn" in refused(*args, "--seed", "2")
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before


def test_verify_needs_a_calibration_file(bench, tmp_path):
    folder, _ = bench
    save(SimulationTruth(protocol="servo", model=TRUE), tmp_path / "truth.json")
    line = refused("verify", tmp_path / "truth.json", folder / "test.csv", "--reference", folder / "ref.csv",
                   "--ref-units", "deg/s", "-o", tmp_path / "out")
    assert "expected 'gyrocal.calibration' or 'gyrocal.thermal'" in line


def test_compare_is_a_production_check(tmp_path):
    cov = np.diag([1e-6] * 3 + [1e-8] * 3)
    save(Calibration(model=TRUE, covariance=cov), tmp_path / "a.json")
    save(Calibration(model=ScaleBias(TRUE.k + [0, 5e-3, 0], TRUE.b), covariance=cov), tmp_path / "b.json")
    code, out, err = invoke("compare", tmp_path / "a.json", tmp_path / "b.json")
    assert code == 0, err
    assert "ky" in out and "+3.54" in out
    code, out, _ = invoke("compare", tmp_path / "a.json", tmp_path / "b.json", "--tolerance", "3")
    assert code == 1 and "OUTSIDE 3 sigma" in out
    code, out, _ = invoke("compare", tmp_path / "a.json", tmp_path / "b.json", "--tolerance", "4")
    assert code == 0 and "within 4 sigma" in out


def test_bad_compare_input_is_one_line(tmp_path):
    save(Calibration(model=TRUE), tmp_path / "a.json")
    assert "at least two files" in refused("compare", tmp_path / "a.json")
    assert "no 1-sigma" in refused("compare", tmp_path / "a.json", tmp_path / "a.json", "--tolerance", "3")
    (tmp_path / "junk.json").write_text("{}")
    assert "format" in refused("compare", tmp_path / "a.json", tmp_path / "junk.json")


@pytest.mark.parametrize("args, words", [
    (("--ref-offset", "1"), "--ref-offset describes the reference log"),
    (("--reference", "REF", "--protocol", "turntable"), "--reference does not apply"),
    (("--reference", "REF", "--ref-noise", "-1"), "--ref-noise must be finite and >= 0"),
    (("--reference", "REF", "--ref-mounting", "400"), "--ref-mounting must be in [0, 180] deg"),
    (("--reference", "REF", "--ref-sample-rate", "0"), "--ref-sample-rate must be finite and > 0"),
])
def test_bad_simulate_reference_is_one_line(tmp_path, args, words):
    args = tuple(str(tmp_path / "ref.csv") if a == "REF" else a for a in args)
    assert words in refused("simulate", "-o", tmp_path / "rec.csv", *args)
    assert not (tmp_path / "ref.csv").exists()


def test_installed_entry_point_exits_1_outside_the_tolerance(tmp_path):
    cov = np.diag([1e-6] * 3 + [1e-8] * 3)
    save(Calibration(model=TRUE, covariance=cov), tmp_path / "a.json")
    save(Calibration(model=ScaleBias(TRUE.k, TRUE.b + [0.001, 0, 0]), covariance=cov), tmp_path / "b.json")
    proc = subprocess.run([sys.executable, "-m", "gyrocal", "compare", str(tmp_path / "a.json"),
                           str(tmp_path / "b.json"), "--tolerance", "3"], capture_output=True, text=True, timeout=120,
                          check=False)
    assert proc.returncode == 1, proc.stderr
    assert "OUTSIDE 3 sigma" in proc.stdout and "bx" in proc.stdout


def test_bundled_example_verifies_against_its_truth(tmp_path):
    """The bundled testing period and reference log: the clock and mounting in the sidecar come back."""
    from importlib import resources

    truth = json.loads((resources.files("gyrocal") / "data" / "example_servo_repeat.truth.json").read_text())
    save(Calibration(model=ScaleBias(truth["k"], truth["b"]), input_units="deg/s", output_units="deg/s"),
         tmp_path / "cal.json")
    code, out, err = invoke("verify", tmp_path / "cal.json", "--example", "-o", tmp_path / "out", "--no-figures",
                            "--replicates", "100")
    assert code == 0, err
    assert "same as: gyrocal verify" in out
    a = load(tmp_path / "out" / "verify.json").alignment
    ref = truth["reference"]
    assert abs(a.time_offset_s - ref["time_offset_s"]) < 4 * a.std[0]
    assert abs(a.clock_drift_ppm - ref["clock_drift_ppm"]) < 4 * a.std[1]
    assert abs(a.rotation_deg - ref["mounting_rotation_deg"]) < 4 * a.rotation_deg_std
    assert "not both" in refused("verify", tmp_path / "cal.json", "x.csv", "--example", "-o", tmp_path / "o2")


def test_reference_reading_errors_name_the_ref_flags(bench, tmp_path):
    """A reference in deg/s declared as rad/s: the reader's hint names --ref-units and --ref-no-unit-check."""
    folder, _ = bench
    line = refused(*_verify_args(folder, "--ref-units", "rad/s"))
    assert "use --ref-units deg/s (or --ref-no-unit-check)" in line


def test_readme_shows_what_its_verify_commands_print(tmp_path):
    """README's 'Proof on the bench' runs two commands and shows their Table V and alignment. Reference: the
    summary.md those same commands write now (the example and its bootstrap are seeded), so a change that
    moves a figure must re-measure README too."""
    from pathlib import Path

    readme = (Path(__file__).resolve().parent.parent / "README.md").read_text(encoding="utf-8")
    section = readme[readme.index("## Proof on the bench"):]
    section = section[:section.index("\n## ", 1)]
    assert invoke("calibrate", "--example", "-o", tmp_path / "cal.json")[0] == 0
    code, _, err = invoke("verify", tmp_path / "cal.json", "--example", "-o", tmp_path / "verify", "--no-figures")
    assert code == 0, err
    summary = (tmp_path / "verify" / "summary.md").read_text(encoding="utf-8")
    rows = [line for line in summary.splitlines() if line[:4] in ("| x ", "| y ", "| z ")][:3]  # Table V rows
    assert len(rows) == 3
    for row in rows:
        assert row in section, f"README's Table V lacks {row!r}"
    for label, words in (("time offset", "offset {} s"), ("clock drift", "drift {} ppm"),
                         ("mounting rotation angle", "mounting {}°")):
        line = next(ln for ln in summary.splitlines() if ln.startswith(f"| {label}"))
        value = line.split("|")[2].strip().rsplit(" ", 1)[0]  # '-1.82951 ± 0.00073'
        assert words.format(value.replace("-", "−")) in section, f"README lacks {label} {value}"
