"""The ``gyrocal`` Typer application and its error boundary.

Command modules register on :data:`app`. Library errors become one line on stderr
and exit code 2; ``--debug`` shows the traceback instead.

A run imports only the module of the command it runs and builds only that command's click
parameters (:data:`COMMANDS` names each command's module): start-up is then the cost of one
command, not of all of them. ``gyrocal --help``, an unknown command, and anything that reads
:data:`app`'s commands outside a run (tests, a library user) import every command module.
"""

from __future__ import annotations

import contextlib
import functools
import importlib
import os
import sys
import warnings

try:
    import typer
    from rich.console import Console
    from rich.markup import escape
    from rich.measure import Measurement
    from rich.table import Table
except ImportError:  # pragma: no cover - exercised only without the extra
    sys.stderr.write("gyrocal: the command line needs its extra: pip install 'gyrocal[cli]'\n")
    raise SystemExit(2) from None

from typer.core import TyperGroup

from ..errors import GyrocalError, GyrocalWarning
from ._flags import flag

#: Commands in the order ``gyrocal --help`` lists them; set once, in ``gyrocal.cli``.
HELP_ORDER: list[str] = []
#: Every module of ``gyrocal.cli`` that registers commands; set once, in ``gyrocal.cli``.
MODULES: list[str] = []
#: Command (or command group) name -> the module that registers it; set once, in ``gyrocal.cli``.
COMMANDS: dict[str, str] = {}
#: ``lazy``: inside :func:`run` (reading the commands imports nothing); ``loading``, ``complete``: of
#: :func:`load_all`.
_registry = {"lazy": 0, "loading": False, "complete": False}


def load_all() -> None:
    """Import every command module (each registers its commands on :data:`app`)."""
    if _registry["loading"] or _registry["complete"] or not MODULES:
        return
    _registry["loading"] = True
    try:
        for name in MODULES:
            importlib.import_module(f"{__package__}.{name}")
        _registry["complete"] = True
    finally:
        _registry["loading"] = False


class _Registered:
    """One of typer's lists of registrations (commands, groups), kept as ``_<name>`` on the instance: read
    outside :func:`run`, it first imports every command module; inside a run, or while :func:`load_all`
    imports them (the decorators append to it), it imports nothing."""

    def __set_name__(self, owner, name) -> None:
        self.key = f"_{name}"

    def __get__(self, obj, owner=None):
        if obj is None:
            return self
        if not _registry["lazy"]:
            load_all()
        return obj.__dict__[self.key]

    def __set__(self, obj, value) -> None:
        obj.__dict__[self.key] = value


class _Typer(typer.Typer):
    """typer's application whose registered commands, read outside :func:`run`, are every command."""

    registered_commands = _Registered()
    registered_groups = _Registered()


def _name(info) -> str:
    return info.name or typer.main.get_command_name(info.callback.__name__)


def _build(name: str, module: str | None = None):
    """The click command (or group) `name` from its registration, importing `module` (default: its module
    in :data:`COMMANDS`); None if unknown. Its parameters convert ordinary values in plain Python
    (:mod:`gyrocal.cli._coerce`)."""
    from ._coerce import install

    importlib.import_module(f"{__package__}.{module or COMMANDS[name]}")
    cmd = None
    for info in app.__dict__["_registered_commands"]:
        if _name(info) == name:
            cmd = typer.main.get_command_from_info(info, pretty_exceptions_short=app.pretty_exceptions_short,
                                                   rich_markup_mode=app.rich_markup_mode)
    for info in app.__dict__["_registered_groups"]:
        if info.name == name:
            cmd = typer.main.get_group_from_info(info, pretty_exceptions_short=app.pretty_exceptions_short,
                                                 rich_markup_mode=app.rich_markup_mode,
                                                 suggest_commands=app.suggest_commands)
    if cmd is not None:
        install(cmd)
    return cmd


class _Interrupted(BaseException):
    """Ctrl-C inside a command: typer would turn it into a silent exit 130, without the line that says
    what became of the outputs."""


