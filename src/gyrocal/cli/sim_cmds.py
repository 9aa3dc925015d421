"""Commands ``simulate``, ``noise``, ``plan`` and ``study``: simulation-side tools.

User units live here: speeds in deg/s, noise in rad/s (per sample) or a density,
misalignment in degrees; the library gets SI.
"""

from __future__ import annotations

import math
from enum import Enum
from pathlib import Path
from typing import Annotated, Optional

import numpy as np
import typer

from ..errors import InputError
from .app import app, console
from .calibrate_cmds import Columns, SampleRate, Units, _read

TRUTH_FORMAT = "gyrocal.simulation-truth"


class ProtocolName(str, Enum):
    servo = "servo"
    hand = "hand"
    turntable = "turntable"
    profile = "profile"


class StudyChoice(str, Enum):
    servo_normal = "servo-normal"
    servo_extreme = "servo-extreme"
    servo_speed = "servo-speed"
    servo_convergence = "servo-convergence"
    thermal_compare = "thermal-compare"


NoiseDensity = Annotated[Optional[str], typer.Option(
    "--noise-density",
    help="White-noise density: rad/s/sqrt(Hz), 'N deg/s/rtHz', or a noise JSON from 'gyrocal noise --json'.")]


def _triple(name: str, text: str | None, default) -> np.ndarray:
    if text is None:
        return np.asarray(default, dtype=float)
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise InputError(f"{name} must be three comma-separated numbers, got {text!r}") from None
    if len(values) != 3 or not all(map(math.isfinite, values)):
        raise InputError(f"{name} must be three comma-separated finite numbers, got {text!r}")
    return np.asarray(values)


def _noise_std(noise: float | None, density: str | None, sample_rate: float, default: float) -> np.ndarray:
    """Per-sample white noise (3,) [rad/s] from --noise or --noise-density."""
    from ..noise import noise_density_arg

    if noise is not None and density is not None:
        raise InputError("give --noise or --noise-density, not both")
    if density is not None:
        return noise_density_arg(density) * math.sqrt(sample_rate)
    value = default if noise is None else noise
    if not (math.isfinite(value) and value >= 0):
        raise InputError(f"--noise must be >= 0 rad/s, got {value:g}")
    return np.full(3, value)


def _truth_doc(protocol: str, model, settings: dict, extra: dict) -> dict:
    from ..models import Affine

    doc = {"format": TRUTH_FORMAT, "version": 1, "protocol": protocol, "units": {"b": "rad/s", "B": "rad/s"},
           "model": model.kind, "settings": settings}
    if isinstance(model, Affine):
        doc.update(K=model.K.tolist(), B=model.B.tolist())
    else:
        doc.update(k=model.k.tolist(), b=model.b.tolist())
    doc.update(extra)
    return doc


