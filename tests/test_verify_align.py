"""Alignment of two logs from two clocks: offset, drift and mounting rotation against the simulation's truth.

Independent reference throughout: the clock relation and mounting rotation that
``simulate_reference`` used to make the reference log. Tolerances are 4 reported sigma
for single runs, and for z-scores over seeds a band of 3 standard deviations of the RMS
(or mean chi-square) that N standard normal draws would give.
"""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from verify_pairs import make_pair

from gyrocal.errors import GyrocalError, InputError
from gyrocal.verify import AlignmentError, align

CHI2_3_LIMIT = 25.0  # P(chi2 with 3 dof > 25) = 1.6e-5, about a 4-sigma event


def _errors(a, pair):
    """z of offset and drift, chi-square (3 dof) of the rotation, against the truth."""
    truth = pair.truth
    phi = Rotation.from_matrix(a.mounting_rotation @ truth.mounting_rotation.T).as_rotvec()  # test-frame error
    z_off = (a.time_offset_s - truth.time_offset_s) / a.std[0]
    z_drift = (a.clock_drift_ppm - truth.clock_drift_ppm) / a.std[1] if a.drift_fitted else 0.0
    return z_off, z_drift, float(phi @ np.linalg.solve(a.covariance[2:, 2:], phi))


SCENARIOS = [
    # motion, fs_test, fs_ref, offset [s], drift [ppm], mounting [deg], test noise, reference noise [rad/s]
    ("smooth", 200.0, 100.0, 3.2, 40.0, 20.0, 0.02, 0.002),
    ("smooth", 100.0, 200.0, -7.5, -120.0, 45.0, 0.01, 0.001),
    ("servo", 200.0, 100.0, -2.3, 60.0, 5.0, 0.035, 0.0005),
    ("servo", 400.0, 50.0, 12.0, 0.0, 90.0, 0.02, 0.003),
    ("smooth", 200.0, 200.0, 0.0037, 0.0, 0.0, 0.05, 0.005),
    ("smooth", 100.0, 100.0, -0.4, 250.0, 170.0, 0.005, 0.0005),
]


@pytest.mark.parametrize("motion, fs_test, fs_ref, offset, drift, deg, noise_test, noise_ref", SCENARIOS)
def test_alignment_finds_the_truth_within_4_sigma(motion, fs_test, fs_ref, offset, drift, deg, noise_test, noise_ref,
                                                 rng):
    pair = make_pair(rng, motion=motion, fs_test=fs_test, fs_ref=fs_ref, noise_test=noise_test, noise_ref=noise_ref,
                     offset=offset, drift=drift, mounting_deg=deg)
    a = align(pair.test.t, pair.test.gyro, pair.ref.t, pair.ref.gyro)
    z_off, z_drift, chi2 = _errors(a, pair)
    assert abs(z_off) < 4 and abs(z_drift) < 4 and chi2 < CHI2_3_LIMIT, (z_off, z_drift, chi2)
    # the offset to a fraction of the slower sample period, as the issue asks
    assert a.offset_at_centre_std_s < 0.1 / min(fs_test, fs_ref)
    assert a.rotation_deg == pytest.approx(deg, abs=max(4 * a.rotation_deg_std, 1e-6))


@pytest.mark.slow
def test_reported_sigma_holds_over_random_pairs():
    """z-scores over 24 random pairs (rates 50-400 Hz, offsets +-10 s, drift +-200 ppm, rotations 0-60 deg)."""
    z = []
    for seed in range(24):
        rng = np.random.default_rng(1000 + seed)
        pair = make_pair(rng, motion=("smooth", "servo")[seed % 2], duration=40.0,
                         fs_test=float(rng.choice([100.0, 200.0, 400.0])), fs_ref=float(rng.choice([50.0, 100.0, 200.0])),
                         noise_test=rng.uniform(0.005, 0.05), noise_ref=rng.uniform(0.0005, 0.005),
                         offset=rng.uniform(-10, 10), drift=rng.uniform(-200, 200), mounting_deg=rng.uniform(0, 60))
        z.append(_errors(align(pair.test.t, pair.test.gyro, pair.ref.t, pair.ref.gyro), pair))
    z = np.array(z)
    n = len(z)
    rms_band = 3.0 * math.sqrt(1.0 / (2 * n))  # sd of the RMS of n standard normals
    chi_band = 3.0 * math.sqrt(2.0 / (3 * n))  # sd of the mean of n chi2(3)/3
    assert abs(math.sqrt(np.mean(z[:, 0] ** 2)) - 1) < rms_band
    assert abs(math.sqrt(np.mean(z[:, 1] ** 2)) - 1) < rms_band
    assert abs(np.mean(z[:, 2]) / 3 - 1) < chi_band


