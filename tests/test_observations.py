"""Window reductions and the reference per-sample simulation of the servo method's protocol."""

import math

import numpy as np
import pytest

from gyrocal.errors import InputError, NonFiniteInputError
from gyrocal.observations import ObservationSet, observe
from gyrocal.simulation.windows import PAPER_AXES, axis_vector, paper_observations


def test_observe_reductions(rng):
    m = rng.normal(0.5, 0.1, (400, 3))
    o = observe(m, 100.0, "angle", angle=-2 * math.pi)
    np.testing.assert_allclose(o.mean, m.mean(0))
    np.testing.assert_allclose(o.mean_sq, (m**2).mean(0))
    np.testing.assert_allclose(o.noise_var, (np.diff(m, axis=0) ** 2).mean(0) / 2)
    window_s = o.duration  # the window's length in time, not a timing
    assert o.count == 400 and window_s == 4.0
    assert o.rate == pytest.approx(2 * math.pi / 4.0)  # the sense does not matter to the norm
    assert observe(m, 100.0, "speed", speed=1.5).rate == 1.5
    assert observe(m, 100.0, "static").rate == 0.0
    assert observe(m, 100.0, "angle").angle == pytest.approx(2 * math.pi)  # one revolution by default


def test_observe_refuses_bad_input():
    m = np.zeros((10, 3))
    m[3, 1] = np.nan
    with pytest.raises(NonFiniteInputError, match=r"samples holds 1 NaN .* index \(3, 1\)"):
        observe(m, 100.0, "static")
    with pytest.raises(InputError, match="needs speed"):
        observe(np.zeros((10, 3)), 100.0, "speed")
    with pytest.raises(InputError, match="kind='turn' is not one of"):
        observe(np.zeros((10, 3)), 100.0, "turn")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="sample_rate must be finite and > 0"):
        observe(np.zeros((10, 3)), 0.0, "static")
    for bad in (math.nan, math.inf):
        with pytest.raises(NonFiniteInputError, match="sample_rate must be finite"):
            observe(np.zeros((10, 3)), bad, "static")
        with pytest.raises(NonFiniteInputError, match="speed must be finite"):
            observe(np.zeros((10, 3)), 100.0, "speed", speed=bad)
    with pytest.raises(InputError, match="angle must be a non-zero number"):
        observe(np.zeros((10, 3)), 100.0, "angle", angle="full")


def test_set_stacks_and_takes(rng):
    obs = [observe(rng.normal(size=(50, 3)), 50.0, "speed", speed=1.0) for _ in range(6)]
    s = ObservationSet.from_observations(obs)
    assert len(s) == 6 and not s.batched and s.batch_size == 1
    b = s.as_batch()
    assert b.mean.shape == (1, 6, 3)
    two = b.take([0, 0])
    assert two.batch_size == 2
    np.testing.assert_array_equal(two.mean[1], s.mean)
    with pytest.raises(InputError, match="no observations"):
        ObservationSet.from_observations([])


def test_axis_vector():
    np.testing.assert_array_equal(axis_vector("-y"), [0, -1, 0])
    np.testing.assert_array_equal(axis_vector("z"), [0, 0, 1])
    with pytest.raises(InputError, match="'w' is not one of"):
        axis_vector("w")


def test_paper_observations_noise_free_means_are_exact(rng):
    """Jitter is re-centred, so without noise the window mean is exactly the model's reading of speed."""
    k, b = np.array([[0.9, 1.1, 1.05]]), np.array([[0.05, -0.02, 0.08]])
    speed = math.pi / 3
    obs = paper_observations(k, b, speed=speed, noise_std=0.0, jitter=0.05, misalignment=0.0, rng=rng)
    want = np.array([speed * axis_vector(a) for a in PAPER_AXES]) / k - b
    np.testing.assert_allclose(obs.mean[0], want, rtol=0, atol=1e-12)
    assert np.all(obs.count == round(2 * math.pi / speed * 200))
    np.testing.assert_allclose(obs.rate, speed)
    # The jitter shows in the mean of squares of the rotating axis only.
    assert np.all(obs.mean_sq[0, 0, 0] > obs.mean[0, 0, 0] ** 2)


