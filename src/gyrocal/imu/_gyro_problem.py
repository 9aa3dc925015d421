"""The gyro's equations in a hand session, precomputed once and evaluated for any parameters.

Three kinds of equation, each normalised by its predicted noise:

* still poses: the mean reading is the bias (plus ``G f`` with a g-sensitivity), 3 per pose;
* pose pairs (Tedaldi et al., ICRA 2014): the attitude change integrated from the corrected
  gyro between two consecutive poses must carry the first pose's gravity direction onto the
  second's, 2 per pair (the two components across the second direction);
* known-angle turns (Ferraris et al.): a turn of a known angle about the vertical integrates to
  that angle times the vertical's direction, 3 per turn.

The Earth's rotation (7.29e-5 rad/s, unknown direction) is not modelled; its size is added to
the noise of every equation so it cannot masquerade as a bias or scale error.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import quaternion as quat
from .._arrays import rows_times

__all__ = ["EARTH_RATE", "GyroProblem", "Turn", "build_problem"]

#: Rotation rate of the Earth [rad/s].
EARTH_RATE = 7.292115e-5


@dataclass(frozen=True)
class Turn:
    """A turn of known angle about the vertical (Ferraris et al.).

    Attributes
    ----------
    start, stop : int
        Samples of the turn, stop exclusive.
    angle : float
        Declared angle [rad], positive; the sense is read from the data.
    axis : ndarray, shape (3,)
        Unit vertical (specific-force direction) in the corrected frame during the turn.
    axis_std : float
        1-sigma of that direction per tangent axis [rad].
    label : str
    """

    start: int
    stop: int
    angle: float
    axis: np.ndarray
    axis_std: float
    label: str = ""


def _weights(t: np.ndarray) -> np.ndarray:
    """Trapezoid weight of each sample of a span [s]."""
    h = np.diff(t)
    w = np.zeros(len(t))
    w[:-1] += h / 2
    w[1:] += h / 2
    return w


@dataclass
class GyroProblem:
    """Precomputed data of :func:`build_problem`; see there."""

    means: np.ndarray          # (n, 3) static mean readings
    static_sd: np.ndarray      # (n, 3) their noise, Earth rate included [raw]
    f_static: np.ndarray       # (n, 3) specific force at each pose [m/s^2]
    pairs: np.ndarray          # (P, 2) static indices
    t_cat: np.ndarray          # motion samples of all pairs, concatenated
    m_cat: np.ndarray
    f_cat: np.ndarray
    bounds: np.ndarray         # (P, 2) first/last index into the concatenation
    pair_lrv_w2: np.ndarray    # (P,) sum of squared trapezoid weights [s^2]
    pair_time: np.ndarray      # (P,) duration [s]
    turns: tuple[Turn, ...]
    turn_m: np.ndarray         # (T, 3) integral of the reading over each turn [raw s]
    turn_f: np.ndarray         # (T, 3) integral of the specific force [m/s]
    turn_w2: np.ndarray        # (T,)
    turn_time: np.ndarray      # (T,)
    turn_sign: np.ndarray      # (T,) sense of each turn about its axis
    turn_span: np.ndarray      # (T, 2) first and last time [s]
    lrv: float                 # long-run noise variance per sample, mean over axes [raw^2]
    factors: np.ndarray = field(default_factory=lambda: np.ones(3))  # noise factors: poses, pairs, turns

    def omega_params(self, a, b, g):
        """Corrected rates of the concatenated motion samples [rad/s]."""
        m = self.m_cat - b
        if g is not None:
            m -= rows_times(self.f_cat, g)
        return rows_times(m, a)

    def pair_integrals(self, b) -> np.ndarray:
        """Trapezoid integral of ``m - b`` over each pair's motion (P, 3) [raw s]."""
        out = np.zeros((len(self.bounds), 3))
        for k, (i, j) in enumerate(self.bounds):
            out[k] = _weights(self.t_cat[i:j + 1]) @ (self.m_cat[i:j + 1] - b)
        return out

    def static_residuals(self, b, g) -> np.ndarray:
        pred = b + (0 if g is None else self.f_static @ g.T)
        return ((self.means - pred) / (self.static_sd * self.factors[0])).ravel()

    def pair_prediction(self, a, b, g, directions) -> np.ndarray:
        """Second direction of each pair predicted from the first and the integrated attitude change."""
        if not len(self.pairs):
            return np.zeros((0, 3))
        rot = quat.attitude_matrices(self.t_cat, self.omega_params(a, b, g), self.bounds)
        return np.einsum("pji,pj->pi", rot, directions[self.pairs[:, 0]])

    def pair_sigma(self, a, directions_std) -> np.ndarray:
        scale2 = float(np.mean(np.diag(a) ** 2))
        return self.factors[1] * np.sqrt(directions_std[self.pairs[:, 0]] ** 2 + directions_std[self.pairs[:, 1]] ** 2
                       + self.lrv * scale2 * self.pair_lrv_w2 + (EARTH_RATE * self.pair_time) ** 2 / 3)

    def pair_residuals(self, a, b, g, directions, directions_std) -> np.ndarray:
        if not len(self.pairs):
            return np.zeros(0)
        pred = self.pair_prediction(a, b, g, directions)
        e1, e2 = tangent_basis(directions[self.pairs[:, 1]])
        r = np.stack([np.einsum("pi,pi->p", pred, e1), np.einsum("pi,pi->p", pred, e2)], axis=1)
        return (r / self.pair_sigma(a, directions_std)[:, None]).ravel()

    def turn_vectors(self, a, b, g) -> np.ndarray:
        """Integrated rotation vector of each turn [rad]."""
        m = self.turn_m - self.turn_time[:, None] * b
        if g is not None:
            m = m - self.turn_f @ g.T
        return m @ a.T

    def turn_residuals(self, a, b, g) -> np.ndarray:
        if not self.turns:
            return np.zeros(0)
        want = np.array([s * t.angle * t.axis for s, t in zip(self.turn_sign, self.turns)])
        scale2 = float(np.mean(np.diag(a) ** 2))
        axis = np.array([(t.angle * t.axis_std) ** 2 for t in self.turns])
        sd = self.factors[2] * np.sqrt(self.lrv * scale2 * self.turn_w2 + axis + (EARTH_RATE * self.turn_time) ** 2 / 3)
        return ((self.turn_vectors(a, b, g) - want) / sd[:, None]).ravel()

    @property
    def equations(self) -> int:
        return self.means.size + 2 * len(self.pairs) + 3 * len(self.turns)


