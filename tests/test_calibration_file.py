"""The versioned calibration file (format version 2, docs/files.md): round trips, units, and refusal
of malformed files. References: the document's own fields re-derived with numpy, and the model's
exact parameters."""

import json
import math

import numpy as np
import pytest

from gyrocal.errors import FileFormatError
from gyrocal.models import Affine, ScaleBias
from gyrocal.results.calibration import Calibration
from gyrocal.results.files import from_document, load_calibration, save_calibration


def scale_bias_cal(rng) -> Calibration:
    model = ScaleBias(rng.uniform(0.8, 1.2, 3), rng.uniform(-0.1, 0.1, 3))
    a = rng.normal(size=(6, 6)) * 1e-4
    return Calibration(model, "deg/s", "deg/s", method="first-moment", covariance=a @ a.T,
                       noise_std=np.full(3, 0.035), windows=({"start": 0, "stop": 10, "kind": "rotation"},))


def affine_cal(rng) -> Calibration:
    model = Affine(np.eye(3) + rng.uniform(-0.05, 0.05, (3, 3)), rng.uniform(-0.1, 0.1, 3))
    return Calibration(model, "counts", "deg/s", sensitivity=131.0, method="thermal")


@pytest.mark.parametrize("make", [scale_bias_cal, affine_cal], ids=["scale-bias", "affine"])
def test_save_load_round_trip(make, rng, tmp_path):
    cal = make(rng)
    path = tmp_path / "cal.json"
    save_calibration(cal, path)
    back = load_calibration(path)
    assert type(back.model) is type(cal.model)
    np.testing.assert_array_equal(back.model.params, cal.model.params)
    assert (back.input_units, back.output_units, back.sensitivity, back.method) == (
        cal.input_units, cal.output_units, cal.sensitivity, cal.method)
    if cal.covariance is None:
        assert back.covariance is None
    else:
        np.testing.assert_array_equal(back.covariance, cal.covariance)
    assert back.windows == cal.windows
    raw = rng.normal(0, 100, (20, 3))
    np.testing.assert_allclose(back.correct(raw), cal.correct(raw), rtol=1e-14)


def test_units_are_applied_at_the_edges(rng):
    cal = scale_bias_cal(rng)
    raw_deg = rng.normal(0, 50, (5, 3))
    want = cal.model.correct(np.deg2rad(raw_deg))  # internal rad/s
    np.testing.assert_allclose(cal.correct(raw_deg), np.rad2deg(want), rtol=1e-13)
    doc = cal.to_document()
    assert doc["units"] == {"input": "deg/s", "output": "deg/s", "sensitivity": None, "internal": "rad/s"}
    assert set(doc["std"]) == {"kx", "ky", "kz", "bx", "by", "bz"}


def write(tmp_path, doc) -> str:
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(doc))
    return str(p)


@pytest.mark.parametrize(
    "edit, field",
    [
        (lambda d: d.update(version=99), "version"),
        (lambda d: d.update(format="imucal"), "format"),
        (lambda d: d.update(model="quadratic"), "model"),
        (lambda d: d["parameters"]["scale_bias"].pop("k"), "parameters.scale_bias.k"),
        (lambda d: d["parameters"]["scale_bias"].update(k=[1, 2]), "parameters.scale_bias.k"),
        (lambda d: d["parameters"]["scale_bias"].update(k=[1, -1, 1]), "parameters"),
        (lambda d: d.update(parameters={"seed000": d["parameters"]["scale_bias"]}), "parameters.scale_bias.k"),
        (lambda d: d["units"].update(input="furlongs"), "units"),
        (lambda d: d["correction"].update(offset=[9, 9, 9]), "correction"),
        (lambda d: d.update(covariance=[[1.0]]), "covariance"),
        (lambda d: d.pop("units"), "units.input"),
        (lambda d: d.update(version=True), "version"),
        (lambda d: d.update(version=1.0), "version"),
        (lambda d: d.update(method=None), "method"),
        (lambda d: d.update(windows=5), "windows"),
        (lambda d: d.update(windows=[1, 2]), "windows"),
        (lambda d: d.update(windows=None), "windows"),
        (lambda d: d["units"].update(sensitivity="x"), "units.sensitivity"),
        (lambda d: d["units"].update(sensitivity=[1]), "units.sensitivity"),
        (lambda d: d.update(covariance=(-np.eye(6)).tolist()), "covariance"),
        (lambda d: d.update(covariance=(np.eye(6) + np.triu(np.ones((6, 6)), 1)).tolist()), "covariance"),
        (lambda d: d.update(fit={"chi2": -1.0}), "fit.chi2"),
        (lambda d: d.update(fit=[1]), "fit"),
        (lambda d: d.update(observed={"sample_rate": "fast"}), "observed.sample_rate"),
        (lambda d: d.update(accelerometer={"units": {"input": "m/s^2", "output": "m/s^2"},
                                           "correction": {"matrix": [1], "offset": [0, 0, 0]}}),
         "accelerometer.correction.matrix"),
        (lambda d: d.update(accelerometer={"correction": {"matrix": np.eye(3).tolist(), "offset": [0, 0, 0]}}),
         "accelerometer.units"),
    ],
)
def test_malformed_files_name_the_field(rng, tmp_path, edit, field):
    doc = scale_bias_cal(rng).to_document()
    edit(doc)
    with pytest.raises(FileFormatError, match=f"'{field.split('.')[0]}") as info:
        load_calibration(write(tmp_path, doc))
    assert info.value.field == field


