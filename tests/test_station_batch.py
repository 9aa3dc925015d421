"""Batch calibration of a lot into a real store (SQLite file and a PostgreSQL server), and the store commands.

References: the simulator's truth (a unit built 2 % off in kx must fail limits of +-1 %), the store's
own rows counted with SQL-free queries of the API, and each parameter's change in sigmas worked here
from the two stored documents.
"""

import json
import math
import time

import pytest
from cli_runner import invoke, refused

from gyrocal.store import open_store

SPEED = "--units deg/s --speed 60"


@pytest.fixture(scope="module")
def lot(tmp_path_factory):
    """Three simulated servo sessions: two good units, one whose kx is 2 % high."""
    folder = tmp_path_factory.mktemp("lot")
    for name, k in (("a", "1.001,0.999,1.0"), ("b", "1.0,1.002,0.998"), ("c", "1.02,1.0,1.0")):
        code, _, err = invoke("simulate", "-o", folder / f"{name}.csv", "--seed", str(ord(name)), "--k", k)
        assert code == 0, err
    (folder / "limits.toml").write_text("guard = 2\n[limits.k]\nmin = 0.99\nmax = 1.01\n")
    return folder


def _manifest(folder, rows, name="manifest.csv"):
    path = folder / name
    path.write_text("file,serial,job,args,station\n" + "".join(f"{r}\n" for r in rows))
    return path


@pytest.mark.parametrize("store_url", ["sqlite", "postgresql"], indirect=True)
def test_batch_records_every_unit_and_a_rerun_skips_them(lot, store_url, tmp_path):
    manifest = _manifest(tmp_path, [
        f"{lot / 'a.csv'},SN-A,calibrate,{SPEED},bench-1",
        f"{lot / 'b.csv'},SN-B,calibrate,{SPEED},bench-2",
        f"{lot / 'c.csv'},SN-C,calibrate,{SPEED},bench-2",
        f"{lot / 'a.csv'},SN-D,calibrate,--units rad/s --speed 60,bench-1",  # refused: the data are deg/s
    ])
    code, out, err = invoke("batch", manifest, "--store", store_url, "--limits", lot / "limits.toml", "-j", "2")
    assert code == 1, err
    assert "kx 1" in out  # failures by criterion: kx once (unit C)
    with open_store(store_url) as store:
        records = store.list()
        by_serial = {r.serial: r for r in records}
        assert len(records) == 4
        assert by_serial["SN-A"].verdict == by_serial["SN-B"].verdict == "pass"
        assert by_serial["SN-C"].verdict == "fail" and by_serial["SN-C"].kind == "calibration"
        refusal = by_serial["SN-D"]
        assert refusal.kind == "refusal" and refusal.verdict == "fail" and "deg/s" in refusal.document["reason"]
        assert by_serial["SN-A"].station == "bench-1" and by_serial["SN-A"].args == SPEED
        assert by_serial["SN-A"].document["unit"]["serial"] == "SN-A"
    code, out, _ = invoke("batch", manifest, "--store", store_url, "--limits", lot / "limits.toml")
    assert code == 1 and "4 row(s) already in the store" in out  # the rerun exits as the first run did
    with open_store(store_url) as store:
        assert store.count() == 4


def test_without_limits_every_calibrated_unit_exits_zero(lot, tmp_path):
    manifest = _manifest(tmp_path, [f"{lot / 'a.csv'},SN-A,calibrate,{SPEED},bench-1",
                                    f"{lot / 'c.csv'},SN-C,calibrate,{SPEED},bench-1"])
    code, out, err = invoke("batch", manifest, "--store", tmp_path / "s.db")
    assert code == 0, err
    with open_store(tmp_path / "s.db") as store:
        assert [r.verdict for r in store.list()] == [None, None]


@pytest.mark.parametrize("text, says", [
    ("file,serial,job\nx.csv,S1,calibrate\n", "lacks the column(s) args"),
    ("file,serial,job,args\nx.csv,S1,fit,\n", "unknown job 'fit'"),
    ("file,serial,job,args\nx.csv,S1,calibrate,--unit S2\n", "args sets --unit"),
    ("file,serial,job,args\nx.csv,a/b,calibrate,\n", "holds '/', which a file name cannot hold"),
    ("file,serial,job,args,colour\nx.csv,S1,calibrate,,red\n", "unknown column 'colour'"),
    ("file,serial,job,args\n", "has no rows"),
])
def test_bad_manifests_are_refused_before_anything_runs(tmp_path, text, says):
    manifest = tmp_path / "m.csv"
    manifest.write_text(text)
    assert says in refused("batch", manifest, "--store", tmp_path / "s.db")
    assert not (tmp_path / "s.db").exists()


def test_unreachable_store_is_one_line(lot, tmp_path):
    manifest = _manifest(tmp_path, [f"{lot / 'a.csv'},SN-A,calibrate,{SPEED},bench-1"])
    line = refused("batch", manifest, "--store", "postgresql://nobody@127.0.0.1:1/none")
    assert "127.0.0.1" in line


