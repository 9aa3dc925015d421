"""The station's flags (--unit, --limits, --store) on every command that writes a result besides calibrate.

Each of ``imu``, ``thermal``, ``noise`` and ``thermal-bias`` runs on a small simulated input with a unit,
hand-made limits and a real SQLite store: once with loose limits (exit 0, the file written) and once with
tight ones and no output file (exit 1, nothing on disk, the record still holding the document).

References: the input's SHA-256 from hashlib over its bytes; each criterion's value, 1-sigma and margin
worked by hand from the result file's own fields and the limit (ISO 14253-1: value +- guard x sigma
inside the bounds); the store read back through :func:`gyrocal.store.open_store`.
"""

from __future__ import annotations

import hashlib
import json
import math

import pytest
from cli_runner import invoke, refused, simulated
from thermal_sessions import thermal_session

from gyrocal.store import open_store

DEG = math.pi / 180


def _sha(path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    d = tmp_path_factory.mktemp("station")
    return {
        "imu": simulated(d / "hand.csv", "--protocol", "multi-position", "--poses", "12", "--still", "2",
                         "--sample-rate", "50", "--noise", "0.002", "--k", "1.01,0.99,1.02", "--seed", "5"),
        "noise": simulated(d / "rest.csv", "--protocol", "static", "--duration", "300", "--sample-rate", "50",
                           "--noise", "0.005", "--units", "rad/s", "--seed", "5"),
        "thermal-bias": simulated(d / "warm.csv", "--protocol", "static", "--duration", "1200", "--sample-rate",
                                  "20", "--noise", "0.005", "--temp-start", "-5", "--temp-end", "50",
                                  "--warmup-tau", "300", "--temp-quantum", "1", "--bias-tempco",
                                  "2e-4,-1e-4,5e-5;-3e-6,0,2e-6;5e-8,0,0", "--seed", "3"),
        "thermal": thermal_session(d / "thermal.csv"),
    }


def _kx(doc):
    """kx of the whole-IMU gyro (diagonal of K) and its 1-sigma, from the file."""
    return doc["parameters"]["affine"]["K"][0][0], doc["std"]["Kxx"]


def _density_x(doc):
    """x density [deg/s/rtHz] and half its interval as the 1-sigma, from the noise file."""
    fig = doc["gyroscope"]["x"]["density"]
    return fig["value"] / DEG, (fig["high"] - fig["low"]) / 2 / DEG


def _largest_residual(doc):
    """Largest residual RMS of the temperature points [deg/s], no 1-sigma."""
    return max(max(p["residual_rms"]) for p in doc["points"]) / DEG, 0.0


def _bias_x(doc):
    """The calibration's bias of x [deg/s]: minus the fitted bias at tref, with that term's 1-sigma."""
    ax = doc["axes"]["x"]
    return -ax["coefs"][0] / DEG, math.sqrt(ax["covariance"][0][0]) / DEG


#: command -> (its arguments before the flags, output flag, loose limits, tight limits, the first criterion's
#: name, and how to read its value and 1-sigma from the file in the limit's unit)
CASES = {
    "imu": (["--units", "deg/s", "--accel-units", "m/s^2"], "-o",
            "[limits.k]\nmin = 0.9\nmax = 1.1\n", "[limits.k]\nmin = 0.999\nmax = 1.001\n", "kx", _kx),
    "thermal": (["--units", "deg/s", "--settle", "1"], "-o",
                '[limits.thermal_residual]\nmax = 0.1\nunit = "deg/s"\n',
                '[limits.thermal_residual]\nmax = 0.001\nunit = "deg/s"\n', "thermal_residual", _largest_residual),
    "noise": (["--units", "rad/s"], "--json",
              '[limits.noise_density]\nmax = 1\nunit = "deg/s/rtHz"\n',
              '[limits.noise_density]\nmax = 0.01\nunit = "deg/s/rtHz"\n', "noise_density_x", _density_x),
    "thermal-bias": (["--units", "deg/s"], "-o",
                     '[limits.b]\nmax_abs = 1\nunit = "deg/s"\n[limits.thermal_residual]\nmax = 0.1\nunit = "deg/s"\n',
                     '[limits.b]\nmax_abs = 0.001\nunit = "deg/s"\n', "bx", _bias_x),
}


@pytest.mark.parametrize("command", list(CASES))
def test_unit_limits_and_store(command, inputs, tmp_path):
    args, out_flag, loose, tight, first, reference = CASES[command]
    source = inputs[command]
    store = tmp_path / "station.db"
    (tmp_path / "loose.toml").write_text("guard = 2\n" + loose)
    (tmp_path / "tight.toml").write_text("guard = 2\n" + tight)
    out = tmp_path / "result.json"
    code, stdout, err = invoke(command, source, *args, out_flag, out, "--unit", "SN-23", "--station", "bench-2",
                               "--procedure", f"{command}@1", "--limits", tmp_path / "loose.toml", "--store", store)
    assert code == 0, (stdout, err)
    assert "stored as record 1 in" in stdout and stdout.rstrip().endswith("SN-23: PASS")
    doc = json.loads(out.read_text())
    unit = doc["unit"]
    assert unit["serial"] == "SN-23" and unit["station"] == "bench-2"
    assert unit["procedure"] == {"name": command, "version": "1"}
    assert unit["inputs"] == [{"file": source.name, "sha256": _sha(source)}]
    acc = doc["acceptance"]
    assert acc["verdict"] == "pass" and all(c["verdict"] == "pass" for c in acc["criteria"])
    c = acc["criteria"][0]
    value, sigma = reference(doc)
    assert c["name"] == first and c["value"] == pytest.approx(value, rel=1e-9)
    assert c["sigma"] == pytest.approx(sigma, rel=1e-9, abs=1e-15)
    assert c["margin"] == pytest.approx(min(value - 2 * sigma - (c["low"] if c["low"] is not None else -math.inf),
                                            c["high"] - value - 2 * sigma), rel=1e-9)

    # tight limits, no output file: exit 1, nothing written, the record holds the whole document
    code, stdout, err = invoke(command, source, *args, *(["-o", tmp_path / "fail.json"] if command == "thermal" else []),
                               "--unit", "SN-23", "--limits", tmp_path / "tight.toml", "--store", store)
    assert code == 1, (stdout, err)
    assert "stored as record 2 in" in stdout and f"SN-23: FAIL ({first}" in stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["loose.toml", "tight.toml", "result.json", "station.db"] + (["fail.json"] if command == "thermal" else []))
    with open_store(store) as st:
        new, old = st.history("SN-23")
    assert (old.kind, old.serial, old.verdict, old.station, old.input_sha256) == (command, "SN-23", "pass", "bench-2",
                                                                                 _sha(source))
    assert old.document == doc and old.job == command
    assert (new.kind, new.verdict, new.input_sha256) == (command, "fail", _sha(source))
    failed = new.document["acceptance"]
    assert failed["verdict"] == "fail" and failed["criteria"][0]["name"] == first
    assert failed["criteria"][0]["value"] == pytest.approx(value, rel=1e-6)  # the same fit, judged again
    assert new.document["format"] == doc["format"] and new.document["unit"]["serial"] == "SN-23"


