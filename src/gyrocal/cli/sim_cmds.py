"""Command ``simulate``: a recording and its truth, from a protocol of the simulation library.

User units live here: speeds in deg/s, noise in rad/s (per sample) or a density,
misalignment in degrees; the library gets SI and checks its own protocols.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..choices import DeviceWire, Protocol, TimeStamps
from ..errors import InputError
from ._options import NoiseDensity, given, in_unit, noise_std, numbers, refuse_unused, triple
from ._outputs import check_output, json_format, starts_with
from ._sim_device import refuse_device_flags, serve_device
from ._sim_output import announce, output_unit, rate_flags, write_output
from ._sim_runs import multi_position, profile_run, turntable, turntable_protocol
from .app import app, console

__all__ = ["simulate"]

_SIMULATED = "gyrocal simulate"  # first words of a simulated recording: a later simulate may replace it
_SERVO = ("servo", "hand")
#: Flags that only some protocols use; the rest apply to every protocol.
_PROTOCOL_FLAGS = {
    **dict.fromkeys(("speed", "turns", "wait", "ramp", "revolutions", "angle_error"), _SERVO),
    **dict.fromkeys(("vibration", "ripple", "ripple_freq"), ("servo",)),
    "misalignment": (*_SERVO, "multi-position"),
    # the turntable gyro follows the full-temperature-range method's thermal truth
    **dict.fromkeys(("k", "b"), (*_SERVO, "profile", "multi-position")),
    **dict.fromkeys(("poses", "tilt", "still"), ("multi-position",)),
    **dict.fromkeys(("temps", "rates", "step_duration"), ("turntable",)),
    "temp_noise": ("turntable", "static", "multi-position"),
    "temp_quantum": ("turntable", "static"),
    **dict.fromkeys(("temp_points", "temp_soak", "temp_hysteresis", "temp_ramp"), ("multi-position",)),
    **dict.fromkeys(("profile", "profile_units"), ("profile",)),
    "duration": ("profile", "static"),
    **dict.fromkeys(("temp_start", "temp_end", "warmup_tau", "bias_tempco", "accel_random_walk"), ("static",)),
    "accel_noise_density": ("static", "multi-position"),
    # a reference log needs turns about several axes, which the single-axis turntable does not make
    "reference": (*_SERVO, "profile"),
}
#: Flags that describe the reference log, so they need --reference.
_REFERENCE_FLAGS = ("ref_sample_rate", "ref_offset", "ref_drift", "ref_mounting", "ref_noise", "ref_units")


@app.command()
def simulate(
    ctx: typer.Context,
    output: Annotated[Path | None, typer.Option(
        "-o", "--output", help="Recording to write (CSV); the truth goes to *.truth.json (required, except with --device).")] = None,
    protocol: Annotated[Protocol, typer.Option("--protocol", help="Motion source.")] = "servo",
    speed: Annotated[Optional[str], typer.Option(
        "--speed", help="Servo/hand turn speed, deg/s unless a unit is written, e.g. 1.05rad/s (default: 60 deg/s)."
    )] = None,
    turns: Annotated[str, typer.Option("--turns", help="Turns, comma-separated.")] = "+x,-x,+y,-y,+z,-z",
    wait: Annotated[float, typer.Option("--wait", help="Static wait between turns [s].")] = 3.0,
    ramp: Annotated[float, typer.Option("--ramp", help="Acceleration ramp of each turn [s].")] = 0.3,
    vibration: Annotated[float, typer.Option("--vibration", help="RMS speed vibration, fraction of speed.")] = 0.05,
    misalignment: Annotated[float, typer.Option("--misalignment", help="Mounting misalignment [deg], <= 10.")] = 5.0,
    k: Annotated[Optional[str], typer.Option(
        "--k", help="True scale factors kx,ky,kz (the servo method of Wang et al., eq. 1) (default: 1,1,1).")] = None,
    b: Annotated[Optional[str], typer.Option(
        "--b", help="True biases bx,by,bz (the servo method of Wang et al., eq. 1), rad/s unless a unit is written "
                    "after them, e.g. 0.5,-0.2,0.1deg/s (default: 0,0,0).")] = None,
    noise: Annotated[Optional[str], typer.Option(
        "--noise", help="Per-sample white noise, rad/s unless a unit is written, e.g. 2deg/s (default: 0.035 rad/s, "
                        "the paper's; 0.005 rad/s for the turntable and static).")] = None,
    noise_density: NoiseDensity = None,
    bias_instability: Annotated[Optional[str], typer.Option(
        "--bias-instability", help="Gauss-Markov bias std, rad/s unless a unit is written (default: 0).")] = None,
    rate_random_walk: Annotated[Optional[str], typer.Option(
        "--rrw", help="Rate random walk, rad/s/sqrt(s) unless a unit is written (0.01deg/s: deg/s/sqrt(s)) (default: "
                      "0).")] = None,
    quantum: Annotated[Optional[str], typer.Option(
        "--quantum", help="Output resolution, rad/s unless a unit is written (default: none, not quantised).")] = None,
    full_scale: Annotated[Optional[str], typer.Option(
        "--full-scale", help="Saturation, deg/s unless a unit is written (default: none, never saturates).")] = None,
    poses: Annotated[int, typer.Option(
        "--poses", help="--protocol multi-position: still poses of the hand session.")] = 24,
    tilt: Annotated[float, typer.Option(
        "--tilt", help="--protocol multi-position: tilt between successive poses [deg].")] = 90.0,
    still: Annotated[float, typer.Option(
        "--still", help="--protocol multi-position: still time in each pose [s] (each drawn within +-25 %).")] = 3.0,
    temp_points: Annotated[Optional[str], typer.Option(
        "--temp-points", help="--protocol multi-position: a chamber session, a full pose sequence at each of these "
                              "temperatures [degC], comma-separated, e.g. -25,0,25,50 (default: none, one session "
                              "at one temperature).")] = None,
    temp_soak: Annotated[float, typer.Option(
        "--temp-soak", help="--temp-points: soak before each later point, not recorded (the log jumps) [s].")] = 600.0,
    temp_hysteresis: Annotated[float, typer.Option(
        "--temp-hysteresis", help="--temp-points: accelerometer offsets of a point colder than the one before (the "
                                  "cooling branch) off the heating branch, sign drawn per axis [m/s^2].")] = 0.0,
    temp_ramp: Annotated[Optional[str], typer.Option(
        "--temp-ramp", help="--protocol multi-position: a chamber session on a ramp, LOW:HIGH[:RATE] [degC, degC/min], "
                            "the poses repeated while the temperature drifts, e.g. -25:60 (default: none; RATE "
                            "1 degC/min; HIGH below LOW cools).")] = None,
    profile: Annotated[Optional[Path], typer.Option("--profile", help="--protocol profile: CSV of t,wx,wy,wz (required there).")] = None,
    profile_units: Annotated[str, typer.Option("--profile-units", help="Unit of the profile rates.")] = "rad/s",
    duration: Annotated[Optional[float], typer.Option(
        "--duration", help="--protocol profile, static: length [s] (required there).")] = None,
    temp_start: Annotated[float, typer.Option(
        "--temp-start", help="--protocol static: temperature at power-on [degC].")] = 25.0,
    temp_end: Annotated[float, typer.Option(
        "--temp-end", help="--protocol static: temperature the board warms to [degC] (= --temp-start: no warm-up).")]
    = 25.0,
    warmup_tau: Annotated[float, typer.Option(
        "--warmup-tau", help="--protocol static: time constant of the exponential warm-up [s].")] = 600.0,
    bias_tempco: Annotated[Optional[str], typer.Option(
        "--bias-tempco", help="--protocol static: bias against temperature, x,y,z [rad/s/degC^n] for n = 1, 2, .. "
                              "about 25 degC, ';' between powers, e.g. 1e-4,-5e-5,2e-5;1e-6,0,0 (default: none, "
                              "no temperature dependence).")] = None,
    accel_noise_density: Annotated[Optional[float], typer.Option(
        "--accel-noise-density", help="--protocol static: also an accelerometer (gravity on z), white noise "
                                      "[m/s^2/sqrt(Hz)] (default: none, no accelerometer); --protocol "
                                      "multi-position: the accelerometer's noise (default: 0.002).")] = None,
    accel_random_walk: Annotated[Optional[float], typer.Option(
        "--accel-random-walk", help="--protocol static: accelerometer bias random walk [m/s^3/sqrt(Hz)] (default: "
                                    "none, no accelerometer; 0 with --accel-noise-density).")] = None,
    temps: Annotated[Optional[str], typer.Option(
        "--temps", help="--protocol turntable: temperatures [degC], comma-separated (default: the full-temperature-"
                        "range method's Table 1, -40 to 50 by 10).")] = None,
    rates: Annotated[Optional[str], typer.Option(
        "--rates", help="--protocol turntable: rates, comma-separated, deg/s unless a unit is written after the "
                        "last, each run forward and reverse "
                        "(default: the full-temperature-range method's Table 2, 0 to 400).")] = None,
    step_duration: Annotated[Optional[float], typer.Option(
        "--step-duration", help="--protocol turntable: length of each rate step [s] (default: 60, the paper's).")]
    = None,
    temp_noise: Annotated[float, typer.Option(
        "--temp-noise", help="--protocol turntable, static, multi-position with --temp-points: std of each "
                             "temperature reading [degC].")] = 0.0,
    temp_quantum: Annotated[Optional[float], typer.Option(
        "--temp-quantum", help="--protocol turntable, static: resolution of the temperature readings [degC], e.g. 1 (default: none, not quantised).")]
    = None,
    revolutions: Annotated[Optional[str], typer.Option(
        "--revolutions", help="Servo/hand: revolutions of each turn, one number or one per turn (0.375,0.5,0.75 = "
                              "135, 180, 270 deg). Default: 1.")] = None,
    ripple: Annotated[float, typer.Option(
        "--ripple", help="Servo: sinusoidal speed ripple, amplitude as a fraction of the speed (0.05 = 5 %).")] = 0.0,
    ripple_freq: Annotated[float, typer.Option("--ripple-freq", help="Servo: frequency of the ripple [Hz].")] = 2.5,
    angle_error: Annotated[float, typer.Option(
        "--angle-error", help="Servo/hand: each turn's true angle is off its declared size by a draw of this sd "
                              "[deg] (a robot's or a hand's angle error; the truth file has the true sizes; "
                              "calibrate --angle-sd carries it) (default: 0, exact).")] = 0.0,
    stamps: Annotated[TimeStamps, typer.Option(
        "--stamps", help="Time stamps: the sensor's clock, or receive times of a PC reading packets of two samples "
                         "(steps of about 3 and 17 ms at 100 Hz).")] = "sensor",
    late_per_minute: Annotated[float, typer.Option(
        "--late-per-minute", help="--stamps receive: late packets per minute (a long step caught up by a burst; "
                                  "nothing lost).")] = 0.0,
    gaps: Annotated[int, typer.Option("--gaps", help="Packet gaps: runs of samples never delivered.")] = 0,
    gap_length: Annotated[float, typer.Option("--gap-length", help="Length of each gap [s].")] = 0.17,
    sample_rate: Annotated[float, typer.Option("--sample-rate", help="Sampling rate [Hz].")] = 200.0,
    units: Annotated[str, typer.Option(
        "--units", help="Unit of the written gyro columns: deg/s, rad/s, or counts with --sensitivity.",
        metavar="<deg/s|rad/s|counts>")] = "deg/s",
    sensitivity: Annotated[Optional[float], typer.Option(
        "--sensitivity", help="For --units counts: LSB per deg/s of the written integers, e.g. 131 for an MPU-9250 at "
                              "+-250 deg/s (required there; add --full-scale to clip at the sensor's range).")] = None,
    seed: Annotated[int, typer.Option("--seed", help="Random seed.", min=0)] = 0,
    reference: Annotated[Optional[Path], typer.Option(
        "--reference", help="Also write the log of a reference gyro on the same motion (its own clock, mount, rate "
                            "and noise; the truth goes to the sidecar), for planning 'gyrocal verify' (default: none).")] = None,
    ref_sample_rate: Annotated[float, typer.Option("--ref-sample-rate", help="Reference rate [Hz].")] = 100.0,
    ref_offset: Annotated[float, typer.Option(
        "--ref-offset", help="Clock offset [s]: t_test = t_ref * (1 + drift) + offset.")] = 0.0,
    ref_drift: Annotated[float, typer.Option("--ref-drift", help="Clock drift of the test clock [ppm].")] = 0.0,
    ref_mounting: Annotated[float, typer.Option(
        "--ref-mounting", help="Angle of the mounting rotation between the sensors [deg], axis drawn at random.")]
    = 0.0,
    ref_noise: Annotated[Optional[str], typer.Option(
        "--ref-noise", help="Reference white noise per sample, rad/s unless a unit is written (default: an "
                            "ADIS16465, 0.0025 deg/s/sqrt(Hz)).")]
    = None,
    ref_units: Annotated[str, typer.Option("--ref-units", help="Unit of the reference's gyro columns.")] = "deg/s",
    force: Annotated[bool, typer.Option("--force", help="Replace an -o file that gyrocal simulate did not write.")]
    = False,
    device: Annotated[bool, typer.Option(
        "--device", help="Serve a servo, hand or multi-position session on a pseudo-terminal as a board would, for 'gyrocal "
                         "capture --port ...' (raw counts at 131 LSB per deg/s; frames are the example firmware's: "
                         "samples, its own six-turn calibration, corrected samples).")] = False,
    wire: Annotated[DeviceWire, typer.Option("--wire", help="--device: gyrocal frames or text lines.")] = "frames",
    faults: Annotated[str | None, typer.Option(
        "--faults", help="--device: drop=P,corrupt=P (per byte),stall=AT:SECONDS,disconnect=AT (AT: fraction of "
                         "the stream) (default: none).")] = None,
    pace: Annotated[float, typer.Option(
        "--pace", help="--device: 1 = real time, 10 = ten times faster, 0 = as fast as the reader reads.")] = 1.0,
) -> None:
    """Simulate a recording (servo, hand, turntable, profile, static, or a whole IMU's multi-position hand
    session) with its truth sidecar."""
    import numpy as np

    from ..io import write_recording
    from ..models import ScaleBias
    from ..results.files import save
    from ..simulation.truth import SimulationTruth
    from ..units import parse_rate_unit

    refuse_unused(ctx, _PROTOCOL_FLAGS, protocol, "--protocol")
    speed, noise, bias_instability, rate_random_walk, quantum, full_scale, b = rate_flags(
        speed, noise, bias_instability, rate_random_walk, quantum, full_scale, b)
    _refuse_reference_flags(ctx, reference)
    if device:
        return serve_device(ctx, protocol, model=(k, b), speed=speed, turns=turns, wait=wait, misalignment=misalignment,
                            noise=(noise, noise_density), sample_rate=sample_rate, seed=seed, wire=wire, faults=faults,
                            pace=pace, poses=poses, still=still)
    refuse_device_flags(ctx)
    truth_file = _check_outputs(output, reference, profile, force)
    ref_unit = parse_rate_unit(ref_units, "ref_units")
    unit = output_unit(units, sensitivity)
    rng = np.random.default_rng(seed)
    sd = noise_std(noise, noise_density, sample_rate, 0.035 if protocol not in ("turntable", "static") else 0.005)
    model = ScaleBias(triple("--k", k, (1.0, 1.0, 1.0)), b)
    gyro_kw = dict(noise_std=tuple(sd), bias_instability=bias_instability, rate_random_walk=rate_random_walk,
                   quantum=quantum, full_scale=None if full_scale is None else math.radians(full_scale))
    settings = {"sample_rate": sample_rate, "noise_std": sd.tolist(), "bias_instability": bias_instability,
                "rate_random_walk": rate_random_walk, "quantum": quantum, "full_scale_deg_s": full_scale,
                "seed": seed, "units": unit}
    size = announce(protocol, ctx.params, sample_rate, temps, rates, step_duration, unit, console)
    if protocol in _SERVO:
        rec, facts, true_rates = _servo(protocol, model, gyro_kw, turns, speed, wait, ramp, vibration, misalignment,
                                        sample_rate, rng, settings, revolutions=revolutions, ripple=ripple,
                                        ripple_freq=ripple_freq, angle_error=angle_error)
    elif protocol == "multi-position":
        rec, model, facts = multi_position(model, gyro_kw, ctx.params, sample_rate, rng, settings)
    elif protocol == "turntable":
        rec, model, facts = turntable(gyro_kw, turntable_protocol(temps, rates, step_duration, temp_noise,
                                                                     temp_quantum), sample_rate, rng, settings)
    elif protocol == "static":
        rec, facts = _static(gyro_kw, ctx.params, sample_rate, rng, settings)
    else:
        rec, facts, true_rates = profile_run(model, gyro_kw, profile, profile_units, duration, sample_rate, rng,
                                          settings)
    ref_rec = None
    if reference is not None:
        ref_rec, facts["reference"] = _reference_log(rec.t, true_rates, reference, rng, sample_rate=ref_sample_rate,
                                                     offset=ref_offset, drift=ref_drift, mounting=ref_mounting,
                                                     noise=in_unit("--ref-noise", ref_noise, "rad/s"))
    if stamps == "receive" or gaps or given(ctx, "late_per_minute"):
        rec, facts = _time_defects(rec, facts, settings, stamps, late_per_minute, gaps, gap_length, reference, rng)
    write_output(output, rec, unit, sensitivity, settings, f"{_SIMULATED} --protocol {protocol}", large=bool(size))
    if ref_rec is not None:
        write_recording(reference, ref_rec, units=ref_unit,
                        header_comment=f"{_SIMULATED} reference of {output.name}; gyro in {ref_unit}, t in s "
                                       "on the reference clock")
    save(SimulationTruth(protocol=protocol, model=model, settings=settings, facts=facts), truth_file)
    also = "" if reference is None else f", {reference} ({len(ref_rec)} samples at {ref_sample_rate:g} Hz)"
    console.print(f"wrote {output} ({len(rec)} samples, {len(rec) / sample_rate:.1f} s, {unit}){also} and "
                  f"{truth_file}", highlight=False)


def _check_outputs(output: Path | None, reference: Path | None, profile: Path | None, force: bool) -> Path:
    """Refuse outputs that would destroy something, before anything is simulated; the truth file's path."""
    from ..io import check_csv_name
    from ..simulation.truth import SimulationTruth, truth_path

    if output is None:
        raise InputError("give -o FILE.csv for the recording (or --device to serve a session on a pseudo-terminal)")
    check_output(output, inputs=(profile,), force=force, replaceable=starts_with(f"# {_SIMULATED}"))
    check_csv_name(output)
    truth_file = truth_path(output)
    check_output(truth_file, flag="truth file", inputs=(profile,), force=force,
                 replaceable=json_format(SimulationTruth.FORMAT))
    if reference is not None:
        check_output(reference, flag="--reference", inputs=(profile, output, truth_file),
                     outputs=(output, truth_file), force=force, replaceable=starts_with(f"# {_SIMULATED}"))
        check_csv_name(reference)
    return truth_file


