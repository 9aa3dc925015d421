"""Export of calibration files: JSON, YAML and C header, with format dispatch."""

import json

import numpy as np
import pytest

from gyrocal import Calibration, ScaleBias, save_calibration
from gyrocal.errors import FileFormatError, InputError
from gyrocal.export import export_file, load_any, render


@pytest.fixture
def cal_path(tmp_path):
    model = ScaleBias(k=[1.0069, 0.9960, 0.9955], b=[0.0442, -0.0089, 0.0076])
    cal = Calibration(model=model, input_units="deg/s", output_units="deg/s", covariance=np.eye(6) * 1e-8)
    path = tmp_path / "cal.json"
    save_calibration(cal, path)
    return path


def test_json_export_is_the_document(cal_path, tmp_path):
    out = tmp_path / "copy.json"
    export_file(cal_path, "json", out)
    assert json.loads(out.read_text()) == json.loads(cal_path.read_text())
    assert load_any(out).model.k.tolist() == [1.0069, 0.9960, 0.9955]


def test_yaml_export_holds_the_same_document(cal_path):
    yaml = pytest.importorskip("yaml")
    doc = yaml.safe_load(render(cal_path, "yaml"))
    assert doc == json.loads(cal_path.read_text())
    assert doc["correction"]["equation"] == "w_true = matrix @ (raw - offset)"


def test_c_header_export(cal_path):
    pytest.importorskip("gyrocal.firmware")
    text = render(cal_path, "c-header")
    assert "#" in text and "1.0069" in text


def test_unknown_export_format_is_refused(cal_path):
    with pytest.raises(InputError, match="format='xml'"):
        render(cal_path, "xml")


def test_file_of_another_kind_is_refused_naming_the_field(tmp_path):
    path = tmp_path / "other.json"
    path.write_text(json.dumps({"format": "imucal.ferraris", "version": 2}))
    with pytest.raises(FileFormatError, match="field 'format' is 'imucal.ferraris'") as info:
        load_any(path)
    assert info.value.field == "format"


def test_failed_export_leaves_no_output(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    out = tmp_path / "out.yaml"
    with pytest.raises(FileFormatError, match="not valid JSON"):
        export_file(bad, "yaml", out)
    assert not out.exists()
