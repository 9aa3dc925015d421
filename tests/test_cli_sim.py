"""The ``simulate``, ``noise``, ``plan`` and ``study`` commands, in-process and once as a subprocess.

References: the truth sidecar (the simulator's own parameters) against what calibrate recovers, and the
numbers of samples, rates and temperatures the flags ask for.
"""

import json
import math
import subprocess
import sys

import numpy as np
import pytest
from cli_runner import invoke, refused  # noqa: E402

from gyrocal import load_calibration  # noqa: E402
from gyrocal.io import read_recording  # noqa: E402
from gyrocal.noise.document import load_noise  # noqa: E402


def test_simulated_recording_travels_the_calibration_path(tmp_path):
    rec = tmp_path / "rec.csv"
    code, out, err = invoke("simulate", "-o", rec, "--k", "1.02,0.97,1.01", "--b", "0.03,-0.02,0.01",
                            "--noise", "0.02", "--seed", "4")
    assert code == 0, err
    truth = json.loads((tmp_path / "rec.truth.json").read_text())
    assert truth["format"] == "gyrocal.simulation-truth" and truth["k"] == [1.02, 0.97, 1.01]
    assert len(truth["windows"]) >= 6
    code, out, err = invoke("calibrate", rec, "--units", "deg/s", "-o", tmp_path / "cal.json")
    assert code == 0, err
    cal = load_calibration(tmp_path / "cal.json")
    err_k = cal.model.k - np.array(truth["k"])
    err_b = cal.model.b - np.array(truth["b"])
    std = cal.std
    assert np.all(np.abs(np.concatenate([err_k, err_b])) < 4 * std), (err_k, err_b, std)


def test_simulate_turntable_and_profile(tmp_path):
    code, _, err = invoke("simulate", "-o", tmp_path / "tt.csv", "--protocol", "turntable", "--sample-rate", "5")
    assert code == 0, err
    rec = read_recording(tmp_path / "tt.csv", units="deg/s")
    assert rec.temp is not None and rec.table_rate is not None and set(rec.axis) == {"x", "y", "z"}
    prof = tmp_path / "profile.csv"
    prof.write_text("t,wx,wy,wz\n0,0,0,0\n10,1,0,0\n")
    code, _, err = invoke("simulate", "-o", tmp_path / "p.csv", "--protocol", "profile", "--profile", prof,
                          "--duration", "10", "--noise", "0", "--units", "rad/s")
    assert code == 0, err
    rec = read_recording(tmp_path / "p.csv", units="rad/s")
    np.testing.assert_allclose(rec.gyro[:, 0], rec.t / 10, atol=1e-12)  # k = 1, b = 0, no noise
    assert "--profile" in refused("simulate", "-o", tmp_path / "q.csv", "--protocol", "profile")