class _OrderedGroup(TyperGroup):
    """Lists commands in :data:`HELP_ORDER`, then any others by name, each with its whole first sentence;
    builds a command when it is first asked for (:func:`_build`); Ctrl-C inside a command reaches
    :func:`run` (as :class:`_Interrupted`)."""

    def get_command(self, ctx, cmd_name):
        cmd = self.commands.get(cmd_name)
        if cmd is None and cmd_name in COMMANDS:
            cmd = _build(cmd_name)
        elif cmd is None:
            # unknown here: a command of a module missing from COMMANDS, or a typo (whose suggestions
            # need every name)
            self._add_all()
            cmd = self.commands.get(cmd_name)
        if cmd is not None:
            self.commands[cmd_name] = cmd
        return cmd

    def _add_all(self) -> None:
        load_all()
        registered = [(_name(i), i.callback.__module__) for i in app.__dict__["_registered_commands"]]
        registered += [(i.name, __name__) for i in app.__dict__["_registered_groups"]]
        for name, module in registered:
            if name not in self.commands:
                cmd = _build(name, COMMANDS.get(name, module.rsplit(".", 1)[-1]))
                if cmd is not None:
                    self.commands[name] = cmd

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt as exc:
            raise _Interrupted from exc

    def list_commands(self, ctx):
        self._add_all()
        names = super().list_commands(ctx)
        rank = {name: i for i, name in enumerate(HELP_ORDER)}
        return sorted(names, key=lambda n: (rank.get(n, len(rank)), n))

    def format_commands(self, ctx, formatter) -> None:
        # click cuts each description to the width left by the names ("...;..."): a newcomer reads
        # them to choose a command, so they wrap instead
        rows = [(name, cmd.short_help or " ".join((cmd.help or "").split("\n\n")[0].split()))
                for name in self.list_commands(ctx)
                if (cmd := self.get_command(ctx, name)) is not None and not cmd.hidden]
        if rows:
            with formatter.section("Commands"):
                formatter.write_dl(rows)


app = _Typer(
    name="gyrocal",
    cls=_OrderedGroup,
    help="Calibrate triaxial MEMS gyroscopes: servo-aided and full-temperature-range methods.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # help texts carry units in brackets, e.g. [deg/s]: not markup
    context_settings={"max_content_width": 100, "help_option_names": ["-h", "--help"]},
)


_WIDE = 10_000  # columns: wider than any table gyrocal prints


class _Console(Console):
    """rich's console with two changes for a command line whose output users keep.

    * A table is never narrower than its content: on a narrow terminal, or a pipe (80 columns),
      rich would cut numbers to ``0.0…``; the table is printed at its natural width instead.
    * A closed pipe (``gyrocal ... | head``) stops the printing, not the command: rich would exit
      at once, before the outputs are written; here the rest of the text goes nowhere and the
      command finishes with its own exit code.
    """

    def print(self, *objects, **kwargs) -> None:
        tables = [o for o in objects if isinstance(o, Table)]
        if tables and len(tables) == len(objects) and not any(t.expand for t in tables):
            need = _WIDE  # alone, a table that does not expand takes its natural width: no need to measure it
        else:
            need = max((Measurement.get(self, self.options.update_width(_WIDE), t).maximum for t in tables), default=0)
        if need <= self.width:
            super().print(*objects, **kwargs)
            return
        # print(width=) is capped at the terminal's width: widen the console itself for this call
        setting = self._width
        self.width = need
        try:
            super().print(*objects, **kwargs)
        finally:
            self._width = setting

    def on_broken_pipe(self) -> None:
        self.quiet = True
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, (sys.stderr if self.stderr else sys.stdout).fileno())


# no emoji codes: a path such as C:\logs:cube: is printed as written
console = _Console(emoji=False)
err_console = _Console(stderr=True, emoji=False)
_state = {"debug": False}


def _print_version(value: bool) -> None:
    if value:
        from .._version import __version__

        console.print(f"gyrocal {__version__}", highlight=False)
        raise typer.Exit(0)


@app.callback()
def _root(
    debug: bool = typer.Option(False, "--debug", help="Show tracebacks instead of one-line errors."),
    version: bool = typer.Option(False, "--version", is_eager=True, callback=_print_version,
                                 help="Print gyrocal's version and exit."),
) -> None:
    _state["debug"] = debug


def fail(message: str) -> "typer.Exit":
    """Print one line to stderr and return the exit to raise (code 2)."""
    err_console.print(f"[bold red]error:[/] {escape(message)}", highlight=False, soft_wrap=True)
    return typer.Exit(code=2)


def warn(message: str) -> None:
    """Print one ``warning:`` line to stderr."""
    err_console.print(f"[yellow]warning:[/] {escape(message)}", highlight=False, soft_wrap=True)