@app.command()
def simulate(
    output: Annotated[Path, typer.Option(
        "-o", "--output", help="Recording to write (CSV); the truth goes to *.truth.json.")],
    protocol: Annotated[ProtocolName, typer.Option("--protocol", help="Motion source.")] = ProtocolName.servo,
    speed: Annotated[float, typer.Option("--speed", help="Servo/hand turn speed [deg/s].")] = 60.0,
    turns: Annotated[str, typer.Option("--turns", help="Turns, comma-separated.")] = "+x,-x,+y,-y,+z,-z",
    wait: Annotated[float, typer.Option("--wait", help="Static wait between turns [s].")] = 3.0,
    ramp: Annotated[float, typer.Option("--ramp", help="Acceleration ramp of each turn [s].")] = 0.3,
    vibration: Annotated[float, typer.Option("--vibration", help="RMS speed vibration, fraction of speed.")] = 0.05,
    misalignment: Annotated[float, typer.Option("--misalignment", help="Mounting misalignment [deg], <= 10.")] = 5.0,
    k: Annotated[Optional[str], typer.Option("--k", help="True scale factors kx,ky,kz (seed 000 eq. 1).")] = None,
    b: Annotated[Optional[str], typer.Option("--b", help="True biases bx,by,bz [rad/s] (seed 000 eq. 1).")] = None,
    noise: Annotated[Optional[float], typer.Option("--noise", help="Per-sample white noise [rad/s].")] = None,
    noise_density: NoiseDensity = None,
    bias_instability: Annotated[float, typer.Option("--bias-instability", help="Gauss-Markov bias std [rad/s].")] = 0.0,
    rate_random_walk: Annotated[float, typer.Option("--rrw", help="Rate random walk [rad/s/sqrt(s)].")] = 0.0,
    quantum: Annotated[Optional[float], typer.Option("--quantum", help="Output resolution [rad/s].")] = None,
    full_scale: Annotated[Optional[float], typer.Option("--full-scale", help="Saturation [deg/s].")] = None,
    profile: Annotated[Optional[Path], typer.Option("--profile", help="--protocol profile: CSV of t,wx,wy,wz.")] = None,
    profile_units: Annotated[str, typer.Option("--profile-units", help="Unit of the profile rates.")] = "rad/s",
    duration: Annotated[Optional[float], typer.Option("--duration", help="--protocol profile: length [s].")] = None,
    sample_rate: Annotated[float, typer.Option("--sample-rate", help="Sampling rate [Hz].")] = 200.0,
    units: Annotated[str, typer.Option("--units", help="Unit of the written gyro columns.")] = "deg/s",
    seed: Annotated[int, typer.Option("--seed", help="Random seed.")] = 0,
) -> None:
    """Simulate a recording (servo, hand, turntable or profile) with its truth sidecar."""
    from .._jsonfile import write_json
    from ..io import write_csv
    from ..models import ScaleBias
    from ..simulation import VirtualGyro
    from ..units import from_rad_s, parse_rate_unit

    unit = parse_rate_unit(units)
    rng = np.random.default_rng(seed)
    sd = _noise_std(noise, noise_density, sample_rate, 0.035 if protocol != ProtocolName.turntable else 0.005)
    model = ScaleBias(_triple("--k", k, (1.0, 1.0, 1.0)), _triple("--b", b, (0.0, 0.0, 0.0)))
    fs_rad = None if full_scale is None else math.radians(full_scale)
    gyro_kw = dict(noise_std=tuple(sd), bias_instability=bias_instability, rate_random_walk=rate_random_walk,
                   quantum=quantum, full_scale=fs_rad)
    settings = {"sample_rate": sample_rate, "noise_std": sd.tolist(), "bias_instability": bias_instability,
                "rate_random_walk": rate_random_walk, "quantum": quantum, "full_scale_deg_s": full_scale,
                "seed": seed, "units": unit}
    extra: dict = {}
    if protocol in (ProtocolName.servo, ProtocolName.hand):
        from ..simulation.servo import ServoProtocol, simulate_servo

        turn_list = tuple(t.strip() for t in turns.split(",") if t.strip())
        kw = dict(speed=math.radians(speed), wait=wait, ramp=ramp, misalignment_deg=misalignment)
        proto = (ServoProtocol.hand(turn_list, **kw) if protocol == ProtocolName.hand
                 else ServoProtocol(turns=turn_list, vibration=vibration, **kw))
        rec, truth = simulate_servo(VirtualGyro(model, **gyro_kw), proto, sample_rate=sample_rate, rng=rng)
        settings.update(speed_deg_s=speed, turns=list(turn_list), wait_s=wait, ramp_s=ramp, vibration=vibration,
                        misalignment_deg=misalignment)
        extra = {"mounting": truth.mounting.tolist(), "windows": [w.to_dict() for w in truth.windows],
                 "plateaus": [w.to_dict() for w in truth.plateaus]}
    elif protocol == ProtocolName.turntable:
        from ..models import Affine
        from ..simulation.thermal_truth import ThermalTruth
        from ..simulation.turntable import simulate_turntable

        thermal = ThermalTruth()
        K, B = thermal(np.array([thermal.ref_temp]))
        model = Affine(K[0], B[0])
        rec = simulate_turntable(VirtualGyro(model, thermal=thermal, **gyro_kw), sample_rate=sample_rate, rng=rng)
        extra = {"thermal": {"ref_temp": thermal.ref_temp, "kg_ref": list(map(float, thermal.kg_ref)),
                             "scale_slope": list(thermal.scale_slope),
                             "bias_poly_deg_s": [list(r) for r in thermal.bias_poly]}}
    else:
        from ..simulation.profiles import read_profile, simulate_profile

        if profile is None or duration is None:
            raise InputError("--protocol profile needs --profile FILE.csv and --duration SECONDS")
        rec, _ = simulate_profile(VirtualGyro(model, **gyro_kw), read_profile(profile, units=profile_units),
                                  duration=duration, sample_rate=sample_rate, rng=rng)
        settings.update(profile=str(profile), duration_s=duration)
    columns = {"t": rec.t}
    columns.update({f"g{a}": from_rad_s(rec.gyro[:, i], unit) for i, a in enumerate("xyz")})
    if rec.temp is not None:
        columns["temp"] = rec.temp
    if rec.table_rate is not None:
        columns["table_rate"] = from_rad_s(rec.table_rate, unit)
        columns["axis"] = rec.axis
    write_csv(output, columns, header_comment=f"gyrocal simulate --protocol {protocol.value}; gyro in {unit}, t in s")
    truth_path = output.with_name(output.stem + ".truth.json")
    write_json(truth_path, _truth_doc(protocol.value, model, settings, extra))
    console.print(f"wrote {output} ({len(rec)} samples, {len(rec) / sample_rate:.1f} s, {unit}) and {truth_path}")


