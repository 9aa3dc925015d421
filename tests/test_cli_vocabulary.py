"""One vocabulary across commands (issue 21, item 6): every command's options, walked with click's
introspection, against the rules a user learns once.

* A rate option takes a unit (``60deg/s``, ``1.05rad/s``) and its help states the unit of a bare number,
  one per kind of quantity: a motion (turn speed, range) in deg/s, a sensor's error (noise, bias, resolution)
  in rad/s, and in the data's rate unit for a command that reads a recording.
* A result file is written with ``-o/--output``; the other paths are listed here with the reason.
* ``--sensitivity`` means LSB per deg/s wherever it appears.
* A help text names only the command's own flags, or another command's as ``'gyrocal CMD --flag'``: a
  sentence copied from another command names flags the command does not have.

That every help text states its default or that the flag is required is
``test_cli_newcomer.test_every_option_states_its_default_or_that_it_is_required``.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
import typer
from cli_runner import invoke, refused
from typer._click.core import Context

from gyrocal.cli import app


def _walk(cmd, path: tuple[str, ...]):
    if hasattr(cmd, "commands"):
        for name, sub in cmd.commands.items():
            yield from _walk(sub, path + (name,))
    else:
        yield " ".join(path), cmd


COMMANDS = dict(_walk(typer.main.get_command(app), ()))


def _options(cmd):
    return [p for p in cmd.params if p.param_type_name == "option"]


def _name(p) -> str:
    """The option's name: its first long name (later ones are old names kept working)."""
    return next(o for o in p.opts if o.startswith("--"))


def _all_options():
    return [(command, p) for command, cmd in COMMANDS.items() for p in _options(cmd)]


# ---------------------------------------------------------------- rates take units

#: Names of rate options; any option whose help gives its unit as [deg/s] or [rad/s] is one too.
_RATE_NAME = re.compile(r"(^|-)(speed|speed-sd|noise|noise-std|b|full-scale|quantum|bias-instability|rrw|rates|"
                        r"peak-rate|target-bias)$")
#: Kind of quantity -> the unit of a bare number.
_KIND_UNIT = {"motion": "deg/s", "error": "rad/s"}
_ERRORS = ("noise", "noise-std", "b", "quantum", "bias-instability", "rrw", "target-bias")
#: "<unit> unless a unit is written": the stated unit of a bare number.
_STATED = re.compile(r"(deg/s|rad/s(?:/sqrt\(s\))?|the data's rate unit|the data's unit) unless a unit is written")


def _rate_options():
    return [(c, p) for c, p in _all_options() if not _name(p).startswith("--temp-")  # temperatures
            and _RATE_NAME.search(_name(p)[2:]) or re.search(r"\[(deg|rad)/s\]", p.help or "")]


def _reads_a_recording(command: str) -> bool:
    return any(p.param_type_name == "argument" for p in COMMANDS[command].params) and any(
        _name(p) == "--units" for p in _options(COMMANDS[command]))


def test_there_are_rate_options_to_check():
    names = {(c, _name(p)) for c, p in _rate_options()}
    assert {("simulate", "--speed"), ("plan", "--noise"), ("capture", "--speed"), ("calibrate", "--speed"),
            ("thermal", "--full-scale"), ("simulate", "--ref-noise")} <= names, sorted(names)


@pytest.mark.parametrize("command,param", _rate_options(), ids=lambda v: v if isinstance(v, str) else _name(v))
def test_every_rate_option_takes_a_unit_and_states_the_unit_of_a_bare_number(command, param):
    value = "0.5,0.5,0.5deg/s" if _name(param) == "--b" else "1.05rad/s"
    ctx = Context(COMMANDS[command])
    assert param.process_value(ctx, value) == value, f"{command} {_name(param)} refuses a unit"
    stated = _STATED.search(param.help or "")
    assert stated, f"{command} {_name(param)}: the help does not say '<unit> unless a unit is written'"
    if _reads_a_recording(command):
        want = ("the data's rate unit", "the data's unit")
    else:
        kind = "error" if _name(param).removeprefix("--ref-")[2:] in _ERRORS or "noise" in _name(param) else "motion"
        want = (_KIND_UNIT[kind], f"{_KIND_UNIT[kind]}/sqrt(s)")
    assert stated.group(1) in want, f"{command} {_name(param)}: a bare number in {stated.group(1)}, not {want}"


def _csv(path):
    return np.loadtxt(path, delimiter=",", skiprows=2)


def test_a_rate_with_its_unit_is_the_bare_number_in_the_stated_unit(tmp_path):
    """The same run whether a rate is written bare, in its stated unit, or in the other unit (deg = rad * 180/pi)."""
    common = ("--turns", "+x,-z", "--wait", "1", "--sample-rate", "50", "--seed", "3")
    bare = ("--speed", "60", "--noise", "0.01", "--b", "0.02,0,-0.01", "--full-scale", "250", "--quantum", "0.001")
    other = ("--speed", f"{math.radians(60)!r}rad/s", "--noise", f"{math.degrees(0.01)!r}deg/s",
             "--b", f"{math.degrees(0.02)!r},0,{math.degrees(-0.01)!r}deg/s", "--full-scale",
             f"{math.radians(250)!r}rad/s", "--quantum", f"{math.degrees(0.001)!r}deg/s")
    for name, rates in (("bare", bare), ("other", other)):
        code, _, err = invoke("simulate", "-o", tmp_path / f"{name}.csv", *common, *rates)
        assert code == 0, err
    np.testing.assert_allclose(_csv(tmp_path / "other.csv"), _csv(tmp_path / "bare.csv"), rtol=1e-9, atol=1e-9)

    plans = [invoke("plan", "--speed", s, "--noise", n, "--target-bias", "0.001", "--max-speed", m)
             for s, n, m in (("60", "0.035", "180"), (f"{math.radians(60)!r}rad/s", f"{math.degrees(0.035)!r}deg/s",
                                                      f"{math.pi!r}rad/s"))]
    assert plans[0][0] == 0 and plans[0] == plans[1], plans