def test_non_json_and_missing_files(tmp_path):
    p = tmp_path / "x.json"
    p.write_text("{not json")
    with pytest.raises(FileFormatError, match="not valid JSON"):
        load_calibration(p)
    with pytest.raises(FileFormatError, match="no such file"):
        load_calibration(tmp_path / "missing.json")
    with pytest.raises(FileFormatError, match="top level"):
        from_document([], "x")  # type: ignore[arg-type]
    with pytest.raises(FileFormatError, match="top level"):
        Calibration.from_document([], "x")  # type: ignore[arg-type]


def test_file_records_version_and_units(rng, tmp_path):
    """The affine file holds K, B and Kg in eq. 14 order; its correction is K^-1 scaled by the unit
    factors, recomputed here with numpy from the file's own K (independent of gyrocal's code)."""
    path = tmp_path / "c.json"
    cal = affine_cal(rng)
    save_calibration(cal, path)
    doc = json.loads(path.read_text())
    assert doc["format"] == "gyrocal.calibration" and doc["version"] == 2
    assert doc["units"]["internal"] == "rad/s" and doc["units"]["sensitivity"] == 131.0
    affine = doc["parameters"]["affine"]
    assert affine["kg_order"][3] == "Kyx"
    K = np.array(affine["K"])
    assert affine["kg"][3] == K[0, 1] and affine["kg"][5] == K[1, 0]  # Kyx = K[0][1], Kxy = K[1][0] (eq. 11)
    counts_to_rad_s = math.radians(1.0) / 131.0  # counts -> deg/s -> rad/s inside
    want = np.linalg.inv(K) * counts_to_rad_s / math.radians(1.0)
    np.testing.assert_allclose(doc["correction"]["matrix"], want, rtol=1e-12)
    np.testing.assert_allclose(doc["correction"]["offset"], np.array(affine["B"]) / counts_to_rad_s, rtol=1e-12)
    assert doc["fit"] is None and doc["observed"] is None and doc["accelerometer"] is None


def test_sections_round_trip_and_stay_read_only(rng, tmp_path):
    """Optional sections keep documented and undocumented keys (other engineers add keys) and are read-only."""
    cal = Calibration(ScaleBias([1.0, 1.0, 1.0], [0.0, 0.0, 0.0]), "deg/s", "deg/s",
                      fit={"chi2": 3.5, "dof": 4, "warnings": ["residuals exceed the noise"], "new_key": {"a": [1, 2]}},
                      observed={"sample_rate": 200.0, "noise_std": np.array([0.1, 0.2, 0.3])})
    path = tmp_path / "c.json"
    save_calibration(cal, path)
    back = load_calibration(path)
    assert back.fit == cal.fit and back.observed == cal.observed
    assert back.fit["new_key"]["a"] == (1, 2) and back.fit.to_document()["new_key"] == {"a": [1, 2]}
    with pytest.raises(TypeError):
        back.fit["chi2"] = 0.0  # type: ignore[index]
    with pytest.raises(AttributeError):
        back.fit._data = {}
