"""Command ``plan``: accuracy of a protocol before it is run (Cramer-Rao bound)."""

from __future__ import annotations

import math
from typing import Annotated, Optional

import typer

from ..choices import PlanDesign
from ..errors import InputError
from ._options import NoiseDensity, in_unit, noise_std, refuse_unused, triple
from .app import app, console

__all__ = ["plan"]


def _rate_arg(name: str, text: str | None, default_unit: str) -> float | None:
    """A rate with an optional unit suffix (``0.01deg/s``, ``2e-4 rad/s``) in rad/s."""
    from ..units import unit_factor

    value = in_unit(name, text, default_unit)
    if value is not None and not (math.isfinite(value) and value > 0):
        raise InputError(f"{name} must be > 0, got {text!r}")
    return None if value is None else value * unit_factor(default_unit)


#: Flags of one kind of design only (the rest apply to both).
_DESIGN_FLAGS = {
    **dict.fromkeys(("speed", "revolutions", "k", "wait", "max_speed"), ("six", "six-static", "twelve")),
    **dict.fromkeys(("poses", "tilt", "still", "peak_rate", "accel_noise_density", "target_cross",
                     "target_accel_scale", "target_accel_offset", "temp_points", "temp_range"), ("poses",)),
}


@app.command()
def plan(
    ctx: typer.Context,
    speed: Annotated[str, typer.Option("--speed", help="Turn speed, deg/s unless a unit is written, e.g. 1.05rad/s.")]
    = "60",
    revolutions: Annotated[float, typer.Option("--revolutions", help="Revolutions per turn.")] = 1.0,
    design: Annotated[PlanDesign, typer.Option(
        "--design", help="six (the servo method of Wang et al., Fig. 1), six-static, twelve; poses: a hand session "
        "of still poses for 'gyrocal imu'.")] = "six",
    sample_rate: Annotated[float, typer.Option("--sample-rate", help="Sampling rate [Hz].")] = 200.0,
    noise: Annotated[Optional[str], typer.Option(
        "--noise", help="Per-sample white noise, rad/s unless a unit is written, e.g. 2deg/s (default: 0.035 rad/s, "
        "the paper's simulations; 0.0017 rad/s for --design poses).")] = None,
    noise_density: NoiseDensity = None,
    k: Annotated[Optional[str], typer.Option(
        "--k", help="Expected scale factors kx,ky,kz (default: 1,1,1).")] = None,
    wait: Annotated[float, typer.Option("--wait", help="Wait between turns (static window for six-static) [s].")]
    = 3.0,
    target_scale: Annotated[Optional[float], typer.Option(
        "--target-scale", help="Target std of every k [-] (default: none; no suggestion).")]
    = None,
    target_bias: Annotated[Optional[str], typer.Option(
        "--target-bias", help="Target std of every bias, rad/s unless a unit is written, e.g. 0.01deg/s "
        "(default: none; no suggestion).")] = None,
    max_speed: Annotated[str, typer.Option(
        "--max-speed", help="Fastest speed to consider, deg/s unless a unit is written.")] = "180",
    poses: Annotated[int, typer.Option("--poses", help="--design poses: still poses.")] = 24,
    tilt: Annotated[float, typer.Option("--tilt", help="--design poses: tilt between successive poses [deg].")]
    = 90.0,
    still: Annotated[float, typer.Option("--still", help="--design poses: still time per pose [s].")] = 2.0,
    peak_rate: Annotated[str, typer.Option(
        "--peak-rate", help="--design poses: peak rate of each hand move, deg/s unless a unit is written.")] = "150",
    accel_noise_density: Annotated[float, typer.Option(
        "--accel-noise-density", help="--design poses: accelerometer noise density [m/s^2/sqrt(Hz)] (MPU-6050: "
        "about 0.004).")] = 0.002,
    target_cross: Annotated[Optional[float], typer.Option(
        "--target-cross", help="--design poses: target std of every cross term (misalignment) of both sensors [-] "
        "(default: none).")] = None,
    target_accel_scale: Annotated[Optional[float], typer.Option(
        "--target-accel-scale", help="--design poses: target std of the accelerometer's scale factors [-] "
        "(default: none).")] = None,
    target_accel_offset: Annotated[Optional[float], typer.Option(
        "--target-accel-offset", help="--design poses: target std of the accelerometer's offsets [m/s^2] "
        "(default: none).")] = None,
    temp_points: Annotated[Optional[int], typer.Option(
        "--temp-points", help="--design poses: a chamber session of this many temperature points over "
        "--temp-range, the accelerometer's 1-sigma at a point and across the range (default: none, one "
        "temperature).")] = None,
    temp_range: Annotated[str, typer.Option(
        "--temp-range", help="--temp-points: the chamber's range LOW:HIGH [degC].")] = "-25:50",
) -> None:
    """Predict each parameter's std and the protocol time; suggest the fastest protocol for a target."""
    import numpy as np
    from rich.markup import escape
    from rich.table import Table

    from .._validation import positive

    refuse_unused(ctx, _DESIGN_FLAGS, design, "--design")
    speed, max_speed, peak_rate = (in_unit(f"--{n}", v, "deg/s") for n, v in (
        ("speed", speed), ("max-speed", max_speed), ("peak-rate", peak_rate)))
    noise = in_unit("--noise", noise, "rad/s")
    positive("speed", speed)
    positive("max_speed", max_speed)
    for name in ("target_scale", "target_cross", "target_accel_scale", "target_accel_offset"):
        if ctx.params[name] is not None:
            positive(name, ctx.params[name])
    if design == "poses":
        targets = {"gyro_scale": target_scale, "gyro_bias": _rate_arg("--target-bias", target_bias, "rad/s"),
                   "gyro_cross": target_cross, "accel_cross": target_cross, "accel_scale": target_accel_scale,
                   "accel_offset": target_accel_offset}
        density = noise_std(noise, noise_density, sample_rate, 0.0017, allow_zero=False) / math.sqrt(sample_rate)
        if temp_points is not None:
            from ._plan_thermal import plan_thermal

            options = dict(static_duration=still, peak_rate_deg=peak_rate, sample_rate=sample_rate,
                           accel_noise_density=accel_noise_density, gyro_noise_density=float(np.mean(density)))
            return plan_thermal(temp_points, poses, tilt, temp_range, {k: v for k, v in targets.items()
                                                                      if v is not None}, options)
        if temp_range != "-25:50":
            raise InputError("--temp-range describes a chamber session; add --temp-points N")
        return _plan_poses(poses, tilt, still, peak_rate, sample_rate, accel_noise_density, float(np.mean(density)),
                           {k: v for k, v in targets.items() if v is not None})

    from ..models import ScaleBias
    from ..planning import predict, suggest

    density = noise_std(noise, noise_density, sample_rate, 0.035, allow_zero=False) / math.sqrt(sample_rate)
    model = ScaleBias(np.asarray(triple("--k", k, (1.0, 1.0, 1.0))), np.zeros(3))
    options = dict(sample_rate=sample_rate, noise_density=density, model=model, static_duration=wait, pause=wait)
    given = predict(design, speed=math.radians(speed), revolutions=revolutions, **options)
    plans = [("as given", given)]
    bias_target = _rate_arg("--target-bias", target_bias, "rad/s")
    verdict = None
    if target_scale is not None or bias_target is not None:
        best = suggest(target_scale=target_scale, target_bias=bias_target, max_speed=math.radians(max_speed),
                       design=design, baseline=given, **options)
        verdict = _verdict(given, best, target_scale, bias_target, max_speed)
        if best is not None:
            plans.append(("suggested", best))
    console.print(f"Cramer-Rao prediction, design {design}, {sample_rate:g} Hz, noise density "
                  f"{density.mean():.3g} rad/s/sqrt(Hz)", highlight=False, soft_wrap=True)
    table = Table()
    for col in ("protocol", "speed\n[deg/s]", "revolutions", "time\n[s]", "std k\n[1e-4]", "std b\n[deg/s]"):
        table.add_column(escape(col), justify="right", no_wrap=True)
    for label, p in plans:
        table.add_row(label, f"{math.degrees(p.speed):.1f}", f"{p.revolutions:g}", f"{p.total_time:.1f}",
                      _per_axis(1e4 * p.std[:3]), _per_axis(np.degrees(p.std[3:])))
    console.print(table)
    if verdict is not None:
        console.print(verdict, highlight=False, soft_wrap=True)