def test_history_export_and_list(lot, tmp_path):
    """Two calibrations of one unit: history shows the second's change since the first in sigmas, worked
    here as (new - old) / hypot(sigma_new, sigma_old); export --at picks the one in force at each time."""
    store = tmp_path / "s.db"
    for name in ("a", "b"):
        time.sleep(1.05 - time.time() % 1)  # records are stamped to the second: the two in different seconds
        code, _, err = invoke("calibrate", lot / f"{name}.csv", *SPEED.split(), "--unit", "SN-H", "--store", store,
                              "-o", tmp_path / f"{name}.json")
        assert code == 0, err
    code, out, _ = invoke("store", "history", "SN-H", "--store", store, "--json")
    newest, oldest = json.loads(out)
    assert oldest["change_sigma"] is None
    new, old = newest["document"], oldest["document"]
    for i, axis in enumerate("xyz"):
        expected = (new["parameters"]["scale_bias"]["k"][i] - old["parameters"]["scale_bias"]["k"][i]) / math.hypot(
            new["std"][f"k{axis}"], old["std"][f"k{axis}"])
        assert newest["change_sigma"][f"k{axis}"] == pytest.approx(expected, rel=1e-12)
    assert new["as_found"]["record"] == oldest["id"]  # the second session was first corrected with the first
    code, out, _ = invoke("store", "list", "--store", f"sqlite:///{store}", "--json")
    listed = json.loads(out)
    assert [r["id"] for r in listed] == [newest["id"], oldest["id"]]
    assert set(listed[0]) >= {"id", "serial", "kind", "created", "station", "input_sha256", "verdict", "document"}
    code, _, _ = invoke("store", "export", "SN-H", "--store", store, "-o", tmp_path / "now.json")
    assert code == 0 and json.loads((tmp_path / "now.json").read_text()) == new
    code, _, _ = invoke("store", "export", "SN-H", "--store", store, "-o", tmp_path / "then.json", "--at",
                        oldest["created"])
    assert code == 0 and json.loads((tmp_path / "then.json").read_text()) == old
    assert "no calibration in force" in refused("store", "export", "SN-H", "--store", store, "-o",
                                                tmp_path / "x.json", "--at", "2001-01-01T00:00:00Z")
    assert "ISO 8601" in refused("store", "list", "--store", store, "--since", "yesterday")


def test_apply_takes_the_calibration_in_force_from_the_store(lot, tmp_path):
    """apply --store --unit: the unit's calibration in force at the recording's file time (or --at) corrects it
    exactly as the exported file does (reference: apply with that file)."""
    store = tmp_path / "s.db"
    code, _, err = invoke("calibrate", lot / "a.csv", *SPEED.split(), "--unit", "SN-P", "--store", store,
                          "-o", tmp_path / "a.json")
    assert code == 0, err
    recording = tmp_path / "rec.csv"
    recording.write_bytes((lot / "b.csv").read_bytes())  # written now: after the calibration
    code, out, err = invoke("apply", "--store", store, "--unit", "SN-P", recording, "-o", tmp_path / "from-store.csv")
    assert code == 0, err
    assert "record 1 of" in out and "the recording's file time" in out
    code, _, err = invoke("apply", tmp_path / "a.json", recording, "-o", tmp_path / "from-file.csv")
    assert code == 0, err
    body = [line for line in (tmp_path / "from-store.csv").read_text().splitlines() if not line.startswith("#")]
    assert body == [line for line in (tmp_path / "from-file.csv").read_text().splitlines() if not line.startswith("#")]
    assert "no calibration in force" in refused("apply", "--store", store, "--unit", "SN-P", recording, "-o",
                                                tmp_path / "x.csv", "--at", "2001-01-01T00:00:00Z")
    assert "--unit SERIAL" in refused("apply", "--store", store, recording, "-o", tmp_path / "x.csv")
    assert "give only the recording" in refused("apply", "--store", store, "--unit", "SN-P", tmp_path / "a.json",
                                                recording, "-o", tmp_path / "x.csv")


def test_ctrl_c_keeps_what_finished_and_leaves_nothing_half_written(lot, tmp_path):
    """SIGINT to a running batch: one line, exit 2; every stored record has its result file and no temporary
    file is left (reference: the store's own count against the folder)."""
    import signal
    import subprocess
    import sys
    from pathlib import Path

    rows = []
    for i in range(12):  # distinct inputs (a rerun check is by content)
        copy = tmp_path / f"u{i}.csv"
        copy.write_text(f"# copy {i}\n" + (lot / "a.csv").read_text())
        rows.append(f"{copy},SN-{i},calibrate,{SPEED},bench-1")
    manifest = _manifest(tmp_path, rows)
    store = tmp_path / "s.db"
    proc = subprocess.Popen([str(Path(sys.executable).with_name("gyrocal")), "batch", str(manifest), "--store",
                             str(store)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while not (store.exists() and _count(store) >= 1):
            assert proc.poll() is None and time.monotonic() < deadline, "no row finished"
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=120) == 2
        lines = proc.stderr.read().strip().splitlines()
    finally:
        proc.kill()
        proc.stderr.close()
    assert len(lines) == 1 and lines[0].startswith("error: interrupted:"), lines
    results = sorted((tmp_path / "results").iterdir())
    assert all(p.suffix == ".json" and ".tmp" not in p.name for p in results)
    assert 1 <= _count(store) == len(results) < 12


def _count(store) -> int:
    with open_store(store) as st:
        return st.count()


def test_a_store_of_a_newer_schema_is_refused_by_every_command(lot, tmp_path):
    """A store a newer gyrocal migrated (its alembic_version stamped ahead, with sqlite3 directly): refused in one
    line, and nothing is written to it."""
    import sqlite3

    store = tmp_path / "s.db"
    with open_store(store):
        pass
    with sqlite3.connect(store) as connection:
        connection.execute("UPDATE alembic_version SET version_num = '9999'")
    for args in (("store", "list", "--store", store),
                 ("calibrate", lot / "a.csv", *SPEED.split(), "--unit", "SN-N", "--store", store)):
        assert "newer than this gyrocal" in refused(*args)
    with sqlite3.connect(store) as connection:
        assert connection.execute("SELECT count(*) FROM records").fetchone()[0] == 0
