import numpy as np
import pytest

#: Tests that skipped (or xfailed) in this run; any makes the run fail (see pytest_sessionfinish).
_NOT_RUN: list[str] = []


@pytest.fixture
def rng(request) -> np.random.Generator:
    """A generator seeded from the test's name: reproducible, and different per test."""
    import zlib

    return np.random.default_rng(zlib.crc32(request.node.nodeid.encode()))


def pytest_runtest_logreport(report):
    if report.skipped:
        _NOT_RUN.append(f"{report.nodeid}: {report.longrepr[-1] if isinstance(report.longrepr, tuple) else ''}")


def pytest_sessionfinish(session, exitstatus):
    """A test that skips in CI does not exist: the `test` extra installs everything, so any skip fails the run."""
    if _NOT_RUN and exitstatus == pytest.ExitCode.OK:
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


def pytest_terminal_summary(terminalreporter):
    if _NOT_RUN:
        terminalreporter.write_line(f"FAILED: {len(_NOT_RUN)} test(s) did not run (skipped); every test must run:",
                                    red=True)
        for line in _NOT_RUN:
            terminalreporter.write_line(f"  {line}", red=True)


@pytest.fixture(scope="session")
def pg_server():
    """A PostgreSQL server for this test session (tests/pg_server.py); a missing binary fails, never skips."""
    from pg_server import MissingPostgres, PostgresServer

    try:
        server = PostgresServer()
        server.start()
    except (MissingPostgres, RuntimeError) as exc:
        pytest.fail(str(exc), pytrace=False)
    yield server
    server.stop()


@pytest.fixture
def pg_url(pg_server, request) -> str:
    """The URL of a fresh, empty database on the session's PostgreSQL server."""
    import zlib

    return pg_server.create_database(f"t{zlib.crc32(request.node.nodeid.encode()):08x}")


@pytest.fixture(params=["sqlite", "postgresql"])
def store_url(request, tmp_path) -> str:
    """A fresh store's URL: an SQLite file in tmp_path, then a fresh PostgreSQL database."""
    if request.param == "sqlite":
        return str(tmp_path / "store.db")
    return request.getfixturevalue("pg_url")
