"""Time alignment and mounting rotation of a test log against a reference log.

Two sensors on one mount record the same motion on two clocks, related by
``t_test = t_ref * (1 + clock_drift_ppm * 1e-6) + time_offset_s``, and in two frames,
related by ``w_test = mounting_rotation @ w_ref``. :func:`align` finds both:

1. coarse offset candidates from the cross-correlation of the rate magnitudes, which do
   not depend on the mounting (:mod:`.coarse`);
2. for each candidate, the rotation that best maps the reference rate vectors onto the
   test ones (Wahba's problem, solved by SVD: :func:`gyrocal.quaternion.align_vectors`);
   the candidate with the smallest residual wins, which resolves motions whose magnitude
   repeats (the six turns of the servo method of Wang et al. look alike in magnitude);
3. a drift guess from segment-wise correlation on long logs;
4. joint least squares of offset, drift and rotation on the interpolated reference
   (:mod:`.refine`), with a covariance that holds for correlated residuals.

Motion too poor to align (a static log, turns about one direction only, a periodic motion)
is refused with a :class:`~gyrocal.errors.GyrocalError` that says what to record instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validation import finite_array
from ..errors import InputError
from ..quaternion import align_vectors, matrix_rotvec
from ..units import STANDARD_GRAVITY
from .coarse import coarse_offsets, grid_rate_for, magnitude_grid, segment_drift
from .refine import PPM, interpolate, refine
from .whitenoise import second_difference_noise

__all__ = ["Alignment", "AlignmentError", "align"]

MIN_MAGNITUDE_SNR = 3.0  # rate-magnitude variation over the per-sample noise, each log (static: about 0.7)
MIN_PEAK = 0.3  # normalised magnitude correlation at the chosen offset
MIN_ROTATION_SNR = 5.0  # rate RMS across the main turning direction over the noise
MAX_ROTATION_STD_DEG = 2.0
AMBIGUITY = 1.25  # a second candidate within this factor of the best residual is ambiguous
MIN_OVERLAP_SAMPLES = 200
MIN_EXPLAINED = 0.5  # share of the test log's rate energy the aligned reference must explain
DRIFT_SEARCH_S = 180.0  # overlap from which the drift is first guessed segment by segment
#: Unit mix-ups seen as the ratio of the test log's rate magnitude to the reference's, with what they mean.
UNIT_RATIOS = ((180.0 / math.pi, "a reference in rad/s read as deg/s: give {param} rad/s"),
               (math.pi / 180.0, "a reference in deg/s read as rad/s: give {param} deg/s"),
               (STANDARD_GRAVITY, "a factor of g: check {param} and that the reference's columns are its gyro's"),
               (1.0 / STANDARD_GRAVITY, "a factor of g: check {param} and that the reference's columns are its gyro's"))
UNIT_RATIO_TOLERANCE = 0.15  # relative distance of the magnitude ratio from a unit factor
MIN_COVERAGE = 0.75  # an ambiguity where every fitting offset covers less of the test log is a short reference


class AlignmentError(InputError):
    """The two logs cannot be aligned: too little motion, no overlap, or an ambiguous offset."""


@dataclass(frozen=True)
class Alignment:
    """Clock and frame relation between a test log and a reference log, with 1-sigma.

    Attributes
    ----------
    time_offset_s : float
        ``t_test = t_ref * (1 + clock_drift_ppm * 1e-6) + time_offset_s`` [s].
    clock_drift_ppm : float
        Rate of the test clock against the reference clock, minus one [ppm].
    offset_at_centre_s : float
        ``t_test - t_ref`` at the test log's centre [s]: the offset where the data are, with
        no extrapolation to the reference clock's zero.
    mounting_rotation : ndarray, shape (3, 3)
        Reference frame to test frame: ``w_test = mounting_rotation @ w_ref``.
    covariance : ndarray, shape (5, 5)
        Of ``(time_offset_s, clock_drift_ppm, phi_x, phi_y, phi_z)``; ``phi`` [rad] is a
        small rotation of the test frame (``R -> Exp(phi) R``).
    offset_at_centre_std_s : float
        1-sigma of `offset_at_centre_s` [s].
    correlation_peak : float
        Normalised correlation of the rate magnitudes at the offset (1 = identical).
    residual_rms : ndarray, shape (3,)
        RMS of ``w_test - R w_ref`` per test axis after alignment [rad/s].
    noise_test, noise_ref : ndarray, shape (3,)
        White-noise standard deviation of each log [rad/s] (second differences).
    n_samples : int
        Test samples inside the reference log, used by the fit.
    overlap_s : float
        Their time span [s].
    drift_fitted : bool
        False when the drift was held at zero.
    block : int
        Batch length of the covariance [samples].
    iterations : int
        Gauss-Newton iterations of the last pass.
    """

    time_offset_s: float
    clock_drift_ppm: float
    offset_at_centre_s: float
    mounting_rotation: np.ndarray
    covariance: np.ndarray
    offset_at_centre_std_s: float
    correlation_peak: float
    residual_rms: np.ndarray
    noise_test: np.ndarray
    noise_ref: np.ndarray
    n_samples: int
    overlap_s: float
    drift_fitted: bool
    block: int
    iterations: int

    @property
    def std(self) -> np.ndarray:
        """1-sigma of ``(time_offset_s [s], clock_drift_ppm [ppm], phi [rad] x3)``."""
        return np.sqrt(np.diag(self.covariance))

    @property
    def rotation_deg(self) -> float:
        """Angle of the mounting rotation [deg]."""
        return math.degrees(float(np.linalg.norm(matrix_rotvec(self.mounting_rotation))))

    @property
    def rotation_deg_std(self) -> float:
        """1-sigma of :attr:`rotation_deg` [deg], along the rotation axis (the largest
        small-angle 1-sigma when the rotation is too small to have an axis)."""
        vec = matrix_rotvec(self.mounting_rotation)
        cov = self.covariance[2:, 2:]
        norm = float(np.linalg.norm(vec))
        if norm < 1e-9:
            return math.degrees(math.sqrt(float(np.linalg.eigvalsh(cov).max())))
        axis = vec / norm
        return math.degrees(math.sqrt(float(axis @ cov @ axis)))

    def reference_time(self, t_test) -> np.ndarray:
        """Reference clock times [s] of test clock times `t_test` [s]."""
        return (np.asarray(t_test, float) - self.time_offset_s) / (1.0 + self.clock_drift_ppm * PPM)

    def reference_at(self, t_test, t_ref, w_ref) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The reference at test times, in the test frame.

        Returns
        -------
        w : ndarray, shape (n, 3)
            Interpolated, rotated reference rates [unit of `w_ref`] at the test times inside
            the reference log.
        inside : ndarray of bool, shape (N,)
            Which test times those are.
        frac : ndarray, shape (n,)
            Fractional position of each between its two reference samples.
        """
        tau = self.reference_time(t_test)
        inside = (tau >= t_ref[0]) & (tau <= t_ref[-1])
        v, _, frac = interpolate(np.asarray(t_ref, float), np.asarray(w_ref, float), tau[inside])
        return v @ self.mounting_rotation.T, inside, frac


