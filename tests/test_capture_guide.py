"""The guided session, step by step, on simulated sessions fed as they would arrive.

Independent references: the simulated motion (which turns were done, and which one was done
wrong), and the true gyro of the simulation, which the final calibration from the accepted
windows must find within 4 sigma of its own covariance.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gyrocal.capture.guide import GUIDES, Guide
from gyrocal.capture.simulated import simulate_device_session
from gyrocal.models import ScaleBias
from gyrocal.pipeline import calibrate
from gyrocal.recording import Recording
from gyrocal.simulation import ServoProtocol

MODEL = ScaleBias(k=np.array([1.02, 0.98, 1.01]), b=np.radians([1.5, -2.0, 0.8]))


def as_recording(s, n=None) -> Recording:
    n = len(s) if n is None else n
    g = s.raw[:n] / s.sensitivity * math.pi / 180
    return Recording(t=(s.t_us[:n] - s.t_us[0]) * 1e-6, gyro=g, source_units="counts", sensitivity=s.sensitivity)


def play(guide: Guide, s, chunk: int = 20, redo_after: str | None = None):
    """Feed the session in chunks as a capture would; optionally ask for a redo right after a step."""
    events = list(guide.start())
    for n in range(chunk, len(s) + 1, chunk):
        new = guide.update(as_recording(s, n))
        events += new
        if redo_after and any(e.kind == "accepted" and e.text.startswith(redo_after) for e in new):
            events += guide.redo(n)
            redo_after = None
    return events


def check_truth(s, guide: Guide):
    run = calibrate(as_recording(s), angle=2 * math.pi, windows=guide.windows())
    sigma = np.sqrt(np.diag(run.calibration.covariance))
    err = run.calibration.model.params - MODEL.params
    assert np.all(np.abs(err) <= 4 * sigma), err / sigma


def test_servo_session_refuses_a_wrong_turn_and_calibrates():
    rng = np.random.default_rng(161)
    wrong = ServoProtocol(turns=("+x",), revolutions=0.75, lead_in=3.0, lead_out=1.0)
    s = simulate_device_session([wrong, ServoProtocol(lead_in=1.0)], model=MODEL, noise_std=0.01, rng=rng)
    guide = Guide("servo")
    events = play(guide, s)
    kinds = [(e.kind, e.text.split(":")[0]) for e in events if e.kind != "prompt"]
    assert kinds[:3] == [("accepted", "still for 2 s"), ("refused", "+x"), ("accepted", "+x")]
    assert "wrong angle" in events[3].text  # the refusal says why, in the segmentation's words
    assert [e.text.split(":")[0] for e in events if e.kind == "accepted"][1:] == ["+x", "-x", "+y", "-y", "+z", "-z"]
    assert events[-1].kind == "complete" and guide.complete
    # every accepted turn is the true turn (the wrong one is not among them)
    truth = [w for w in s.turns][1:]
    for w, t in zip([w for w in guide.windows() if w.kind == "rotation"], truth):
        assert w.start <= t.start and w.stop >= t.stop and w.label == t.label
    check_truth(s, guide)


def test_turn_about_another_axis_is_refused():
    rng = np.random.default_rng(162)
    s = simulate_device_session(ServoProtocol(turns=("-x", "+x"), lead_in=3.0), model=MODEL, noise_std=0.01, rng=rng)
    events = play(Guide("servo"), s)
    refused = [e.text for e in events if e.kind == "refused"]
    assert refused == ["+x: refused: turned -x where +x was asked"]


def test_hand_session_with_a_redo():
    rng = np.random.default_rng(163)
    proto = ServoProtocol.hand(turns=("+x", "+y", "+y", "+z"), lead_in=3.0, wait=4.0, lead_out=4.0)
    s = simulate_device_session(proto, model=MODEL, noise_std=0.01, rng=rng)
    guide = Guide("hand")
    # after the first +y is accepted the person asks to redo it, and does it again
    events = play(guide, s, redo_after="+y")
    accepted = [e.text.split(":")[0] for e in events if e.kind == "accepted"]
    assert accepted == ["still for 2 s", "+x", "still for 2 s", "+y", "+y", "still for 2 s", "+z", "still for 2 s"]
    assert [e.kind for e in events].count("redo") == 1 and guide.complete
    rot = [w for w in guide.windows() if w.kind == "rotation"]
    second_y = s.turns[2]
    assert rot[1].start <= second_y.start and rot[1].stop >= second_y.stop  # the redone +y is the one used
    assert rot[1].start >= s.turns[1].stop
    check_truth(s, guide)


def test_guides_are_the_papers_sessions():
    assert [st.label for st in GUIDES["servo"] if st.kind == "turn"] == ["+x", "-x", "+y", "-y", "+z", "-z"]
    assert [st.label for st in GUIDES["hand"] if st.kind == "turn"] == ["+x", "+y", "+z"]
    with pytest.raises(Exception, match="guide must be one of"):
        Guide("robot")


def test_servo_session_with_a_known_speed():
    """With --speed the turns are judged as constant-speed plateaus (the speed reference of calibrate)."""
    rng = np.random.default_rng(164)
    s = simulate_device_session(ServoProtocol(lead_in=3.0), model=MODEL, noise_std=0.01, rng=rng)
    guide = Guide("servo", speed=math.radians(60.0))
    events = play(guide, s)
    assert guide.complete and not [e for e in events if e.kind == "refused"]
    run = calibrate(as_recording(s), speed=math.radians(60.0), windows=guide.windows())
    sigma = np.sqrt(np.diag(run.calibration.covariance))
    assert np.all(np.abs(run.calibration.model.params - MODEL.params) <= 4 * sigma)