@app.command()
def noise(
    recording: Annotated[Path, typer.Argument(help="Static recording: CSV, Parquet or a ROS/MCAP bag.")],
    units: Units = None,
    columns: Columns = None,
    sample_rate: SampleRate = None,
    plot: Annotated[Optional[Path], typer.Option("--plot", help="Allan deviation plot (.png, .pdf, .svg).")] = None,
    json_out: Annotated[Optional[Path], typer.Option("--json", help="Write the noise figures as JSON.")] = None,
) -> None:
    """Allan deviation of a static recording: angle random walk, bias instability, rate random walk."""
    from rich.table import Table

    from ..noise import characterise, save_noise

    if units is None:
        raise InputError("--units is required (rad/s or deg/s): the Allan deviation is reported in physical units")
    rec = _read(recording, units, columns, sample_rate, None, None, None)
    report = characterise(rec.gyro, rec.sample_rate)
    table = Table(title=f"{recording.name}: {report.duration:.0f} s at {report.sample_rate:g} Hz")
    for col in ("axis", "ARW (deg/sqrt(h))", "density (rad/s/sqrt(Hz))", "sigma/sample (rad/s)",
                "bias instability (deg/h)", "at tau (s)", "RRW (deg/h/sqrt(h))"):
        table.add_column(col, justify="right")
    def shown(value: float, factor: float, missing: str) -> str:
        return f"{value * factor:.4g}" if math.isfinite(value) else missing

    deg_h = math.degrees(1.0) * 3600
    for a in range(3):
        table.add_row("xyz"[a], shown(report.arw[a], math.degrees(1.0) * 60, "-"), f"{report.arw[a]:.4g}",
                      f"{report.noise_std[a]:.4g}", shown(report.bias_instability[a], deg_h, "not reached"),
                      shown(report.bias_instability_tau[a], 1.0, "-"), shown(report.rrw[a], deg_h * 60, "not seen"))
    console.print(table)
    if json_out is not None:
        save_noise(json_out, report)
        console.print(f"wrote {json_out}")
    if plot is not None:
        from ..plotting._mpl import save_figure
        from ..plotting.noise import allan_figure

        save_figure(allan_figure(report, title=recording.name), plot)
        console.print(f"wrote {plot}")


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


class DesignChoice(str, Enum):
    six = "six"
    six_static = "six-static"
    twelve = "twelve"


