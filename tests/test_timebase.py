"""The time base read from the stamps, checked against the simulator's own sensor clock and gap list."""

import re

import numpy as np
import pytest

from gyrocal.errors import InputError
from gyrocal.recording import Recording
from gyrocal.recording.timebase import analyse_time, nominal_period
from gyrocal.simulation.timestamps import ReceiveClock, drop_samples, receive_times, with_time_defects

FS = 100.0
BURSTY = ReceiveClock(packet=2, read_time=0.0035, jitter=0.003)  # steps ~2-5 ms and ~15-18 ms


def test_receive_stamps_come_in_bursts_around_the_sensor_clock(rng):
    """The simulator's stamps look like the logs of issue reports: short and long steps, mean 10 ms."""
    t = receive_times(20_000, FS, BURSTY, rng)
    step = np.diff(t)
    assert np.mean(step < 0.006) == pytest.approx(0.5, abs=0.01)  # every other step is a short read
    # a read takes 3.5 +- 1.5 ms; a packet arrives 20 ms after the one before, +- the 3 ms of latency jitter
    assert 0.002 <= step[step < 0.006].min() and step[step >= 0.006].max() <= 2 / FS + 0.003 - 0.002
    # Over the log the steps add up to the sensor clock's time, up to the first and last samples' delays
    # (a packet waits one period for its second sample, plus latency jitter and read time).
    assert abs(t[-1] - (len(t) - 1) / FS) < 1 / FS + 2 * BURSTY.jitter + BURSTY.read_time


def test_nominal_rate_is_the_sensor_clock_not_the_median_step(rng):
    t = receive_times(20_000, FS, BURSTY, rng)
    assert np.median(np.diff(t)) < 0.006  # the median step reads about 200 Hz
    # The sensor clock's period is 10 ms; the stamps' delays are bounded by jitter + read time (~6.5 ms),
    # so a block mean of 64 steps is within 6.5 / 64 ms of it, and so is the median of those.
    assert abs(nominal_period(t) - 0.01) < 0.0065 / 64
    assert Recording(t=t, gyro=np.zeros((len(t), 3))).sample_rate == pytest.approx(FS, rel=0.0065 / 0.64)


def test_late_deliveries_lose_nothing_and_gaps_are_counted(rng):
    """Against the simulator's truth: which samples were never delivered, and how many."""
    n = 30_000
    rec = Recording.from_rate(rng.normal(size=(n, 3)), FS)
    clock = ReceiveClock(late_per_minute=20, late_delay=0.12)
    out, truth = with_time_defects(rec, rng, clock=clock, gaps=5, gap_length=0.169)
    tb = analyse_time(out.t)
    assert tb.delayed >= 1  # late packets: long steps (> 30 ms) caught up by a burst
    assert len(tb.gaps) == 5
    # truth: [first missing original sample, count]; a gap's index counts the samples kept before it
    expected = [(start - sum(c for s, c in truth["gaps"] if s < start), count) for start, count in truth["gaps"]]
    assert [(g.index, g.lost) for g in tb.gaps] == expected
    assert tb.lost == 5 * 17 and tb.bursty and tb.regular_clock


def test_the_sensor_clock_is_rebuilt_under_receive_stamps(rng):
    """Rebuilt times sit on the sensor's regular clock: within the delays' spread of the stamps, and
    exactly regular across the gaps (the truth: sample k of the sensor was taken at k / fs)."""
    n = 20_000
    rec = Recording.from_rate(rng.normal(size=(n, 3)), FS)
    out, truth = with_time_defects(rec, rng, clock=BURSTY, gaps=3, gap_length=0.2)
    tb = analyse_time(out.t)
    clock = tb.clock_times()
    kept = np.flatnonzero(drop_samples(n, 0, 0, rng))  # all samples
    for start, count in truth["gaps"]:
        kept = kept[(kept < start) | (kept >= start + count)]
    # the sensor took original sample k at k / fs: the rebuilt clock has the same steps
    np.testing.assert_allclose(np.diff(clock), np.diff(kept) / FS, rtol=1e-3)
    assert tb.clock_period == pytest.approx(1 / FS, rel=1e-5)


def test_regular_stamps_are_their_own_clock_and_a_wandering_clock_is_not_rebuilt(rng):
    t = np.arange(5000) / FS
    tb = analyse_time(t)
    assert tb.regular_clock and not tb.gaps and tb.jitter < 1e-9
    np.testing.assert_allclose(tb.clock_times(), t, atol=1e-12)
    # a sampler whose own period wanders (stamps true, clock irregular) is integrated on its stamps
    wander = np.cumsum(rng.uniform(0.005, 0.015, 5000))
    assert not analyse_time(wander).regular_clock and analyse_time(wander).clock_times() is None


def test_time_base_describes_itself(rng):
    out, _ = with_time_defects(Recording.from_rate(np.zeros((20_000, 3)), FS), rng, clock=BURSTY, gaps=1,
                               gap_length=0.169)
    text = "\n".join(analyse_time(out.t).describe())
    assert re.search(r"time base: 100(\.\d+)? Hz nominal", text) and "median" in text and "bursty" in text and "1 gap(s), 17 sample(s)" in text
    assert analyse_time(np.arange(10) / 20.0, has_time=False).describe()[0].startswith("time base: no time column")


def test_bad_time_bases_are_refused():
    with pytest.raises(InputError, match="at least two"):
        analyse_time([0.0])
    with pytest.raises(InputError, match="does not fit"):
        receive_times(10, 1000.0, ReceiveClock(packet=2, read_time=0.004, jitter=0.003), np.random.default_rng(0))


def test_packets_of_four_are_a_rhythm_not_late_deliveries(rng):
    """Four samples per USB packet at 100 Hz: every fourth step is 40 ms, the packets' own rhythm; only a
    packet held up beyond it is late. Reference: the stamps of the independent generator (tests/realistic.py),
    which holds up exactly the deliveries it was told to."""
    import realistic

    t = np.arange(6000) / FS
    calm = realistic.receive_packets(t, 4, rng, late_per_minute=0.0)
    assert analyse_time(calm).delayed == 0  # the former rule (any step over 3 periods) counted 1,500
    held = realistic.receive_packets(t, 4, np.random.default_rng(3), late_per_minute=6.0)
    tb = analyse_time(held)
    assert 1 <= tb.delayed <= 6 and not tb.gaps and tb.regular_clock


@pytest.mark.parametrize("rate", [100.0, 104.0, 208.0, 833.0, 400.0])
def test_a_sample_counter_is_recognised_with_rounding_and_lost_packets(rate):
    """Stamps made as ``i / rate`` (a counter times the nominal rate) written with six decimals: counted, also
    after a lost packet; a crystal 20 ppm off a round rate, and a PC's receive times, are clocks. Reference: how
    each column was made."""
    i = np.arange(20_000)
    counter = np.round(i / rate, 6)
    assert analyse_time(counter).counted
    assert analyse_time(np.delete(counter, np.s_[5000:5005])).counted  # five samples lost
    assert not analyse_time(np.round(i / (rate * (1 + 20e-6)), 6)).counted
    jitter = np.random.default_rng(int(rate)).uniform(0, 0.3 / rate, len(i))
    assert not analyse_time(i / rate + jitter).counted
