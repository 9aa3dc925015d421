"""The file registry (docs/files.md): one load for every kind, by the ``format`` field.

References: documents built by hand in each test, and the kinds' own round trips.
"""

import json
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

from gyrocal.errors import FileFormatError, InputError
from gyrocal.models import Affine, ScaleBias
from gyrocal.results.calibration import Calibration
from gyrocal.results.files import KINDS, kinds, load, register, save
from gyrocal.simulation.truth import SimulationTruth, truth_path
from gyrocal.thermal import ThermalCalibration


def test_every_listed_kind_is_known_by_name():
    found = kinds()
    assert set(KINDS) <= set(found)
    assert found["gyrocal.calibration"] is Calibration and found["gyrocal.thermal"] is ThermalCalibration
    assert found["gyrocal.simulation-truth"] is SimulationTruth


def test_unknown_format_lists_the_known_ones(tmp_path):
    path = tmp_path / "x.json"
    path.write_text(json.dumps({"format": "acme.gyro", "version": 1}))
    with pytest.raises(FileFormatError) as info:
        load(path)
    assert info.value.field == "format"
    for fmt in KINDS:
        assert fmt in str(info.value)


@pytest.mark.parametrize("version", [0, 3, "2", 2.0, None])
def test_versions_this_gyrocal_cannot_read_are_refused(tmp_path, version):
    path = tmp_path / "x.json"
    save(Calibration(ScaleBias([1.0, 1.0, 1.0], [0.0, 0.0, 0.0])), path)
    doc = json.loads(path.read_text())
    doc["version"] = version
    path.write_text(json.dumps(doc))
    with pytest.raises(FileFormatError, match="versions 1 to 2") as info:
        load(path)
    assert info.value.field == "version"


def test_a_file_of_another_kind_is_refused_by_a_typed_load(tmp_path):
    path = tmp_path / "cal.json"
    save(Calibration(ScaleBias([1.0, 1.0, 1.0], [0.0, 0.0, 0.0])), path)
    with pytest.raises(FileFormatError, match="expected 'gyrocal.thermal'") as info:
        load(path, ThermalCalibration)
    assert info.value.field == "format"
    assert isinstance(load(path, (ThermalCalibration, Calibration)), Calibration)


def test_register_checks_the_interface():
    class NoVersion:
        FORMAT = "x.y"

    with pytest.raises(InputError, match="VERSION"):
        register(NoVersion)

    class NoMethods:
        FORMAT, VERSION = "x.y", 1

    with pytest.raises(InputError, match="to_document"):
        register(NoMethods)

    class Other:
        FORMAT, VERSION = "gyrocal.calibration", 1

        def to_document(self):
            return {}

        @classmethod
        def from_document(cls, doc, path="d"):
            return cls()

    with pytest.raises(InputError, match="already registered"):
        register(Other)


def test_a_new_kind_plugs_in_without_changing_the_registry(tmp_path):
    @register
    @dataclass(frozen=True)
    class Note:
        FORMAT: ClassVar[str] = "test.note"
        VERSION: ClassVar[int] = 1
        text: str

        def to_document(self):
            return {"format": self.FORMAT, "version": self.VERSION, "text": self.text}

        @classmethod
        def from_document(cls, doc, path="d"):
            return cls(doc["text"])

    save(Note("hello"), tmp_path / "n.json")
    assert load(tmp_path / "n.json") == Note("hello")
    with pytest.raises(InputError, match="not a registered"):
        save(object(), tmp_path / "o.json")


def test_simulation_truth_round_trip_and_path(tmp_path):
    truth = SimulationTruth("turntable", Affine(np.eye(3) * 1.01, [0.01, 0.0, -0.01]), {"seed": 3},
                            {"thermal": {"ref_temp": 25.0}}, "a test")
    path = truth_path(tmp_path / "rec.csv")
    assert path.name == "rec.truth.json"
    save(truth, path)
    doc = json.loads(path.read_text())
    assert doc["K"][0][0] == 1.01 and doc["thermal"] == {"ref_temp": 25.0} and doc["settings"] == {"seed": 3}
    back = load(path)
    np.testing.assert_array_equal(back.model.K, truth.model.K)
    assert (back.protocol, back.settings, back.facts, back.description) == ("turntable", {"seed": 3},
                                                                           truth.facts, "a test")
    with pytest.raises(InputError, match="document's own keys"):
        SimulationTruth("servo", ScaleBias([1, 1, 1], [0, 0, 0]), facts={"k": [1]})
