"""Motion found in logs that should be still, and drift that is not motion.

References: the simulated truth (where the turn, tilt or knock was put) and the property that a
running median follows any monotone drift exactly.
"""

import numpy as np

from gyrocal.segmentation.stillness import find_motion


def test_warm_up_drift_is_not_motion(rng):
    fs, n = 100.0, 180_000  # 30 min
    t = np.arange(n) / fs
    drift = 0.02 * (1 - np.exp(-t / 300.0))  # 1.1 deg/s of warm-up drift, 200 block-noise units
    g = rng.standard_normal((n, 3)) * 0.005 + drift[:, None]
    assert find_motion(g, fs).still


def test_turn_knock_and_tilt_are_found(rng):
    fs, n = 100.0, 60_000
    g = rng.standard_normal((n, 3)) * 0.005
    a = np.array([0.0, 0.0, 9.81]) + rng.standard_normal((n, 3)) * 0.02
    g[10_000:10_600, 0] += 0.3  # a 6 s turn
    g[30_000:30_020] += rng.standard_normal((20, 3)) * 0.5  # a 0.2 s knock
    a[45_000:, :] = [0.0, 1.7, 9.66]  # tilted by 10 degrees and left there
    found = find_motion([g, a], fs)
    assert len(found.spans) == 3
    for (start, stop), at in zip(found.spans, (10_000, 30_000, 45_000)):
        assert start <= at < stop and stop - start <= 1200
    start, stop = found.longest_still()
    assert (start, stop) == (int(found.spans[0, 1]), int(found.spans[1, 0]))
    assert "3 motions, at 9" in found.describe(fs)
