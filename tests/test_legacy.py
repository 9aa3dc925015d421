"""Version 1 files (made by gyrocal 0.1.0, tests/data/README.md) load, upgrade and apply as they did.

References: the old files' own JSON fields (read with json, not with gyrocal), and the corrected CSVs
that gyrocal 0.1.0 wrote from the same files (tests/data/*.applied.csv).
"""

import json
from pathlib import Path

import numpy as np
import pytest
from approx import assert_close_tree
from cli_runner import invoke

from gyrocal.errors import FileFormatError
from gyrocal.io import read_recording
from gyrocal.models import KG_NAMES
from gyrocal.results.calibration import Calibration
from gyrocal.results.files import load, to_document
from gyrocal.results.legacy import upgrade
from gyrocal.thermal import ThermalCalibration

DATA = Path(__file__).parent / "data"


def _old(name: str) -> dict:
    return json.loads((DATA / name).read_text())


@pytest.mark.parametrize("name", ["v1_calibration.json", "v1_affine.json", "v1_counts.json"])
def test_v1_calibration_loads_with_its_numbers_unchanged(name):
    old = _old(name)
    assert old["version"] == 1
    cal = load(DATA / name)
    assert isinstance(cal, Calibration)
    doc = cal.to_document()
    assert doc["version"] == 2 and doc["fit"] is None and doc["accelerometer"] is None
    # the parts scripts read keep their names, shapes, units and values
    for key in ("units", "std", "noise_std", "method", "model"):
        assert doc[key] == old[key], key
    np.testing.assert_allclose(doc["covariance"] or 0.0, old["covariance"] or 0.0, rtol=0, atol=0)
    np.testing.assert_allclose(doc["correction"]["matrix"], old["correction"]["matrix"], rtol=1e-15)
    np.testing.assert_allclose(doc["correction"]["offset"], old["correction"]["offset"], rtol=1e-15)
    if "seed000" in old["parameters"]:
        assert doc["parameters"] == {"scale_bias": old["parameters"]["seed000"]}
    else:
        affine, kg = doc["parameters"]["affine"], old["parameters"]["seed001"]["kg"]
        assert affine["kg"] == kg and affine["kg_order"] == list(KG_NAMES)
        # eq. 11: K = [[Kxx, Kyx, Kzx], [Kxy, Kyy, Kzy], [Kxz, Kyz, Kzz]], written out by hand
        assert affine["K"] == [[kg[0], kg[3], kg[4]], [kg[5], kg[1], kg[6]], [kg[7], kg[8], kg[2]]]
        assert affine["B"] == kg[9:]


def test_v1_thermal_loads_with_its_numbers_unchanged():
    old = _old("v1_thermal.json")
    tc = load(DATA / "v1_thermal.json")
    assert isinstance(tc, ThermalCalibration)
    doc = tc.to_document()
    assert doc["version"] == 2 and doc["kg_order"] == old["kg_names"] and "kg_names" not in doc
    assert "seed" not in doc["interpolation"]["rule"]
    # the inverse matrices are recomputed on load: equal to a few ulps times their condition, not bit for bit
    for key in ("points", "smooth", "range"):
        assert_close_tree(doc[key], old[key], rtol=1e-13, path=key)


def _csv(path: Path) -> tuple[list[str], np.ndarray, list[str]]:
    lines = path.read_text().splitlines()
    header = lines[1].split(",")
    rows = [line.split(",") for line in lines[2:]]
    numeric = [i for i, name in enumerate(header) if name != "axis"]
    return header, np.array([[float(r[i]) for i in numeric] for r in rows]), [lines[0]]


@pytest.mark.parametrize("cal_name, rec_name", [("v1_calibration.json", "v1_servo_head.csv"),
                                                ("v1_thermal.json", "v1_thermal_test.csv")])
def test_v1_files_apply_as_gyrocal_0_1_0_did(tmp_path, cal_name, rec_name):
    """``gyrocal apply`` with the old file writes what gyrocal 0.1.0 wrote, to rounding (1e-12 relative)."""
    out = tmp_path / "applied.csv"
    code, _, err = invoke("apply", DATA / cal_name, DATA / rec_name, "-o", out)
    assert code == 0, err
    want_header, want, _ = _csv(DATA / rec_name.replace(".csv", ".applied.csv"))
    got_header, got, _ = _csv(out)
    assert got_header == want_header
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)


def test_v1_calibration_applies_through_the_library(tmp_path):
    """Calibration.apply on the old file: the old file's own matrix and offset, applied with numpy."""
    old = _old("v1_calibration.json")
    rec = read_recording(DATA / "v1_servo_head.csv", units="deg/s")
    out = load(DATA / "v1_calibration.json").apply(rec)
    raw = np.degrees(rec.gyro)
    want = (raw - np.array(old["correction"]["offset"])) @ np.array(old["correction"]["matrix"]).T
    assert out.source_units == "deg/s"
    np.testing.assert_allclose(np.degrees(out.gyro), want, rtol=1e-12, atol=1e-12)


def test_v1_counts_calibration_applies_to_counts():
    old = _old("v1_counts.json")
    raw = np.array([[-40.0, 12.0, -7.5], [91.0, 143.0, 123.5]])  # the offset (-b), then 131 counts above it
    from gyrocal.recording import Recording

    rec = Recording.from_rate(raw, 100.0, units="counts", source_units="counts")
    out = load(DATA / "v1_counts.json").apply(rec)
    want = (raw - np.array(old["correction"]["offset"])) @ np.array(old["correction"]["matrix"]).T  # deg/s
    np.testing.assert_allclose(np.degrees(out.gyro), want, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(want[1], [1.01, 0.99, 1.002], rtol=1e-12)  # 131 counts = 1 deg/s times k


def test_upgrade_leaves_the_old_document_alone_and_names_missing_fields():
    old = _old("v1_calibration.json")
    copy = json.loads(json.dumps(old))
    new = upgrade(old, "x")
    assert old == copy and new is not old and new["version"] == 2
    del old["parameters"]
    with pytest.raises(FileFormatError, match="'parameters'") as info:
        upgrade(old, "x")
    assert info.value.field == "parameters"
    bad = _old("v1_calibration.json")
    bad["parameters"] = {"other": {}}
    with pytest.raises(FileFormatError, match="neither 'seed000' nor 'seed001'"):
        upgrade(bad, "x")
    assert upgrade({"format": "gyrocal.calibration", "version": True}, "x")["version"] is True  # refused later


def test_v1_thermal_bias_loads_and_exports_as_it_did(tmp_path):
    """A version 1 thermal-bias file (gyro only, made before the accelerometer section) loads as version 2 with
    no accelerometer, and exports the PX4 and ArduPilot parameters the old gyrocal wrote from it (reference:
    tests/data/v1_thermal_bias.params and .parm, written by that gyrocal)."""
    old = _old("v1_thermal_bias.json")
    assert old["version"] == 1 and "accelerometer" not in old
    tb = load(DATA / "v1_thermal_bias.json")
    doc = to_document(tb)
    assert doc["version"] == 2 and doc["accelerometer"] is None and doc["axes"] == old["axes"]
    for fmt, name, extra in (("px4", "v1_thermal_bias.params", ("--device-id", "7")),
                             ("ardupilot", "v1_thermal_bias.parm", ())):
        out = tmp_path / name
        assert invoke("export", DATA / "v1_thermal_bias.json", "--format", fmt, "-o", out, *extra)[0] == 0
        rows = [line for line in out.read_text().splitlines() if not line.startswith("#")]
        assert rows == [line for line in (DATA / name).read_text().splitlines() if not line.startswith("#")]
