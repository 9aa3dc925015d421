"""The command line's plain conversion of values (``gyrocal.cli._coerce``) against typer's own.

Reference: typer's pydantic-based conversion of the same parameter (``typer._coercion``), run on
the same values: every parameter of every command gives the same value, or the same refusal.
"""

import math
import subprocess
import sys
from pathlib import Path

import pytest
import typer
from typer._click.core import Context
from typer._coercion import build_runtime_param

from gyrocal.cli import app
from gyrocal.cli._coerce import install

NUMBERS = ["1", "-7", "+3", "007", "1.5", "-2e-3", ".5", "1.", "1e999", "inf", "nan", "abc", "", " 2", "1_000",
           "0x10", "1.0", 3, 2.0, 2.5, True]
WORDS = ["abc", "", "ü", "60deg/s", 5]
FLAGS = [True, False, "true", "no"]


def _params():
    group = typer.main.get_command(app)
    install(group)
    out = []

    def walk(cmd, path):
        for p in cmd.params:
            if type(getattr(p, "_runtime_param", None)).__name__ == "Plain":
                out.append((path, cmd, p))
        for name, sub in getattr(cmd, "commands", {}).items():
            walk(sub, f"{path} {name}")

    walk(group, "gyrocal")
    return out


PARAMS = _params()


def _outcome(runtime, value, param, ctx):
    try:
        return "ok", runtime.coerce(value, param=param, ctx=ctx)
    except Exception as exc:  # the refusal itself is compared
        return type(exc).__name__, str(exc)


def _same(a, b) -> bool:
    if a[0] != b[0] or type(a[1]) is not type(b[1]):
        return False
    if isinstance(a[1], float):
        return (math.isnan(a[1]) and math.isnan(b[1])) or math.isclose(a[1], b[1], rel_tol=1e-15)
    return a[1] == b[1]


def _values(desc, tmp: Path):
    from typer._typing import is_literal_type, literal_values

    ann = desc.annotation
    if is_literal_type(ann):
        choices = list(literal_values(ann))
        return choices + [c.upper() for c in choices] + ["nope", ""]
    if ann is bool:
        return FLAGS
    if ann in (int, float):
        return NUMBERS
    if ann is str:
        return WORDS
    return [str(tmp / "missing.csv"), str(tmp), str(tmp / "here.csv"), tmp / "here.csv", "-", "", 7]


def test_every_parameter_converts_as_typer_does(tmp_path):
    """Each converted parameter of every command, on numbers, words, choices and paths typed well and
    badly: the same value (or the same refusal) as typer's conversion."""
    (tmp_path / "here.csv").write_text("t\n")
    assert len(PARAMS) > 100
    for path, cmd, param in PARAMS:
        ctx = Context(cmd, info_name=path)
        for value in _values(param.type_descriptor, tmp_path):
            ours = _outcome(param._runtime_param, value, param, ctx)
            theirs = _outcome(build_runtime_param(param.type_descriptor), value, param, ctx)
            assert _same(ours, theirs), (path, param.name, value, ours, theirs)


@pytest.mark.parametrize("argv", [["calibrate", "--example"], ["simulate", "--help"]])
def test_a_run_of_ordinary_values_imports_no_pydantic(argv):
    """A fresh interpreter's ``sys.modules`` after the run."""
    code = (f"import sys, io, contextlib, gyrocal.cli as c\nwith contextlib.redirect_stdout(io.StringIO()): "
            f"c.run({argv!r})\nprint('loaded:', [m for m in ('pydantic', 'typer._adapters') if m in sys.modules])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    assert out.stdout.strip().splitlines()[-1] == "loaded: []"
