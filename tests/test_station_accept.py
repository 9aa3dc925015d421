"""Acceptance limits with a guard band (ISO 14253-1), unit identity, and the commands that use them.

References: margins and verdicts worked by hand from value, 1-sigma and bound; the SHA-256 of the
input from hashlib over the file's bytes; the ISO 14253-1 rule itself (conformance is proved when
value +- guard x sigma lies inside the specification).
"""

import hashlib
import json
import math
import re

import pytest
from cli_runner import invoke, refused

from gyrocal.errors import InputError
from gyrocal.station.accept import accept
from gyrocal.station.identity import Identity, check_serial
from gyrocal.station.limits import read_limits

DEG = math.pi / 180


def _doc(k=(1.0, 1.0, 1.0), b=(0.0, 0.0, 0.0), sk=1e-3, sb=1e-4, p=0.5):
    std = {f"k{a}": sk for a in "xyz"} | {f"b{a}": sb for a in "xyz"}
    return {"format": "gyrocal.calibration", "units": {"internal": "rad/s"},
            "parameters": {"scale_bias": {"k": list(k), "b": list(b)}}, "std": std, "fit": {"p_value": p}}


def _limits(tmp_path, text):
    path = tmp_path / "limits.toml"
    path.write_text(text)
    return read_limits(path)


def test_guard_band_margin_and_verdict_by_hand(tmp_path):
    """kx = 1.006 +- 0.002 with guard 2 reaches 1.010: on the bound (margin 0, pass); ky = 1.0061 just over."""
    lim = _limits(tmp_path, "guard = 2\n[limits.k]\nmin = 0.99\nmax = 1.01\n")
    result = accept(_doc(k=(1.006, 1.0061, 0.985), sk=0.002), lim)
    kx, ky, kz = result.criteria
    assert kx.margin == pytest.approx(0.0, abs=1e-12) and kx.passed
    assert ky.margin == pytest.approx(-1e-4, rel=1e-6) and not ky.passed
    assert kz.margin == pytest.approx(0.985 - 0.004 - 0.99) and not kz.passed  # below the lower bound
    assert result.verdict == "fail" and result.failures() == ["ky", "kz"]


def test_without_guard_the_bound_alone_decides(tmp_path):
    lim = _limits(tmp_path, "guard = 0\n[limits.k]\nmin = 0.99\nmax = 1.01\n")
    assert accept(_doc(k=(1.0099, 1.0, 1.0), sk=0.01), lim).passed


def test_bias_in_the_stated_unit_with_max_abs(tmp_path):
    """b = -1.5 deg/s +- 0.2 deg/s, |b| + 2 sigma = 1.9 <= 2 deg/s: margin 0.1 deg/s."""
    lim = _limits(tmp_path, '[limits.b]\nmax_abs = 2.0\nunit = "deg/s"\n')
    result = accept(_doc(b=(-1.5 * DEG, 0.0, 0.0), sb=0.2 * DEG), lim)
    bx = result.criteria[0]
    assert bx.unit == "deg/s" and bx.value == pytest.approx(-1.5) and bx.sigma == pytest.approx(0.2)
    assert bx.margin == pytest.approx(0.1) and result.passed


def test_the_sigma_itself_and_the_p_value_are_judged(tmp_path):
    lim = _limits(tmp_path, "[limits.sigma_k]\nmax = 5e-4\n[limits.p_value]\nmin = 0.001\n")
    result = accept(_doc(sk=1e-3, p=1e-4), lim)
    assert result.failures() == ["sigma_kx", "sigma_ky", "sigma_kz", "p_value"]


def test_a_missing_sigma_never_passes(tmp_path):
    """A value without a 1-sigma proves nothing: NaN sigma fails whatever the value."""
    doc = _doc()
    doc["std"] = None
    assert not accept(doc, _limits(tmp_path, "[limits.k]\nmin = 0.9\nmax = 1.1\n")).passed


def test_limits_that_do_not_apply(tmp_path):
    lim = _limits(tmp_path, '[limits.noise_density]\nmax = 0.01\nunit = "deg/s/rtHz"\n[limits.k]\nmax = 2\n')
    assert accept(_doc(), lim).not_applicable == ("noise_density",)
    only_noise = _limits(tmp_path, '[limits.noise_density]\nmax = 0.01\nunit = "deg/s/rtHz"\n')
    with pytest.raises(InputError, match="none of the limits"):
        accept(_doc(), only_noise)


