"""Small helpers shared by command modules: which flags were typed, and lists of numbers."""

from __future__ import annotations

import math
from datetime import datetime, timezone
from typing import Annotated, Optional

import typer

from ..errors import InputError

__all__ = ["AcceptImplausible", "NoiseDensity", "StoreUrl", "given", "in_unit", "iso_time", "judge_plausible",
           "list_in_unit", "noise_density_option", "noise_std", "numbers", "refuse_unused", "triple", "triple_in_unit"]


def given(ctx: typer.Context, name: str) -> bool:
    """Whether parameter `name` was typed on the command line rather than left at its default."""
    source = ctx.get_parameter_source(name)
    return source is not None and source.name == "COMMANDLINE"


def refuse_unused(ctx: typer.Context, users: dict[str, tuple[str, ...]], choice: str, what: str) -> None:
    """Refuse a flag given on the command line that `choice` does not use: ignoring it would mislead.

    `users` maps a parameter name to the choices that use it; parameters not in it apply to all.
    """
    for param in ctx.command.params:
        if param.name in users and choice not in users[param.name] and given(ctx, param.name):
            flag = max(param.opts, key=len)
            raise InputError(f"{flag} does not apply to {what} {choice} (only to {', '.join(users[param.name])}); "
                             "drop it")


def numbers(name: str, text: str) -> list[float]:
    """Comma-separated finite numbers."""
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise InputError(f"{name} must be comma-separated numbers, got {text!r}") from None
    if not all(map(math.isfinite, values)):
        raise InputError(f"{name} must be finite numbers, got {text!r}")
    return values


def triple(name: str, text: str | None, default) -> list[float]:
    """Three comma-separated numbers, or `default` when `text` is None."""
    if text is None:
        return [float(v) for v in default]
    values = numbers(name, text)
    if len(values) != 3:
        raise InputError(f"{name} must be three comma-separated numbers, got {text!r}")
    return values


def noise_density_option(otherwise: str):
    """The --noise-density option; `otherwise` says what applies without it (this command's own words)."""
    return Annotated[Optional[str], typer.Option(
        "--noise-density", help="White-noise density: rad/s/sqrt(Hz) unless a unit is written ('N deg/s/rtHz'), or "
        f"a noise file from 'gyrocal noise -o' (default: none; {otherwise}).")]


#: --noise-density where --noise is the other way to give the noise (simulate, plan).
NoiseDensity = noise_density_option("--noise applies")


def noise_std(noise: float | None, density: str | None, sample_rate: float, default: float, *,
              allow_zero: bool = True):
    """Per-sample white noise (3,) [rad/s] from --noise or --noise-density (> 0 unless `allow_zero`)."""
    import numpy as np

    from ..noise.document import noise_density_arg

    if noise is not None and density is not None:
        raise InputError("give --noise or --noise-density, not both")
    if density is not None:
        return noise_density_arg(density) * math.sqrt(sample_rate)
    value = default if noise is None else noise
    if not (math.isfinite(value) and (value > 0 or allow_zero and value == 0)):
        raise InputError(f"--noise must be {'>=' if allow_zero else '>'} 0 rad/s, got {value:g}")
    return np.full(3, value)


#: Rate units a number on the command line may carry, in rad/s per unit.
_RATE_UNITS = {"rad/s": 1.0, "deg/s": math.pi / 180.0, "dps": math.pi / 180.0, "\u00b0/s": math.pi / 180.0}


def _split_unit(flag: str, text: str) -> tuple[str, str | None]:
    raw = text.strip().replace(" ", "")
    for unit in sorted(_RATE_UNITS, key=len, reverse=True):
        if raw.lower().endswith(unit):
            return raw[: -len(unit)], unit
    if raw and raw[-1].isalpha():
        if not any(c.isdigit() for c in raw):
            raise InputError(f"{flag} must be a number, with a unit if you like (0.035rad/s, 2deg/s), got {text!r}")
        raise InputError(f"{flag} {text!r}: the unit is not one of rad/s, deg/s, dps")
    return raw, None


def in_unit(flag: str, text: str | None, unit: str) -> float | None:
    """A rate flag's number in `unit`: a bare number is already in it; ``2deg/s`` or ``0.035rad/s`` is converted."""
    if text is None:
        return None
    raw, given_unit = _split_unit(flag, str(text))
    try:
        value = float(raw)
    except ValueError:
        raise InputError(f"{flag} must be a number, with a unit if you like (0.035rad/s, 2deg/s), got {text!r}") \
            from None
    return value * _RATE_UNITS[given_unit or unit] / _RATE_UNITS[unit]


def list_in_unit(flag: str, text: str, unit: str) -> list[float]:
    """Comma-separated rates in `unit`; one unit written after the last applies to all."""
    raw, given_unit = _split_unit(flag, text)
    return [v * _RATE_UNITS[given_unit or unit] / _RATE_UNITS[unit] for v in numbers(flag, raw)]


def triple_in_unit(flag: str, text: str | None, unit: str, default) -> list[float]:
    """Three comma-separated rates in `unit`; one unit written after the last applies to all three."""
    if text is None:
        return list(default)
    raw, given_unit = _split_unit(flag, text)
    return [v * _RATE_UNITS[given_unit or unit] / _RATE_UNITS[unit] for v in triple(flag, raw, default)]


StoreUrl = Annotated[str, typer.Option("--store", help="The store: an SQLite file (path or sqlite:///path) or "
                                       "postgresql://user@host:port/db.", metavar="URL")]


def iso_time(text: str | None, flag: str) -> datetime | None:
    """ISO 8601 (``YYYY-MM-DDTHH:MM:SSZ``, or with an offset; a date alone is its midnight UTC)."""
    if text is None:
        return None
    try:
        when = datetime.fromisoformat(text.strip().replace("Z", "+00:00"))
    except ValueError:
        raise InputError(f"{flag} takes an ISO 8601 time such as 2026-12-02T13:45:00Z, got {text!r}") from None
    return when.replace(tzinfo=timezone.utc) if when.tzinfo is None else when.astimezone(timezone.utc)


AcceptImplausible = Annotated[bool, typer.Option(
    "--accept-implausible", help="Write a result the plausibility rule refuses (a scale factor more than 20 % from 1 "
    "for deg/s or rad/s, a common factor that points at the sample rate or the units, a sensitivity no vendor's "
    "setting comes near), with the warning in the file (default: refuse, exit 2, nothing written).")]


def judge_plausible(doc: dict, diagnosis: str | None, accept: bool) -> dict:
    """The result document `doc`, refused (one line, exit 2, before anything is written) when `diagnosis` says it
    is implausible, unless `accept`: then with the diagnosis among its warnings (:func:`gyrocal.jobs.result.judge`),
    which is also printed."""
    from ..jobs.result import judge

    doc, text = judge(doc, diagnosis, accept)
    if text is not None:
        from .app import warn

        warn(text)
    return doc