@contextlib.contextmanager
def warnings_as_lines():
    """Show the library's warnings raised inside the block as one ``warning:`` line each."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield
    for w in caught:
        warn(str(w.message))


def _is_usage_error(exc: BaseException) -> bool:
    # Click's exceptions (bundled inside typer, or the click package with older typer).
    return hasattr(exc, "format_message") and hasattr(exc, "exit_code")


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A library warning as one ``warning:`` line. A numerical library's own warnings (numpy's
    RuntimeWarning, ...) say nothing a user can act on: they show with ``--debug`` only; the test
    suite turns every one of them into an error, so each is found and fixed at its source."""
    if issubclass(category, GyrocalWarning):
        warn(str(message))
    elif _state["debug"]:
        warn(f"{category.__name__}: {message} ({filename}:{lineno})")


def message(exc: BaseException) -> str:
    """The one line shown for a library or OS error; library parameters appear as their flags."""
    if isinstance(exc, GyrocalError):
        return exc.render(flag)
    return f"{getattr(exc, 'strerror', None) or exc}: {getattr(exc, 'filename', None) or ''}".strip(": ")


@functools.cache
def _click_command():
    """The click group typer builds from :data:`app`, with the commands registered so far (the others are
    built when asked for): built once, as typer would rebuild it for every run in the same process (tests
    run hundreds)."""
    from ._coerce import install

    group = typer.main.get_command(app)
    install(group)
    return group


def run(argv: list[str] | None = None) -> int:
    """Run the CLI; map library, OS and usage errors to one line and exit code 2."""
    if argv is not None and not argv:
        argv = ["--help"]  # bare 'gyrocal' is a request for help, not a mistake
    _registry["lazy"] += 1
    try:
        return _run(argv)
    finally:
        _registry["lazy"] -= 1


def _run(argv: list[str] | None) -> int:
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("always", GyrocalWarning)
            warnings.showwarning = _show_warning
            rv = _click_command()(args=argv, prog_name="gyrocal", standalone_mode=False)
    except (GyrocalError, OSError) as exc:
        if _state["debug"]:
            raise
        fail(message(exc))
        return 2
    except typer.Exit as exc:
        return exc.exit_code
    except typer.Abort:
        err_console.print("aborted")
        return 1
    except (KeyboardInterrupt, _Interrupted):
        if _state["debug"]:
            raise
        err_console.print("interrupted; no output was left half written")
        return 130
    except Exception as exc:
        if not _is_usage_error(exc) or _state["debug"]:
            raise
        fail(usage_line(exc, argv))
        return 2
    # Without standalone mode, typer returns the code of a raised Exit instead of raising it.
    return rv if isinstance(rv, int) else 0


def _command_path(argv: list[str] | None) -> str:
    """``gyrocal NAME`` for the first word of `argv` that names a command, else ``gyrocal``."""
    names = set(COMMANDS) | {c.name or c.callback.__name__.replace("_", "-") for c in app.registered_commands}
    word = next((a for a in argv or () if a in names), None)
    return f"gyrocal {word}" if word else "gyrocal"


def usage_line(exc, argv: list[str] | None = None) -> str:
    """One line for a command-line mistake (a missing option, a bad choice, a number that is not one),
    pointing to the help of the command it was typed for."""
    ctx = getattr(exc, "ctx", None)
    where = ctx.command_path if ctx is not None else _command_path(argv)
    param = getattr(exc, "param", None)
    cause = exc.__cause__
    errors = cause.errors() if cause is not None and hasattr(cause, "errors") else None
    if param is not None and errors:
        opts = getattr(param, "opts", None) or [param.name]
        name = max(opts, key=len) if getattr(param, "param_type_name", "") == "option" else str(param.name).upper()
        first = errors[0]
        value, kind = first.get("input"), str(first.get("type", ""))
        if kind == "value_error":
            text = str(first.get("msg", "")).removeprefix("Value error, ").rstrip(".")
        elif kind.startswith(("int_", "float_")) or "parsing" in kind:
            text = f"{value!r} is not {'a whole number' if kind.startswith('int') else 'a number'}"
        else:
            text = f"{value!r}: {first.get('msg', '')}"
        line = f"invalid value for {name}: {text}"
    else:
        # click lists a missing choice's values one per line ("Choose from:\n\tjson,\n\t...")
        line = " ".join(exc.format_message().split()).rstrip(".")
        line = line[:1].lower() + line[1:]
    return f"{line} (see '{where} --help')"
