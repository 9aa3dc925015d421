"""An independent generator of realistic gyro recordings, written for the issue-10 audit.

It shares no code with ``gyrocal.simulation`` (so tests built on it are not circular) and models
what real labs produce rather than what the calibration assumes:

* **motion** in physical time: turns about a tool axis with trapezoidal or S-curve speed
  profiles, speed ripple, a wobbling axis (``q = Rot(u, theta) Rot(w, phi)``, so the net rotation
  is exactly ``theta`` about ``u`` while the rate vector wanders), uneven hand speeds, pauses and
  re-poses; the Earth's rate is carried through the attitude;
* **the sensor**: ``m = diag(1/k) (I + N) R omega + offset(T, t) + noise``, with a mounting
  rotation ``R``, non-orthogonality ``N``, white noise on an internal 8-times grid through the
  chip's low-pass filter (DLPF) then decimated, flicker-like bias wander (three Ornstein-Uhlenbeck
  processes), temperature-driven bias, quantisation to the chip's LSB and clipping at full scale,
  all sampled on the chip's own clock (which may be off its nominal rate);
* **the time column**: none, the chip's sample counter times its nominal period, or a PC's
  receive times (alternating short/long steps, USB packets of 1-4 samples, late deliveries
  caught up by a burst, real packet gaps), in epoch seconds at microsecond resolution.

The truth is what a scale-bias model (``omega = diag(k) (m + b)``, the servo method of Wang et
al., eq. 1) can represent: :func:`effective_k` solves the norm equations of the noise-free turns
for the non-orthogonal sensor, so "error" is against the best the model can do.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

D2R = math.pi / 180.0
EARTH = 7.2921159e-5 / D2R  # [deg/s]
EPOCH = 1_733_050_000.0  # [s] a PC's epoch time at the start of the log


@dataclass(frozen=True)
class Gyro:
    """A MEMS gyro as it reads (deg/s unless stated)."""

    k: tuple = (1.0, 1.0, 1.0)  # true model scale factors (omega = k (m - offset))
    offset: tuple = (0.8, -0.5, 0.3)  # reading at rest [deg/s] (the model's b is minus this)
    mount_deg: float = 3.0  # mounting rotation [deg] about a random axis
    cross: float = 0.002  # non-orthogonality, sd of the off-diagonal terms [1]
    noise_density: float = 0.01  # white rate noise [deg/s/sqrt(Hz)] (MPU-9250 datasheet figure)
    flicker: float = 0.003  # bias wander, sd [deg/s], correlation times 2, 20, 200 s
    lsb: float | None = 65.5  # LSB per deg/s (None: no quantisation)
    full_scale: float = 500.0  # [deg/s] of the raw reading
    dlpf_hz: float | None = 41.0  # internal low-pass corner [Hz]
    clock_error: float = 0.0  # the chip's clock runs (1 + this) times its nominal rate
    bias_tempco: tuple = (0.0, 0.0, 0.0)  # [deg/s per degC]
    scale_tempco: float = 0.0  # relative change of the reading per degC

    def matrix(self, rng: np.random.Generator) -> np.ndarray:
        """``diag(1/k) (I + N) R``: tool-frame rate -> reading (drawn once per gyro)."""
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        r = _rodrigues(axis[None], np.array([self.mount_deg * D2R]))[0]
        n = rng.normal(scale=self.cross, size=(3, 3))
        np.fill_diagonal(n, 0.0)
        return np.diag(1.0 / np.asarray(self.k, float)) @ (np.eye(3) + n) @ r


@dataclass(frozen=True)
class Turn:
    """A rotation about tool axis `axis` by `angle` [deg] (signed) at peak `speed` [deg/s]."""

    axis: tuple
    angle: float
    speed: float
    accel: float = 200.0  # [deg/s^2]
    profile: str = "scurve"  # "trapezoid", "scurve" or "hand"
    ripple: float = 0.0  # relative speed ripple on the cruise
    ripple_hz: float = 2.5
    jitter_deg: float = 0.0  # servo vibration: a smooth random angle error [deg rms], band-limited to 8 Hz
    plateau_ripple: float = 0.0  # relative sinusoidal speed ripple on the cruise only, zero mean over it
    plateau_ripple_hz: float = 2.5
    wobble_deg: float = 0.0  # wobble of the axis about a perpendicular one [deg]
    wobble_hz: float = 1.5
    calibration: bool = True  # part of the calibration (in the windows file)


@dataclass(frozen=True)
class Pause:
    seconds: float


@dataclass
class Log:
    """A generated recording and its truth."""

    t_true: np.ndarray  # physical sample times [s]
    stamps: np.ndarray | None  # the time column as written [s], None without one
    gyro: np.ndarray  # readings as written (deg/s or counts)
    temp: np.ndarray | None
    turns: list = field(default_factory=list)  # dicts: start/stop physical time, angle, axis index, sign, declared
    statics: list = field(default_factory=list)  # (start, stop) physical time
    k_eff: np.ndarray | None = None
    b_true: np.ndarray | None = None  # model b [deg/s] (minus the offset at the reference temperature)
    keep: np.ndarray | None = None  # which sensor samples were delivered

    def write(self, path, *, counts: bool = False, decimals: int = 5) -> None:
        cols = ["gx", "gy", "gz"]
        data = [self.gyro]
        head = []
        if self.stamps is not None:
            head.append("t")
            data.insert(0, self.stamps[:, None])
        head += cols
        if self.temp is not None:
            head.append("temp")
            data.append(self.temp[:, None])
        table = np.hstack(data)
        fmt = (["%.6f"] if self.stamps is not None else []) + (["%d"] * 3 if counts else [f"%.{decimals}f"] * 3)
        fmt += ["%.2f"] if self.temp is not None else []
        np.savetxt(path, table, delimiter=",", header=",".join(head), comments="", fmt=fmt)

    def windows(self, *, margin: float = 0.3, statics: bool = True, offset: float = 0.0,
                rng: np.random.Generator | None = None, sync_sd: float = 0.0) -> list[dict]:
        """The windows file a user writes from the robot's log: seconds on the log's time column.

        The robot's motion start/end (its clock aligned to the log within `sync_sd`), widened by
        `margin` each side; each turn's angle is the robot-measured one (``declared``).
        """
        t0 = self.stamps[0] if self.stamps is not None else 0.0
        base = t0 - self.t_true[0]
        out = []
        for tr in self.turns:
            if not tr["calibration"]:
                continue
            shift = offset + (rng.normal(scale=sync_sd) if rng is not None and sync_sd else 0.0)
            out.append({"t_start": base + tr["start"] - margin + shift, "t_stop": base + tr["stop"] + margin + shift,
                        "kind": "rotation", "angle_deg": round(abs(tr["declared"]), 4),
                        "axis": ("+" if tr["sign"] > 0 else "-") + "xyz"[tr["axis"]]})
        if statics:
            for a, b in self.statics:
                if b - a > 2 * margin + 0.5:
                    out.append({"t_start": base + a + margin, "t_stop": base + b - margin, "kind": "static"})
        out.sort(key=lambda w: w["t_start"])
        return out


def _rodrigues(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotation matrices (n, 3, 3) about unit axes (n, 3) by angles (n,) [rad]."""
    axis = np.broadcast_to(axis, (len(angle), 3))
    x, y, z = axis.T
    c, s = np.cos(angle), np.sin(angle)
    cc = 1 - c
    return np.stack([
        np.stack([c + x * x * cc, x * y * cc - z * s, x * z * cc + y * s], -1),
        np.stack([y * x * cc + z * s, c + y * y * cc, y * z * cc - x * s], -1),
        np.stack([z * x * cc - y * s, z * y * cc + x * s, c + z * z * cc], -1),
    ], -2)


