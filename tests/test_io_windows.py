"""Windows files: imucal's section list, JSON records, CSV tables."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from gyrocal.errors import FileFormatError
from gyrocal.io import read_windows
from gyrocal.segmentation.windows import Window

# imucal's layout, written the way imucal writes it (a synthetic session, not its data)
IMUCAL = {
    "x_p": {"start": 10, "end": 50}, "x_a": {"start": 60, "end": 90},
    "y_p": {"start": 100, "end": 130}, "y_a": {"start": 140, "end": 170},
    "z_p": {"start": 180, "end": 210}, "z_a": {"start": 220, "end": 250},
    "x_rot": {"start": 260, "end": 300}, "y_rot": {"start": 310, "end": 350}, "z_rot": {"start": 360, "end": 400},
}


def test_imucal_section_list(tmp_path):
    path = tmp_path / "session_list.json"
    path.write_text(json.dumps(IMUCAL, separators=(",", ":")))
    windows = read_windows(path, sample_rate=102.4, n_samples=400)
    assert [w.label for w in windows] == list(IMUCAL)
    rot = {w.label: w for w in windows if w.kind == "rotation"}
    assert set(rot) == {"x_rot", "y_rot", "z_rot"}
    assert rot["y_rot"] == Window(start=310, stop=350, kind="rotation", axis="y", label="y_rot")
    static = [w for w in windows if w.kind == "static"]
    assert len(static) == 6 and all(w.axis is None and w.sign == 0 for w in static)
    assert (static[0].start, static[0].stop) == (10, 50)  # imucal's end is exclusive, as ours


def test_json_records_in_samples_and_seconds(tmp_path):
    records = [
        {"start": 100, "stop": 200, "kind": "rotation", "angle_deg": 360, "axis": "-z"},
        {"t_start": 3.0, "t_stop": 4.5, "kind": "static"},
        {"start": 0.5, "end": 0.9, "unit": "s", "kind": "rotation", "axis": "x", "sign": 1},
    ]
    path = tmp_path / "w.json"
    path.write_text(json.dumps(records))
    windows = read_windows(path, sample_rate=100.0, t0=0.5, n_samples=1000)
    assert [(w.start, w.stop, w.kind) for w in windows] == [(0, 40, "rotation"), (100, 200, "rotation"), (250, 400, "static")]
    assert windows[1].axis == "z" and windows[1].sign == -1 and windows[1].angle == pytest.approx(2 * math.pi)
    assert windows[0].sign == 1 and math.isnan(windows[0].angle)


def test_windows_of_a_calibration_file_read_back(tmp_path):
    original = [Window(5, 95, "rotation", "x", -1, angle=2 * math.pi, rate=1.05, label="x-"), Window(100, 150, "static")]
    path = tmp_path / "cal.json"
    path.write_text(json.dumps({"format": "gyrocal.calibration", "windows": [w.to_dict() for w in original]}))
    assert read_windows(path, sample_rate=50.0) == original


def test_csv_table(tmp_path):
    path = tmp_path / "w.csv"
    path.write_text("\nstart;stop;kind;angle_deg;axis\n10;50;static;;\n60;160;rotation;-360;y\n")
    windows = read_windows(path, sample_rate=20.0, n_samples=200)
    assert windows[0] == Window(10, 50, "static")
    assert windows[1].axis == "y" and windows[1].angle == pytest.approx(-2 * math.pi)
    timed = tmp_path / "t.csv"
    timed.write_text("t_start,t_stop,kind\n0.5,2.5,rotation\n")
    assert read_windows(timed, sample_rate=20.0)[0] == Window(10, 50, "rotation")


@pytest.mark.parametrize(
    ("content", "match"),
    [
        ('{"x_rot": {"start": 10, "end": 5000}}', "window x_rot ends at sample 5000, past the recording's 1000 samples"),
        ('{"x_rot": {"start": 50, "end": 10}}', "needs 0 <= start < stop, got 50:10"),
        ('[{"start": 1, "stop": 9, "kind": "spin"}]', "field 'kind' is 'spin'; use 'rotation' or 'static'"),
        ('[{"start": 1.5, "stop": 9, "kind": "static"}]', "field 'start' is a sample index and must be whole"),
        ('[{"start": "a", "stop": 9, "kind": "static"}]', "field 'start' must be a number, got 'a'"),
        ('[{"stop": 9, "kind": "static"}]', "needs one of the fields start, t_start"),
        ('[{"start": 1, "stop": 9, "kind": "rotation", "axis": "q"}]', "field 'axis' is 'q'"),
        ('[{"start": 1, "stop": 9, "kind": "rotation", "angle_deg": 0}]', "field 'angle_deg' is 0; give the size"),
        ('{"x_rot": [1, 2]}', "expected imucal's section list"),
        ("[]", "holds no windows"),
        ("{not json", "not valid JSON"),
    ],
)
def test_bad_windows_files(tmp_path, content, match):
    path = tmp_path / "w.json"
    path.write_text(content)
    with pytest.raises(FileFormatError, match=match):
        read_windows(path, sample_rate=100.0, n_samples=1000)


def test_missing_or_empty_windows_file(tmp_path):
    with pytest.raises(FileFormatError, match="does not exist"):
        read_windows(tmp_path / "none.json", sample_rate=100.0)
    (tmp_path / "w.csv").write_text("\n")
    with pytest.raises(FileFormatError, match="w.csv: no header row"):
        read_windows(tmp_path / "w.csv", sample_rate=100.0)
    (tmp_path / "h.csv").write_text("start,stop,kind\n")
    with pytest.raises(FileFormatError, match="h.csv: holds no windows"):
        read_windows(tmp_path / "h.csv", sample_rate=100.0)


def test_windows_in_seconds_follow_the_time_column_across_a_gap(tmp_path):
    """A log at 100 Hz that lost 17 samples (a 180 ms packet gap) at 2 s: a window written in seconds after the
    gap holds the samples stamped inside it (reference: the stamps themselves), not samples 0.17 s later, and
    one that ends at the log's last stamp is inside it (through the nominal rate it would run past the end)."""
    t = 100.0 + np.delete(np.arange(1017) / 100.0, np.arange(200, 217))  # 1000 samples, 17 lost at 2.00 s
    path = tmp_path / "w.json"
    path.write_text(json.dumps([{"t_start": 105.0, "t_stop": 106.0, "kind": "rotation"},
                                {"t_start": 109.0, "t_stop": float(t[-1]), "kind": "static"}]))
    rot, sta = read_windows(path, sample_rate=100.0, t0=float(t[0]), n_samples=len(t), t=t)
    assert (t[rot.start], t[rot.stop]) == (pytest.approx(105.0), pytest.approx(106.0))
    assert rot.stop - rot.start == 100 and sta.stop <= len(t)
    with pytest.raises(FileFormatError, match="past the recording"):
        read_windows(path, sample_rate=100.0, t0=float(t[0]), n_samples=len(t))  # the nominal rate alone
