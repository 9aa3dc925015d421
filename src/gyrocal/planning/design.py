"""Experimental design: how accurate a protocol will be, before it is run.

A :class:`Design` is a list of windows: rotations (axis, speed, angle turned) and
static waits. For a true model, a per-sample noise level and a sample rate it gives

* the Fisher information matrix of ``(k, b)`` and its inverse, the Cramér–Rao bound
  (CRB). Both come from the first-moment estimator's own Jacobian
  (:func:`gyrocal.estimators.first_moment.residuals_and_jacobian`) evaluated on the
  noise-free expected windows, so the plan and the fit's covariance are one piece
  of code;
* D- and G-efficiency of the rotation axes for the servo method's regression model (section
  II-B), defined below;
* the total protocol time.

Efficiencies (the servo method of Wang et al., section II-B). The paper's regression (eq. 4, 7) has the
six regressors ``f(x) = [x1^2, x2^2, x3^2, x1, x2, x3]`` of a reading direction
``x`` on the unit sphere (the design region: ``|m| ~ omega``, scaled to 1). For a
design with rotation directions ``x_i`` and weights ``w_i`` (sample counts,
normalised to sum 1) the moment matrix is ``M = sum w_i f(x_i) f(x_i)^T`` and the
standardised prediction variance is ``d(x) = f(x)^T M^-1 f(x)``. Then

* ``D-efficiency = (det M / det M*)^(1/6)``, with ``M* = I/3`` the moment matrix of the
  six-point design +-x, +-y, +-z;
* ``G-efficiency = 6 / max_{|x|=1} d(x)`` (maximum over a dense spherical grid).

The six-point design has ``d(x) = 3 (1 + sum x_j^4) <= 6 = p`` with equality at the
axes, so by the Kiefer–Wolfowitz theorem it is both D- and G-optimal: both
efficiencies are 1 for it, as the paper states. The efficiencies rate the geometry of
the rotation axes only; static windows (``x = 0``, ``f = 0``) and the nonlinear tie
``beta0(beta)`` lie outside that linear model and are left out. The CRB includes
everything and is the number to plan with.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from .._arrays import readonly
from .._validation import finite_array, positive
from ..errors import InputError
from ..estimators import require_count, require_full_rank
from ..estimators.first_moment import PARAM_NAMES, residuals_and_jacobian, sandwich_covariance
from ..models import ScaleBias
from ..observations import ObservationSet
from ..segmentation.windows import axis_vector

__all__ = [
    "Design",
    "DesignReport",
    "Rotation",
    "Static",
    "compare_designs",
    "crb_covariance",
    "d_efficiency",
    "expected_observations",
    "format_design_table",
    "g_efficiency",
    "information_matrix",
    "predicted_covariance",
    "predicted_std",
]

_P = 6
_REFERENCE_DET = (1.0 / 3.0) ** _P  # det M of the +-x, +-y, +-z design


@dataclass(frozen=True)
class Rotation:
    """A turn about a fixed axis.

    Parameters
    ----------
    axis : array_like, shape (3,), or str
        Rotation axis in the gyro frame (normalised; the sign gives the sense), or a
        signed name such as ``"+x"``.
    speed : float
        Rate magnitude [rad/s].
    angle : float
        Angle turned inside the window [rad]; one revolution by default.
    """

    axis: np.ndarray
    speed: float
    angle: float = 2 * math.pi

    def __post_init__(self):
        a = axis_vector(self.axis) if isinstance(self.axis, str) else finite_array("axis", self.axis, shape_tail=(3,), ndim=1)
        norm = float(np.linalg.norm(a))
        if norm == 0:
            raise InputError("axis must be a non-zero vector, got [0, 0, 0]")
        object.__setattr__(self, "axis", readonly(a / norm, copy=False))
        object.__setattr__(self, "speed", positive("speed", self.speed))
        object.__setattr__(self, "angle", positive("angle", self.angle))

    @property
    def duration(self) -> float:
        """Window length [s]."""
        return self.angle / self.speed


@dataclass(frozen=True)
class Static:
    """A static window of `duration` seconds (rate zero)."""

    duration: float

    def __post_init__(self):
        object.__setattr__(self, "duration", positive("duration", self.duration))


@dataclass(frozen=True)
class Design:
    """A calibration protocol: windows in order, and the pause between consecutive windows.

    Parameters
    ----------
    windows : sequence of Rotation or Static
    pause : float
        Time between windows that is not used as an observation [s] (the paper waits 3 s).
    name : str
        Label for tables.
    """

    windows: tuple[Rotation | Static, ...]
    pause: float = 0.0
    name: str = ""

    def __post_init__(self):
        w = tuple(self.windows)
        if not w or not all(isinstance(x, (Rotation, Static)) for x in w):
            raise InputError("windows must be a non-empty sequence of Rotation and Static windows")
        if not (math.isfinite(self.pause) and self.pause >= 0):
            raise InputError(f"{{param}} must be finite and >= 0 [s], got {self.pause!r}", param="pause")
        object.__setattr__(self, "windows", w)

    @property
    def rotations(self) -> tuple[Rotation, ...]:
        return tuple(x for x in self.windows if isinstance(x, Rotation))

    @property
    def total_time(self) -> float:
        """Protocol length [s]: every window plus the pauses between them."""
        return sum(x.duration for x in self.windows) + self.pause * (len(self.windows) - 1)

    @classmethod
    def from_axes(cls, axes: Sequence, speed: float, *, revolutions: float = 1.0, static_duration: float = 0.0,
                  pause: float = 0.0, name: str = "") -> Design:
        """One turn of `revolutions` about each axis, each followed by a static window if asked."""
        windows: list[Rotation | Static] = []
        for a in axes:
            windows.append(Rotation(a, speed, 2 * math.pi * positive("revolutions", revolutions)))
            if static_duration > 0:
                windows.append(Static(static_duration))
        return cls(tuple(windows), pause=pause, name=name)

    @classmethod
    def paper_six(cls, speed: float = math.pi / 3, pause: float = 3.0) -> Design:
        """The servo method of Wang et al., Fig. 1: one revolution about +x, -x, +y, -y, +z, -z, 3 s apart. G-optimal."""
        return cls.from_axes(("+x", "-x", "+y", "-y", "+z", "-z"), speed, pause=pause, name="paper six")

    @classmethod
    def paper_six_static(cls, speed: float = math.pi / 3, static_duration: float = 3.0) -> Design:
        """The paper's protocol with its 3 s waits recorded and used as static windows."""
        return cls.from_axes(("+x", "-x", "+y", "-y", "+z", "-z"), speed, static_duration=static_duration,
                             name="paper six + static waits")

    @classmethod
    def face_diagonals(cls, speed: float = math.pi / 3, pause: float = 3.0) -> Design:
        """Twelve turns, one about each face diagonal of the cube ``(+-1, +-1, 0)/sqrt 2`` and permutations."""
        axes = []
        for i, j in ((0, 1), (0, 2), (1, 2)):
            for si in (1, -1):
                for sj in (1, -1):
                    a = np.zeros(3)
                    a[i], a[j] = si, sj
                    axes.append(a)
        return cls.from_axes(axes, speed, pause=pause, name="12 face diagonals")


