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
