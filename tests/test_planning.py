"""Protocol planning: predictions, and the suggested protocol reaches its target.

References: the design's Cramer-Rao bound, the 1/sqrt(revolutions) law, and a brute-force search over
the same grid.
"""

import math

import numpy as np
import pytest

from gyrocal.errors import InputError
from gyrocal.planning import build_design, predict, suggest
from gyrocal.planning.design import Design, predicted_std

DENSITY = 0.035 / math.sqrt(200.0)


def test_predict_is_the_design_crb():
    p = predict("six", speed=math.pi / 3, noise_density=DENSITY)
    expect = predicted_std(Design.paper_six(math.pi / 3), None, 0.035, 200.0)
    np.testing.assert_allclose(p.std, expect, rtol=1e-12)
    assert p.total_time == pytest.approx(6 * 6.0 + 5 * 3.0)


def test_more_revolutions_shrink_std_as_one_over_sqrt():
    one = predict("six", speed=1.0, noise_density=DENSITY)
    four = predict("six", speed=1.0, revolutions=4, noise_density=DENSITY)
    # window sample counts are rounded to whole samples: 1 in ~1257 per window
    np.testing.assert_allclose(four.std, one.std / 2, rtol=1e-3)


def test_designs_have_their_windows():
    assert len(build_design("six-static", 1.0).windows) == 12
    assert len(build_design("twelve", 1.0).rotations) == 12
    with pytest.raises(InputError, match="design"):
        build_design("eight", 1.0)


def test_suggestion_reaches_target_in_least_time_on_its_grid():
    target_k, target_b = 3e-4, math.radians(0.02)
    speeds = np.linspace(0.2, 3.0, 8)
    best = suggest(target_scale=target_k, target_bias=target_b, max_speed=3.0, noise_density=DENSITY,
                   speeds=speeds, revolutions=range(1, 11))
    assert best.max_scale_std <= target_k and best.max_bias_std <= target_b
    # brute force over the same grid
    times = [p.total_time for rev in range(1, 11) for s in speeds
             for p in [predict("six", speed=s, revolutions=rev, noise_density=DENSITY)]
             if p.max_scale_std <= target_k and p.max_bias_std <= target_b]
    assert best.total_time == pytest.approx(min(times))


def test_unreachable_target_gives_none_and_bad_input_is_refused():
    assert suggest(target_scale=1e-9, max_speed=1.0, noise_density=DENSITY, revolutions=(1, 2)) is None
    with pytest.raises(InputError, match="target"):
        suggest(max_speed=1.0, noise_density=DENSITY)
    with pytest.raises(InputError, match="noise_density"):
        predict("six", speed=1.0, noise_density=-1.0)
