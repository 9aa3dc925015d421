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
from ._outputs import check_output, json_format, starts_with
from .app import app, console, warnings_as_lines
from .calibrate_cmds import Columns, OutputUnits, SampleRate, Sensitivity, Units, _read

TRUTH_FORMAT = "gyrocal.simulation-truth"
_SIMULATED = "gyrocal simulate"  # first words of a simulated recording: a later simulate may replace it


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


def _numbers(name: str, text: str) -> list[float]:
    """Comma-separated finite numbers."""
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise InputError(f"{name} must be comma-separated numbers, got {text!r}") from None
    if not all(map(math.isfinite, values)):
        raise InputError(f"{name} must be finite numbers, got {text!r}")
    return values


def _triple(name: str, text: str | None, default) -> np.ndarray:
    if text is None:
        return np.asarray(default, dtype=float)
    values = _numbers(name, text)
    if len(values) != 3:
        raise InputError(f"{name} must be three comma-separated numbers, got {text!r}")
    return np.asarray(values)


def _given(ctx: typer.Context, name: str) -> bool:
    """Whether parameter `name` was typed on the command line rather than left at its default."""
    source = ctx.get_parameter_source(name)
    return source is not None and source.name == "COMMANDLINE"


def _refuse_unused(ctx: typer.Context, users: dict[str, tuple[str, ...]], choice: str, what: str) -> None:
    """Refuse a flag given on the command line that `choice` does not use: ignoring it would mislead.

    `users` maps a parameter name to the choices that use it; parameters not in it apply to all.
    """
    for param in ctx.command.params:
        if param.name in users and choice not in users[param.name] and _given(ctx, param.name):
            flag = max(param.opts, key=len)
            raise InputError(f"{flag} does not apply to {what} {choice} (only to {', '.join(users[param.name])}); "
                             "drop it")


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


_SERVO = ("servo", "hand")
#: Flags that only some protocols use; the rest apply to every protocol.
_PROTOCOL_FLAGS = {
    **dict.fromkeys(("speed", "turns", "wait", "ramp", "misalignment"), _SERVO), "vibration": ("servo",),
    **dict.fromkeys(("k", "b"), (*_SERVO, "profile")),  # the turntable gyro follows seed 001's thermal truth
    **dict.fromkeys(("temps", "rates", "step_duration", "temp_noise", "temp_quantum"), ("turntable",)),
    **dict.fromkeys(("profile", "profile_units", "duration"), ("profile",)),
}


def _turntable_protocol(temps: str | None, rates: str | None, step_duration: float | None, temp_noise: float,
                        temp_quantum: float | None):
    """The seed 001 protocol from the command line's flags; unset ones keep the paper's values."""
    from ..simulation.turntable import TurntableProtocol

    kw: dict = {}
    if temps is not None:
        kw["temps"] = tuple(_numbers("--temps", temps))
    if rates is not None:
        kw["rates"] = tuple(_numbers("--rates", rates))
        if min(kw["rates"]) < 0:
            raise InputError(f"--rates are magnitudes >= 0 deg/s (each runs forward and reverse), got {rates!r}")
    if step_duration is not None:
        if not (math.isfinite(step_duration) and step_duration > 0):
            raise InputError(f"--step-duration must be > 0 s, got {step_duration:g}")
        kw["step_duration"] = step_duration
    if not (math.isfinite(temp_noise) and temp_noise >= 0):
        raise InputError(f"--temp-noise must be >= 0 degC, got {temp_noise:g}")
    if temp_quantum is not None and not (math.isfinite(temp_quantum) and temp_quantum > 0):
        raise InputError(f"--temp-quantum must be > 0 degC (e.g. 1 for whole degrees), got {temp_quantum:g}")
    return TurntableProtocol(**kw, temp_noise=temp_noise, temp_quantum=temp_quantum)


