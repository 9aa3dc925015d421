"""Shared pieces of the store's tests: raw driver access (no SQLAlchemy), times, spawned writers."""

from __future__ import annotations

import multiprocessing
import queue
import sqlite3
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
    """Run `target(*args, barrier, results)` in one spawned process per args tuple; what they put, sorted."""
    context = multiprocessing.get_context("spawn")
    barrier = context.Barrier(len(args_per_worker))
    results = context.Queue()
    processes = [context.Process(target=target, args=(*args, barrier, results)) for args in args_per_worker]
    for process in processes:
        process.start()
    out = []
    try:
        for _ in processes:
            out.append(results.get(timeout=timeout))
    except queue.Empty:
        raise AssertionError(f"only {len(out)} of {len(processes)} workers reported") from None
    finally:
        for process in processes:
            process.join(timeout=30)
    assert [p.exitcode for p in processes] == [0] * len(processes)
    return sorted(out)


__all__ = ["T0", "at", "raw_execute", "spawn", "store_workers"]