def test_results_with_a_unit_still_load_and_export(inputs, tmp_path):
    """The added sections do not stop the files' own readers: apply, thermal-report, export, --noise-density."""
    files = {}
    for command, (args, out_flag, *_) in CASES.items():
        files[command] = tmp_path / f"{command}.json"
        code, _, err = invoke(command, inputs[command], *args, out_flag, files[command], "--unit", "SN-9")
        assert code == 0, err
    assert invoke("apply", files["imu"], inputs["imu"], "-o", tmp_path / "corrected.csv")[0] == 0
    assert invoke("thermal-report", files["thermal"], inputs["thermal"], "-o", tmp_path / "report", "--settle", "1",
                  "--no-figures")[0] == 0
    assert invoke("export", files["thermal-bias"], "--format", "ardupilot", "-o", tmp_path / "tc.parm")[0] == 0
    from gyrocal.noise.document import load_noise

    assert load_noise(files["noise"]).sample_rate == 50.0


def test_a_session_folder_records_each_file_it_read(inputs, tmp_path):
    folder = tmp_path / "session"
    folder.mkdir()
    part = folder / "part1.csv"
    part.write_bytes(inputs["thermal"].read_bytes())
    (folder / "README.md").write_text("not a recording")
    out = tmp_path / "thermal.json"
    code, _, err = invoke("thermal", folder, "--units", "deg/s", "--settle", "1", "-o", out, "--unit", "SN-5")
    assert code == 0, err
    assert json.loads(out.read_text())["unit"]["inputs"] == [{"file": "part1.csv", "sha256": _sha(part)}]


@pytest.mark.parametrize("command", list(CASES))
def test_station_flags_are_checked_before_reading(command, tmp_path):
    """Refused in one line before the (missing) input is read."""
    missing = tmp_path / "none.csv"
    extra = ["-o", tmp_path / "t.json"] if command == "thermal" else []
    assert "--store keeps records per unit" in refused(command, missing, "--units", "deg/s", *extra, "--store",
                                                       tmp_path / "s.db")
    assert "limits file" in refused(command, missing, "--units", "deg/s", *extra, "--unit", "SN-1", "--limits",
                                    tmp_path / "none.toml")
    assert not (tmp_path / "s.db").exists()