def test_paper_observations_misalignment_is_a_tilt(rng):
    k, b = np.ones((400, 3)), np.zeros((400, 3))
    obs = paper_observations(k, b, speed=1.0, noise_std=0.0, jitter=0.0, misalignment=0.1,
                             axes=("+z",), rng=rng)
    tilt = np.arccos(obs.mean[:, 0, 2])  # |mean| = 1 with k = 1, b = 0
    assert tilt.max() <= 0.1 + 1e-12
    # U(0, 0.1): mean 0.05 with sd 0.1/sqrt(12)/sqrt(400); allow 4 sigma
    assert abs(tilt.mean() - 0.05) < 4 * 0.1 / math.sqrt(12) / 20


def test_paper_observations_noise_and_statics(rng):
    k, b = np.ones((300, 3)), np.full((300, 3), 0.1)
    obs = paper_observations(k, b, speed=1.0, noise_std=0.03, jitter=0.0, static_duration=2.0, rng=rng)
    assert len(obs) == 12
    np.testing.assert_array_equal(obs.static, [False, True] * 6)
    np.testing.assert_array_equal(obs.count[1::2], 400)
    # First differences: d^2/2 has variance 2 sigma^4 and neighbours covary by sigma^4/2,
    # so the pooled estimate has relative sd sqrt(3 / N) over N differences.
    nv = obs.noise_var[:, 1::2].mean(axis=(0, 1)) / 0.03**2
    assert np.all(np.abs(nv - 1) < 4 * math.sqrt(3 / (399 * 300 * 6)))
    np.testing.assert_allclose(obs.mean[:, 1::2].mean(axis=(0, 1)), -0.1, atol=4 * 0.03 / math.sqrt(400 * 1800))


def test_paper_observations_refuses_bad_input(rng):
    with pytest.raises(InputError, match="k must be > 0"):
        paper_observations([[1, 0, 1]], [[0, 0, 0]], speed=1.0, rng=rng)
    with pytest.raises(InputError, match="speed must be finite and > 0"):
        paper_observations([[1, 1, 1]], [[0, 0, 0]], speed=0.0, rng=rng)
    with pytest.raises(NonFiniteInputError):
        paper_observations([[1, np.nan, 1]], [[0, 0, 0]], speed=1.0, rng=rng)


def test_sample_times_weight_a_window_with_gaps(rng):
    m = rng.normal(0.5, 0.1, (400, 3))
    t = np.arange(400) / 100.0
    even = observe(m, 100.0, "angle", angle=2 * math.pi)
    timed = observe(m, 100.0, "angle", angle=2 * math.pi, t=t)
    np.testing.assert_allclose(timed.mean, even.mean, rtol=1e-12)
    window_s = timed.duration
    assert window_s == pytest.approx(4.0)
    # drop every other sample of the second half, which turns faster: those left stand for twice the time
    m[200:] += 1.0
    keep = np.r_[np.arange(200), np.arange(200, 400, 2)]
    gappy = observe(m[keep], 100.0, "angle", angle=2 * math.pi, t=t[keep])
    window_s = gappy.duration
    assert window_s == pytest.approx(3.98 + (0.01 + 0.02) / 2)  # span plus half a step at each end
    # each half of the time counts alike, however many samples it kept
    np.testing.assert_allclose(gappy.mean, (m[:200].mean(0) + m[200:400:2].mean(0)) / 2, atol=2e-3)
    assert np.all(gappy.mean - m[keep].mean(0) > 0.15)  # a plain sample mean would read 1/6 too low
    with pytest.raises(InputError, match="t has 3 sample times"):
        observe(m, 100.0, "angle", t=t[:3])
