"""``gyrocal thermal`` and ``gyrocal thermal-report``, in process and once through the installed entry point.

References: the simulated thermal truth and the files the commands write.
"""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from gyrocal.cli import run
from gyrocal.io import write_csv
from gyrocal.simulation.thermal_truth import ThermalTruth
from gyrocal.simulation.turntable import TurntableProtocol, simulate_turntable

RATES = (0.0, 1.0, 50.0, 200.0, 400.0)


def _write(rec, path, drop=None, **extra):
    d = np.degrees(rec.gyro)
    cols = {"t": rec.t, "gx": d[:, 0], "gy": d[:, 1], "gz": d[:, 2], "temp": rec.temp,
            "table_rate": np.degrees(rec.table_rate), "axis": rec.axis}
    for name in drop or ():
        del cols[name]
    write_csv(path, cols)
    return path


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    rng = np.random.default_rng(3004)
    root = tmp_path_factory.mktemp("thermal")
    gyro = ThermalTruth().gyro(np.radians(0.05), full_scale=np.radians(300.0))
    proto = {"rates": RATES, "step_duration": 3.0}
    session = simulate_turntable(gyro, TurntableProtocol(temps=(-20.0, 0.0, 20.0, 40.0), **proto), sample_rate=50.0,
                                 rng=rng)
    test = simulate_turntable(gyro, TurntableProtocol(temps=(-15.0, 35.0), **proto), sample_rate=50.0, rng=rng)
    two_axes = simulate_turntable(gyro, TurntableProtocol(temps=(0.0, 10.0, 20.0), axes=("x", "y"), **proto),
                                  sample_rate=50.0, rng=rng)
    return {"session": _write(session, root / "session.csv"), "test": _write(test, root / "test.csv"),
            "no_temp": _write(test, root / "no_temp.csv", drop=["temp"]),
            "two_axes": _write(two_axes, root / "two_axes.csv"), "root": root}


def test_thermal_then_report(files, tmp_path, capsys, monkeypatch):
    from gyrocal.cli.app import console

    monkeypatch.setattr(console, "_width", 80)  # piped output: both tables must fit
    out = tmp_path / "thermal.json"
    assert run(["thermal", str(files["session"]), "--units", "deg/s", "-o", str(out), "--full-scale", "300",
                "--settle", "1"]) == 0
    captured = capsys.readouterr()
    assert "warning:" in captured.err and "saturated" in captured.err and "+400 deg/s" in captured.err
    doc = json.loads(out.read_text())
    assert doc["format"] == "gyrocal.thermal" and doc["units"]["input"] == "deg/s"
    assert [p["temp"] for p in doc["points"]] == [-20.0, 0.0, 20.0, 40.0]
    # Every point's row ends with its largest std of scale factors, misalignments and biases [deg/s].
    assert "sd mis" in captured.out and "sd B" in captured.out
    for p in doc["points"]:
        std = np.array(p["std"])
        row = [line for line in captured.out.splitlines() if line.split()[:1] == [f"{p['temp']:.1f}"]][-1]
        assert row.split()[-3:] == [f"{v:.1e}" for v in (std[:3].max(), std[3:9].max(), np.degrees(std[9:]).max())]
    rep = tmp_path / "report"
    assert run(["thermal-report", str(out), str(files["test"]), "-o", str(rep), "--settle", "1",
                "--full-scale", "300"]) == 0
    for name in ("summary.md", "summary.csv", "coefficients.png", "error_vs_rate.png", "error_vs_temperature.png"):
        assert (rep / name).stat().st_size > 0
    assert "lagrange" in capsys.readouterr().out
    # again without figures: the first run's figures would not match the new tables, so they go; a user's file stays
    (rep / "notes.txt").write_text("mine")
    assert run(["thermal-report", str(out), str(files["test"]), "-o", str(rep), "--settle", "1",
                "--full-scale", "300", "--no-figures"]) == 0
    assert not list(rep.glob("*.png")) and (rep / "notes.txt").read_text() == "mine"


def test_thermal_bad_session_is_one_line_exit_2(files, tmp_path, capsys):
    assert run(["thermal", str(files["two_axes"]), "--units", "deg/s", "-o", str(tmp_path / "t.json"),
                "--settle", "1", "--full-scale", "300"]) == 2
    err = capsys.readouterr().err
    assert "2 position(s) (x, y)" in err and "Traceback" not in err
    assert not (tmp_path / "t.json").exists()


def test_report_without_temp_column_is_refused(files, tmp_path, capsys):
    out = tmp_path / "thermal.json"
    assert run(["thermal", str(files["session"]), "--units", "deg/s", "-o", str(out), "--full-scale", "300",
                "--settle", "1"]) == 0
    assert run(["thermal-report", str(out), str(files["no_temp"]), "-o", str(tmp_path / "r"), "--no-figures"]) == 2
    assert "temp" in capsys.readouterr().err


def test_installed_entry_point(files, tmp_path):
    exe = Path(sys.executable).with_name("gyrocal")
    out = tmp_path / "thermal.json"
    proc = subprocess.run([str(exe), "thermal", str(files["session"]), "--units", "deg/s", "-o", str(out),
                           "--full-scale", "300", "--settle", "1"], capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(out.read_text())["version"] == 2


def test_report_outside_the_calibrated_range_names_the_flag(files, tmp_path, capsys):
    out = tmp_path / "thermal.json"
    assert run(["thermal", str(files["session"]), "--units", "deg/s", "-o", str(out), "--full-scale", "300",
                "--settle", "1", "--temp-tolerance", "1"]) == 0
    doc = json.loads(out.read_text())
    doc["points"] = doc["points"][1:]  # calibrated from 0 degC up; the test holds -15 degC
    out.write_text(json.dumps(doc))
    assert run(["thermal-report", str(out), str(files["test"]), "-o", str(tmp_path / "r"), "--no-figures",
                "--settle", "1", "--full-scale", "300"]) == 2
    assert "-15.00 degC; set --out-of-range to 'clamp'" in capsys.readouterr().err


def test_thermal_output_is_replaced_only_when_the_same_or_forced(files, tmp_path, capsys):
    out = tmp_path / "thermal.json"
    args = ["thermal", str(files["session"]), "--units", "deg/s", "-o", str(out), "--full-scale", "300", "--settle", "1"]
    assert run(args) == 0 and run(args) == 0  # the same table again
    before = out.read_text()
    capsys.readouterr()
    assert run(args + ["--ref-temp", "0"]) == 2
    assert "different calibration" in capsys.readouterr().err and out.read_text() == before
    assert run(args + ["--ref-temp", "0", "--force"]) == 0
    assert run(["thermal", str(files["session"]), "--units", "deg/s", "-o", str(files["session"]), "--force"]) == 2
    assert "also an input" in capsys.readouterr().err