@app.command()
def plan(
    speed: Annotated[float, typer.Option("--speed", help="Turn speed [deg/s].")] = 60.0,
    revolutions: Annotated[float, typer.Option("--revolutions", help="Revolutions per turn.")] = 1.0,
    design: Annotated[DesignChoice, typer.Option("--design", help="six (seed 000 Fig. 1), six-static, twelve.")]
    = DesignChoice.six,
    sample_rate: Annotated[float, typer.Option("--sample-rate", help="Sampling rate [Hz].")] = 200.0,
    noise: Annotated[Optional[float], typer.Option("--noise", help="Per-sample white noise [rad/s].")] = None,
    noise_density: NoiseDensity = None,
    k: Annotated[Optional[str], typer.Option("--k", help="Expected scale factors kx,ky,kz.")] = None,
    wait: Annotated[float, typer.Option("--wait", help="Wait between turns (static window for six-static) [s].")]
    = 3.0,
    target_scale: Annotated[Optional[float], typer.Option("--target-scale", help="Target std of every k [-].")]
    = None,
    target_bias: Annotated[Optional[str], typer.Option(
        "--target-bias", help="Target std of every bias, e.g. 0.01deg/s (default unit rad/s).")] = None,
    max_speed: Annotated[float, typer.Option("--max-speed", help="Fastest speed to consider [deg/s].")] = 180.0,
) -> None:
    """Predict each parameter's std and the protocol time; suggest the fastest protocol for a target."""
    from rich.table import Table

    from ..models import ScaleBias
    from ..planning import predict, suggest

    density = _noise_std(noise, noise_density, sample_rate, 0.035) / math.sqrt(sample_rate)
    model = ScaleBias(_triple("--k", k, (1.0, 1.0, 1.0)), np.zeros(3))
    options = dict(sample_rate=sample_rate, noise_density=density, model=model, static_duration=wait, pause=wait)
    plans = [("as given", predict(design.value, speed=math.radians(speed), revolutions=revolutions, **options))]
    bias_target = _rate_arg("--target-bias", target_bias, "rad/s")
    if target_scale is not None or bias_target is not None:
        best = suggest(target_scale=target_scale, target_bias=bias_target, max_speed=math.radians(max_speed),
                       design=design.value, **options)
        if best is None:
            console.print(f"no protocol up to {max_speed:g} deg/s and 20 revolutions per turn reaches the target")
        else:
            plans.append(("suggested", best))
    table = Table(title=f"Cramer-Rao prediction, design {design.value}, {sample_rate:g} Hz, "
                        f"noise density {density.mean():.3g} rad/s/sqrt(Hz)")
    for col in ("protocol", "speed (deg/s)", "revolutions", "time (s)", "std kx, ky, kz (1e-4)",
                "std bx, by, bz (deg/s)"):
        table.add_column(col, justify="right")
    for label, p in plans:
        table.add_row(label, f"{math.degrees(p.speed):.1f}", f"{p.revolutions:g}", f"{p.total_time:.1f}",
                      ", ".join(f"{1e4 * v:.3g}" for v in p.std[:3]),
                      ", ".join(f"{math.degrees(v):.3g}" for v in p.std[3:]))
    console.print(table)


@app.command()
def study(
    name: Annotated[StudyChoice, typer.Argument(help="Which study.")],
    out: Annotated[Path, typer.Option("-o", "--output", help="Output folder for figures and tables.")],
    gyros: Annotated[Optional[int], typer.Option("--gyros", help="Simulated gyros (default: the paper's).")] = None,
    reps: Annotated[Optional[int], typer.Option("--reps", help="Calibrations per gyro (default: the paper's).")] = None,
    seed: Annotated[int, typer.Option("--seed", help="Random seed.")] = 0,
    methods: Annotated[Optional[str], typer.Option(
        "--methods", help="servo-speed: estimators, comma-separated (algorithm1, lm, first-moment).")] = None,
    noise_density: NoiseDensity = None,
    sample_rate: Annotated[float, typer.Option("--sample-rate", help="Servo studies: sampling rate [Hz].")] = 200.0,
    speed: Annotated[float, typer.Option(
        "--speed", help="Servo studies but servo-speed: turn speed [deg/s] (paper: 60).")] = 60.0,
) -> None:
    """Run a Monte Carlo study of seed 000 or 001 and write its figures and tables."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from ..studies import ServoSettings, run_study, study_units

    options: dict = {}
    if methods is not None:
        if name != StudyChoice.servo_speed:
            raise InputError("--methods applies to servo-speed only")
        options["methods"] = tuple(m.strip() for m in methods.split(",") if m.strip())
    if not (math.isfinite(speed) and speed > 0):
        raise InputError(f"--speed must be > 0 deg/s, got {speed:g}")
    settings = ServoSettings(speed=math.radians(speed), sample_rate=sample_rate)
    if noise_density is not None:
        from ..noise import noise_density_arg

        sd = float(np.mean(noise_density_arg(noise_density))) * math.sqrt(sample_rate)
        settings = ServoSettings(speed=settings.speed, sample_rate=sample_rate, noise_levels=(sd,))
    with Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                  TimeElapsedColumn(), console=console, transient=False) as bar:
        task = bar.add_task(name.value, total=study_units(name.value, settings))

        def progress(advance: int, label: str) -> None:
            bar.update(task, advance=advance, description=f"{name.value}: {label}")

        result = run_study(name.value, out, gyros=gyros, reps=reps, seed=seed, settings=settings, progress=progress,
                           **options)
    console.print(result.summary, highlight=False, markup=False)
    for path in result.files:
        console.print(f"wrote {path}")