def _profile(turn: Turn, fs: float, rng: np.random.Generator) -> np.ndarray:
    """Angle [deg] along the turn on a grid of `fs`, from 0 to ``|angle|``; ends at rest."""
    theta, v = abs(turn.angle), turn.speed
    if turn.profile == "hand":
        dur = theta / v * 1.6
        n = max(8, int(math.ceil(dur * fs)))
        tau = (np.arange(n + 1)) / n
        bump = np.sin(np.pi * tau) ** 2
        slow = np.interp(tau, np.linspace(0, 1, 7), 1 + 0.35 * rng.normal(size=7))  # uneven hand speed
        rate = bump * np.clip(slow, 0.3, None)
        ang = np.concatenate([[0], np.cumsum((rate[1:] + rate[:-1]) / 2)])
        return theta * ang / ang[-1]
    tr = v / turn.accel * (1.5 if turn.profile == "scurve" else 1.0)  # ramp time
    if theta / v < tr:  # never reaches the speed: a shorter, slower turn
        v = math.sqrt(theta * turn.accel / (1.5 if turn.profile == "scurve" else 1.0))
        tr = v / turn.accel * (1.5 if turn.profile == "scurve" else 1.0)
    cruise = theta / v - tr
    dur = cruise + 2 * tr
    n = max(8, int(math.ceil(dur * fs)))
    t = np.arange(n + 1) / fs  # the sample grid (1 / fs); the last step may end past `dur`, at rest
    up = np.clip(t / tr, 0, 1)
    down = np.clip((dur - t) / tr, 0, 1)
    shape = (lambda u: u) if turn.profile == "trapezoid" else (lambda u: 0.5 - 0.5 * np.cos(np.pi * u))
    rate = v * np.minimum(shape(up), shape(down))
    ang = np.concatenate([[0], np.cumsum((rate[1:] + rate[:-1]) / 2)]) * (t[1] - t[0])
    ang *= theta / ang[-1]  # exactly the turn; ripple and vibration then ride on the commanded speed
    taper = (rate / v) ** 2
    if turn.ripple:  # a speed ripple about the commanded speed (its angle is bounded, not rescaled)
        phase = rng.uniform(0, 2 * np.pi)
        w = 2 * np.pi * turn.ripple_hz
        ang += turn.ripple * v / w * (np.sin(w * t + phase) - np.sin(phase)) * taper
    if turn.jitter_deg:  # servo vibration: a bounded random angle error, tapered to zero at the ends
        from scipy.signal import butter, lfilter

        b, a = butter(2, 8.0 / (fs / 2))
        e = lfilter(b, a, rng.normal(size=len(t)))
        ang += turn.jitter_deg * e / e.std() * taper
    if turn.plateau_ripple:  # on the cruise [tr, dur - tr] only; its angle is zero at both ends
        phase, w, span = rng.uniform(0, 2 * np.pi), 2 * np.pi * turn.plateau_ripple_hz, cruise
        tau = np.clip(t - tr, 0.0, span)
        mean = (np.cos(phase) - np.cos(w * span + phase)) / (w * span)
        ang += turn.plateau_ripple * v * ((np.cos(phase) - np.cos(w * tau + phase)) / w - mean * tau)
    return ang