def _refuse_reference_flags(ctx: typer.Context, reference: Path | None) -> None:
    """A --ref-* flag without --reference would be silently ignored: refuse it."""
    if reference is not None:
        return
    for name in _REFERENCE_FLAGS:
        if given(ctx, name):
            raise InputError(f"--{name.replace('_', '-')} describes the reference log; add --reference REF.csv")


def _reference_log(t, true_rates, path: Path, rng, *, sample_rate: float, offset: float, drift: float,
                   mounting: float, noise: float | None):
    """The reference recording and its truth for the sidecar (reference flags name themselves in errors)."""
    from .._validation import at_least, positive
    from ..models import ScaleBias
    from ..simulation import VirtualGyro
    from ..simulation.reference import ADIS16465_NOISE_DENSITY, simulate_reference
    from ._reading import prefixed_params

    with prefixed_params("ref_"):
        sample_rate = positive("sample_rate", sample_rate)
        sd = ADIS16465_NOISE_DENSITY * math.sqrt(sample_rate) if noise is None else at_least("noise_std", noise, 0.0,
                                                                                              " rad/s")
        gyro = VirtualGyro(ScaleBias((1.0, 1.0, 1.0), (0.0, 0.0, 0.0)), noise_std=sd)
        rec, truth = simulate_reference(t, true_rates, gyro, sample_rate=sample_rate, time_offset_s=offset,
                                        clock_drift_ppm=drift, mounting_deg=mounting, rng=rng)
    return rec, {"path": path.name, **truth.to_dict()}


