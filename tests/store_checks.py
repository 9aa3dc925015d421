"""Shared pieces of the store's tests: raw driver access (no SQLAlchemy), times, spawned writers."""

from __future__ import annotations

import multiprocessing
import queue
import sqlite3
import time
from datetime import UTC, datetime, timedelta

import store_workers

T0 = datetime(2024, 5, 1, 12, 0, tzinfo=UTC)


def at(hours: float) -> datetime:
    """T0 plus `hours`."""
    return T0 + timedelta(hours=hours)


def raw_execute(url: str, sql: str) -> None:
    """Run `sql` on the store's database through the bare driver, committing."""
    if url.startswith("postgresql://"):
        import psycopg

        with psycopg.connect(url) as connection:
            connection.execute(sql)
        return
    connection = sqlite3.connect(url)
    try:
        connection.execute(sql)
        connection.commit()
    finally:
        connection.close()


def spawn(target, args_per_worker: list[tuple], timeout: float = 90) -> list[tuple]:
    """Run `target(*args, barrier, results)` in one spawned process per args tuple; what they put, sorted.

    Fails (and ends the workers) when one dies, or when they have not all reported within `timeout` s.
    """
    context = multiprocessing.get_context("spawn")
    barrier = context.Barrier(len(args_per_worker))
    results = context.Queue()
    processes = [context.Process(target=target, args=(*args, barrier, results)) for args in args_per_worker]
    for process in processes:
        process.start()
    out, deadline = [], time.monotonic() + timeout
    try:
        while len(out) < len(processes) and time.monotonic() < deadline:
            try:
                out.append(results.get(timeout=0.2))
            except queue.Empty:
                dead = [p.exitcode for p in processes if p.exitcode not in (None, 0)]
                assert not dead, f"a worker failed (exit status {dead[0]}); its traceback is above"
        assert len(out) == len(processes), f"only {len(out)} of {len(processes)} workers reported in {timeout} s"
    finally:
        for process in processes:
            process.join(timeout=30)
            if process.is_alive():
                process.terminate()
                process.join()
    assert [p.exitcode for p in processes] == [0] * len(processes)
    return sorted(out)


__all__ = ["T0", "at", "raw_execute", "spawn", "store_workers"]