def _check_inputs(t_test, w_test, t_ref, w_ref):
    out = []
    for name, t, w in (("test", t_test, w_test), ("reference", t_ref, w_ref)):
        t = finite_array(f"{name} times", t, ndim=1)
        w = finite_array(f"{name} rates", w, shape_tail=(3,), ndim=2)
        if len(t) != len(w) or len(t) < MIN_OVERLAP_SAMPLES:
            raise AlignmentError(f"the {name} log has {len(w)} samples ({len(t)} times); "
                                 f"alignment needs at least {MIN_OVERLAP_SAMPLES}")
        if np.any(np.diff(t) <= 0):
            raise AlignmentError(f"the {name} log's times do not increase; sort or deduplicate it")
        out += [t, w]
    return out


def _check_motion(name: str, t, w, noise: np.ndarray, rate: float) -> None:
    mag = magnitude_grid(t, w, rate)
    spread, floor = float(mag.std()), float(np.sqrt(np.mean(noise**2)))
    if not spread > MIN_MAGNITUDE_SNR * floor:
        raise AlignmentError(
            f"the {name} log shows no motion to align on: its rate magnitude varies by "
            f"{math.degrees(spread):.3g} deg/s against a noise of {math.degrees(floor):.3g} deg/s; "
            "record both logs while the sensors turn (for example the calibration turns)")