def _time_defects(rec, facts, settings, stamps, late_per_minute, gaps, gap_length, reference, rng):
    """Receive-time stamps and packet gaps (:func:`gyrocal.simulation.timestamps.simulate_time_defects`)."""
    from ..simulation.timestamps import simulate_time_defects

    if stamps != "receive" and late_per_minute:
        raise InputError("--late-per-minute is for --stamps receive; add it or leave --late-per-minute out")
    if reference is not None:
        raise InputError("--reference is written on the true clock; give it or --stamps receive/--gaps, not both")
    rec, facts, more = simulate_time_defects(rec, facts, rng, stamps=stamps, late_per_minute=late_per_minute,
                                             gaps=gaps, gap_length=gap_length)
    settings.update(more)
    return rec, facts


def _servo(protocol, model, gyro_kw, turns, speed, wait, ramp, vibration, misalignment, sample_rate, rng, settings,
           *, revolutions: str | None = None, ripple: float = 0.0, ripple_freq: float = 2.5, angle_error: float = 0.0):
    """A servo or hand session: the recording, its facts and true rates; `settings` gains the protocol's."""
    from ..simulation import VirtualGyro
    from ..simulation.servo import ServoProtocol, simulate_servo
    from ..simulation.truth import servo_facts

    turn_list = tuple(t.strip() for t in turns.split(",") if t.strip())
    revs = (1.0,) if revolutions is None else tuple(numbers("--revolutions", revolutions))
    if not (math.isfinite(angle_error) and angle_error >= 0):
        raise InputError(f"--angle-error must be a number of degrees >= 0, got {angle_error:g}")
    base = revs * len(turn_list) if len(revs) == 1 else revs
    if angle_error and len(base) == len(turn_list):  # the true sizes: the declared ones plus one draw per turn
        revs = tuple(float(r + e / 360.0) for r, e in zip(base, rng.normal(scale=angle_error, size=len(base))))
    kw = dict(speed=math.radians(speed), wait=wait, ramp=ramp, misalignment_deg=misalignment,
              revolutions=revs[0] if len(revs) == 1 else revs)
    proto = (ServoProtocol.hand(turn_list, **kw) if protocol == "hand"
             else ServoProtocol(turns=turn_list, vibration=vibration, ripple=ripple, ripple_freq=ripple_freq, **kw))
    rec, truth = simulate_servo(VirtualGyro(model, **gyro_kw), proto, sample_rate=sample_rate, rng=rng)
    settings.update(speed_deg_s=speed, turns=list(turn_list), wait_s=wait, ramp_s=ramp, vibration=vibration,
                    misalignment_deg=misalignment, revolutions=[float(r) for r in proto.turn_angles() / (2 * math.pi)],
                    ripple=ripple, ripple_freq_hz=ripple_freq, angle_error_deg=angle_error)
    return rec, servo_facts(truth), truth.rates


