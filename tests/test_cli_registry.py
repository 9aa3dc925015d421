"""The command line's lazy registration: ``gyrocal.cli.COMMANDS`` against what the modules register.

References: the registrations themselves (every command module imported, each command's callback
module read back), and a fresh interpreter's ``sys.modules`` for what a run imports.
"""

import subprocess
import sys

import typer

import gyrocal.cli as cli


def _registered() -> dict[str, str]:
    """Command name -> module, from typer's registrations after every command module is imported."""
    for name in cli.COMMAND_MODULES:
        __import__(f"gyrocal.cli.{name}")
    out = {}
    for info in cli.app.registered_commands:
        name = info.name or typer.main.get_command_name(info.callback.__name__)
        out[name] = info.callback.__module__.rsplit(".", 1)[1]
    for group in cli.app.registered_groups:
        # a group's subcommands live in the module that adds the group
        modules = {c.callback.__module__ for c in group.typer_instance.registered_commands}
        assert len(modules) == 1, modules
        out[group.name] = modules.pop().rsplit(".", 1)[1]
    return out


def test_commands_names_every_registered_command_and_its_module():
    """Every command the modules register is in COMMANDS with its module, and COMMANDS names no other."""
    assert _registered() == cli.COMMANDS
    assert set(cli.COMMANDS.values()) == set(cli.COMMAND_MODULES)


def _fresh(code: str) -> str:
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    return out.stdout.strip().splitlines()[-1]


_LOADED = ("import sys, gyrocal.cli as c; c.run({argv!r}); "
           "print(','.join(sorted(m.rsplit('.', 1)[1] for m in sys.modules if m.startswith('gyrocal.cli.') "
           "and m.endswith('_cmds'))))")


def test_a_run_imports_only_the_module_of_its_command():
    """``calibrate --example`` and ``store --help`` in fresh interpreters: one command module each."""
    assert _fresh(_LOADED.format(argv=["calibrate", "--example"])) == "calibrate_cmds"
    assert _fresh(_LOADED.format(argv=["store", "--help"])) == "store_cmds"


def test_help_and_a_typo_see_every_command():
    """``gyrocal --help`` lists every command of COMMANDS (each module imported); a typo is matched
    against all of them."""
    code = ("import sys, io, contextlib, gyrocal.cli as c; buf = io.StringIO()\n"
            "with contextlib.redirect_stdout(buf): c.run(['--help'])\n"
            "print('missing:', ','.join(n for n in c.COMMANDS if '  ' + n + ' ' not in buf.getvalue()))")
    assert _fresh(code) == "missing:"
    code = ("import sys, io, contextlib, gyrocal.cli as c; buf = io.StringIO()\n"
            "with contextlib.redirect_stderr(buf): c.run(['thermal-bais'])\n"
            "print(buf.getvalue().replace(chr(10), ' '))")
    assert "thermal-bias" in _fresh(code)
