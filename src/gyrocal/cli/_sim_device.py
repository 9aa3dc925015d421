"""``gyrocal simulate --device``: a simulated session served on a pseudo-terminal, as a board would send it
(kept apart from ``sim_cmds`` to keep that module small)."""

from __future__ import annotations

import math

import typer

from ..errors import InputError
from ._options import given, noise_std, triple
from .app import console

__all__ = ["refuse_device_flags", "serve_device"]

#: Flags of a simulated recording that a served multi-position session does not use (its person follows the
#: guide's plan; its sensors are an MPU-6050's).
_NOT_FOR_IMU_DEVICE = ("tilt", "noise", "noise_density", "accel_noise_density", "temp_points", "temp_ramp")


def refuse_device_flags(ctx: typer.Context) -> None:
    """--wire, --faults and --pace describe a served device: refuse them without --device."""
    for name in ("wire", "faults", "pace"):
        if given(ctx, name):
            raise InputError(f"--{name} is for --device only; add --device or leave --{name} out")


def _imu_session(ctx: typer.Context, model, misalignment: float, sample_rate: float, poses: int, still: float, rng):
    from ..capture.pose_guide import MIN_POSES, guided_directions
    from ..capture.simulated_imu import simulate_device_imu_session

    for name in _NOT_FOR_IMU_DEVICE:
        if given(ctx, name):
            flag = "--" + name.replace("_", "-")
            raise InputError(f"{flag} is not used by --device --protocol multi-position (its person follows the "
                             f"guide's poses, its sensors are an MPU-6050's); leave {flag} out")
    # 100 Hz unless asked: 6-axis frames and the firmware's corrected samples at 200 Hz fill 94 % of 115200 baud
    return simulate_device_imu_session(guided_directions(poses if given(ctx, "poses") else MIN_POSES), rng=rng,
                                       model=model, misalignment_deg=misalignment,
                                       sample_rate=sample_rate if given(ctx, "sample_rate") else 100.0,
                                       still=(0.75 * still, 1.25 * still))


def serve_device(ctx: typer.Context, protocol: str, *, model, speed, turns: str, wait: float, misalignment: float,
                 noise, sample_rate: float, seed: int, wire: str, faults: str | None, pace: float, poses: int,
                 still: float) -> None:
    """Serve a servo, hand or multi-position session until it has been read to the end (or the reader left)."""
    import numpy as np

    from ..capture.device import VirtualDevice, damage, device_bytes, parse_faults
    from ..models import ScaleBias

    if given(ctx, "reference"):
        raise InputError("--reference writes a second log; it does not go with --device (leave one out)")
    if protocol not in ("servo", "hand", "multi-position"):
        raise InputError(f"--device serves servo, hand or multi-position sessions, got --protocol {protocol}")
    if not pace >= 0:
        raise InputError(f"--pace must be >= 0, got {pace!r}")
    fault = parse_faults(faults, seed)
    truth = ScaleBias(triple("--k", model[0], (1.0, 1.0, 1.0)), model[1])
    rng = np.random.default_rng(seed)
    if protocol == "multi-position":
        session = _imu_session(ctx, truth, misalignment, sample_rate, poses, still, rng)
    else:
        from ..capture.simulated import simulate_device_session
        from ..simulation.servo import ServoProtocol

        turn_list = tuple(t.strip() for t in turns.split(",") if t.strip())
        kw = dict(speed=math.radians(speed), wait=wait, misalignment_deg=misalignment, lead_in=3.0)
        proto = ServoProtocol.hand(turn_list, **kw) if protocol == "hand" else ServoProtocol(turns=turn_list, **kw)
        session = simulate_device_session(proto, model=truth, noise_std=noise_std(*noise, sample_rate, 0.01), rng=rng,
                                          sample_rate=sample_rate)
    data, _ = damage(device_bytes(session, wire), fault)
    fs = session.sample_rate
    rate = None if pace == 0 else len(data) / (len(session) / fs) * pace
    with VirtualDevice(data, faults=fault, byte_rate=rate, wait_for="reader") as dev:
        port = dev.start()
        console.print(f"virtual device on {port}: {protocol} session, {len(session)} samples "
                      f"({len(session) / fs:.0f} s at {fs:g} Hz), {wire}; it starts when a reader "
                      f"opens the port, e.g.\n  gyrocal capture --port {port} -o rec.csv --guide {protocol}",
                      highlight=False, soft_wrap=True, markup=False)
        while not dev.wait(1.0):
            pass
    console.print(f"sent {dev.sent:,} bytes; the device closed the link", highlight=False)
