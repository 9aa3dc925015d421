"""Functions the store's concurrency tests run in spawned processes (importable by name, so picklable)."""

from __future__ import annotations


def insert_many(url: str, worker: int, count: int, barrier, results) -> None:
    """Open the store at `url`, wait for the others, then add `count` records one transaction each."""
    from gyrocal.store import open_store

    with open_store(url) as store:
        barrier.wait(timeout=60)
        ids = [store.add(f"SN-{worker}", "calibration.servo", {"worker": worker, "i": i}, verdict="pass")
               for i in range(count)]
    results.put((worker, ids))


def create_and_add(url: str, worker: int, barrier, results) -> None:
    """Wait for the others, then open (and so create) the store at `url` and add one record."""
    import gyrocal.store.store  # noqa: F401 - SQLAlchemy and Alembic loaded before the race, not during it
    from gyrocal.store import open_store

    barrier.wait(timeout=60)
    with open_store(url) as store:
        results.put((worker, store.add(f"SN-{worker}", "imu", {"worker": worker}), store.revision()))
