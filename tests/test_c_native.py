"""The C library's own tests (tests/c/test_*.c), compiled with AddressSanitizer and UndefinedBehaviorSanitizer.

Each C test program is linked with every source of the library (src/gyrocal/c/*.c) and must exit 0 with
nothing on stderr; an out-of-bounds access, a NULL dereference or undefined behaviour makes the
sanitizers abort the program. A missing C compiler fails these tests: CI installs one.
References: the numbers worked out by hand inside each C test, the header gyrocal_cal.h itself (for
the status codes), and the Python tables that must agree with it.
"""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import pytest

from gyrocal.capture.frames import STATUS_NAMES
from gyrocal.errors import GyrocalError
from gyrocal.firmware import c_source_dir, find_c_compiler
from gyrocal.firmware.host import STATUS

C_TESTS = sorted((Path(__file__).parent / "c").glob("test_*.c"))
SANITIZE = ("-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer")
FLAGS = ("-std=c99", "-O1", "-g", "-ffp-contract=off", "-Wall", "-Wextra", "-Werror")


def _compiler() -> str:
    cc = find_c_compiler()
    if cc is None:
        pytest.fail("no C compiler (cc, gcc or clang; or set CC): the C library cannot be tested; install one")
    return cc


@pytest.mark.parametrize("source", C_TESTS, ids=[p.stem for p in C_TESTS])
def test_c_program_passes_under_sanitizers(source, tmp_path):
    cc = _compiler()
    exe = tmp_path / source.stem
    src = c_source_dir()
    build = subprocess.run([cc, *FLAGS, *SANITIZE, f"-I{src}", str(source), *map(str, sorted(src.glob("*.c"))),
                            "-lm", "-o", str(exe)], capture_output=True, text=True, check=False)
    assert build.returncode == 0, build.stderr
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1:abort_on_error=0", UBSAN_OPTIONS="print_stacktrace=1")
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120, env=env, check=False)
    assert run.returncode == 0 and run.stderr == "", run.stderr


def test_there_are_native_tests():
    assert [p.name for p in C_TESTS][:1] == ["test_gyrocal_cal.c"]


def test_status_codes_agree_between_c_and_python():
    header = (c_source_dir() / "gyrocal_cal.h").read_text()
    body = header[header.index("typedef enum {"):header.index("} gyrocal_status_t;")]
    codes = {int(value): name for name, value in re.findall(r"(GYROCAL_\w+)\s*=\s*(\d+)", body)}
    assert codes[0] == "GYROCAL_OK" and len(codes) == 6
    assert {k: v for k, v in codes.items() if k} == {k: name for k, (name, _) in STATUS.items()}
    assert all(issubclass(cls, GyrocalError) for _, cls in STATUS.values())
    assert {k: v for k, v in STATUS_NAMES.items() if k in codes} == codes
