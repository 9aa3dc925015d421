"""``gyrocal plan --design poses --temp-points N``: a chamber session, points and poses for a target 1-sigma
(kept apart from ``plan_cmds`` to keep that module small)."""

from __future__ import annotations

from ..errors import InputError
from ._options import numbers
from .app import console

__all__ = ["plan_thermal"]


def temp_range(text: str) -> tuple[float, float]:
    """``LOW:HIGH`` [degC] as two numbers, low below high."""
    parts = text.split(":")
    values = numbers("--temp-range", ",".join(parts)) if len(parts) == 2 else []
    if len(values) != 2 or not values[0] < values[1]:
        raise InputError(f"--temp-range must be LOW:HIGH in degC with LOW < HIGH, e.g. -25:50, got {text!r}")
    return values[0], values[1]


def plan_thermal(points: int, poses: int, tilt: float, span: str, targets: dict, options: dict) -> None:
    """Print the predicted 1-sigma at one point and across the range, and the smallest plan for `targets`."""
    from rich.table import Table

    from ..imu.thermal_planning import THERMAL_FIGURES, predict_thermal, suggest_thermal

    flags = {"accel_cross": "--target-cross", "gyro_cross": "--target-cross", "gyro_scale": "--target-scale",
             "gyro_bias": "--target-bias"}
    other = sorted({flags[k] for k in set(targets) - set(THERMAL_FIGURES)})
    if other:
        raise InputError(f"--temp-points plans the accelerometer's scale and offset (--target-accel-scale, "
                         f"--target-accel-offset) and the gyro's scale and bias (--target-scale, --target-bias); "
                         f"drop {', '.join(other)} or --temp-points")
    if points < 3:
        raise InputError(f"--temp-points must be 3 or more (a model in temperature needs 3 points), got {points}")
    rng = temp_range(span)
    plans = [("as given", predict_thermal(points, poses, tilt, temp_range=rng, **options))]
    if targets:
        plans.append(("suggested", suggest_thermal(targets, turn_deg=tilt, temp_range=rng, **options)))
    table = Table(title=f"chamber session over {rng[0]:g}..{rng[1]:g} degC (gyrocal imu), Cramer-Rao per point "
                        "carried through the smooth polynomial")
    table.add_column("")
    for label, _ in plans:
        table.add_column(label, justify="right")
    rows = [("temperature points", lambda p: str(p.points)), ("poses per point", lambda p: str(p.poses)),
            ("polynomial order", lambda p: str(p.order)),
            ("pose time, all points (s)", lambda p: f"{p.total_time:.0f}")]
    for key, label, scale, unit in (("accel_scale", "accel scale", 1e4, "1e-4"),
                                    ("accel_offset", "accel offset", 1.0, "m/s^2"),
                                    ("gyro_scale", "gyro scale", 1e4, "1e-4"),
                                    ("gyro_bias", "gyro bias", 180 / 3.141592653589793, "deg/s")):
        rows += [(f"{label} at a point ({unit})", lambda p, k=key, s=scale: f"{s * p.per_point[k]:.3g}"),
                 (f"{label} across the range, largest ({unit})", lambda p, k=key, s=scale: f"{s * p.between[k]:.3g}"),
                 (f"{label} across the range, RMS ({unit})", lambda p, k=key, s=scale: f"{s * p.between_rms[k]:.3g}")]
    for name, cell in rows:
        table.add_row(name, *(cell(p) for _, p in plans))
    console.print(table)
    console.print("each figure is the largest 1-sigma of its kind; the points are spread evenly over the range, "
                  "soaks are not counted; a target is met by the largest 1-sigma across the range; the suggestion "
                  "is the plan of fewest poses in all (5 to 12 points, so that a cubic is fitted, and 12 to 48 poses per point)", highlight=False,
                  soft_wrap=True)