def _candidate_score(t_test, w_test, t_ref, w_ref, offset: float) -> tuple[float, np.ndarray | None]:
    """Energy [(rad/s)^2 s] the candidate offset leaves unexplained, and its best rotation.

    Inside the overlap: the residual after the best rotation for the offset. Outside: the
    motion of either log that the other does not cover. A wrong offset that matches only
    some turns of a repeating protocol (each turn of the servo method of Wang et al. looks
    like the next) leaves the unmatched turns unexplained and loses.
    """
    tau = t_test - offset
    inside = (tau >= t_ref[0]) & (tau <= t_ref[-1])
    if inside.sum() < MIN_OVERLAP_SAMPLES:
        return math.inf, None
    v, _, _ = interpolate(t_ref, w_ref, tau[inside])
    r = align_vectors(w_test[inside], v)
    dt_test = (t_test[-1] - t_test[0]) / (len(t_test) - 1)
    dt_ref = (t_ref[-1] - t_ref[0]) / (len(t_ref) - 1)
    covered = (t_ref >= t_test[inside][0] - offset) & (t_ref <= t_test[inside][-1] - offset)
    energy = (np.sum((w_test[inside] - v @ r.T) ** 2) + np.sum(w_test[~inside] ** 2)) * dt_test
    return float(energy + np.sum(w_ref[~covered] ** 2) * dt_ref), r


def _overlap(t_test, t_ref, offset: float) -> np.ndarray:
    """Which test samples fall inside the reference log at `offset` (``t_test - t_ref``)."""
    tau = t_test - offset
    return (tau >= t_ref[0]) & (tau <= t_ref[-1])


def _check_units(t_test, w_test, t_ref, w_ref, coarse) -> None:
    """Refuse a reference whose rate magnitudes are a unit factor away from the test log's.

    The magnitude correlation is normalised, so it finds the offset whatever the scale; the
    candidates' residuals are then all about the test log's whole motion, which would read
    as an ambiguous offset. The ratio of the RMS magnitudes over the overlap at the highest
    correlation names the unit instead.
    """
    if coarse.peaks[0] < MIN_PEAK:
        return
    inside = _overlap(t_test, t_ref, coarse.offsets[0])
    if inside.sum() < MIN_OVERLAP_SAMPLES:
        return
    v, _, _ = interpolate(t_ref, w_ref, t_test[inside] - coarse.offsets[0])
    ratio = math.sqrt(float(np.sum(w_test[inside] ** 2)) / max(float(np.sum(v**2)), np.finfo(float).tiny))
    for factor, meaning in UNIT_RATIOS:
        if abs(ratio / factor - 1.0) < UNIT_RATIO_TOLERANCE:
            size = f"{ratio:.3g} times smaller" if ratio > 1 else f"{1.0 / ratio:.3g} times larger"
            raise AlignmentError(f"the reference's rates are {size} than the test log's over their overlap, so "
                                 f"its unit is wrong, as with {meaning}", param="ref_units", value=ratio)


def _ambiguous(t_test, t_ref, coarse, scored) -> AlignmentError:
    """The error for two offsets that fit about equally: a reference covering only part of the
    test log at each of them, or else a motion that repeats itself."""
    fits = [float(coarse.offsets[i]) for score, i in scored if score < AMBIGUITY * scored[0][0]]
    shown = " or ".join(f"{off:.3f} s" for off in fits[:2])
    duration = t_test[-1] - t_test[0]
    cover = []
    for off in fits:
        inside = t_test[_overlap(t_test, t_ref, off)]
        cover.append((inside[-1] - inside[0]) / duration if len(inside) > 1 else 0.0)
    if max(cover) < MIN_COVERAGE:
        return AlignmentError(
            f"the reference log covers only {100 * max(cover):.0f} % of the test log ({t_ref[-1] - t_ref[0]:.1f} s "
            f"of {duration:.1f} s) at each offset that fits ({shown}), so the clock offset is ambiguous; record "
            "the reference over the whole test log, or cut the test log to the part the reference covers")
    return AlignmentError(
        f"the motion repeats itself, so the clock offset is ambiguous ({shown} fit about equally); record a "
        "motion that does not repeat (turns about different axes, different pauses)")