def _model(model) -> ScaleBias:
    if model is None:
        return ScaleBias(k=np.ones(3), b=np.zeros(3))
    if not isinstance(model, ScaleBias):
        raise InputError(f"model must be a ScaleBias (the servo method's model), got {type(model).__name__}")
    return model


def _noise_var(noise_std, noise_density, sample_rate: float) -> np.ndarray:
    if (noise_std is None) == (noise_density is None):
        raise InputError("give exactly one of noise_std [rad/s per sample] and noise_density [rad/s/sqrt(Hz)]")
    sd = noise_std if noise_std is not None else np.asarray(noise_density, dtype=float) * math.sqrt(sample_rate)
    sd = np.broadcast_to(finite_array("noise_std", sd), (3,))
    if np.any(sd <= 0):
        raise InputError(f"noise must be > 0 on every axis, got {sd.tolist()}")
    return sd**2


def expected_observations(design: Design, model=None, sample_rate: float = 200.0, noise_std=0.0) -> ObservationSet:
    """Noise-free window means a gyro with `model` would give under `design` (a batch of one).

    Parameters
    ----------
    design : Design
    model : ScaleBias, optional
        True parameters; ``k = 1, b = 0`` by default.
    sample_rate : float
        Sampling rate [Hz]; sets each window's sample count.
    noise_std : float or array_like of shape (3,)
        Per-sample noise [rad/s], recorded as the windows' noise variance.
    """
    model = _model(model)
    fs = positive("sample_rate", sample_rate)
    rot = [isinstance(w, Rotation) for w in design.windows]
    true = np.array([w.speed * w.axis if r else np.zeros(3) for w, r in zip(design.windows, rot)])
    mean = model.distort(true)  # the servo method of Wang et al., eq. 1 solved for m
    count = np.array([max(2, round(w.duration * fs)) for w in design.windows], dtype=float)
    nv = np.broadcast_to(np.square(np.asarray(noise_std, dtype=float)), mean.shape)
    rate = np.array([w.speed if r else 0.0 for w, r in zip(design.windows, rot)])
    return ObservationSet(mean[None], (mean**2 + nv)[None], nv[None], rate[None], count, count / fs, ~np.array(rot))


