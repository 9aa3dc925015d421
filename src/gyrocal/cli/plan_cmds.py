"""Command ``plan``: accuracy of a protocol before it is run (Cramer-Rao bound)."""

from __future__ import annotations

import math
from typing import Annotated, Optional

import typer

from ..choices import DesignName
from ..errors import InputError
from ._options import NoiseDensity, noise_std, triple
from .app import app, console

__all__ = ["plan"]


def _rate_arg(name: str, text: str | None, default_unit: str) -> float | None:
    """A rate with an optional unit suffix (``0.01deg/s``, ``2e-4 rad/s``) in rad/s."""
    from ..units import unit_factor

    if text is None:
        return None
    raw = text.strip().lower().replace(" ", "")
    unit = default_unit
    for suffix in ("deg/s", "dps", "rad/s"):
        if raw.endswith(suffix):
            raw, unit = raw[: -len(suffix)], suffix
    try:
        value = float(raw) * unit_factor(unit)
    except ValueError:
        raise InputError(f"{name} must be a number with an optional unit (deg/s or rad/s), got {text!r}") from None
    if not (math.isfinite(value) and value > 0):
        raise InputError(f"{name} must be > 0, got {text!r}")
    return value


@app.command()
def plan(
    speed: Annotated[float, typer.Option("--speed", help="Turn speed [deg/s].")] = 60.0,
    revolutions: Annotated[float, typer.Option("--revolutions", help="Revolutions per turn.")] = 1.0,
    design: Annotated[DesignName, typer.Option(
        "--design", help="six (the servo method of Wang et al., Fig. 1), six-static, twelve.")] = "six",
    sample_rate: Annotated[float, typer.Option("--sample-rate", help="Sampling rate [Hz].")] = 200.0,
    noise: Annotated[Optional[float], typer.Option(
        "--noise", help="Per-sample white noise [rad/s] (default: 0.035, the paper's simulations).")] = None,
    noise_density: NoiseDensity = None,
    k: Annotated[Optional[str], typer.Option(
        "--k", help="Expected scale factors kx,ky,kz (default: 1,1,1).")] = None,
    wait: Annotated[float, typer.Option("--wait", help="Wait between turns (static window for six-static) [s].")]
    = 3.0,
    target_scale: Annotated[Optional[float], typer.Option(
        "--target-scale", help="Target std of every k [-] (default: none; no suggestion).")]
    = None,
    target_bias: Annotated[Optional[str], typer.Option(
        "--target-bias", help="Target std of every bias, e.g. 0.01deg/s (unit rad/s if none given) (default: "
        "none; no suggestion).")] = None,
    max_speed: Annotated[float, typer.Option("--max-speed", help="Fastest speed to consider [deg/s].")] = 180.0,
) -> None:
    """Predict each parameter's std and the protocol time; suggest the fastest protocol for a target."""
    import numpy as np
    from rich.table import Table

    from ..models import ScaleBias
    from ..planning import predict, suggest

    density = noise_std(noise, noise_density, sample_rate, 0.035) / math.sqrt(sample_rate)
    model = ScaleBias(np.asarray(triple("--k", k, (1.0, 1.0, 1.0))), np.zeros(3))
    options = dict(sample_rate=sample_rate, noise_density=density, model=model, static_duration=wait, pause=wait)
    plans = [("as given", predict(design, speed=math.radians(speed), revolutions=revolutions, **options))]
    bias_target = _rate_arg("--target-bias", target_bias, "rad/s")
    if target_scale is not None or bias_target is not None:
        best = suggest(target_scale=target_scale, target_bias=bias_target, max_speed=math.radians(max_speed),
                       design=design, **options)
        if best is None:
            console.print(f"no protocol up to {max_speed:g} deg/s and 20 revolutions per turn reaches the target")
        else:
            plans.append(("suggested", best))
    table = Table(title=f"Cramer-Rao prediction, design {design}, {sample_rate:g} Hz, "
                        f"noise density {density.mean():.3g} rad/s/sqrt(Hz)")
    for col in ("protocol", "speed (deg/s)", "revolutions", "time (s)", "std kx, ky, kz (1e-4)",
                "std bx, by, bz (deg/s)"):
        table.add_column(col, justify="right")
    for label, p in plans:
        table.add_row(label, f"{math.degrees(p.speed):.1f}", f"{p.revolutions:g}", f"{p.total_time:.1f}",
                      ", ".join(f"{1e4 * v:.3g}" for v in p.std[:3]),
                      ", ".join(f"{math.degrees(v):.3g}" for v in p.std[3:]))
    console.print(table)
