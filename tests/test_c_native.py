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


def _mirrors() -> dict:
    """The ctypes mirrors of the C structs, by C type name."""
    from gyrocal.capture import c_device as cd
    from gyrocal.firmware import host

    return {"gyrocal_hello_t": cd._Hello, "gyrocal_turn_t": cd._Turn, "gyrocal_accum_t": cd._Accum,
            "gyrocal_obs_t": cd._Obs, "gyrocal_scale_bias_t": cd._ScaleBias, "gyrocal_session_t": cd._Session,
            "gyrocal_affine_t": host._Affine, "gyrocal_imu_t": host._Imu, "gyrocal_thermal_t": host._Thermal,
            "host gyrocal_accum_t": host._Accum, "host gyrocal_obs_t": host._Obs,
            "host gyrocal_scale_bias_t": host._ScaleBias}


def test_ctypes_mirrors_match_the_headers(tmp_path):
    """Reference: the host compiler's sizeof and offsetof of every mirrored struct and field (a probe built
    from the headers), and the headers' GYROCAL_FRAME_MAX and GYROCAL_TURN_* codes."""
    import ctypes

    from gyrocal.capture import c_device as cd
    from gyrocal.capture import frames

    lines, want = [], {}
    for key, cls in _mirrors().items():
        ctype = key.split()[-1]
        lines.append(f'printf("{key} %zu\\n", sizeof({ctype}));')
        want[key] = ctypes.sizeof(cls)
        for name, *_ in cls._fields_:
            lines.append(f'printf("{key}.{name} %zu\\n", offsetof({ctype}, {name}));')
            want[f"{key}.{name}"] = getattr(cls, name).offset
    lines.append('printf("FRAME_MAX %u\\n", (unsigned)GYROCAL_FRAME_MAX);')
    want["FRAME_MAX"] = ctypes.sizeof(cd._BUF)
    probe = tmp_path / "probe.c"
    probe.write_text('#include <stddef.h>\n#include <stdio.h>\n#include "gyrocal_session.h"\nint main(void)\n{\n'
                     + "\n".join(lines) + "\nreturn 0;\n}\n")
    exe = tmp_path / "probe"
    build = subprocess.run([_compiler(), *FLAGS, f"-I{c_source_dir()}", str(probe), "-o", str(exe)],
                           capture_output=True, text=True, check=False)
    assert build.returncode == 0, build.stderr
    out = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout.split("\n")
    got = {key: int(value) for key, value in (line.rsplit(" ", 1) for line in out if line)}
    assert got == want
    header = (c_source_dir() / "gyrocal_frame.h").read_text()
    codes = {int(v): name for name, v in re.findall(r"#define GYROCAL_TURN_(\w+) (\d+)u", header)}
    assert sorted(codes) == list(range(len(cd._REASONS))) and codes[0] == "ACCEPTED"
    assert {k: v.upper().replace(" ", "_") for k, v in frames._TURN_REASONS.items()} == \
        {k: v for k, v in codes.items() if k} == {k: r.split(": ")[1].upper().replace(" ", "_")
                                                  for k, r in enumerate(cd._REASONS) if k}