@pytest.mark.parametrize("args", [
    ("capture", "--port", "/nonexistent/gyrocal-port", "-o", "x.csv"),
    ("study", "servo-normal", "-o", "study-out", "--sample-rate", "-1"),
])
def test_a_speed_with_its_unit_gets_past_the_speed_check(args, tmp_path, monkeypatch):
    """The command refuses something else (the port, the sample rate), not the speed; a bad unit is refused."""
    monkeypatch.chdir(tmp_path)
    line = refused(*args, "--speed", "1.05rad/s")
    assert "--speed" not in line, line
    line = refused(*args, "--speed", "60furlongs/s")
    assert "--speed" in line and "unit" in line, line


def test_thermal_full_scale_in_counts_or_with_its_unit():
    from gyrocal.cli.thermal_cmds import _full_scale

    assert _full_scale("32768", "counts", "deg/s", 131.0) == pytest.approx(math.radians(32768 / 131.0))
    assert _full_scale("250deg/s", "counts", "deg/s", 131.0) == pytest.approx(math.radians(250))
    assert _full_scale("250", "deg/s", "deg/s", None) == pytest.approx(math.radians(250))


# ---------------------------------------------------------------- outputs are -o

#: Path options that are not the command's result file, and why.
_OTHER_PATHS = {
    "--plot": "a picture beside the result, named the same in every command",
    "--windows": "read: windows chosen by hand",
    "--limits": "read: acceptance limits",
    "--profile": "read: the motion to simulate",
    "--accel-log": "read: the accelerometer's own log",
    ("verify", "--reference"): "read: the reference gyro's log",
    ("simulate", "--reference"): "a second recording, of the reference gyro, beside the -o one",
    ("capture", "--cal"): "the calibration made from the recording that -o writes",
}


def test_every_result_file_is_written_with_o():
    wrong = []
    for command, p in _all_options():
        annotation = getattr(p.type_descriptor, "annotation", None)
        if "Path" not in str(annotation):
            continue
        if "-o" in p.opts and "--output" in p.opts:
            continue
        if _name(p) not in _OTHER_PATHS and (command, _name(p)) not in _OTHER_PATHS:
            wrong.append(f"{command} {_name(p)}")
    assert not wrong, f"name the result -o/--output, or list the path here with the reason: {wrong}"


def test_an_old_name_is_named_only_where_it_is_said_to_be_old():
    """``noise --json`` still works, but the rest of its help says -o."""
    for command, cmd in COMMANDS.items():
        for p in _options(cmd):
            for old in [o for o in p.opts if o.startswith("--")][1:]:
                others = [_name(q) for q in _options(cmd) if q is not p and re.search(rf"{old}\b", q.help or "")]
                assert not others, f"{command}: {others} name {old}, the old name of {_name(p)}"


# ---------------------------------------------------------------- --sensitivity means one thing


def test_sensitivity_is_lsb_per_deg_s_everywhere():
    found = []
    for command, p in _all_options():
        name = _name(p)
        if name.endswith("-sensitivity") and name.startswith("--accel"):
            assert (p.help or "").startswith("For --accel-units counts: LSB per g"), (command, p.help)
        elif name in ("--sensitivity", "--ref-sensitivity"):
            found.append(command)
            prefix = "ref-" if name.startswith("--ref-") else ""
            assert (p.help or "").startswith(f"For --{prefix}units counts: LSB per deg/s"), (command, p.help)
    assert {"calibrate", "noise", "simulate", "capture", "verify"} <= set(found)


# ---------------------------------------------------------------- help written per command


def _flags_named(text: str, command: str) -> list[tuple[str, str]]:
    """(command, flag) for each flag a help text names: 'gyrocal CMD ... --flag' or 'CMD --flag' name another's."""
    named = []
    cmds = "|".join(sorted(map(re.escape, COMMANDS), key=len, reverse=True))
    for m in re.finditer(rf"'gyrocal ({cmds})([^']*)'", text):
        named += [(m.group(1), f) for f in re.findall(r"(?<![\w-])(--?[a-z][\w-]*)", m.group(2))]
    text = re.sub(rf"'gyrocal ({cmds})[^']*'", "", text)
    for m in re.finditer(rf"\b({cmds}) (--[a-z][\w-]*)", text):
        named.append((m.group(1), m.group(2)))
    text = re.sub(rf"\b({cmds}) (--[a-z][\w-]*)", "", text)
    named += [(command, f) for f in re.findall(r"(?<![\w+,-])(--[a-z][\w-]*|-[a-z](?![\w,-]))", text)]
    return named


def test_a_help_text_names_only_flags_its_command_has():
    wrong = []
    for command, cmd in COMMANDS.items():
        for where, text in [("", cmd.help or "")] + [(_name(p), p.help or "") for p in _options(cmd)]:
            for owner, flag in _flags_named(text, command):
                if owner in COMMANDS and flag not in {o for q in COMMANDS[owner].params for o in q.opts} | {"-h",
                                                                                                     "--help"}:
                    wrong.append(f"{command} {where or '(help)'}: {flag} ({owner} has no such flag)")
    assert not wrong, wrong


def test_the_check_finds_a_copied_sentence():
    """What the check above reads, on a sentence of calibrate's in another command."""
    assert ("noise", "--angle") in _flags_named("Known angle (default: 360 unless --angle).", "noise")
    assert _flags_named("a noise file from 'gyrocal noise -o', turns +x,-x", "plan") == [("noise", "-o")]
