"""Export through the exporter registry (docs/files.md): JSON, YAML and C header for every calibration kind.

References: the file's own JSON document (json, yaml), and the correction numbers parsed back out of the
C text with a regular expression (c-header); the header is compiled against the C library in
tests/test_firmware.py.
"""

import json
import re

import numpy as np
import pytest
import yaml

from gyrocal import Calibration, ScaleBias, save_calibration
from gyrocal.errors import FileFormatError, InputError
from gyrocal.export import EXPORT_FORMATS, export_file, exporter, register_exporter, render
from gyrocal.results.files import load


@pytest.fixture
def cal_path(tmp_path):
    model = ScaleBias(k=[1.0069, 0.9960, 0.9955], b=[0.0442, -0.0089, 0.0076])
    cal = Calibration(model=model, input_units="deg/s", output_units="deg/s", covariance=np.eye(6) * 1e-8)
    path = tmp_path / "cal.json"
    save_calibration(cal, path)
    return path


def test_builtin_formats_are_registered():
    assert EXPORT_FORMATS[:3] == ("json", "yaml", "c-header")
    assert [exporter(f).suffix for f in EXPORT_FORMATS[:3]] == [".json", ".yaml", ".h"]


def test_json_export_is_the_document(cal_path, tmp_path):
    out = tmp_path / "copy.json"
    export_file(cal_path, "json", out)
    assert json.loads(out.read_text()) == json.loads(cal_path.read_text())
    assert load(out).model.k.tolist() == [1.0069, 0.9960, 0.9955]


def test_yaml_export_holds_the_same_document(cal_path):
    doc = yaml.safe_load(render(cal_path, "yaml"))
    assert doc == json.loads(cal_path.read_text())
    assert doc["correction"]["equation"] == "w_true = matrix @ (raw - offset)"


def test_c_header_export_holds_the_correction_under_its_prefix(cal_path):
    """The matrix and offset literals in the header are the file's correction to float32 precision."""
    doc = json.loads(cal_path.read_text())
    text = render(cal_path, "c-header", prefix="imu2")
    body = text[text.index("static const gyrocal_affine_t IMU2_CALIBRATION"):]
    values = [float(v) for v in re.findall(r"(-?\d\.\d+e[+-]\d+)f", body)]
    want = np.concatenate([np.ravel(doc["correction"]["matrix"]), doc["correction"]["offset"]])
    np.testing.assert_allclose(values, want, rtol=2 ** -23)
    assert "GYROCAL_CALIBRATION" not in text  # every name carries the prefix


def test_unknown_export_format_and_options_are_refused(cal_path):
    with pytest.raises(InputError, match="fmt='xml'") as info:
        render(cal_path, "xml")
    assert info.value.param == "fmt"
    with pytest.raises(InputError, match="prefix does not apply to json export") as info:
        render(cal_path, "json", prefix="x")
    assert info.value.param == "prefix"
    with pytest.raises(InputError, match="must be a C identifier"):
        render(cal_path, "c-header", prefix="9lives")


def test_a_format_must_be_listed_before_it_registers():
    with pytest.raises(InputError, match="EXPORTER_MODULES"):
        register_exporter("xml", None, lambda obj: "", suffix=".xml")


def test_file_of_another_kind_is_refused_naming_the_field(tmp_path):
    path = tmp_path / "other.json"
    path.write_text(json.dumps({"format": "imucal.ferraris", "version": 2}))
    with pytest.raises(FileFormatError, match="field 'format' is 'imucal.ferraris'; gyrocal reads") as info:
        render(path, "json")
    assert info.value.field == "format"
    assert "gyrocal.calibration" in str(info.value) and "gyrocal.thermal" in str(info.value)


def test_failed_export_leaves_no_output(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    out = tmp_path / "out.yaml"
    with pytest.raises(FileFormatError, match="not valid JSON"):
        export_file(bad, "yaml", out)
    assert not out.exists()


def test_export_command_takes_a_prefix_for_c_headers_only(cal_path, tmp_path):
    from cli_runner import invoke, refused

    code, _, err = invoke("export", cal_path, "--format", "c-header", "--prefix", "imu2", "-o", tmp_path / "a.h")
    assert code == 0, err
    assert "static const gyrocal_affine_t IMU2_CALIBRATION" in (tmp_path / "a.h").read_text()
    line = refused("export", cal_path, "--format", "yaml", "--prefix", "imu2", "-o", tmp_path / "a.yaml")
    assert "--prefix does not apply to yaml export" in line
    assert not (tmp_path / "a.yaml").exists()
