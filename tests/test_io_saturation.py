"""Saturation: runs stuck at full scale, and what is not saturation.

References: a virtual gyro clipped at a known full scale (the clipped samples are known exactly) and
noisy signals that are not clipped.
"""

from __future__ import annotations

import numpy as np
import pytest

from gyrocal.errors import InputError
from gyrocal.io import find_saturation
from gyrocal.models import ScaleBias
from gyrocal.simulation import VirtualGyro


def test_clipped_virtual_gyro_is_found_exactly(rng):
    n = 2000
    w = np.zeros((n, 3))
    w[300:900, 1] = np.radians(np.linspace(0, 2500, 600))  # a turn that overshoots +-2000 deg/s
    w[1200:1500, 2] = -np.radians(2200)
    fs = np.radians(2000)
    gyro = VirtualGyro(ScaleBias(k=np.ones(3), b=np.zeros(3)), noise_std=np.radians(0.05), full_scale=fs, quantum=np.radians(1 / 16.4))
    m = gyro.measure(w, sample_rate=1000.0, rng=rng)
    expected = np.abs(m) >= fs
    assert expected[:, 1].sum() > 50 and expected[:, 2].sum() == 300
    np.testing.assert_array_equal(find_saturation(m), expected)
    np.testing.assert_array_equal(find_saturation(m, full_scale=fs), expected)


def test_noisy_constant_rate_quantised_is_not_saturation(rng):
    # 60 deg/s turns with MPU noise (about 1.6 LSB) never sit 5 samples at the extreme
    n = 5000
    w = np.zeros((n, 3))
    w[1000:2000, 0] = 60.0
    w[3000:4000, 0] = -60.0
    m = np.round((w + rng.normal(0, 0.1, (n, 3))) * 16.4)
    assert not find_saturation(m).any()


def test_quiet_constant_axis_is_not_saturation():
    m = np.zeros((100, 3))
    m[:, 0] = 3.0  # a raw axis reading the same count everywhere
    assert not find_saturation(m).any()


def test_short_runs_are_kept_and_bad_arguments(rng):
    m = rng.normal(0, 1, (50, 3))
    m[10:14, 0] = 9.0  # four samples: shorter than the default run
    assert not find_saturation(m).any()
    assert find_saturation(m, min_run=4)[:, 0].sum() == 4
    with pytest.raises(InputError, match=r"shape \(N, 3\)"):
        find_saturation(np.zeros((5, 2)))
    with pytest.raises(InputError, match="full_scale must be finite and > 0"):
        find_saturation(m, full_scale=0)


@pytest.mark.parametrize("sign", [1, -1])
def test_run_at_one_extreme_is_found_when_the_other_sign_reaches_further(rng, sign):
    # int16 counts clipped at +32767 for 40 samples, one reading at -32768 elsewhere (and the mirror)
    m = np.round(rng.normal(0, 300, (1000, 3)))
    m[400:440, 1] = 32767 * sign
    m[700, 1] = -32768 * sign
    m[:, 0] = 3.0  # a quiet constant axis with one spike: its run fails the median rule
    m[50, 0] = -100.0
    sat = find_saturation(m)
    np.testing.assert_array_equal(np.flatnonzero(sat[:, 1]), np.arange(400, 440))
    assert not sat[:, 0].any() and not sat[:, 2].any()