def _static(gyro_kw, flags: dict, sample_rate, rng, settings):
    """``--protocol static``: a board lying still, warming up when --temp-start and --temp-end differ."""
    from ..constants import STANDARD_GRAVITY
    from ..models import ScaleBias
    from ..simulation import BiasDrift, StillAccelerometer, StillProtocol, VirtualGyro, simulate_still

    if flags["duration"] is None:
        raise InputError("--protocol static needs --duration SECONDS")
    tempco = flags["bias_tempco"]
    rows = [numbers("--bias-tempco", part) for part in (tempco or "0,0,0").split(";")]
    if any(len(r) != 3 for r in rows):
        raise InputError(f"--bias-tempco takes triples x,y,z per power of (T - 25 degC), ';' between powers, "
                         f"got {tempco!r}")
    drift = BiasDrift([[0.0, *c] for c in zip(*rows)], ref_temp=25.0)
    proto = StillProtocol(duration=flags["duration"], temp_start=flags["temp_start"], temp_end=flags["temp_end"],
                          temp_tau=flags["warmup_tau"], temp_noise=flags["temp_noise"],
                          temp_quantum=flags["temp_quantum"])
    accel = None
    if flags["accel_noise_density"] is not None or flags["accel_random_walk"] is not None:
        accel = StillAccelerometer(flags["accel_noise_density"] or 0.0, flags["accel_random_walk"] or 0.0)
    gyro = VirtualGyro(ScaleBias([1.0, 1.0, 1.0], [0.0, 0.0, 0.0]), thermal=drift, **gyro_kw)
    rec, _ = simulate_still(gyro, proto, sample_rate=sample_rate, rng=rng, accel=accel)
    settings.update(duration_s=proto.duration, temp_noise_degC=proto.temp_noise, temp_quantum_degC=proto.temp_quantum)
    facts = {"still": {"temp_start_degC": proto.temp_start, "temp_end_degC": proto.temp_end,
                       "warmup_tau_s": proto.temp_tau,
                       "bias_tempco": {"ref_temp_degC": 25.0, "coefs": drift.coefs.tolist(),
                                       "equation": "bias(T) = sum_n coefs[:, n] (T - 25)^n [rad/s]"},
                       "accelerometer": None if accel is None else {
                           "noise_density": accel.noise_density, "random_walk": accel.random_walk,
                           "gravity": [0.0, 0.0, STANDARD_GRAVITY]}}}
    return rec, facts

