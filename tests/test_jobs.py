"""One job interface: every registered job returns a JobResult alike, and its document is what the CLI writes.

References: the inputs are simulated by ``gyrocal simulate`` and the turntable simulator (seeded), not by
the jobs; a job's document is compared with the file the CLI command writes for the same inputs (the
command's own flag parsing, reading and writing path), apart from which gyrocal wrote it. Refusals are
checked against the error contract (:class:`~gyrocal.errors.InputError`), atomic saves against the files
left on disk after a write that fails halfway, and the lazy registry against ``sys.modules`` of a fresh
interpreter.
"""

from __future__ import annotations

import dataclasses
import json
import math
import pathlib
import subprocess
import sys

import pytest
from cli_runner import invoke, simulated
from thermal_sessions import thermal_session

from gyrocal.errors import InputError
from gyrocal.jobs import JOBS, make_job, run_job
from gyrocal.jobs.result import JobResult, same_document

DATA = pathlib.Path(__file__).resolve().parents[1] / "src" / "gyrocal" / "data"


@pytest.fixture(scope="module")
def cases(tmp_path_factory):
    """Job name -> (its options, the CLI command line that writes the same result, the file it writes)."""
    d = tmp_path_factory.mktemp("jobs")
    servo = simulated(d / "servo.csv", "--seed", "11")
    hand = simulated(d / "hand.csv", "--protocol", "multi-position", "--poses", "12", "--still", "2",
                     "--sample-rate", "50", "--noise", "0.002", "--k", "1.01,0.99,1.02", "--seed", "5")
    rest = simulated(d / "rest.csv", "--protocol", "static", "--duration", "120", "--sample-rate", "50",
                     "--noise", "0.005", "--units", "rad/s", "--seed", "5")
    warm = simulated(d / "warm.csv", "--protocol", "static", "--duration", "600", "--sample-rate", "10",
                     "--noise", "0.005", "--temp-start", "-5", "--temp-end", "50", "--warmup-tau", "150",
                     "--temp-quantum", "1", "--bias-tempco", "2e-4,-1e-4,5e-5;-3e-6,0,2e-6;5e-8,0,0", "--seed", "3")
    session = thermal_session(d / "thermal.csv")
    cal = d / "example.json"
    code, _, err = invoke("calibrate", "--example", "-o", cal)
    assert code == 0, err
    test, ref = DATA / "example_servo_repeat.csv", DATA / "example_servo_reference.csv"
    return {
        "calibrate": ({"recording": servo, "reading": {"units": "deg/s"}, "speed": math.radians(60.0)},
                      ["calibrate", servo, "--units", "deg/s", "--speed", "60", "-o"], d / "c.json"),
        "imu": ({"recording": hand, "reading": {"units": "deg/s", "accel_units": "m/s^2"}},
                ["imu", hand, "--units", "deg/s", "--accel-units", "m/s^2", "-o"], d / "i.json"),
        "thermal": ({"session": session, "units": "deg/s", "settle": 1.0},
                    ["thermal", session, "--units", "deg/s", "--settle", "1", "-o"], d / "t.json"),
        "thermal-bias": ({"recording": warm, "reading": {"units": "deg/s"}, "min_span": 10.0},
                         ["thermal-bias", warm, "--units", "deg/s", "-o"], d / "tb.json"),
        "noise": ({"recording": rest, "reading": {"units": "rad/s"}}, ["noise", rest, "--units", "rad/s", "-o"],
                  d / "n.json"),
        "verify": ({"calibration": cal, "test": test, "reference": ref, "reading": {"units": "deg/s"},
                    "ref_reading": {"units": "deg/s"}, "replicates": 50},
                   ["verify", cal, test, "--reference", ref, "--ref-units", "deg/s", "--replicates", "50",
                    "--no-figures", "-o"], d / "v"),
    }


def test_every_job_has_a_case():
    """The registry's names are the six commands' (the test covers each one registered)."""
    assert set(JOBS) == {"calibrate", "imu", "thermal", "thermal-bias", "noise", "verify"}


