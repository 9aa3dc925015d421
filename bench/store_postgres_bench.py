"""The calibration store on PostgreSQL: many stations writing one server, and one unit's history.

Run by hand:  python bench/store_postgres_bench.py [--records 100000] [--stations 4] [--inserts 500]

Starts a throw-away PostgreSQL server from the machine's binaries (as the tests do, tests/pg_server.py),
then, in this process and in `--stations` spawned processes:

* ``add`` from one station: ``Store.add`` one record per transaction (each a full calibration's commit),
  the baseline;
* ``add`` from `--stations` stations at once: the records per second the server takes in all;
* the store filled to `--records` records, ``history(serial)`` of one unit (10 records), median of 200,
  against the same query with index scans switched off (a table scan), median of 20.
"""

from __future__ import annotations

import argparse
import multiprocessing
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from pg_server import PostgresServer  # noqa: E402  (the tests' throw-away server)
from sqlalchemy import text  # noqa: E402
from store_bench import PER_UNIT, _item, _median  # noqa: E402

from gyrocal.store import open_store  # noqa: E402


def _station(url: str, first: int, count: int) -> float:
    with open_store(url) as store:
        start = time.perf_counter()
        for i in range(first, first + count):
            store.add(**_item(i))
        return time.perf_counter() - start


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=int, default=100_000)
    parser.add_argument("--stations", type=int, default=4)
    parser.add_argument("--inserts", type=int, default=500, help="records per station")
    options = parser.parse_args(argv)
    server = PostgresServer()
    server.start()
    try:
        url = server.create_database("bench")
        open_store(url).close()
        one = _station(url, 0, options.inserts)
        print(f"add, 1 station:  {options.inserts / one:8.0f} records/s ({one / options.inserts * 1e3:.2f} ms each)")
        n = options.stations
        with multiprocessing.get_context("spawn").Pool(n) as pool:
            times = pool.starmap(_station, [(url, (s + 1) * options.inserts, options.inserts) for s in range(n)])
        wall = max(times)  # each station's own inserting time (their start-up left out); they overlap
        print(f"add, {n} stations: {n * options.inserts / wall:8.0f} records/s in all "
              f"({n * options.inserts / wall / (options.inserts / one):.2f} x one station)")
        with open_store(url) as store:
            done = (n + 1) * options.inserts
            for first in range(done, options.records, 5000):
                store.add_many(_item(i) for i in range(first, min(first + 5000, options.records)))
            serial = f"SN{(options.records // PER_UNIT) // 2:07d}"
            indexed = _median(lambda: store.history(serial), 200)
            with store._engine.connect() as connection:  # the same query as a table scan
                connection.execute(text("SET enable_indexscan = off"))
                connection.execute(text("SET enable_bitmapscan = off"))
                query = text("SELECT * FROM records WHERE serial = :s ORDER BY created DESC, id DESC")
                scan = _median(lambda: connection.execute(query, {"s": serial}).fetchall(), 20)
        print(f"history(serial) among {options.records}: {indexed * 1e3:.2f} ms (median of 200); table scan "
              f"{scan * 1e3:.1f} ms: {scan / indexed:.0f} x")
    finally:
        server.stop()


if __name__ == "__main__":
    main()
