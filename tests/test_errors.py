"""Structured errors: the library names the parameter, the command line shows its flag.

Reference for the flag table: the flags the commands really define (typer's own parameter list), and
every ``param="..."`` the library source raises with (read as text).
"""

import re
from pathlib import Path

import typer
from cli_runner import invoke, refused

import gyrocal
from gyrocal.cli import app
from gyrocal.cli._flags import FLAGS, NOT_FLAGS, flag
from gyrocal.errors import ConvergenceError, FileFormatError, GyrocalError, InputError, OutOfRangeError

SRC = Path(gyrocal.__file__).parent


def test_render_fills_in_the_name_of_the_caller():
    exc = OutOfRangeError("2 readings outside [0, 40] degC", param="out_of_range", value="refuse",
                          hint="set {param} to 'clamp' or 'extrapolate' to accept them")
    assert str(exc) == "2 readings outside [0, 40] degC; set out_of_range to 'clamp' or 'extrapolate' to accept them"
    assert exc.render(flag).endswith("set --out-of-range to 'clamp' or 'extrapolate' to accept them")
    assert (exc.param, exc.value) == ("out_of_range", "refuse")
    plain = InputError("no data")
    assert str(plain) == "no data" and plain.param is None and plain.hint is None
    assert ConvergenceError("stuck", 7, param="method").iterations == 7
    assert FileFormatError("bad", "units.input").field == "units.input"
    assert isinstance(InputError("x"), ValueError) and isinstance(InputError("x"), GyrocalError)
    both = InputError("no column for gx", param="columns", hint="map it with {param} gx=NAME, or {param:skip_rows} N")
    assert str(both) == "no column for gx; map it with columns gx=NAME, or skip_rows N"
    assert both.render(flag) == "no column for gx; map it with --columns gx=NAME, or --skip-rows N"


def _all_flags() -> set[str]:
    command = typer.main.get_command(app)
    flags = set()
    for sub in command.commands.values():
        for param in sub.params:
            if param.param_type_name == "option":
                flags.update(param.opts)
    return flags


def test_every_flag_in_the_table_exists():
    missing = {f for f in FLAGS.values() if f not in _all_flags()}
    assert not missing


def test_every_parameter_the_library_names_has_a_flag_or_is_declared_flagless():
    named = set()
    for path in SRC.rglob("*.py"):
        if "cli" in path.parts:
            continue
        text = path.read_text()
        named.update(re.findall(r"""\bparam=["']([A-Za-z_][\w.]*)["']""", text))
        named.update(re.findall(r"\{param:([A-Za-z_]\w*)\}", text))
    unknown = named - set(FLAGS) - NOT_FLAGS
    assert not unknown, f"add these to gyrocal/cli/_flags.py: {sorted(unknown)}"


def test_the_command_line_shows_flags_not_parameter_names(tmp_path):
    line = refused("simulate", "-o", tmp_path / "t.csv", "--protocol", "turntable", "--temp-quantum", "-1")
    assert "--temp-quantum must be finite and > 0" in line and "temp_quantum" not in line
    line = refused("simulate", "-o", tmp_path / "t.csv", "--protocol", "turntable", "--rates", "-5,10")
    assert "--rates are magnitudes >= 0 deg/s" in line


def test_help_lists_calibrate_first():
    code, out, _ = invoke("--help")
    assert code == 0
    listing = out[out.index("Commands:"):]
    names = re.findall(r"^  ([a-z-]+) ", listing, flags=re.M)
    assert names[:4] == ["calibrate", "segments", "apply", "export"], out