def _jacobian(design: Design, model, sample_rate: float):
    model = _model(model)
    obs = expected_observations(design, model, sample_rate)
    n_rot, n_sta = len(design.rotations), len(design.windows) - len(design.rotations)
    require_count(n_rot + 3 * n_sta, f"{n_rot} rotation and {n_sta} static window(s)")
    _, J, S = residuals_and_jacobian(model.params[None], obs)
    require_full_rank(J[0], PARAM_NAMES, f"the windows of design {design.name!r}" if design.name else "the windows of the design")
    return J, S


def information_matrix(design: Design, model=None, noise_std=None, sample_rate: float = 200.0, *,
                       noise_density=None) -> np.ndarray:
    """Fisher information (6, 6) of ``(k, b)`` [1/unit^2] for white noise on the window means.

    Each turn's axis direction is unknown, as in the norm equations (a mount is never exact): the
    bound on b is wider than with known axes (3x in variance for the six turns of Wang et al.).

    Parameters
    ----------
    design : Design
    model : ScaleBias, optional
        True parameters (``k = 1, b = 0`` by default).
    noise_std : float or array_like of shape (3,)
        Per-sample white-noise standard deviation [rad/s]; or give `noise_density`.
    sample_rate : float
        Sampling rate [Hz].
    noise_density : float or array_like of shape (3,)
        White-noise density [rad/s/sqrt(Hz)], instead of `noise_std`.
    """
    nv = _noise_var(noise_std, noise_density, positive("sample_rate", sample_rate))
    J, S = _jacobian(design, model, sample_rate)
    row_var = np.einsum("bmj,j->bm", S * S, nv)  # variance of each weighted row
    return np.einsum("mi,m,mj->ij", J[0], 1.0 / row_var[0], J[0])


def crb_covariance(design: Design, model=None, noise_std=None, sample_rate: float = 200.0, *,
                   noise_density=None) -> np.ndarray:
    """Cramér–Rao bound (6, 6): the inverse of :func:`information_matrix`."""
    return np.linalg.inv(information_matrix(design, model, noise_std, sample_rate, noise_density=noise_density))


def predicted_std(design: Design, model=None, noise_std=None, sample_rate: float = 200.0, *,
                  noise_density=None) -> np.ndarray:
    """Smallest achievable standard deviation of ``[kx, ky, kz, bx, by, bz]`` (the CRB) [-, rad/s].

    Examples
    --------
    >>> import math
    >>> from gyrocal.planning.design import Design, predicted_std
    >>> sd = predicted_std(Design.paper_six(math.pi / 3), noise_std=0.035, sample_rate=200)
    >>> round(float(sd[0]) * 1e4, 1)   # scale factor at k = 1, in 1e-4
    6.8
    """
    return np.sqrt(np.diag(crb_covariance(design, model, noise_std, sample_rate, noise_density=noise_density)))


