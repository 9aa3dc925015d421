"""The production station's batch: sessions per second on 1 and 2 workers, and what the store costs in it.

Run by hand:  python bench/bench_station.py [--sessions 100] [--keep DIR]

Simulates `--sessions` servo sessions of about 60 s at 200 Hz (the six turns of the servo method of
Wang et al. with static waits), writes a manifest, and runs ``gyrocal batch`` on it in this process
twice into fresh SQLite stores: with ``-j 1`` (the baseline) and ``-j 2``. Then it times, in this
process, the store's own part of each calibration on the documents just made (the rerun check, the
calibration in force for as-found, the insert, the batch's own lookups), against the batch's time
per session.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from cli_runner import invoke  # noqa: E402  (the CLI in-process, as the tests run it)


def _sessions(folder: Path, count: int) -> Path:
    rows = ["file,serial,job,args,station"]
    for i in range(count):
        code, _, err = invoke("simulate", "-o", folder / f"s{i}.csv", "--seed", str(i), "--wait", "6")
        if code:
            raise SystemExit(err)
        rows.append(f"s{i}.csv,SN{i:05d},calibrate,--units deg/s --speed 60,bench-{i % 3}")
    manifest = folder / "manifest.csv"
    manifest.write_text("\n".join(rows) + "\n")
    return manifest


def _batch(manifest: Path, store: Path, jobs: int) -> float:
    start = time.perf_counter()
    code, out, err = invoke("batch", manifest, "--store", store, "-j", jobs, "--output-dir",
                            manifest.parent / f"out{jobs}")
    seconds = time.perf_counter() - start
    if code:
        raise SystemExit(f"batch -j {jobs} exited {code}: {err or out}")
    return seconds


def _store_part(store: Path, fresh: Path) -> tuple[float, int]:
    """Seconds the store takes for the records of `store` replayed into `fresh` as the batch and command do."""
    from gyrocal.store import open_store

    with open_store(store) as st:
        records = st.list()
    start = time.perf_counter()
    with open_store(fresh) as batch_side, open_store(fresh) as worker_side:  # each keeps its store open
        for r in reversed(records):
            batch_side.find(r.input_sha256, r.job, r.args)  # the batch's rerun check
            worker_side.in_force(r.serial)  # the command: as found, then the record
            worker_side.add(r.serial, r.kind, r.document, station=r.station, verdict=r.verdict,
                            input_sha256=r.input_sha256, job=r.job, args=r.args)
    return time.perf_counter() - start, len(records)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sessions", type=int, default=100)
    parser.add_argument("--keep", type=Path, help="work in this (empty) folder and keep it")
    options = parser.parse_args(argv)
    folder = options.keep or Path(tempfile.mkdtemp(prefix="gyrocal-station-bench-"))
    folder.mkdir(parents=True, exist_ok=True)
    manifest = _sessions(folder, options.sessions)
    one = _batch(manifest, folder / "one.db", 1)
    two = _batch(manifest, folder / "two.db", 2)
    n = options.sessions
    print(f"batch -j 1: {one:7.2f} s  {n / one:6.2f} sessions/s (baseline)")
    print(f"batch -j 2: {two:7.2f} s  {n / two:6.2f} sessions/s  ({one / two:.2f} x the baseline)")
    store_s, records = _store_part(folder / "one.db", folder / "replay.db")
    print(f"store part of a calibration: {store_s / records * 1e3:.1f} ms ({records} records: rerun check, "
          f"as-found lookup, insert), {100 * store_s / one:.1f} % of the -j 1 batch")
    if options.keep is None:
        shutil.rmtree(folder)


if __name__ == "__main__":
    main()