def _best_candidate(t_test, w_test, t_ref, w_ref, coarse) -> tuple[float, np.ndarray, float]:
    scored = sorted((_candidate_score(t_test, w_test, t_ref, w_ref, off)[0], i) for i, off in enumerate(coarse.offsets))
    best_score, best = scored[0]
    if not math.isfinite(best_score):
        raise AlignmentError("the two logs do not overlap in time at any offset the rate magnitudes suggest")
    if coarse.peaks[best] < MIN_PEAK:
        raise AlignmentError(
            f"the rate magnitudes of the two logs do not match (best correlation {coarse.peaks[best]:.2f}); "
            "check that both logs record the same motion and overlap in time")
    if len(scored) > 1 and scored[1][0] < AMBIGUITY * best_score:
        raise _ambiguous(t_test, t_ref, coarse, scored)
    _, rot = _candidate_score(t_test, w_test, t_ref, w_ref, coarse.offsets[best])
    return float(coarse.offsets[best]), rot, float(coarse.peaks[best])


def _initial_drift(t_test, w_test, t_ref, w_ref, offset: float, rate: float) -> tuple[float, float]:
    if t_test[-1] - t_test[0] < DRIFT_SEARCH_S:
        return offset, 0.0
    line = segment_drift(t_test, w_test, t_ref, w_ref, offset, rate)
    if line is None:
        return offset, 0.0
    t0, local0, slope = line  # local offset t - t_ref = (t * d + offset) / (1 + d)
    d = slope / (1.0 - slope)
    return local0 * (1.0 + d) - t0 * d, d / PPM


def _rotation_excitation(v: np.ndarray, noise_test: np.ndarray, noise_ref: np.ndarray) -> None:
    """Refuse a motion that turns about one direction only: the rotation about it is unknown."""
    lam, vec = np.linalg.eigh(v.T @ v / len(v))  # ascending
    across = math.sqrt(max(float(lam[0] + lam[1]) - 2.0 * float(np.mean(noise_ref**2)), 0.0))
    floor = float(max(np.sqrt(np.mean(noise_test**2)), np.sqrt(np.mean(noise_ref**2))))
    if not across > MIN_ROTATION_SNR * floor:
        axis = vec[:, 2] * np.sign(vec[np.argmax(np.abs(vec[:, 2])), 2])
        raise AlignmentError(
            f"the motion turns about one direction only (reference axis {np.round(axis, 2).tolist()}), so the "
            "mounting rotation about it cannot be found; record turns about a second axis as well")


def _fit_pass(t_test, w_test, t_ref, w_ref, offset, drift, rot, margin, fit_drift, noise, last: bool):
    tau = (t_test - offset) / (1.0 + drift * PPM)
    keep = (tau >= t_ref[0] + margin) & (tau <= t_ref[-1] - margin)
    if keep.sum() < MIN_OVERLAP_SAMPLES:
        raise AlignmentError(f"the logs overlap for only {int(keep.sum())} test samples; "
                             f"alignment needs at least {MIN_OVERLAP_SAMPLES}")
    t, w = t_test[keep], w_test[keep]
    if noise is not None:
        _rotation_excitation(interpolate(t_ref, w_ref, tau[keep])[0], *noise)
    tc = 0.5 * (t[0] + t[-1])
    fit = refine(t, w, t_ref, w_ref, (tc - offset) / (1.0 + drift * PPM), drift, rot, fit_drift=fit_drift,
                 covariance=last)
    new_offset = tc - fit.a * (1.0 + fit.drift_ppm * PPM)
    return fit, new_offset, t


def _public_covariance(fit) -> np.ndarray:
    """Covariance of (offset, drift, phi) from that of (a, drift, theta): offset = tc - a (1 + drift)."""
    jac = np.zeros((5, 5))
    jac[0, 0], jac[0, 1] = -(1.0 + fit.drift_ppm * PPM), -fit.a * PPM
    jac[1, 1] = 1.0
    jac[2:, 2:] = fit.rotation  # R Exp(theta) = Exp(R theta) R
    return jac @ fit.covariance @ jac.T