def tangent_basis(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors across each unit vector of (P, 3)."""
    helper = np.where(np.abs(v[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    e1 = np.cross(v, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    return e1, np.cross(v, e1)


def build_problem(t, gyro, force, statics, pairs, turns, scale_guess: float) -> GyroProblem:
    """Precompute the equations.

    Parameters
    ----------
    t, gyro : ndarray
        Times [s] and raw gyro readings (N, 3).
    force : ndarray, shape (N, 3)
        Calibrated specific force [m/s^2] (for the g-sensitivity).
    statics : sequence of Static
    pairs : ndarray, shape (P, 2)
        Static indices ``i, j``: integrate from the last sample of ``i`` to the first of ``j``.
    turns : sequence of Turn
    scale_guess : float
        Rough gyro scale [rad/s per raw unit], to express the Earth rate in raw units.
    """
    pairs = np.asarray(pairs, dtype=int).reshape(-1, 2)
    ratio_n = np.array([s.gyro_se**2 * s.count for s in statics])  # long-run variance per sample, each pose
    lrv = float(np.mean(ratio_n))
    earth_raw = EARTH_RATE / scale_guess
    means = np.array([s.gyro_mean for s in statics])
    static_sd = np.sqrt(np.array([s.gyro_se**2 for s in statics]) + earth_raw**2 / 3)
    f_static = np.array([force[s.start:s.stop].mean(axis=0) for s in statics])
    spans = [(statics[i].stop - 1, statics[j].start) for i, j in pairs]
    pieces = [np.arange(a, b + 1) for a, b in spans]
    lengths = np.array([len(p) for p in pieces], dtype=int)
    starts = np.concatenate([[0], np.cumsum(lengths)[:-1]]) if len(pieces) else np.zeros(0, int)
    idx = np.concatenate(pieces) if pieces else np.zeros(0, int)
    w2 = np.array([np.sum(_weights(t[p]) ** 2) for p in pieces])
    turn_w = [_weights(t[tu.start:tu.stop]) for tu in turns]
    turn_m = np.array([w @ gyro[tu.start:tu.stop] for w, tu in zip(turn_w, turns)]).reshape(-1, 3)
    turn_f = np.array([w @ force[tu.start:tu.stop] for w, tu in zip(turn_w, turns)]).reshape(-1, 3)
    return GyroProblem(
        means=means, static_sd=static_sd, f_static=f_static, pairs=pairs,
        t_cat=t[idx], m_cat=gyro[idx], f_cat=force[idx],
        bounds=np.stack([starts, starts + lengths - 1], axis=1) if len(pieces) else np.zeros((0, 2), int),
        pair_lrv_w2=w2, pair_time=np.array([t[b] - t[a] for a, b in spans]),
        turns=tuple(turns), turn_m=turn_m, turn_f=turn_f,
        turn_w2=np.array([np.sum(w**2) for w in turn_w]),
        turn_time=np.array([t[tu.stop - 1] - t[tu.start] for tu in turns]),
        turn_sign=np.ones(len(turns)), lrv=lrv,
        turn_span=np.array([[t[tu.start], t[tu.stop - 1]] for tu in turns]).reshape(-1, 2))
