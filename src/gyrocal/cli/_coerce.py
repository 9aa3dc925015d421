"""Plain-Python conversion of the command line's ordinary values, ahead of typer's pydantic one.

typer (0.2x) converts every parameter's value with a pydantic ``TypeAdapter``, built for each
parameter of the command that runs: importing pydantic and building them costs more than
importing numpy. Most values are a number, a word, a choice or a path, typed correctly; for
those the result is computed here, equal to the adapter's. Anything else (a value that does not
parse, ``inf``, a number outside its range, a list, a custom parser) goes to typer's own
conversion, so every refusal and its message is typer's. With a typer that has no such
conversion (older versions use click's types) nothing changes.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = ["install"]

_FLOAT = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_INT = re.compile(r"[+-]?\d+")
#: A value this module leaves to typer.
_TYPER = object()


def _number(kind, info):
    """Conversion of a float or int option without clamping; range checks stay typer's."""
    pattern = _FLOAT if kind is float else _INT

    def convert(value, param, ctx):
        if isinstance(value, str):
            if not pattern.fullmatch(value):
                return _TYPER
        elif isinstance(value, bool) or not isinstance(value, (int, float) if kind is float else int):
            return _TYPER
        value = kind(value)
        if (info.min is not None and value < info.min) or (info.max is not None and value > info.max):
            return _TYPER
        return value

    return None if info.clamp else convert


def _word(value, param, ctx):
    return value if isinstance(value, str) else _TYPER


def _flag(value, param, ctx):
    return value if isinstance(value, bool) else _TYPER


def _choice(choices, info):
    from typer._param_types import coerce_cli_choice

    def convert(value, param, ctx):
        try:
            return coerce_cli_choice(value, choices=choices, case_sensitive=info.case_sensitive, ctx=ctx)
        except ValueError:
            return _TYPER

    return convert


def _path(kind, info):
    from typer._param_types import coerce_cli_path

    def convert(value, param, ctx):
        if not isinstance(value, (str, Path)) or value == "":
            return _TYPER
        # typer's own path checks (exists, file or folder), given a path it need not convert
        return coerce_cli_path(kind(value), info, path_type=kind, param=param, ctx=ctx)

    return convert


def _converter(descriptor):
    """The plain conversion of a parameter, or None to leave it to typer."""
    from typer._typing import is_literal_type, literal_values

    ann, info = descriptor.annotation, descriptor.parameter_info
    if info.parser is not None or getattr(info, "click_type", None) is not None or descriptor.file_annotation:
        return None
    if ann in (float, int):
        return _number(ann, info)
    if ann is str:
        return _word
    if ann is bool:
        return _flag
    if is_literal_type(ann) and all(isinstance(v, str) for v in literal_values(ann)):
        return _choice(literal_values(ann), info)
    kind = info.path_type or ann
    if isinstance(kind, type) and issubclass(kind, Path):
        return _path(kind, info)
    return None


def _runtime_class():
    from typer._coercion import RuntimeParam, build_runtime_param

    @dataclass(frozen=True)
    class Plain(RuntimeParam):
        """The plain conversion, falling back to typer's for what it leaves."""

        convert: Any

        def _coerce_value(self, value, param, ctx):
            out = self.convert(value, param, ctx)
            if out is _TYPER:
                return build_runtime_param(param.type_descriptor)._coerce_value(value, param=param, ctx=ctx)
            return out

    return Plain


def _give(param, plain) -> None:
    desc = getattr(param, "type_descriptor", None)
    if desc is None or getattr(param, "_runtime_param", True) is not None:
        return
    convert = _converter(desc)
    if convert is not None:
        param._runtime_param = plain(parameter_info=desc.parameter_info, annotation=desc.annotation, convert=convert)


def install(command) -> None:
    """Give each parameter of a click command (and of its subcommands), its ``--help`` option included,
    the plain conversion it has."""
    if getattr(command, "_plain_conversion", False):
        return
    try:
        plain = _runtime_class()
    except ImportError:  # a typer without pydantic conversion: nothing to replace
        return
    command._plain_conversion = True
    for param in command.params:
        _give(param, plain)
    real = command.get_help_option

    def get_help_option(ctx):
        option = real(ctx)
        if option is not None:
            _give(option, plain)
        return option

    command.get_help_option = get_help_option
    for sub in getattr(command, "commands", {}).values():
        install(sub)
