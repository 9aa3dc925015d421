"""Command ``study``: Monte Carlo studies that reproduce both papers."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..choices import StudyName
from ..errors import InputError
from ._options import given, in_unit, noise_density_option, refuse_unused
from ._outputs import check_output
from .app import app, console

__all__ = ["study"]

_SERVO_STUDIES = ("servo-normal", "servo-extreme", "servo-speed", "servo-convergence")
#: Flags that only some studies use; a study refuses the others instead of ignoring them.
_STUDY_FLAGS = {
    "gyros": ("servo-normal", "servo-extreme", "servo-speed", "thermal-compare"),  # convergence: Table I's 3 gyros
    "methods": ("servo-speed",),
    "speed": ("servo-normal", "servo-extreme", "servo-convergence"),  # servo-speed sweeps the speed
}


@app.command()
def study(
    ctx: typer.Context,
    name: Annotated[StudyName, typer.Argument(help="Which study.")],
    out: Annotated[Path, typer.Option("-o", "--output", help="Output folder for figures and tables.")],
    gyros: Annotated[Optional[int], typer.Option("--gyros", help="Simulated gyros (default: the paper's).")] = None,
    reps: Annotated[Optional[int], typer.Option("--reps", help="Calibrations per gyro (default: the paper's).")] = None,
    seed: Annotated[int, typer.Option("--seed", help="Random seed.", min=0)] = 0,
    methods: Annotated[Optional[str], typer.Option(
        "--methods", help="servo-speed: estimators, comma-separated (algorithm1, lm, first-moment) (default: "
        "all three).")] = None,
    noise_density: noise_density_option("the study's own noise levels apply") = None,
    sample_rate: Annotated[float, typer.Option(
        "--sample-rate", help="Sampling rate [Hz] (thermal-compare's default: 100).")] = 200.0,
    speed: Annotated[str, typer.Option(
        "--speed", help="Servo studies but servo-speed: turn speed, deg/s unless a unit is written (paper: 60).")]
    = "60",
) -> None:
    """Run a Monte Carlo study of the servo method of Wang et al. or the full-temperature-range method."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from ..studies import ServoSettings, run_study, study_units

    refuse_unused(ctx, _STUDY_FLAGS, name, "study")
    check_output(out, folder=True)
    options: dict = {}
    if methods is not None:
        from ..choices import Method, values

        options["methods"] = tuple(m.strip() for m in methods.split(",") if m.strip())
        if not options["methods"] or not set(options["methods"]) <= set(values(Method)):
            raise InputError(f"--methods takes a comma-separated list of {', '.join(values(Method))}, got "
                             f"{methods!r}")
    speed = in_unit("--speed", speed, "deg/s")
    if not (math.isfinite(speed) and speed > 0):
        raise InputError(f"--speed must be > 0 deg/s, got {speed:g}")
    if not (math.isfinite(sample_rate) and sample_rate > 0):
        raise InputError(f"--sample-rate must be > 0 Hz, got {sample_rate:g}")
    settings = None
    if name in _SERVO_STUDIES:
        settings = ServoSettings(speed=math.radians(speed), sample_rate=sample_rate)
    else:  # thermal-compare keeps its own sampling rate unless told
        from ..studies.thermal_compare import SAMPLE_RATE

        if given(ctx, "sample_rate"):
            options["sample_rate"] = sample_rate
        sample_rate = options.get("sample_rate", SAMPLE_RATE)
    if noise_density is not None:
        import numpy as np

        from ..noise.document import noise_density_arg

        sd = float(np.mean(noise_density_arg(noise_density))) * math.sqrt(sample_rate)
        if settings is None:
            options["noise"] = sd
        else:
            settings = ServoSettings(speed=settings.speed, sample_rate=sample_rate, noise_levels=(sd,))
    with Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                  TimeElapsedColumn(), console=console, transient=False) as bar:
        task = bar.add_task(name, total=study_units(name, settings, gyros=gyros, **options))

        def progress(advance: int, label: str) -> None:
            bar.update(task, advance=advance, description=f"{name}: {label}")

        result = run_study(name, out, gyros=gyros, reps=reps, seed=seed, settings=settings, progress=progress,
                           **options)
    console.print(result.summary, highlight=False, markup=False)
    for path in result.files:
        console.print(f"wrote {path}")