@pytest.mark.parametrize("name", list(JOBS))
def test_a_job_returns_the_document_the_cli_writes(name, cases):
    """Same attribute set for every job; the document equals the CLI's file (reference: the command path)."""
    options, argv, out = cases[name]
    result = run_job(name, **options)
    assert isinstance(result, JobResult) and result.job == name
    assert [f.name for f in dataclasses.fields(result)] == [f.name for f in dataclasses.fields(JobResult)]
    assert isinstance(result.document, dict) and result.document["format"].startswith("gyrocal.")
    assert all(isinstance(w, str) for w in result.warnings + result.notes)
    assert all(callable(draw) for draw in result.figures.values())
    assert result.summary()[0].startswith(f"{name}: {result.document['format']}")
    code, _, err = invoke(*argv, out)
    assert code == 0, err
    written = json.loads((out / "verify.json" if name == "verify" else out).read_text())
    _assert_same(json.loads(json.dumps(result.document)), written, name)


def _assert_same(mine, theirs, where: str) -> None:
    """Equal documents apart from ``created_by``: the same keys, strings and shapes; numbers within 1e-9
    relative (a fit repeated in another process may differ in its last bits, never more)."""
    if isinstance(mine, dict):
        assert isinstance(theirs, dict), where
        keys = set(mine) - {"created_by"}
        assert keys == set(theirs) - {"created_by"}, (where, keys ^ set(theirs))
        for key in keys:
            _assert_same(mine[key], theirs[key], f"{where}.{key}")
    elif isinstance(mine, list):
        assert isinstance(theirs, list) and len(mine) == len(theirs), where
        for i, (a, b) in enumerate(zip(mine, theirs)):
            _assert_same(a, b, f"{where}[{i}]")
    elif isinstance(mine, float) and not isinstance(theirs, bool):
        assert theirs == pytest.approx(mine, rel=1e-9, abs=1e-300), where
    else:
        assert mine == theirs, where


@pytest.mark.parametrize("name", list(JOBS))
def test_unknown_or_missing_options_are_refused(name, cases):
    """An option the job does not take, or a required one left out, is an InputError naming it."""
    options = cases[name][0]
    with pytest.raises(InputError, match="takes no option 'colour'"):
        make_job(name, **options, colour="red")
    required = next(iter(options))
    with pytest.raises(InputError, match=f"needs {required}"):
        make_job(name, **{k: v for k, v in options.items() if k != required})


def test_bad_inputs_refuse_with_input_error(cases):
    """The library's refusals reach a job's caller as InputError (reference: the error contract)."""
    with pytest.raises(InputError, match="unknown job 'fit'"):
        run_job("fit")
    rest = cases["noise"][0]["recording"]
    with pytest.raises(InputError, match="temperature"):  # a log at rest without temperatures
        run_job("thermal-bias", recording=rest, reading={"units": "rad/s"})
    with pytest.raises(InputError):  # the data are deg/s: read as rad/s, the unit check refuses them
        run_job("calibrate", recording=cases["calibrate"][0]["recording"], reading={"units": "rad/s"}, speed=60.0)


def test_save_is_atomic_and_refuses_another_document(cases, tmp_path, monkeypatch):
    """A write that fails halfway leaves no file (and no temporary); an existing other file is kept."""
    result = run_job("noise", **cases["noise"][0])
    target = tmp_path / "noise.json"
    real = pathlib.Path.write_text

    def half(self, text, *args, **kwargs):
        real(self, text[: len(text) // 2], *args, **kwargs)
        raise OSError("disk full")

    monkeypatch.setattr(pathlib.Path, "write_text", half)
    with pytest.raises(OSError, match="disk full"):
        result.save(target)
    monkeypatch.undo()
    assert list(tmp_path.iterdir()) == []
    other = tmp_path / "other.json"
    other.write_text('{"format": "gyrocal.calibration"}\n')
    with pytest.raises(InputError, match="holds another document"):
        result.save(other)
    assert json.loads(other.read_text()) == {"format": "gyrocal.calibration"}
    assert same_document(result.document)(result.save(other, force=True))
    with pytest.raises(InputError, match="input of this job"):
        result.save(cases["noise"][0]["recording"], force=True)


def test_the_registry_imports_no_job_at_import():
    """``import gyrocal.jobs`` loads no job module and no numpy (a fresh interpreter's sys.modules)."""
    code = ("import sys, gyrocal.jobs, gyrocal.jobs.result\n"
            "print(sorted(m for m in sys.modules if m.startswith(('numpy', 'gyrocal.jobs.', 'gyrocal.io'))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "['gyrocal.jobs.result']"


def test_every_batch_job_is_a_registered_job():
    """A manifest's jobs are jobs of the registry (the station runs them by name)."""
    from gyrocal.station.manifest import JOBS as BATCH

    assert set(BATCH) <= set(JOBS) and set(JOBS) - set(BATCH) == {"verify"}  # verify writes a folder, no unit
