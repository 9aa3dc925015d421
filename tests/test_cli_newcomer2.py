"""--time-units and --nan drop (issue 22, item 10): a ms/us time column and NaN rows without editing the file.

Reference: the same simulated servo session written with seconds; scaling stamps by 1e3/1e6 changes nothing
but the unit, so k must agree to 1e-9; five NaN rows dropped remove 5 of ~20 000 samples, well within 1 sigma.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from cli_runner import invoke

from gyrocal.io import write_csv
from gyrocal.models import ScaleBias
from gyrocal.simulation import VirtualGyro
from gyrocal.simulation.servo import ServoProtocol, simulate_servo

TRUE = ScaleBias(k=[1.0069, 0.9960, 0.9955], b=[0.0442, -0.0089, 0.0076])


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    out = tmp_path_factory.mktemp("newcomer2")
    rec, _ = simulate_servo(VirtualGyro(model=TRUE, noise_std=0.01), ServoProtocol(), sample_rate=200.0,
                            rng=np.random.default_rng(5))
    g = np.degrees(rec.gyro)
    for name, scale in (("s.csv", 1.0), ("ms.csv", 1e3), ("us.csv", 1e6)):
        write_csv(out / name, {"t": rec.t * scale, "gx": g[:, 0], "gy": g[:, 1], "gz": g[:, 2]})
    g2 = g.copy()
    g2[3000:3005, 1] = np.nan
    write_csv(out / "nan.csv", {"t": rec.t, "gx": g2[:, 0], "gy": g2[:, 1], "gz": g2[:, 2]})
    return out


def _k(folder, name, *flags):
    code, out, err = invoke("calibrate", folder / name, "--units", "deg/s", "--speed", "60",
                            "-o", folder / (name + ".json"), "--force", *flags)
    assert code == 0, err
    doc = json.loads((folder / (name + ".json")).read_text())
    return doc, out + err


def _kvec(doc):
    return np.asarray([doc["parameters"]["scale_bias"]["k"]], dtype=float)


def test_ms_and_us_stamps_give_the_seconds_k(folder):
    ref, _ = _k(folder, "s.csv")
    for name, unit in (("ms.csv", "ms"), ("us.csv", "us")):
        given, _ = _k(folder, name, "--time-units", unit)
        np.testing.assert_allclose(_kvec(given), _kvec(ref), rtol=1e-9)
        recognised, text = _k(folder, name, "--sample-rate", "200")
        assert f"read as {unit}" in text
        np.testing.assert_allclose(_kvec(recognised), _kvec(ref), rtol=1e-9)


def test_nan_rows_refused_naming_the_flag_then_dropped(folder):
    code, _, err = invoke("calibrate", folder / "nan.csv", "--units", "deg/s", "--speed", "60")
    assert code == 2 and "--nan drop" in err and len(err.strip().splitlines()) == 1
    ref, _ = _k(folder, "s.csv")
    doc, text = _k(folder, "nan.csv", "--nan", "drop")
    assert "5 row(s)" in text
    assert any("5 row(s)" in n for n in doc["fit"]["notes"])
    sd = np.asarray([doc["std"][f"k{a}"] for a in "xyz"], dtype=float)
    assert np.all(np.abs(_kvec(doc) - _kvec(ref)) < sd)


def test_a_recording_given_for_a_json_file_is_named(folder):
    """A CSV recording where a gyrocal file is expected: every command says what the file is, in one line."""
    from cli_runner import refused

    cal, _ = _k(folder, "s.csv")
    rec = folder / "s.csv"
    cases = [(("export", rec, "--format", "json", "-o", folder / "x.json"), "a recording (CSV), not a gyrocal"),
             (("compare", rec, folder / "s.csv.json"), "a recording (CSV), not a gyrocal"),
             (("accept", rec, "--limits", rec), "is not TOML"),
             (("apply", folder / "s.csv.json", folder / "s.csv.json", "-o", folder / "y.csv"), "not a recording")]
    for args, says in cases:
        assert says in refused(*args)
    assert "look swapped" in refused("verify", rec, folder / "s.csv.json", "--reference", rec)
    assert "look swapped" in refused("apply", rec, folder / "s.csv.json", "-o", folder / "z.csv")