def predicted_covariance(design: Design, model=None, noise_std=None, sample_rate: float = 200.0, *,
                         noise_density=None) -> np.ndarray:
    """Covariance (6, 6) the first-moment estimator reports for this design (its sandwich).

    Equal to the CRB for six rotation windows; slightly above it when rows of unequal
    noise share the estimator's ``sqrt(count)`` weights.
    """
    nv = _noise_var(noise_std, noise_density, positive("sample_rate", sample_rate))
    J, S = _jacobian(design, model, sample_rate)
    return sandwich_covariance(J, S, nv[None])[0]


def _regressors(x: np.ndarray) -> np.ndarray:
    """The servo method of Wang et al., eq. 7 regressors ``[x^2, x]`` of directions x (n, 3)."""
    return np.concatenate([x * x, x], axis=-1)


def _moment_matrix(design: Design) -> np.ndarray:
    rot = design.rotations
    if not rot:
        return np.zeros((_P, _P))
    w = np.array([r.duration for r in rot])  # sample counts at any common rate
    F = _regressors(np.array([r.axis for r in rot]))
    return np.einsum("n,ni,nj->ij", w / w.sum(), F, F)


def d_efficiency(design: Design) -> float:
    """``(det M / det M*)^(1/6)`` for the servo method's regression on the sphere; 1 for the paper's six."""
    det = np.linalg.det(_moment_matrix(design))
    return float(max(det, 0.0) / _REFERENCE_DET) ** (1.0 / _P)


def _sphere(n: int = 4000) -> np.ndarray:
    """A Fibonacci grid of n unit vectors, plus the six axis points."""
    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    phi = math.pi * (3 - math.sqrt(5)) * i
    r = np.sqrt(1 - z * z)
    return np.concatenate([np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1), np.eye(3), -np.eye(3)])


def g_efficiency(design: Design) -> float:
    """``6 / max_{|x|=1} f(x)^T M^-1 f(x)``: 1 for a G-optimal design, 0 when M is singular."""
    M = _moment_matrix(design)
    if np.linalg.matrix_rank(M, tol=1e-10) < _P:
        return 0.0
    F = _regressors(_sphere())
    d = np.einsum("ni,ij,nj->n", F, np.linalg.inv(M), F)
    return float(_P / d.max())


@dataclass(frozen=True)
class DesignReport:
    """One row of a design comparison.

    Attributes
    ----------
    name : str
    windows : int
    total_time : float
        Protocol length [s].
    d_efficiency, g_efficiency : float
        See the module notes.
    std : ndarray, shape (6,)
        CRB standard deviations of ``[kx, ky, kz, bx, by, bz]`` [-, rad/s].
    """

    name: str
    windows: int
    total_time: float
    d_efficiency: float
    g_efficiency: float
    std: np.ndarray = field(repr=False)


def compare_designs(designs: Mapping[str, Design] | Sequence[Design], model=None, noise_std=None,
                    sample_rate: float = 200.0, *, noise_density=None) -> list[DesignReport]:
    """Evaluate several designs under one true model and noise level."""
    items = designs.items() if isinstance(designs, Mapping) else [(d.name, d) for d in designs]
    return [
        DesignReport(name or "design", len(d.windows), d.total_time, d_efficiency(d), g_efficiency(d),
                     predicted_std(d, model, noise_std, sample_rate, noise_density=noise_density))
        for name, d in items
    ]


def format_design_table(reports: Sequence[DesignReport]) -> str:
    """A Markdown table: time, efficiencies and the worst CRB std of scale and bias."""
    head = "| design | windows | time [s] | D-eff | G-eff | max std k [1e-4] | max std b [1e-4 rad/s] |"
    rows = [head, "|" + "---|" * 7]
    for r in reports:
        rows.append(f"| {r.name} | {r.windows} | {r.total_time:.1f} | {r.d_efficiency:.3f} | {r.g_efficiency:.3f} "
                    f"| {1e4 * r.std[:3].max():.2f} | {1e4 * r.std[3:].max():.2f} |")
    return "\n".join(rows)