def _per_axis(values) -> str:
    """One figure when the three axes agree (a symmetric design), else x/y/z."""
    shown = [f"{v:.3g}" for v in values]
    return shown[0] if len(set(shown)) == 1 else "/".join(shown)


def _verdict(given, best, target_scale, target_bias, max_speed: float) -> str:
    """What the targets mean for the protocol as given, and what the suggestion is."""
    parts = []
    if target_scale is not None:
        parts.append(f"std k <= {target_scale:.3g}")
    if target_bias is not None:
        parts.append(f"std b <= {math.degrees(target_bias):.3g} deg/s")
    target = "target " + " and ".join(parts)
    if given.meets(target_scale, target_bias):
        if best is None:
            return (f"the protocol as given already meets the {target}; no shorter protocol up to {max_speed:g} "
                    "deg/s meets it without a larger std on a target")
        return (f"the protocol as given already meets the {target}; the suggestion meets it too, "
                f"{given.total_time - best.total_time:.1f} s shorter, with no larger std on a target")
    if best is None:
        return (f"the protocol as given misses the {target}, and no protocol up to {max_speed:g} deg/s and "
                "20 revolutions per turn reaches it")
    return (f"the protocol as given misses the {target}; the suggestion is the shortest protocol up to "
            f"{max_speed:g} deg/s that reaches it without a larger std on a target")


