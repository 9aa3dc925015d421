"""The calibration store on SQLite: insert rate, and one unit's history in a large store.

Run by hand:  python bench/store_bench.py [--records 100000 | --million] [--inserts 2000] [--keep DIR]

Stages, all in this process on one fresh SQLite file:

* ``add``: ``Store.add`` one record at a time, one transaction (and one fsync) each: the naive baseline;
* ``add_many``: the same records through ``Store.add_many``, 1000 per transaction;
* the store is then filled to ``--records`` records (``add_many``, 10 records per unit), and
* ``history``: ``Store.history(serial)`` of one unit (10 records), median of 200 calls, against
* ``full scan``: the same query through the bare sqlite3 driver with ``NOT INDEXED`` (a table scan, what
  a store without the serial index would do), median of 20 calls.

Prints seconds, records/s, and the ratios add_many / add and full scan / history.
"""

from __future__ import annotations

import argparse
import sqlite3
import statistics
import tempfile
import time
from datetime import UTC, datetime, timedelta
from pathlib import Path

from gyrocal.store import open_store

PER_UNIT = 10
T0 = datetime(2024, 1, 1, tzinfo=UTC)


def _document(i: int) -> dict:
    """About 400 bytes of JSON, the size of a small calibration result."""
    return {"kind": "calibration.servo", "correction": {"matrix": [[1.0 + i * 1e-9, 0.001, -0.002]] * 3,
                                                         "bias": [0.01, -0.02, 0.003]},
            "fit": {"rms": 0.0012, "chi2": 5.1, "dof": 12}, "notes": [f"run {i}"]}


def _item(i: int) -> dict:
    return {"serial": f"SN{i // PER_UNIT:07d}", "kind": "calibration.servo", "document": _document(i),
            "created": T0 + timedelta(seconds=i), "station": f"bench-{i % 4}", "operator": "bench",
            "verdict": "pass" if i % 7 else "fail", "input_sha256": f"{i:064x}", "job": "bench", "args": "--x"}


def _rate(count: int, seconds: float) -> str:
    return f"{seconds:8.3f} s  {count / seconds:10.0f} records/s"


def _inserts(store, count: int) -> tuple[float, float]:
    start = time.perf_counter()
    for i in range(count):
        store.add(**_item(i))
    one_each = time.perf_counter() - start
    start = time.perf_counter()
    for first in range(count, 2 * count, 1000):
        store.add_many(_item(i) for i in range(first, min(first + 1000, 2 * count)))
    batched = time.perf_counter() - start
    print(f"add       (1 transaction per record)   {count:8d}: {_rate(count, one_each)}")
    print(f"add_many  (1000 per transaction)        {count:8d}: {_rate(count, batched)}")
    print(f"add_many / add: {one_each / batched:.1f} x the insert rate")
    return one_each, batched


def _fill(store, start: int, records: int) -> None:
    begin = time.perf_counter()
    for first in range(start, records, 5000):
        store.add_many(_item(i) for i in range(first, min(first + 5000, records)))
    print(f"filled to {records} records ({records // PER_UNIT} units): {_rate(records - start, time.perf_counter() - begin)}")


def _median(call, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def _history(store, path: Path, records: int) -> None:
    serial = f"SN{(records // PER_UNIT) // 2:07d}"
    assert len(store.history(serial)) == PER_UNIT
    indexed = _median(lambda: store.history(serial), 200)
    connection = sqlite3.connect(path)
    query = "SELECT * FROM records NOT INDEXED WHERE serial = ? ORDER BY created DESC, id DESC"
    assert len(connection.execute(query, (serial,)).fetchall()) == PER_UNIT
    scan = _median(lambda: connection.execute(query, (serial,)).fetchall(), 20)
    connection.close()
    print(f"history(serial) of {PER_UNIT} records among {records}: {indexed * 1e3:8.3f} ms (median of 200)")
    print(f"full scan, bare sqlite3, no index:          {scan * 1e3:8.3f} ms (median of 20)")
    print(f"full scan / history: {scan / indexed:.0f} x")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=int, default=100_000, help="records in the store for history()")
    parser.add_argument("--million", action="store_true", help="a store of 1,000,000 records")
    parser.add_argument("--inserts", type=int, default=2000, help="records per insert stage")
    parser.add_argument("--keep", type=Path, help="write the store into this folder and keep it")
    options = parser.parse_args(argv)
    records = 1_000_000 if options.million else options.records
    folder = options.keep or Path(tempfile.mkdtemp(prefix="gyrocal-store-bench-"))
    path = folder / "bench.db"
    if path.exists():
        raise SystemExit(f"{path} exists; give an empty --keep folder")
    print(f"store: {path} (SQLite {sqlite3.sqlite_version}, WAL, synchronous=FULL)")
    with open_store(path) as store:
        _inserts(store, options.inserts)
        _fill(store, 2 * options.inserts, records)
        _history(store, path, records)
    size = sum(p.stat().st_size for p in folder.glob("bench.db*"))
    print(f"file size: {size / 2**20:.1f} MiB ({size / records:.0f} bytes per record)")
    if options.keep is None:
        for leftover in folder.glob("bench.db*"):
            leftover.unlink()
        folder.rmdir()


if __name__ == "__main__":
    main()
