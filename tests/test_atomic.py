"""Atomic output: a failed write leaves the old file and no temporary; a new file gets normal permissions.

References: the file system itself (contents, modes, names left behind) and a real process killed by
SIGTERM.
"""

import os
import stat

import pytest

from gyrocal._atomic import atomic_path, write_text_atomic


def test_a_failed_write_keeps_the_old_file_and_leaves_no_temporary(tmp_path):
    target = tmp_path / "cal.json"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("writer failed")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["cal.json"]


def test_a_new_file_gets_the_umask_mode_not_a_private_one(tmp_path):
    old = os.umask(0o022)
    try:
        write_text_atomic(tmp_path / "new.json", "{}")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "new.json").stat().st_mode) == 0o644


def test_a_replaced_file_keeps_its_mode(tmp_path):
    target = tmp_path / "cal.json"
    target.write_text("old")
    target.chmod(0o640)
    write_text_atomic(target, "new")
    assert target.read_text() == "new"
    assert stat.S_IMODE(target.stat().st_mode) == 0o640


_WRITER = """
import sys, time
from gyrocal._atomic import atomic_path
with atomic_path(sys.argv[1]) as tmp:
    with open(tmp, "w") as f:
        f.write("half a file")
        f.flush()
        print("writing", flush=True)
        time.sleep(60)
"""


@pytest.mark.parametrize("replace", [False, True])
def test_sigterm_during_a_write_leaves_no_temporary_and_kills_with_the_signal(tmp_path, replace):
    """A real process, stopped by SIGTERM while its temporary file is half written (the reference:
    what Ctrl-C leaves, the folder as it was before the run)."""
    import signal
    import subprocess
    import sys

    target = tmp_path / "out.csv"
    if replace:
        target.write_text("old")
    proc = subprocess.Popen([sys.executable, "-c", _WRITER, str(target)], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().strip() == "writing"
        assert len(list(tmp_path.iterdir())) == 1 + replace  # the temporary is there
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=30) == -signal.SIGTERM  # it still dies of the signal
    finally:
        proc.kill()
        proc.stdout.close()
    assert [p.name for p in tmp_path.iterdir()] == (["out.csv"] if replace else [])
    if replace:
        assert target.read_text() == "old"


def test_handlers_are_restored_and_a_programs_own_handler_is_kept(tmp_path):
    import signal

    before = signal.getsignal(signal.SIGTERM)
    write_text_atomic(tmp_path / "a.txt", "x")
    assert signal.getsignal(signal.SIGTERM) is before

    def mine(signum, frame):  # pragma: no cover - never called
        pass

    signal.signal(signal.SIGTERM, mine)
    try:
        with atomic_path(tmp_path / "b.txt") as tmp:
            assert signal.getsignal(signal.SIGTERM) is mine
            tmp.write_text("y")
    finally:
        signal.signal(signal.SIGTERM, before)
    assert (tmp_path / "b.txt").read_text() == "y"