@pytest.mark.slow
def test_reported_sigma_matches_monte_carlo_spread():
    """One motion and geometry, 20 noise draws: the spread of the estimates against the mean reported 1-sigma."""
    base = make_pair(np.random.default_rng(7), duration=30.0, noise_test=0.0, noise_ref=0.0, offset=-1.7, drift=80.0,
                     mounting_deg=25.0)
    errors, sigmas = [], []
    for seed in range(20):
        rng = np.random.default_rng(seed)
        test = base.test.gyro + 0.03 * rng.standard_normal(base.test.gyro.shape)
        ref = base.ref.gyro + 0.003 * rng.standard_normal(base.ref.gyro.shape)
        a = align(base.test.t, test, base.ref.t, ref)
        phi = Rotation.from_matrix(a.mounting_rotation @ base.truth.mounting_rotation.T).as_rotvec()
        errors.append([a.time_offset_s - base.truth.time_offset_s, a.clock_drift_ppm - base.truth.clock_drift_ppm,
                       *phi])
        sigmas.append(a.std)
    ratio = np.std(errors, axis=0, ddof=1) / np.mean(sigmas, axis=0)
    band = 3.0 * math.sqrt(1.0 / (2 * (len(errors) - 1)))  # relative sd of a sample sd
    assert np.all(np.abs(ratio - 1) < band), ratio


def test_long_log_with_drift_uses_segment_offsets(rng):
    """A 10-minute pair at 150 ppm: the ends are 90 ms apart, more than the motion's fast features."""
    pair = make_pair(rng, duration=600.0, fs_test=100.0, fs_ref=50.0, offset=-4.0, drift=150.0, mounting_deg=10.0)
    a = align(pair.test.t, pair.test.gyro, pair.ref.t, pair.ref.gyro)
    z_off, z_drift, chi2 = _errors(a, pair)
    assert abs(z_off) < 4 and abs(z_drift) < 4 and chi2 < CHI2_3_LIMIT
    assert a.std[1] < 1.0  # ppm: a long log measures the drift well


def test_drift_held_at_zero(rng):
    pair = make_pair(rng, duration=30.0, offset=0.25, drift=0.0)
    a = align(pair.test.t, pair.test.gyro, pair.ref.t, pair.ref.gyro, fit_drift=False)
    assert a.clock_drift_ppm == 0.0 and a.std[1] == 0.0 and not a.drift_fitted
    assert abs(a.time_offset_s - 0.25) < 4 * a.std[0]


def test_static_logs_are_refused(rng):
    t = np.arange(6000) / 100.0
    still = 0.01 * rng.standard_normal((6000, 3))
    with pytest.raises(AlignmentError, match="no motion to align on"):
        align(t, still, t, 0.001 * rng.standard_normal((6000, 3)))


def test_turns_about_one_direction_are_refused(rng):
    """Every rate along z: the rotation about z cannot be found."""
    pair = make_pair(rng, duration=40.0, mounting_deg=0.0)
    only_z = pair.rates * [0.0, 0.0, 1.0]
    t_ref = pair.ref.t
    w_ref = np.stack([np.zeros_like(t_ref), np.zeros_like(t_ref), np.interp(t_ref, pair.test.t, only_z[:, 2])], 1)
    with pytest.raises(AlignmentError, match="one direction only"):
        align(pair.test.t, only_z + 0.01 * rng.standard_normal(only_z.shape), t_ref,
              w_ref + 0.001 * rng.standard_normal(w_ref.shape))


