"""Servo and hand-turn sessions: the motion of the servo method's protocol (Fig. 1), simulated.

A session is a static lead-in, a sequence of turns about body axes separated by
static waits, and a static lead-out. Every turn is built as a turn *angle* sampled at
the sample boundaries, so the rates integrate (rectangle rule, ``sum(rate) / fs``)
to exactly ``360 * revolutions`` degrees whatever the ramps, vibration or pauses.

Servo vibration (the servo method of Wang et al., Fig. 7-8) is modelled as a bounded *angle* error of a
position-controlled servo: a periodic part at ``vibration_freq`` plus a random part,
tapered to zero at both ends of each turn. Its derivative is the speed jitter, and
the mean speed over a plateau stays the commanded one up to ``error / duration``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._arrays import readonly
from .._validation import positive
from ..errors import InputError
from ..models import CalibrationModel
from ..recording import Recording
from ..segmentation.windows import Window
from .gyro import VirtualGyro
from .windows import PAPER_AXES, axis_vector

__all__ = ["PAPER_TURNS", "ServoProtocol", "ServoTruth", "simulate_servo"]

#: The servo method of Wang et al., Fig. 1: clockwise and counter-clockwise about x, y and z.
PAPER_TURNS: tuple[str, ...] = PAPER_AXES


def _parse_turn(turn: str) -> tuple[int, int]:
    """``"+x"`` -> (axis index 0, sign +1)."""
    e = axis_vector(turn)
    j = int(np.abs(e).argmax())
    return j, int(e[j])


@dataclass(frozen=True)
class ServoProtocol:
    """A calibration session: which turns, how fast, with which imperfections.

    Parameters
    ----------
    speed : float
        Plateau speed of every turn [rad/s] (the servo method of Wang et al.: 60 deg/s).
    turns : tuple of str
        Turns in order, each ``+x``, ``-x``, ``+y``, ``-y``, ``+z`` or ``-z``; repeats allowed.
    revolutions : float or tuple of float
        Revolutions per turn; each turn turns exactly ``2 pi revolutions`` [rad]. A tuple gives
        one per turn (a robot's turns of 135 to 270 deg, a hand's uneven tilts).
    wait : float or tuple of float
        Static time between turns [s] (the servo method of Wang et al.: 3 s); a tuple gives one per gap.
    lead_in, lead_out : float
        Static time before the first and after the last turn [s].
    ramp : float
        Acceleration (and deceleration) time of each turn or turn piece [s]; 0 = instant.
    vibration : float
        RMS speed jitter as a fraction of `speed`, half periodic at `vibration_freq`,
        half random (servo vibration, the servo method of Wang et al., Fig. 7-8).
    vibration_freq : float
        Frequency of the periodic jitter [Hz].
    misalignment_deg : float
        Angle of the fixed mounting rotation between table and body axes [deg], <= 10;
        its axis is drawn at random once per session.
    unevenness : float
        Slow random speed modulation, as a fraction of the speed (hand turns), in [0, 0.9].
    pauses : int
        Stops inside each turn (a hand turn done as several pieces).
    pause_length : float
        Length of each stop [s].
    ripple : float
        Amplitude of a sinusoidal speed ripple as a fraction of `speed` (a motor's or robot
        joint's velocity ripple), in [0, 0.5]. It is a bounded angle error, faded in over the
        ramps, so every turn still turns exactly its angle; the mean speed over a plateau
        differs from the commanded one by up to ``ripple * speed / (pi * ripple_freq * T)``.
    ripple_freq : float
        Frequency of the ripple [Hz].
    """

    speed: float = math.radians(60.0)
    turns: tuple[str, ...] = PAPER_TURNS
    revolutions: float | tuple[float, ...] = 1.0
    wait: float | tuple[float, ...] = 3.0
    lead_in: float = 2.0
    lead_out: float = 2.0
    ramp: float = 0.3
    vibration: float = 0.05
    vibration_freq: float = 2.0
    misalignment_deg: float = 0.0
    unevenness: float = 0.0
    pauses: int = 0
    pause_length: float = 0.3
    ripple: float = 0.0
    ripple_freq: float = 2.5
    _parsed: tuple[tuple[int, int], ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        positive("speed", self.speed)
        if not np.isscalar(self.revolutions):
            object.__setattr__(self, "revolutions", tuple(float(r) for r in self.revolutions))
        revs = np.atleast_1d(np.asarray(self.revolutions, dtype=float))
        if revs.size not in (1, len(self.turns)) or not np.all(revs > 0) or not np.all(np.isfinite(revs)):
            raise InputError(f"{{param}} must be one number > 0 or one per turn ({len(self.turns)}), "
                             f"got {self.revolutions!r}", param="revolutions")
        if not self.turns:
            raise InputError("{param} is empty; give at least one of +x, -x, +y, -y, +z, -z", param="turns")
        object.__setattr__(self, "turns", tuple(self.turns))
        object.__setattr__(self, "_parsed", tuple(_parse_turn(t) for t in self.turns))
        waits = np.atleast_1d(np.asarray(self.wait, dtype=float))
        if waits.size not in (1, len(self.turns) - 1) and len(self.turns) > 1:
            raise InputError(f"{{param}} must be one value or {len(self.turns) - 1} (one per gap), got {waits.size}",
                             param="wait")
        for name in ("lead_in", "lead_out", "ramp", "vibration", "pause_length"):
            if not getattr(self, name) >= 0:
                raise InputError(f"{{param}} must be >= 0, got {getattr(self, name)!r}", param=name)
        if np.any(~(waits >= 0)):
            raise InputError(f"{{param}} must be >= 0 s, got {self.wait!r}", param="wait")
        positive("vibration_freq", self.vibration_freq)
        positive("ripple_freq", self.ripple_freq)
        if not 0 <= self.ripple <= 0.5:
            raise InputError(f"{{param}} must be in [0, 0.5] (a fraction of the speed), got {self.ripple!r}",
                             param="ripple")
        if not 0 <= self.misalignment_deg <= 10:
            raise InputError(f"{{param}} must be in [0, 10] deg, got {self.misalignment_deg!r}",
                             param="misalignment_deg")
        if not 0 <= self.unevenness <= 0.9:
            raise InputError(f"unevenness must be in [0, 0.9], got {self.unevenness!r}")
        if int(self.pauses) != self.pauses or self.pauses < 0:
            raise InputError(f"pauses must be a whole number >= 0, got {self.pauses!r}")

    @classmethod
    def hand(
        cls,
        turns: tuple[str, ...] = ("+x", "+y", "+z"),
        *,
        speed: float = math.radians(150.0),
        wait: float | tuple[float, ...] = 5.0,
        pauses: int = 3,
        unevenness: float = 0.4,
        misalignment_deg: float = 5.0,
        **kwargs,
    ) -> ServoProtocol:
        """A hand-turned session: uneven speed, each turn done in pieces with pauses.

        The waits are the static poses between turns (for a gyro a pose is only a
        stretch of standstill). Defaults follow the imucal Ferraris session: one turn
        per axis, four 90 deg pieces each.
        """
        kwargs.setdefault("ramp", 0.15)
        kwargs.setdefault("vibration", 0.0)
        return cls(speed=speed, turns=tuple(turns), wait=wait, pauses=pauses, unevenness=unevenness,
                   misalignment_deg=misalignment_deg, **kwargs)

    def waits(self) -> np.ndarray:
        """Static time after each turn but the last [s]."""
        return np.broadcast_to(np.atleast_1d(np.asarray(self.wait, dtype=float)), (max(len(self.turns) - 1, 0),))

    @property
    def turn_angle(self) -> float:
        """Angle of every turn [rad] (of the first, when they differ)."""
        return float(self.turn_angles()[0])

    def turn_angles(self) -> np.ndarray:
        """Angle of each turn [rad]."""
        revs = np.atleast_1d(np.asarray(self.revolutions, dtype=float))
        return 2.0 * math.pi * np.broadcast_to(revs, (len(self.turns),))


@dataclass(frozen=True)
class ServoTruth:
    """What really happened in a simulated session.

    Attributes
    ----------
    rates : ndarray, shape (N, 3)
        True body rates [rad/s].
    windows : tuple of Window
        Every turn (whole turn, exact ``angle`` [rad] and mean ``rate`` [rad/s]) and every
        static stretch, in time order.
    plateaus : tuple of Window
        The constant-speed part of every turn (``rate`` = the commanded speed); empty
        for hand turns, which have none.
    model : ScaleBias or Affine
        The gyro's true errors.
    mounting : ndarray, shape (3, 3)
        Rotation from table axes to body axes.
    """

    rates: np.ndarray
    windows: tuple[Window, ...]
    plateaus: tuple[Window, ...]
    model: CalibrationModel
    mounting: np.ndarray


def _trapezoid_angle(t: np.ndarray, speed: float, ramp: float, total: float) -> tuple[np.ndarray, float]:
    """Angle at times `t` [s] of a linear-ramp trapezoid turning `total` [rad]; and its duration [s]."""
    duration = total / speed + ramp
    if ramp == 0:
        return np.clip(speed * t, 0.0, total), duration
    tc = np.clip(t, 0.0, duration)
    up = speed * tc**2 / (2 * ramp)
    mid = speed * (tc - ramp / 2)
    down = total - speed * (duration - tc) ** 2 / (2 * ramp)
    return np.where(tc < ramp, up, np.where(tc > duration - ramp, down, mid)), duration


def _ripple_angle(t: np.ndarray, p: ServoProtocol, ramp: float, duration: float, rng) -> np.ndarray:
    """Angle error [rad] of a speed ripple at times `t`, zero at both ends of the piece.

    The speed ripple ``ripple * speed * cos(2 pi f t + phase)`` integrates to a sinusoidal angle
    error; it fades in over the ramp (half a ripple period without one) so the end angle is exact
    and the plateau carries the full ripple.
    """
    f = p.ripple_freq
    edge = ramp if ramp > 0 else 0.5 / f
    fade = np.clip(np.minimum(t, duration - t) / edge, 0.0, 1.0)
    return fade * p.ripple * p.speed / (2 * np.pi * f) * np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))


def _piece(p: ServoProtocol, total: float, fs: float, rng: np.random.Generator) -> tuple[np.ndarray, int, int]:
    """Rates of one turn piece [rad/s] (sign +), and the sample span of its plateau."""
    ramp = min(p.ramp, total / p.speed)  # a short piece never reaches a plateau longer than itself
    _, duration = _trapezoid_angle(np.zeros(1), p.speed, ramp, total)
    n = max(int(math.ceil(duration * fs)), 2)
    tb = np.arange(n + 1) / fs  # sample boundaries
    if p.unevenness > 0:
        # Time warp: speed varies slowly, the end angle does not.
        knots = 1.0 + p.unevenness * rng.uniform(-1, 1, size=max(int(duration * 2), 2) + 2)
        rate_of_u = np.interp(tb, np.linspace(0, tb[-1], len(knots)), knots)
        u = np.concatenate([[0.0], np.cumsum(rate_of_u[:-1]) / fs])
        u *= duration / u[-1]
        tb = u
    angle, _ = _trapezoid_angle(tb, p.speed, ramp, total)
    if p.vibration > 0:
        taper = np.sin(np.pi * np.arange(n + 1) / n)  # zero at both ends: the turn angle stays exact
        periodic = p.vibration * p.speed / (2 * np.pi * p.vibration_freq) * np.sin(
            2 * np.pi * p.vibration_freq * tb + rng.uniform(0, 2 * np.pi))
        random = p.vibration * p.speed / (2.0 * fs) * rng.standard_normal(n + 1)
        angle = angle + taper * (periodic + random)
    if p.ripple > 0:
        angle = angle + _ripple_angle(np.arange(n + 1) / fs, p, ramp, duration, rng)
    rates = np.diff(angle) * fs
    lo, hi = int(math.ceil(ramp * fs)), int(math.floor((duration - ramp) * fs))
    return rates, lo, max(hi, lo)


def _random_rotation(deg: float, rng: np.random.Generator) -> np.ndarray:
    if deg == 0:
        return np.eye(3)
    from scipy.spatial.transform import Rotation

    axis = rng.standard_normal(3)
    return Rotation.from_rotvec(math.radians(deg) * axis / np.linalg.norm(axis)).as_matrix()


def simulate_servo(
    gyro: VirtualGyro,
    protocol: ServoProtocol,
    *,
    sample_rate: float = 200.0,
    rng: np.random.Generator,
) -> tuple[Recording, ServoTruth]:
    """Simulate a session and what the gyro reads during it.

    Parameters
    ----------
    gyro : VirtualGyro
        The sensor; its ``measure`` adds errors, noise, quantisation and saturation.
    protocol : ServoProtocol
        The motion.
    sample_rate : float
        Sampling rate [Hz] (the servo method of Wang et al.: 200 Hz).
    rng : numpy.random.Generator
        Source of all randomness (mounting axis, vibration, unevenness, sensor noise).

    Returns
    -------
    recording : Recording
        Readings [rad/s] with a time column [s].
    truth : ServoTruth
        True rates, windows and model.
    """
    p, fs = protocol, positive("sample_rate", sample_rate)
    mounting = _random_rotation(p.misalignment_deg, rng)
    chunks: list[np.ndarray] = []
    windows: list[Window] = []
    plateaus: list[Window] = []
    pos = 0

    def static(seconds: float) -> None:
        nonlocal pos
        n = int(round(seconds * fs))
        if n > 0:
            chunks.append(np.zeros((n, 3)))
            if n >= 2:
                windows.append(Window(pos, pos + n, "static", label="static"))
            pos += n

    static(p.lead_in)
    waits = p.waits()
    pieces = int(p.pauses) + 1
    for i, (turn, (axis, sign), total) in enumerate(zip(p.turns, p._parsed, p.turn_angles().tolist())):
        start = pos
        parts = []
        for j in range(pieces):
            rates, lo, hi = _piece(p, total / pieces, fs, rng)
            if pieces == 1 and p.unevenness == 0 and hi - lo >= 2:
                plateaus.append(Window(pos + lo, pos + hi, "rotation", "xyz"[axis], sign, p.speed * (hi - lo) / fs,
                                       p.speed, label=turn))
            parts.append(rates)
            pos += len(rates)
            if j < pieces - 1:
                n_pause = int(round(p.pause_length * fs))
                parts.append(np.zeros(n_pause))
                pos += n_pause
        scalar = np.concatenate(parts)
        chunks.append(np.outer(sign * scalar, mounting[:, axis]))
        windows.append(Window(start, pos, "rotation", "xyz"[axis], sign, total, total * fs / (pos - start),
                              label=turn))
        if i < len(waits):
            static(waits[i])
    static(p.lead_out)
    true = np.concatenate(chunks)
    rec = Recording(t=np.arange(len(true)) / fs, gyro=gyro.measure(true, fs, rng), units="rad/s",
                    source_units="rad/s", sample_rate=fs)
    return rec, ServoTruth(readonly(true, copy=False), tuple(windows), tuple(plateaus), gyro.model,
                           readonly(mounting, copy=False))