@app.command()
def simulate(
    ctx: typer.Context,
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
    temps: Annotated[Optional[str], typer.Option(
        "--temps", help="--protocol turntable: temperatures [degC], comma-separated (default: seed 001 Table 1, "
                        "-40 to 50 by 10).")] = None,
    rates: Annotated[Optional[str], typer.Option(
        "--rates", help="--protocol turntable: rates [deg/s], comma-separated, each run forward and reverse "
                        "(default: seed 001 Table 2, 0 to 400).")] = None,
    step_duration: Annotated[Optional[float], typer.Option(
        "--step-duration", help="--protocol turntable: length of each rate step [s] (default: 60, the paper's).")]
    = None,
    temp_noise: Annotated[float, typer.Option(
        "--temp-noise", help="--protocol turntable: std of each temperature reading [degC].")] = 0.0,
    temp_quantum: Annotated[Optional[float], typer.Option(
        "--temp-quantum", help="--protocol turntable: resolution of the temperature readings [degC], e.g. 1.")]
    = None,
    sample_rate: Annotated[float, typer.Option("--sample-rate", help="Sampling rate [Hz].")] = 200.0,
    units: Annotated[str, typer.Option("--units", help="Unit of the written gyro columns.")] = "deg/s",
    seed: Annotated[int, typer.Option("--seed", help="Random seed.")] = 0,
    force: Annotated[bool, typer.Option("--force", help="Replace an -o file that gyrocal simulate did not write.")]
    = False,
) -> None:
    """Simulate a recording (servo, hand, turntable or profile) with its truth sidecar."""
    from .._jsonfile import write_json
    from ..io import write_csv
    from ..models import ScaleBias
    from ..simulation import VirtualGyro
    from ..units import from_rad_s, parse_rate_unit

    _refuse_unused(ctx, _PROTOCOL_FLAGS, protocol.value, "--protocol")
    truth_path = output.with_name(output.stem + ".truth.json")
    check_output(output, inputs=(profile,), force=force, replaceable=starts_with(f"# {_SIMULATED}"))
    check_output(truth_path, flag="truth file", inputs=(profile,), force=force,
                 replaceable=json_format(TRUTH_FORMAT))
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

        proto = _turntable_protocol(temps, rates, step_duration, temp_noise, temp_quantum)
        thermal = ThermalTruth()
        K, B = thermal(np.array([thermal.ref_temp]))
        model = Affine(K[0], B[0])
        rec = simulate_turntable(VirtualGyro(model, thermal=thermal, **gyro_kw), proto, sample_rate=sample_rate,
                                 rng=rng)
        settings.update(temps_degC=list(proto.temps), rates_deg_s=list(proto.rates), axes=list(proto.axes),
                        step_duration_s=proto.step_duration, table_tau_s=proto.table_tau,
                        temp_noise_degC=proto.temp_noise, temp_quantum_degC=proto.temp_quantum)
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
    write_csv(output, columns, header_comment=f"{_SIMULATED} --protocol {protocol.value}; gyro in {unit}, t in s")
    write_json(truth_path, _truth_doc(protocol.value, model, settings, extra))
    console.print(f"wrote {output} ({len(rec)} samples, {len(rec) / sample_rate:.1f} s, {unit}) and {truth_path}")


class MotionChoice(str, Enum):
    restrict = "restrict"
    refuse = "refuse"


def _figure_cell(fig, r: int, factor: float, missing: str) -> str:
    """Value over its interval, e.g. ``3.438`` over ``3.43-3.45``."""
    v = fig.value[r] * factor
    if not math.isfinite(v):
        return missing
    if not (math.isfinite(fig.low[r]) and math.isfinite(fig.high[r])):
        return f"{v:.4g}"
    return f"{v:.4g}\n{fig.low[r] * factor:.3g}-{fig.high[r] * factor:.3g}"


def _noise_table(title: str, sensor, fs: float, factors: tuple[float, float, float], heads: tuple[str, str, str]):
    from rich.table import Table

    table = Table(title=title)
    for col in ("axis", heads[0], "\u03c3/sample", heads[1], "at \u03c4\ns", heads[2]):
        table.add_column(col, justify="right", no_wrap=True)
    std = sensor.noise_std(fs)
    for r, name in enumerate(("x", "y", "z", "sensor")):
        table.add_row(name, _figure_cell(sensor.density, r, factors[0], "-"), f"{std[r]:.4g}",
                      _figure_cell(sensor.bias_instability, r, factors[1], "not reached"),
                      f"{sensor.bias_instability.tau[r]:.4g}" if math.isfinite(sensor.bias_instability.tau[r]) else "-",
                      _figure_cell(sensor.random_walk, r, factors[2], "not seen"))
    return table


