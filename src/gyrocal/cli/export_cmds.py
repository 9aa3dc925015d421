"""Command ``export``: a calibration file in another format (choices from the exporter registry)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal, Optional

import typer

from ..export import EXPORT_FORMATS
from ._outputs import check_output, same_text
from .app import app, console

__all__ = ["export"]

ExportFormat = Literal[EXPORT_FORMATS]  # type: ignore[valid-type]


@app.command()
def export(
    calibration: Annotated[Path, typer.Argument(
        help="A gyrocal file: calibration, thermal, noise (kalibr, vins, imu_utils) or thermal-bias (px4, "
             "ardupilot).")],
    format: Annotated[ExportFormat, typer.Option("--format", help="Output format.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Output file.")],
    prefix: Annotated[Optional[str], typer.Option(
        "--prefix", help="c-header: start of every C name (default gyrocal), so one firmware can hold several "
                         "sensors' calibrations.")] = None,
    rostopic: Annotated[Optional[str], typer.Option(
        "--rostopic", help="kalibr: the IMU's ROS topic (default: /imu0).")] = None,
    update_rate: Annotated[Optional[float], typer.Option(
        "--update-rate", help="kalibr, vins: IMU rate [Hz] of the target log (default: the noise log's).")] = None,
    inflate: Annotated[Optional[float], typer.Option(
        "--inflate", help="kalibr, vins, imu_utils: safety factor on every noise value, recorded in the file "
                          "(default: 1).")] = None,
    accel_noise_density: Annotated[Optional[float], typer.Option(
        "--accel-noise-density", help="kalibr, vins: accelerometer density [m/s^2/sqrt(Hz)] when the noise file "
                                      "has none (default: none, from the file).")] = None,
    accel_random_walk: Annotated[Optional[float], typer.Option(
        "--accel-random-walk", help="kalibr, vins: accelerometer bias random walk [m/s^3/sqrt(Hz)] when the noise "
                                    "file has none (default: none, from the file).")] = None,
    gyro_random_walk: Annotated[Optional[float], typer.Option(
        "--gyro-random-walk", help="kalibr, vins: gyro bias random walk [rad/s^2/sqrt(Hz)] when the log is too "
                                   "short to see it (default: none, from the file).")] = None,
    random_walk_bound: Annotated[bool, typer.Option(
        "--random-walk-bound", help="kalibr, vins: where a random walk is not seen, use its 95 % upper bound.")]
    = False,
    name: Annotated[Optional[str], typer.Option("--name", help="imu_utils: the IMU's name (default: imu).")] = None,
    slot: Annotated[Optional[int], typer.Option(
        "--slot", help="px4: TC_G slot 0-3; ardupilot: INS_TCAL set 1-3 (default: the log's IMU).")] = None,
    device_id: Annotated[Optional[int], typer.Option(
        "--device-id", help="px4: the gyro's device id, TC_Gn_ID (default: the one in the ULog).")] = None,
    accel_device_id: Annotated[Optional[int], typer.Option(
        "--accel-device-id", help="px4: the accelerometer's device id, TC_An_ID, for a thermal-bias file with an "
                                  "accelerometer part (default: the one in the ULog).")] = None,
    caltemp: Annotated[Optional[float], typer.Option(
        "--caltemp", help="ardupilot: temperature of the INS_GYROFFS companion [degC] (default: mid-range).")]
    = None,
    force: Annotated[bool, typer.Option("--force", help="Replace an output that holds a different calibration.")]
    = False,
) -> None:
    """Write a gyrocal file in another format: JSON, YAML, C header, Kalibr, VINS, imu_utils, PX4, ArduPilot."""
    from .._atomic import write_text_atomic
    from ..export import render

    typed = {"prefix": prefix, "rostopic": rostopic, "update_rate": update_rate, "inflate": inflate,
             "accel_noise_density": accel_noise_density, "accel_random_walk": accel_random_walk,
             "gyro_random_walk": gyro_random_walk, "use_bound": random_walk_bound or None, "name": name,
             "slot": slot, "device_id": device_id, "accel_device_id": accel_device_id, "caltemp": caltemp}
    options = {k: v for k, v in typed.items() if v is not None}  # an exporter refuses options it does not take
    text = render(calibration, format, **options)
    check_output(output, inputs=(calibration,), force=force, replaceable=same_text(text))
    write_text_atomic(output, text)
    console.print(f"wrote {output} ({format})", highlight=False)