def test_a_repeating_motion_is_refused_as_ambiguous(rng):
    """Turns about x then y every 4 s; the reference runs 60 s, so any shift by 4 s fits as well."""
    def motion(t):
        phase = np.mod(t, 4.0)
        return np.stack([np.where(phase < 2, np.sin(np.pi * phase), 0.0),
                         np.where(phase >= 2, np.sin(np.pi * (phase - 2)), 0.0), np.zeros_like(t)], 1)
    t_test = np.arange(2000) / 100.0 + 20.0
    t_ref = np.arange(6000) / 100.0
    with pytest.raises(AlignmentError, match="repeats itself"):
        align(t_test, motion(t_test) + 0.005 * rng.standard_normal((2000, 3)), t_ref,
              motion(t_ref) + 0.001 * rng.standard_normal((6000, 3)))


@pytest.mark.parametrize("factor, words", [
    (math.pi / 180, r"57\.\d times smaller .* rad/s read as deg/s: give ref_units rad/s"),
    (180 / math.pi, r"57\.\d times larger .* deg/s read as rad/s: give ref_units deg/s"),
    (1 / 9.80665, r"9\.\d\d times smaller .* a factor of g: check ref_units"),
])
@pytest.mark.parametrize("motion", ["smooth", "servo"])
def test_a_reference_in_the_wrong_unit_names_the_unit_not_the_motion(motion, factor, words):
    """Reference: the unit factors themselves. The pair's reference, scaled by 180/pi (deg/s and rad/s
    swapped) or g, is the same motion: its rate magnitudes differ from the test log's by that factor
    only, which the error must name (with ``ref_units``) instead of an ambiguous or repeating motion."""
    pair = make_pair(np.random.default_rng(21), motion=motion, offset=-2.3, drift=40.0, mounting_deg=12.0,
                     noise_test=0.035, noise_ref=0.0005)
    with pytest.raises(AlignmentError, match=words) as err:
        align(pair.test.t, pair.test.gyro, pair.ref.t, pair.ref.gyro * factor)
    assert err.value.param == "ref_units" and abs(math.log(err.value.value * factor)) < 0.02
    a = align(pair.test.t, pair.test.gyro, pair.ref.t, pair.ref.gyro * 1.05)  # a calibration 5 % off is no unit
    assert abs(a.time_offset_s + 2.3) < 4 * a.std[0]


@pytest.mark.parametrize("share", [3, 2])
def test_a_reference_covering_part_of_a_repeating_test_log_says_so(share):
    """Reference: the simulated pair's truth. The servo method's turns repeat, so a reference cut to the first
    1/3 (or 1/2) of a 56.8-s test log fits at the true offset, -2.3 s, and one turn further; both leave the
    same share of the test log uncovered, which the error must say (the share it covers, 33 or 50 %), not
    that the motion repeats."""
    pair = make_pair(np.random.default_rng(21), motion="servo", offset=-2.3, drift=40.0, mounting_deg=12.0,
                     noise_test=0.035, noise_ref=0.0005)
    keep = len(pair.ref.t) // share
    with pytest.raises(AlignmentError, match=rf"reference log covers only {100 // share} % of the test log "
                                             r"\(\d+\.\d s of 56\.8 s\) at each offset that fits \(-2\.[23]\d\d s or "
                                             r".*record the reference over the whole test log") as err:
        align(pair.test.t, pair.test.gyro, pair.ref.t[:keep], pair.ref.gyro[:keep])
    assert "repeats" not in str(err.value)


def test_logs_of_different_motions_are_refused(rng):
    a = make_pair(np.random.default_rng(1), duration=40.0)
    b = make_pair(np.random.default_rng(2), duration=40.0)
    with pytest.raises(AlignmentError, match="same motion"):
        align(a.test.t, a.test.gyro, b.ref.t, b.ref.gyro)


@pytest.mark.parametrize("bad", ["short", "shape", "nan", "order"])
def test_bad_arrays_are_refused(bad, rng):
    t = np.arange(1000) / 100.0
    w = rng.standard_normal((1000, 3))
    args = {"short": (t[:50], w[:50]), "shape": (t, w[:, :2]), "nan": (t, np.where(t[:, None] > 5, np.nan, w)),
            "order": (t[::-1].copy(), w)}[bad]
    with pytest.raises(InputError):
        align(*args, t, w)


def test_alignment_error_is_a_gyrocal_error():
    assert issubclass(AlignmentError, GyrocalError)