@app.command()
def noise(
    recording: Annotated[Path, typer.Argument(help="Recording at rest: CSV, Parquet or a ROS/MCAP bag.")],
    units: Units = None,
    columns: Columns = None,
    sample_rate: SampleRate = None,
    sensitivity: Sensitivity = None,
    output_units: OutputUnits = None,
    motion: Annotated[MotionChoice, typer.Option(
        "--motion", help="A log that moves: analyse its longest still stretch (restrict) or refuse it.")]
    = MotionChoice.restrict,
    plot: Annotated[Optional[Path], typer.Option("--plot", help="Allan deviation plot (.png, .pdf, .svg).")] = None,
    json_out: Annotated[Optional[Path], typer.Option("--json", help="Write the noise figures as JSON.")] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace a --json file that is not a noise file.")]
    = False,
) -> None:
    """Allan deviation of a log at rest: noise density, bias instability, random walk, with intervals."""
    from ..noise import FORMAT, characterise_recording, save_noise
    from ..units import parse_rate_unit, unit_factor

    # every output is checked before anything is computed or written
    check_output(json_out, flag="--json", inputs=(recording,), force=force, replaceable=json_format(FORMAT))
    check_output(plot, flag="--plot", inputs=(recording, json_out), force=True)
    if plot is not None:
        from ..plotting._mpl import check_figure_path

        check_figure_path(plot)
        if json_out is not None and plot.absolute() == json_out.absolute():
            raise InputError(f"--plot and --json are both {plot}; give two different files")
    if units is None:
        raise InputError("--units is required (rad/s, deg/s, or counts with --sensitivity): the noise figures are "
                         "physical quantities")
    if units == "counts" and sensitivity is None:
        raise InputError("--units counts needs --sensitivity (LSB per --output-units, e.g. 131 for a +-250 deg/s "
                         "MPU-9250): noise figures are physical quantities")
    rec = _read(recording, units, columns, sample_rate, sensitivity, output_units, None)
    with warnings_as_lines():
        report = characterise_recording(rec, motion=motion.value, source={"file": recording.name})
    shown = parse_rate_unit(rec.source_units if rec.source_units != "counts" else (output_units or "deg/s"))
    per = 1.0 / unit_factor(shown)
    fs = report.sample_rate
    console.print(_noise_table(
        f"{recording.name}: gyro, {report.duration:.0f} s at {fs:g} Hz, {100 * report.confidence:.0f} % intervals",
        report.gyro, fs, (per, per, per), (f"density\n{shown}/\u221aHz", f"bias inst.\n{shown}",
                                           f"random walk\n{shown}/s/\u221aHz")))
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
    name: Annotated[StudyChoice, typer.Argument(help="Which study.")],
    out: Annotated[Path, typer.Option("-o", "--output", help="Output folder for figures and tables.")],
    gyros: Annotated[Optional[int], typer.Option("--gyros", help="Simulated gyros (default: the paper's).")] = None,
    reps: Annotated[Optional[int], typer.Option("--reps", help="Calibrations per gyro (default: the paper's).")] = None,
    seed: Annotated[int, typer.Option("--seed", help="Random seed.")] = 0,
    methods: Annotated[Optional[str], typer.Option(
        "--methods", help="servo-speed: estimators, comma-separated (algorithm1, lm, first-moment).")] = None,
    noise_density: NoiseDensity = None,
    sample_rate: Annotated[float, typer.Option(
        "--sample-rate", help="Sampling rate [Hz] (thermal-compare's default: 100).")] = 200.0,
    speed: Annotated[float, typer.Option(
        "--speed", help="Servo studies but servo-speed: turn speed [deg/s] (paper: 60).")] = 60.0,
) -> None:
    """Run a Monte Carlo study of seed 000 or 001 and write its figures and tables."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from ..studies import ServoSettings, run_study, study_units

    _refuse_unused(ctx, _STUDY_FLAGS, name.value, "study")
    check_output(out, folder=True)
    options: dict = {}
    if methods is not None:
        options["methods"] = tuple(m.strip() for m in methods.split(",") if m.strip())
    if not (math.isfinite(speed) and speed > 0):
        raise InputError(f"--speed must be > 0 deg/s, got {speed:g}")
    if not (math.isfinite(sample_rate) and sample_rate > 0):
        raise InputError(f"--sample-rate must be > 0 Hz, got {sample_rate:g}")
    settings = None
    if name.value in _SERVO_STUDIES:
        settings = ServoSettings(speed=math.radians(speed), sample_rate=sample_rate)
    else:  # thermal-compare keeps its own sampling rate unless told
        from ..studies.thermal_compare import SAMPLE_RATE

        if _given(ctx, "sample_rate"):
            options["sample_rate"] = sample_rate
        sample_rate = options.get("sample_rate", SAMPLE_RATE)
    if noise_density is not None:
        from ..noise import noise_density_arg

        sd = float(np.mean(noise_density_arg(noise_density))) * math.sqrt(sample_rate)
        if settings is None:
            options["noise"] = sd
        else:
            settings = ServoSettings(speed=settings.speed, sample_rate=sample_rate, noise_levels=(sd,))
    with Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                  TimeElapsedColumn(), console=console, transient=False) as bar:
        task = bar.add_task(name.value, total=study_units(name.value, settings, gyros=gyros, **options))

        def progress(advance: int, label: str) -> None:
            bar.update(task, advance=advance, description=f"{name.value}: {label}")

        result = run_study(name.value, out, gyros=gyros, reps=reps, seed=seed, settings=settings, progress=progress,
                           **options)
    console.print(result.summary, highlight=False, markup=False)
    for path in result.files:
        console.print(f"wrote {path}")