def test_simulate_turntable_flags_shape_the_session(tmp_path):
    out = tmp_path / "tt.csv"
    code, _, err = invoke("simulate", "-o", out, "--protocol", "turntable", "--temps", "-10,30", "--rates", "0,20",
                          "--step-duration", "1", "--sample-rate", "20", "--temp-noise", "0.5", "--temp-quantum", "1",
                          "--seed", "3")
    assert code == 0, err
    rec = read_recording(out, units="deg/s")
    assert len(rec) == 2 * 3 * 3 * 20  # temps x positions x (0, +20, -20) x samples per step
    assert set(np.round(np.degrees(rec.table_rate), 9)) == {0.0, 20.0, -20.0}  # read back in rad/s
    assert np.all(rec.temp == np.round(rec.temp))  # whole degrees
    first, second = rec.temp[: len(rec) // 2], rec.temp[len(rec) // 2:]
    assert np.all(np.abs(first + 10) <= 3) and np.all(np.abs(second - 30) <= 3)
    assert 0.3 < np.std(first) < 0.8  # 0.5 degC noise, rounded to 1 degC: ~0.58
    settings = json.loads((tmp_path / "tt.truth.json").read_text())["settings"]
    assert settings["temps_degC"] == [-10.0, 30.0] and settings["rates_deg_s"] == [0.0, 20.0]
    step_s = settings["step_duration_s"]  # the simulated step length, not a timing
    assert step_s == 1.0 and settings["temp_quantum_degC"] == 1.0
    line = refused("simulate", "-o", out, "--protocol", "turntable", "--speed", "30")
    assert "--speed" in line and "turntable" in line
    assert "--temps" in refused("simulate", "-o", out, "--temps", "0,10")
    assert "--temp-quantum" in refused("simulate", "-o", out, "--protocol", "turntable", "--temp-quantum", "0")


def test_noise_command_writes_json_and_plot(tmp_path, rng, monkeypatch):
    from gyrocal.cli.app import console

    monkeypatch.setattr(console, "_width", 80)
    static = tmp_path / "static.csv"
    m = rng.standard_normal((30000, 3)) * 0.01
    np.savetxt(static, np.column_stack([np.arange(30000) / 100.0, m]), delimiter=",", header="t,gx,gy,gz",
               comments="")
    code, out, err = invoke("noise", static, "--units", "rad/s", "--json", tmp_path / "n.json", "--plot",
                            tmp_path / "a.png")
    assert code == 0, err
    assert "bias inst." in out and "\u2026" not in out  # no header cut at 80 columns
    report = load_noise(tmp_path / "n.json")
    # ARW at short tau from 30,000 samples: relative sd well below 1 %
    np.testing.assert_allclose(report.density, 0.01 / math.sqrt(100.0), rtol=0.03)
    assert (tmp_path / "a.png").stat().st_size > 0
    assert "--units" in refused("noise", static)
    code, out, err = invoke("plan", "--noise-density", tmp_path / "n.json", "--sample-rate", "100")
    assert code == 0 and "as given" in out, err


def test_plan_prints_prediction_and_suggestion():
    code, out, err = invoke("plan", "--speed", "60", "--noise", "0.035", "--target-scale", "5e-4",
                            "--target-bias", "0.03deg/s")
    assert code == 0, err
    assert "as given" in out and "suggested" in out
    assert "--target-bias" in refused("plan", "--target-bias", "fast")
    assert "not both" in refused("plan", "--noise", "0.1", "--noise-density", "0.001")


def test_study_command_with_progress(tmp_path):
    code, out, err = invoke("study", "servo-convergence", "-o", tmp_path, "--reps", "5")
    assert code == 0, err
    assert (tmp_path / "convergence.md").exists() and "wrote" in out
    assert "servo-speed" in refused("study", "servo-normal", "-o", tmp_path, "--methods", "lm")
    assert "--gyros" in refused("study", "servo-normal", "-o", tmp_path, "--gyros", "0")


def test_study_flags_are_used_or_refused(tmp_path):
    code, out, err = invoke("study", "thermal-compare", "-o", tmp_path, "--gyros", "1", "--reps", "1",
                            "--sample-rate", "20", "--noise-density", "0.001")
    assert code == 0, err
    assert "1/1" in out  # the progress bar ends full
    # 0.001 rad/s/sqrt(Hz) at 20 Hz, averaged over (10 s - 2 s settle) x 20 Hz samples per step
    floor = math.degrees(0.001 * math.sqrt(20)) / math.sqrt(8 * 20)
    assert f"noise floor of a step mean {floor:.3g}" in " ".join(out.split())  # the summary wraps
    line = refused("study", "servo-convergence", "-o", tmp_path, "--gyros", "2")
    assert "--gyros" in line and "servo-convergence" in line
    assert "--speed" in refused("study", "thermal-compare", "-o", tmp_path, "--speed", "30")


def test_installed_entry_point_runs_a_study(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "gyrocal", "study", "servo-normal", "-o", str(tmp_path),
                           "--gyros", "2", "--reps", "20"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "errors.png").exists()


def test_profile_from_callable_and_from_table(rng):
    from gyrocal.errors import InputError
    from gyrocal.models import ScaleBias
    from gyrocal.simulation import VirtualGyro
    from gyrocal.simulation.profiles import simulate_profile

    gyro = VirtualGyro(ScaleBias([2.0, 1.0, 1.0], [0.1, 0.0, 0.0]))  # m = w / k - b, noise-free
    rec, w = simulate_profile(gyro, lambda t: np.column_stack([np.sin(t), 0 * t, 0 * t]), duration=2.0,
                              sample_rate=50.0, rng=rng)
    np.testing.assert_allclose(rec.gyro[:, 0], np.sin(rec.t) / 2 - 0.1, atol=1e-12)
    rec, w = simulate_profile(gyro, (np.array([0.0, 4.0]), np.array([[0, 0, 0], [0, 4.0, 0]])), duration=2.0,
                              sample_rate=10.0, rng=rng, temp=25.0)
    np.testing.assert_allclose(w[:, 1], rec.t)
    assert np.all(rec.temp == 25.0)
    with pytest.raises(InputError, match="covers"):
        simulate_profile(gyro, (np.array([0.0, 1.0]), np.zeros((2, 3))), duration=2.0, rng=rng)


def test_help_keeps_the_units_written_in_brackets():
    """Help texts give units as [degC]; rich markup would swallow them as tags (rates say 'deg/s unless a unit
    is written' instead)."""
    code, out, _ = invoke("simulate", "--help")
    assert code == 0
    for text in ("[rad/s/degC^n]", "[degC]", "[m/s^2/sqrt(Hz)]"):
        assert text in out
    code, out, _ = invoke("calibrate", "--help")
    assert code == 0 and "[Hz]" in out


def test_outputs_replace_only_their_own_kind(tmp_path):
    rec = tmp_path / "rec.csv"
    assert invoke("simulate", "-o", rec, "--sample-rate", "20")[0] == 0
    assert invoke("simulate", "-o", rec, "--sample-rate", "20", "--seed", "1")[0] == 0  # an earlier simulation
    notes = tmp_path / "notes.csv"
    notes.write_text("mine\n")
    assert "--force" in refused("simulate", "-o", notes, "--sample-rate", "20")
    assert notes.read_text() == "mine\n"
    before = rec.read_text()
    assert "also an input" in refused("noise", rec, "--units", "deg/s", "--json", rec)
    assert rec.read_text() == before
    assert "is a file; give a folder" in refused("study", "servo-normal", "-o", notes, "--gyros", "1", "--reps", "2")