def _plan_poses(poses, tilt, still, peak_rate, sample_rate, accel_density, gyro_density, targets) -> None:
    """The whole-IMU hand session: predicted std of both sensors, and the shortest plan for the targets."""
    from rich.table import Table

    from ..imu.planning import predict_poses, suggest_poses

    options = dict(static_duration=still, peak_rate_deg=peak_rate, sample_rate=sample_rate,
                   accel_noise_density=accel_density, gyro_noise_density=gyro_density)
    plans = [("as given", predict_poses(poses, tilt, **options))]
    if targets:
        plans.append(("suggested", suggest_poses(targets, **options)))
    table = Table(title=f"Cramer-Rao prediction of a hand session (gyrocal imu), {sample_rate:g} Hz")
    table.add_column("")
    for label, _ in plans:
        table.add_column(label, justify="right")
    rows = [("poses", lambda p, f: str(p.poses)), ("tilt between poses (deg)", lambda p, f: f"{p.turn_deg:g}"),
            ("session time (s)", lambda p, f: f"{p.total_time:.0f}"),
            ("gyro scale (1e-4)", lambda p, f: f"{1e4 * f['gyro_scale']:.3g}"),
            ("gyro cross terms (1e-4)", lambda p, f: f"{1e4 * f['gyro_cross']:.3g}"),
            ("gyro bias (deg/s)", lambda p, f: f"{math.degrees(f['gyro_bias']):.2g}"),
            ("accel scale (1e-4)", lambda p, f: f"{1e4 * f['accel_scale']:.3g}"),
            ("accel cross terms (1e-4)", lambda p, f: f"{1e4 * f['accel_cross']:.3g}"),
            ("accel offset (m/s^2)", lambda p, f: f"{f['accel_offset']:.2g}")]
    for name, cell in rows:
        table.add_row(name, *(cell(p, p.figures()) for _, p in plans))
    console.print(table)
    console.print(f"noise densities: gyro {gyro_density:.3g} rad/s/sqrt(Hz), accelerometer {accel_density:.3g} "
                  "m/s^2/sqrt(Hz)", highlight=False, soft_wrap=True)
    if poses < 12:
        console.print(f"note: with {poses} poses 'gyrocal imu' fits the accelerometer's scale and offset only (the "
                      "9-parameter model needs 12 poses to be checked); the accel figures above are for the "
                      "9-parameter model", highlight=False, soft_wrap=True)
    console.print("each figure is the largest 1-sigma of its kind; 'inf': the plan does not determine it (a tilt of "
                  "180 deg only flips the board between two faces)", highlight=False, soft_wrap=True)