def _trapezoid(rate: np.ndarray, fs: float) -> np.ndarray:
    """Cumulative trapezoid integral of samples `rate` 1/fs apart, starting at 0."""
    return np.concatenate([[0.0], np.cumsum((rate[1:] + rate[:-1]) / 2)]) / fs


def _perpendicular(u: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    w = np.cross(u, rng.normal(size=3))
    return w / np.linalg.norm(w)


def motion(plan, fs: float, rng: np.random.Generator, *, latitude: float = 48.0, earth_rate: float = EARTH):
    """Tool-frame angular rate (n, 3) [deg/s] on a grid of `fs` from a list of Turn/Pause, and the segments.

    Returns rate, and a list of (kind, start time, stop time, Turn or None, net rotation angle).
    """
    earth = earth_rate * np.array([math.cos(latitude * D2R), 0.0, math.sin(latitude * D2R)])
    att = np.eye(3)  # world <- tool
    pieces, segs, now = [], [], 0.0
    for item in plan:
        if isinstance(item, Pause):
            n = int(round(item.seconds * fs))
            pieces.append(np.tile(att.T @ earth, (n, 1)))
            segs.append(("pause", now, now + n / fs, None))
            now += n / fs
            continue
        u = np.asarray(item.axis, float)
        u = u / np.linalg.norm(u)
        ang = _profile(item, fs, rng) * D2R * np.sign(item.angle)
        # rates on the 1/fs grid whose trapezoid integral is the angle exactly (what a perfect gyro integrates)
        dth = np.gradient(ang, 1 / fs)
        dth *= ang[-1] / _trapezoid(dth, fs)[-1]
        ang = _trapezoid(dth, fs)
        if item.wobble_deg:
            w = _perpendicular(u, rng)
            tau = np.linspace(0, 1, len(ang))
            phi = item.wobble_deg * D2R * np.sin(2 * np.pi * item.wobble_hz * tau * (len(ang) / fs)) * np.sin(np.pi * tau)
            dphi = np.gradient(phi, 1 / fs)
            phi = _trapezoid(dphi, fs)
            back = _rodrigues(w[None], -phi)
            body = np.einsum("nij,j->ni", back, u) * dth[:, None] + dphi[:, None] * w
            a_of_t = _rodrigues(u[None], ang) @ _rodrigues(w[None], phi)
        else:
            body = dth[:, None] * u
            a_of_t = _rodrigues(u[None], ang)
        frames = att @ a_of_t  # world <- tool along the turn
        body = body / D2R + np.einsum("nji,j->ni", frames, earth)
        pieces.append(body)
        segs.append(("turn", now, now + len(ang) / fs, item))
        now += len(ang) / fs
        att = att @ _rodrigues(u[None], ang[-1:])[0]
    return np.concatenate(pieces), segs


def _ou(n: int, dt: float, sd: float, tau: float, rng: np.random.Generator) -> np.ndarray:
    """Ornstein-Uhlenbeck samples (n, 3) with stationary sd `sd` and correlation time `tau`."""
    from scipy.signal import lfilter

    a = math.exp(-dt / tau)
    e = rng.normal(scale=sd * math.sqrt(1 - a * a), size=(n, 3))
    x = np.empty((n, 3))
    x[0] = rng.normal(scale=sd, size=3)
    return lfilter([1.0], [1.0, -a], np.vstack([x[:1], e[1:]]), axis=0)


def sense(gyro: Gyro, rate_tool: np.ndarray, fs_int: float, decim: int, rng: np.random.Generator,
          temp: np.ndarray | None = None) -> np.ndarray:
    """The chip's readings [deg/s, quantised] at its output rate from the tool-frame rate on its internal grid."""
    from scipy.signal import butter, lfilter

    m = rate_tool @ gyro.matrix(rng).T
    n = len(m)
    m = m + rng.normal(scale=gyro.noise_density * math.sqrt(fs_int), size=(n, 3))
    if gyro.dlpf_hz:
        b, a = butter(2, gyro.dlpf_hz / (fs_int / 2))
        m = lfilter(b, a, m, axis=0)
    m = m[::decim]
    fs = fs_int / decim
    out = np.asarray(gyro.offset, float) + m
    if gyro.flicker:
        out += sum(_ou(len(out), 1 / fs, gyro.flicker / math.sqrt(3), tau, rng) for tau in (2.0, 20.0, 200.0))
    if temp is not None:
        dt = temp - temp[0]
        out += dt[:, None] * np.asarray(gyro.bias_tempco, float)
        out = (out - gyro.offset) * (1 + gyro.scale_tempco * dt[:, None]) + gyro.offset
    if gyro.lsb:
        top = 32767
        counts = np.clip(np.rint(out * gyro.lsb), -top - 1, top)
        return counts / gyro.lsb
    return np.clip(out, -gyro.full_scale, gyro.full_scale)


def effective_k(gyro: Gyro, rng_state, axes) -> np.ndarray:
    """The scale factors the norm equations of noise-free turns about tool `axes` give (3,).

    ``|diag(c k) M u| = 1`` for each turn axis ``u`` (``M = diag(1/k)(I+N)R``) is linear in
    ``c_j^2``; least squares over the axes given.
    """
    mat = gyro.matrix(np.random.default_rng(rng_state))
    v = np.array([np.asarray(gyro.k, float) * (mat @ (np.asarray(u, float) / np.linalg.norm(u))) for u in axes])
    c2, *_ = np.linalg.lstsq(v**2, np.ones(len(axes)), rcond=None)
    return np.asarray(gyro.k, float) * np.sqrt(c2)


# ---- time columns -------------------------------------------------------------------------------------

def receive_alternating(t: np.ndarray, rng: np.random.Generator, *, late_per_minute: float = 4.0) -> np.ndarray:
    """PC receive stamps whose steps alternate about 2-5 and 12-17 ms around a 10 ms clock."""
    n = len(t)
    lat = 0.004 + np.where(np.arange(n) % 2 == 0, rng.uniform(0.0055, 0.0075, n), rng.uniform(0, 0.0015, n))
    lat = _late(t, lat, rng, late_per_minute)
    return _monotone(t + lat)


def receive_packets(t: np.ndarray, per_packet: int, rng: np.random.Generator, *,
                    late_per_minute: float = 4.0) -> np.ndarray:
    """PC receive stamps of USB packets of `per_packet` samples: polled at 1 ms, scheduling jitter, reads 20-80 us apart."""
    n = len(t)
    ready = t[np.minimum(np.arange(n) // per_packet * per_packet + per_packet - 1, n - 1)]
    arrive = np.ceil((ready + 0.0002) * 1000) / 1000 + rng.exponential(0.0006, n // per_packet + 1)[np.arange(n) // per_packet]
    arrive += (np.arange(n) % per_packet) * rng.uniform(2e-5, 8e-5, n)
    lat = _late(t, arrive - t, rng, late_per_minute)
    return _monotone(t + lat)


def _late(t, lat, rng, per_minute):
    """Late deliveries: from a random sample on, nothing arrives until the delay is over (a burst follows)."""
    span = t[-1] - t[0]
    for _ in range(rng.poisson(per_minute * span / 60)):
        i = int(rng.integers(0, len(t)))
        hold = t[i] + rng.uniform(0.04, 0.12)
        j = np.searchsorted(t, hold)
        lat[i:j] = np.maximum(lat[i:j], hold - t[i:j] + 1e-5 * np.arange(j - i))
    return lat


def _monotone(stamps: np.ndarray, resolution: float = 1e-6) -> np.ndarray:
    """Stamps at `resolution` [s], strictly increasing (a reader never stamps two lines alike at 1 us)."""
    ticks = np.rint(stamps / resolution).astype(np.int64)
    i = np.arange(len(ticks))
    ticks = i + np.maximum.accumulate(ticks - i)  # t_i = max over j <= i of (t_j + i - j)
    return ticks * resolution


def drop(n: int, lengths, rng: np.random.Generator, inside=None) -> np.ndarray:
    """A mask of delivered samples with runs of `lengths` samples lost (inside the spans `inside` when given)."""
    keep = np.ones(n, dtype=bool)
    for i, length in enumerate(lengths):
        if inside:
            a, b = inside[i % len(inside)]
            start = int(rng.integers(a, max(a + 1, b - length)))
        else:
            start = int(rng.integers(100, n - length - 100))
        keep[start:start + length] = False
    return keep


# ---- sessions ------------------------------------------------------------------------------------------

def record(plan, gyro: Gyro, *, rate: float = 100.0, stamps: str = "receive", per_packet: int = 2,
           gaps=(), gaps_in_turns: bool = True, late_per_minute: float = 4.0, temp_rise: float = 0.0,
           seed: int = 0, angle_sd: float = 0.05, lead: float = 3.0, unit_seed: int | None = None,
           earth: bool = True) -> Log:
    """Record `plan` (Turn/Pause list) with `gyro` at nominal `rate` [Hz].

    stamps: "receive" (alternating 2-5 / 12-17 ms at 100 Hz), "packets" (USB packets of
    `per_packet`), "sensor" (the chip's counter times its nominal period), "none".
    gaps: lengths [samples] of real packet losses. angle_sd: sd of the robot-measured angle [deg].
    unit_seed: draws the gyro's mounting and non-orthogonality (one physical unit: the same for every
    recording made with it); default from `seed`. earth: the Earth's rate in the readings.
    """
    # long function: the recording's stages in order (motion, sensor, clock, stamps, truth), each a call
    rng = np.random.default_rng(seed)
    mat_state = int(rng.integers(2**31)) if unit_seed is None else int(unit_seed)
    decim = 8
    fs_phys = rate * (1 + gyro.clock_error)  # the chip's actual rate
    fs_int = fs_phys * decim
    rate_tool, segs = motion([Pause(lead)] + list(plan) + [Pause(lead)], fs_int, rng, earth_rate=EARTH if earth else 0.0)
    n_int = len(rate_tool)
    t_int = np.arange(n_int) / fs_int
    temp = None
    if temp_rise:
        temp = 25 + temp_rise * (1 - np.exp(-t_int / (t_int[-1] / 2.5)))
    g_rng = np.random.default_rng(mat_state)
    m_rng = np.random.default_rng(rng.integers(2**31))
    raw = _sense_with(gyro, rate_tool, fs_int, decim, g_rng, m_rng, temp)
    t = t_int[::decim]
    n = len(t)
    turns, statics = [], []
    for kind, a, b, item in segs:
        if kind == "pause":
            statics.append((a, b))
            continue
        u = np.asarray(item.axis, float)
        j = int(np.argmax(np.abs(u)))
        sign = int(np.sign(u[j] * item.angle))
        declared = abs(item.angle) + rng.normal(scale=angle_sd)
        turns.append({"start": a, "stop": b, "angle": abs(item.angle), "axis": j, "sign": sign,
                      "declared": declared, "calibration": item.calibration, "tool_axis": u})
    keep = np.ones(n, dtype=bool)
    if gaps:
        spans = [(int(tr["start"] * fs_phys) + 20, int(tr["stop"] * fs_phys) - 20) for tr in turns] if gaps_in_turns else None
        keep = drop(n, gaps, rng, spans)
    if stamps == "receive":
        col = receive_alternating(t, rng, late_per_minute=late_per_minute)
    elif stamps == "packets":
        col = receive_packets(t, per_packet, rng, late_per_minute=late_per_minute)
    elif stamps == "sensor":
        col = np.arange(n) / rate
    else:
        col = None
    col = None if col is None else (EPOCH + col if stamps != "sensor" else col)
    axes = [tr["tool_axis"] for tr in turns if tr["calibration"]]
    k_eff = effective_k(gyro, mat_state, axes) if axes else None
    return Log(t_true=t[keep], stamps=None if col is None else col[keep], gyro=raw[keep],
               temp=None if temp is None else temp[::decim][keep], turns=turns, statics=statics, k_eff=k_eff,
               b_true=-np.asarray(gyro.offset, float), keep=keep)


def _sense_with(gyro, rate_tool, fs_int, decim, g_rng, m_rng, temp):
    """:func:`sense` with the gyro's fixed matrix drawn from `g_rng` and the noise from `m_rng`."""
    mat = gyro.matrix(g_rng)
    return sense(_Fixed(gyro, mat), rate_tool, fs_int, decim, m_rng, None if temp is None else temp[::decim])


class _Fixed:
    """A Gyro whose matrix is already drawn."""

    def __init__(self, gyro: Gyro, mat: np.ndarray):
        self._g, self._m = gyro, mat

    def __getattr__(self, name):
        return getattr(self._g, name)

    def matrix(self, rng):
        return self._m


def robot_plan(speed: float, rng: np.random.Generator, *, pairs: int = 2, angles=(135.0, 270.0),
               pause=(1.5, 3.0), profile: str | None = None, repose: bool = True) -> list:
    """Turns about each tool axis in both senses at `speed` [deg/s], angles drawn in `angles` [deg].

    Each axis: `pairs` of (+theta, -theta), pauses between; a 90 deg re-pose about another axis
    between axes (not a calibration turn).
    """
    plan: list = []
    accel = float(rng.uniform(150, 400))
    for j in range(3):
        u = np.eye(3)[j]
        for _ in range(pairs):
            theta = float(rng.uniform(*angles))
            prof = profile or str(rng.choice(["trapezoid", "scurve"]))
            for s in (1, -1):
                plan.append(Turn(tuple(u), s * theta, speed, accel=accel, profile=prof))
                plan.append(Pause(float(rng.uniform(*pause))))
        if repose and j < 2:
            plan.append(Turn(tuple(np.eye(3)[(j + 2) % 3]), 90.0, 30.0, accel=100.0, calibration=False))
            plan.append(Pause(float(rng.uniform(*pause))))
    return plan


#: The three gyros of the robot dataset: two good ones and a poor one (inside the paper's extreme study range).
GYROS = (
    Gyro(k=(1.012, 0.985, 1.004), offset=(0.9, -0.6, 0.25), mount_deg=2.0, cross=0.002),
    Gyro(k=(0.991, 1.021, 0.978), offset=(-1.4, 0.3, 0.7), mount_deg=4.0, cross=0.003, noise_density=0.015),
    Gyro(k=(1.55, 1.80, 1.30), offset=(2.5, -1.8, 1.1), mount_deg=3.0, cross=0.004, noise_density=0.02,
         flicker=0.006),
)
SPEEDS = (10.0, 20.0, 40.0, 60.0, 90.0, 120.0)