@pytest.mark.parametrize("text, says", [
    ("[limits.kk]\nmin = 1\n", "unknown parameter 'kk'"),
    ('[limits.b]\nmax_abs = 1\nunit = "dps"\n', "unknown unit 'dps'"),
    ("[limits.k]\nminimum = 1\n", "unknown key 'minimum'"),
    ("[limits.k]\nunit = '1'\n", "sets no bound"),
    ("[limits.k]\nmin = 1.1\nmax = 0.9\n", "leave nothing to accept"),
    ("guard = -1\n[limits.k]\nmax = 2\n", "guard must be >= 0"),
    ("[limits.k]\nmin = 'a'\n", "must be a finite number"),
    ("gaurd = 2\n", "unknown top-level key 'gaurd'"),
    ("[limits.k\n", "is not TOML"),
    ("guard = 2\n", "sets no limits"),
])
def test_bad_limits_are_named(tmp_path, text, says):
    with pytest.raises(InputError, match=re.escape(says)):
        _limits(tmp_path, text)


@pytest.mark.parametrize("serial", ["", "a/b", "a\\b", "x:y", "tab\there", "..", "q?"])
def test_serials_a_file_name_cannot_hold_are_refused(serial):
    with pytest.raises(InputError):
        check_serial(serial)


def test_identity_checks_the_procedure():
    with pytest.raises(InputError, match="NAME@VERSION"):
        Identity("SN1", procedure="servo6@")
    assert Identity(" SN-1.b_2 ").serial == "SN-1.b_2"


def test_calibrate_records_the_unit_and_exits_one_on_a_fail(tmp_path):
    """The example calibrated with identity and limits: the 'unit' section holds the input's SHA-256 (hashlib),
    the acceptance its criteria; tight limits on k make it fail with exit 1, and the file is still written."""
    loose = tmp_path / "loose.toml"
    loose.write_text("guard = 2\n[limits.k]\nmin = 0.98\nmax = 1.02\n")
    out = tmp_path / "cal.json"
    code, stdout, err = invoke("calibrate", "--example", "-o", out, "--unit", "SN-7", "--station", "bench-1",
                               "--procedure", "servo6@1.2", "--limits", loose)
    assert code == 0, err
    assert stdout.rstrip().endswith("SN-7: PASS")
    doc = json.loads(out.read_text())
    unit = doc["unit"]
    from gyrocal.cli.calibrate_cmds import _example_paths

    expected = hashlib.sha256(_example_paths()[0].read_bytes()).hexdigest()
    assert unit["serial"] == "SN-7" and unit["inputs"][0]["sha256"] == expected
    assert unit["procedure"] == {"name": "servo6", "version": "1.2"} and unit["station"] == "bench-1"
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", unit["created"])
    assert doc["acceptance"]["verdict"] == "pass" and len(doc["acceptance"]["criteria"]) == 3
    tight = tmp_path / "tight.toml"
    tight.write_text("guard = 2\n[limits.k]\nmin = 0.999\nmax = 1.001\n")
    code, stdout, _ = invoke("calibrate", "--example", "-o", tmp_path / "fail.json", "--unit", "SN-7", "--limits",
                             tight)
    assert code == 1 and "SN-7: FAIL (kx, ky, kz)" in stdout
    assert json.loads((tmp_path / "fail.json").read_text())["acceptance"]["verdict"] == "fail"
    code, stdout, _ = invoke("accept", out, "--limits", tight)
    assert code == 1 and "FAIL" in stdout


def test_station_flags_are_checked_before_the_fit(tmp_path):
    assert "--store keeps records per unit" in refused("calibrate", "--example", "--store", tmp_path / "s.db")
    assert "holds '/', which a file name cannot hold" in refused("calibrate", "--example", "--unit", "a/b")
    limits = tmp_path / "k.toml"
    limits.write_text("[limits.k]\nmax = 2\n")
    assert "not found" in refused("accept", tmp_path / "none.json", "--limits", limits)
    assert "not found" in refused("accept", limits, "--limits", tmp_path / "none.toml")
    (tmp_path / "data.json").write_text("[1, 2]")
    assert "not a gyrocal result file" in refused("accept", tmp_path / "data.json", "--limits", limits)