def align(t_test, w_test, t_ref, w_ref, *, fit_drift: bool = True) -> Alignment:
    """Align a test log with a reference log of the same motion.

    Parameters
    ----------
    t_test : array_like, shape (N,)
        Test sample times on the test clock [s], increasing.
    w_test : array_like, shape (N, 3)
        Test rates [rad/s]; calibrated, so that they compare with the reference.
    t_ref : array_like, shape (M,)
        Reference sample times on the reference clock [s], increasing.
    w_ref : array_like, shape (M, 3)
        Reference rates [rad/s].
    fit_drift : bool
        False holds the clock drift at zero (both logs stamped by one clock).

    Returns
    -------
    Alignment

    Raises
    ------
    AlignmentError
        Static logs, no overlap, turns about a single direction, a repeating motion, a
        reference a unit factor (57.3, 9.81) away from the test log, or one that covers only
        part of it where that leaves the offset ambiguous.
    """
    t_test, w_test, t_ref, w_ref = _check_inputs(t_test, w_test, t_ref, w_ref)
    noise_test = second_difference_noise(t_test, w_test).std
    noise_ref = second_difference_noise(t_ref, w_ref).std
    rate_test, rate_ref = (len(t) / (t[-1] - t[0]) for t in (t_test, t_ref))
    grid = grid_rate_for(rate_test, rate_ref)
    _check_motion("test", t_test, w_test, noise_test, grid)
    _check_motion("reference", t_ref, w_ref, noise_ref, grid)
    coarse = coarse_offsets(t_test, w_test, t_ref, w_ref, grid)
    _check_units(t_test, w_test, t_ref, w_ref, coarse)
    offset, rot, peak = _best_candidate(t_test, w_test, t_ref, w_ref, coarse)
    drift = 0.0
    if fit_drift:
        offset, drift = _initial_drift(t_test, w_test, t_ref, w_ref, offset, grid)
    # First pass away from the reference's ends, then a last pass on every sample inside it.
    wide = min(1.0, 0.05 * (t_ref[-1] - t_ref[0]))
    fit, offset, _ = _fit_pass(t_test, w_test, t_ref, w_ref, offset, drift, rot, wide, fit_drift,
                               (noise_test, noise_ref), last=False)
    fit, offset, t_used = _fit_pass(t_test, w_test, t_ref, w_ref, offset, fit.drift_ppm, fit.rotation,
                                    0.0, fit_drift, None, last=True)
    cov = _public_covariance(fit)
    tc = 0.5 * (t_used[0] + t_used[-1])  # where t - t_ref = tc - a, uncorrelated with the drift
    result = Alignment(
        time_offset_s=float(offset), clock_drift_ppm=float(fit.drift_ppm),
        offset_at_centre_s=float(tc - fit.a), mounting_rotation=fit.rotation, covariance=cov,
        offset_at_centre_std_s=float(math.sqrt(fit.covariance[0, 0])), correlation_peak=peak,
        residual_rms=fit.residual_rms, noise_test=noise_test, noise_ref=noise_ref, n_samples=len(t_used),
        overlap_s=float(t_used[-1] - t_used[0]), drift_fitted=fit_drift, block=fit.block,
        iterations=fit.iterations)
    explained = 1.0 - float(np.sum(fit.residual_rms**2)) / float(np.mean(np.sum(w_test**2, axis=1)))
    if explained < MIN_EXPLAINED:
        raise AlignmentError(
            f"the reference explains only {100 * max(explained, 0.0):.0f} % of the test log's motion; check that "
            "both logs record the same motion (and that the calibration fits the test gyro)")
    worst = math.degrees(math.sqrt(float(np.linalg.eigvalsh(cov[2:, 2:]).max())))
    if worst > MAX_ROTATION_STD_DEG:
        raise AlignmentError(
            f"the mounting rotation is uncertain by {worst:.2g} deg (1-sigma); the motion does not turn the "
            "sensors enough about every axis. Record turns about at least two axes")
    return result
