"""Peak accelerations of profiles that hold no level, and shivers at low sample rates.

A phase's peak is the largest acceleration of the hand in it, wherever it lies: a joint at
its acceleration limit peaks at the start of a phase and falls off after it, a declared
acceleration holds a level. The truths here are computed from the samples, independently
of `aouc measure`: the hand's acceleration ``J qdd + Jdot qd`` (Pinocchio, from the joint
velocities and accelerations the compiler wrote) and second differences of the hand's
position (forward kinematics of the written samples), or the law a synthetic trajectory
was built from.

A shiver is told from tilts by its speed profile; sampled six times per cycle or more it
is one shiver, however few samples each swing has.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from aou_dsl.core.trajectory import Trajectory
from aou_dsl.driver.builder import build_source
from aou_dsl.measuring.measured import measure
from aou_dsl.robot.batch_fk import batch_fk, classical_acceleration
from aou_dsl.robot.load import load_arm
from tests.conftest import BEHAVIOURS
from tests.synth import Synth

DEG = math.pi / 180
KEYS = {"approach": "approach_acceleration", "retreat": "retreat_acceleration"}

#: Behaviours whose peak is not a level: the panda's and the ur5's approach at a
#: joint's acceleration limit (3.37 and 1.5 m/s^2 where 5 is declared), a retreat at
#: one, an approach capped at 0.3 m/s (a trapezoid with a cruise); and a declared level.
JOINT_LIMITED = ("behaviour fast : confident\nsequence {\npause 0.5s\napproach a=5 v=1\n"
                 "pause 1s\n}\n")
CASES = {
    "panda-approach": (JOINT_LIMITED, None),
    "ur5-approach": (JOINT_LIMITED, "ur5"),
    "capped-approach": (JOINT_LIMITED.replace("v=1", "v=0.3"), None),
    "panda-retreat": ("behaviour r : fearful\napproach a=0.3\npause 1s x2\nretreat 0.1m a=6\n",
                      None),
    "ur5-retreat": ("behaviour r : fearful\napproach a=0.3\npause 1s x2\nretreat 0.1m a=6\n",
                    "ur5"),
    "level": ("behaviour p : confident\nsequence {\npause 0.5s\napproach a=1.2\npause 1s\n}\n",
              None),
}


def _compiled(name: str, rate: float | None = None):
    text, robot = CASES[name]
    options = {"rate": rate} if rate else {}
    res = build_source(text, f"{name}.aou", check=False, robot=robot, **options)
    assert res.ok and res.measured is not None, [d.message for d in res.diagnostics]
    return res


def _truths(res) -> dict[str, tuple[float, float]]:
    """Per kind of episode, the hand's largest acceleration magnitude [m/s^2] over the
    compiled samples: from Pinocchio's ``J qdd + Jdot qd``, and from second differences
    of the samples' forward kinematics."""
    tr = res.trajectory
    arm = load_arm(tr.robot, tr.ee_frame)
    t, q = np.asarray(tr.t), np.asarray(tr.q)
    exact = np.linalg.norm(classical_acceleration(arm, q, np.asarray(tr.qd),
                                                  np.asarray(tr.qdd)), axis=1)
    p, _ = batch_fk(arm, q)
    h = float(t[1] - t[0])
    second = np.zeros(len(t))
    second[1:-1] = np.linalg.norm(p[2:] - 2 * p[1:-1] + p[:-2], axis=1) / h ** 2
    out: dict[str, tuple[float, float]] = {}
    for kind, t0, t1 in tr.episodes:
        if kind in KEYS:
            k = (t >= t0 - 1e-9) & (t <= t1 + 1e-9)
            old = out.get(kind, (0.0, 0.0))
            out[kind] = (max(old[0], float(exact[k].max())), max(old[1], float(second[k].max())))
    return out


@pytest.mark.parametrize("name", list(CASES))
def test_a_compiled_peak_reads_where_it_is(name):
    """Whatever the profile, the compiled trajectory reads the hand's largest
    acceleration: within 1 % of Pinocchio's and of the samples' second differences."""
    res = _compiled(name)
    truths = _truths(res)
    assert truths
    for kind, (exact, second) in truths.items():
        got = res.measured.descriptors[KEYS[kind]]
        assert got == pytest.approx(exact, rel=0.01), (kind, got, exact)
        assert got == pytest.approx(second, rel=0.01), (kind, got, second)


@pytest.mark.parametrize("name,rate", [("panda-approach", 50.0), ("panda-retreat", 50.0),
                                       pytest.param("ur5-approach", 100.0,
                                                    marks=pytest.mark.slow),
                                       pytest.param("capped-approach", 100.0,
                                                    marks=pytest.mark.slow)])
def test_a_low_rate_reads_the_peak_its_samples_show(name, rate):
    """At 50 Hz a peak that lasts a few samples is what the samples' second differences
    show (within 1 %); it is within 3 % of the continuous truth."""
    res = _compiled(name, rate)
    for kind, (exact, second) in _truths(res).items():
        got = res.measured.descriptors[KEYS[kind]]
        assert got == pytest.approx(second, rel=0.01), (kind, got, second)
        assert got == pytest.approx(exact, rel=0.03), (kind, got, exact)


def test_the_compile_check_agrees_with_what_the_joints_reach():
    """A declared acceleration the joints cannot reach: the compiler says what they do
    reach (C304), and its measurement of the compiled trajectory reads just that (said
    once: no C310 repeats what C304 explained)."""
    res = _compiled("panda-approach")
    reached = next(d for d in res.diagnostics if d.code == "C304").fields["achieved"]
    measured = res.measured.descriptors["approach_acceleration"]
    assert measured == pytest.approx(reached, rel=0.01)
    assert not [d for d in res.diagnostics if d.code == "C310"
                and d.fields["descriptor"] == "approach_acceleration"]


def test_the_same_samples_read_the_same_without_their_velocities(tmp_path):
    """aou's CSV carries positions only: its peak is read from them as the JSON's is."""
    res = _compiled("panda-approach")
    tr = res.trajectory
    bare = Trajectory(tr.t, tr.q, tr.joint_names, tr.robot, tr.ee_frame, tr.goal)
    got = measure(bare).descriptors["approach_acceleration"]
    assert got == pytest.approx(res.measured.descriptors["approach_acceleration"], rel=1e-3)


# --- synthetic laws: the peak at a phase's start, at its end, in its middle ------------------


class _Falling(Synth):
    """Rest to rest along the line of sight: the acceleration jumps to its peak ``a`` and
    falls linearly by ``fall`` of it by the top speed; the slowing down mirrors it in
    time (its deceleration grows to ``a`` at the stop). With ``late``, the other way
    round: the acceleration grows to ``a`` at the top speed and the deceleration starts
    at ``a``."""

    late = False
    fall = 2.0 / 3.0

    @classmethod
    def _bang(cls, length: float, a: float, rate: float) -> np.ndarray:
        length, k = abs(length), cls.fall
        # Each phase covers half the length: a T^2 (1/2 - k/6) peak first, a T^2 (1/2 - k/3)
        # peak last.
        half = math.sqrt(length / (2.0 * a * (0.5 - k / (3.0 if cls.late else 6.0))))

        def rise(tau: np.ndarray) -> np.ndarray:  # distance after tau, peak first
            return a * (tau * tau / 2.0 - k * tau ** 3 / (6.0 * half))

        def rise_late(tau: np.ndarray) -> np.ndarray:  # the same law backwards in time
            return a * half * (1.0 - k / 2.0) * tau - (rise(half) - rise(half - tau))

        first = rise_late if cls.late else rise
        t = np.minimum(np.arange(1, int(math.ceil(2 * half * rate)) + 1) / rate, 2 * half)
        return np.where(t <= half, first(np.minimum(t, half)),
                        length - first(np.maximum(2 * half - t, 0.0)))


class _Rising(_Falling):
    late = True


@pytest.mark.parametrize("law", [_Falling, _Rising], ids=["peak-first", "peak-last"])
def test_a_peak_at_a_phase_end_reads_its_peak(law):
    """A phase whose acceleration falls from its peak by two thirds (or grows to it by
    as much) reads its peak, not its mean (a third lower): within 1 % at 1 kHz (one
    sample's step takes 0.3 % off such a peak)."""
    s = law(rate=1000.0)
    s.hold(0.5).line(-0.10, 0.6).hold(1.0).line(+0.06, 1.5).hold(1.0)
    m = measure(s.recording())
    peaks = [e.values["peak_acceleration"] for e in m.episodes if e.kind != "pause"]
    assert peaks == pytest.approx([0.6, 1.5], rel=0.01)


class _FallingSlowly(_Falling):
    fall = 1.0 / 3.0


class _RisingSlowly(_Rising):
    fall = 1.0 / 3.0


@pytest.mark.parametrize("law", [_FallingSlowly, _RisingSlowly], ids=["peak-first", "peak-last"])
@pytest.mark.parametrize("noise,rate", [(5e-5, 250.0), (1e-4, 1000.0)],
                         ids=["250Hz", "1kHz"])
def test_a_peak_at_a_phase_end_reads_its_peak_through_noise(law, noise, rate):
    """A recording with noise: a peak that falls by a third over its phase (about 0.5 s)
    reads within 5 % of it, not as the phase's mean (17 % lower). A recording's
    acceleration is never read over less than an arm's transients (60 ms), and the
    noise sets how much longer: a peak at a phase's end reads a little low."""
    s = law(rate=rate)
    s.hold(0.5).line(-0.15, 0.6).hold(1.0).line(+0.20, 1.0).hold(1.0)
    m = measure(s.recording(noise, seed=4))
    peaks = [e.values["peak_acceleration"] for e in m.episodes if e.kind != "pause"]
    assert peaks == pytest.approx([0.6, 1.0], rel=0.05)


def test_the_laws_peak_where_they_say():
    """The synthetic laws themselves: they cover their length, and their second
    differences peak at the declared acceleration at the start (peak first) or at the
    top speed (peak last), two thirds of it half way through the phase."""
    for law, where in ((_Falling, 0), (_Rising, 1)):
        x = np.concatenate([[0.0], law._bang(0.1, 0.6, 1000.0)])
        assert x[-1] == pytest.approx(0.1, rel=1e-9)
        acc = np.diff(x, 2) * 1000.0 ** 2
        half = len(acc) // 2
        assert acc.max() == pytest.approx(0.6, rel=0.01)
        assert abs(int(np.argmax(acc)) - where * half) < 0.05 * half
        assert acc[half // 2] == pytest.approx(0.4, rel=0.03)


# --- shivers sampled a few times per cycle ---------------------------------------------------


def _kinds(m) -> list[str]:
    return [e.kind for e in m.episodes]


@pytest.mark.parametrize("rate", [25.0, 50.0, 100.0, 250.0])
@pytest.mark.parametrize("f,amplitude", [(2.0, 6.0), (3.0, 4.0), (4.0, 2.0)])
def test_a_shiver_is_one_shiver_at_any_rate_of_six_samples_per_cycle(rate, f, amplitude):
    """Sampled from 6 times per cycle (4 Hz at 25 Hz) to 125, a shiver reads as one
    shiver of its amplitude (within 0.5 deg), never as a shiver and tilts."""
    s = Synth(rate=rate)
    s.line(-0.05, 0.2).hold(1.0).shiver(amplitude * DEG, f, 4).hold(1.0)
    m = measure(s.recording())
    assert _kinds(m).count("shiver") == 1 and "tilt" not in _kinds(m), _kinds(m)
    assert m.descriptors["tilt_angle"] is None
    assert abs(m.descriptors["shiver_amplitude"] - amplitude) <= 0.5


def test_the_newcomers_shiver_at_25_hz_is_one_shiver():
    """The fearful stimulus with a 3 Hz shiver, compiled at 25 Hz (as for a YAML export):
    one shiver, no tilt (the compile's own check agrees)."""
    text = (BEHAVIOURS / "fearful.aou").read_text().replace(
        "shiver 6deg for 1.25s", "shiver 4deg f=3Hz for 1.25s")
    res = build_source(text, "scared.aou", check=False, rate=25.0)
    assert res.ok
    assert not [d.message for d in res.diagnostics if d.code == "C310"]
    assert _kinds(res.measured).count("shiver") == 1
    assert res.measured.descriptors["tilt_angle"] is None


@pytest.mark.parametrize("rate", [20.0, 25.0])
def test_quick_tilts_back_and_forth_stay_tilts_at_a_low_rate(rate):
    """Three tilts back and forth of 0.18 s each, 4 samples per swing: their speed
    rises and falls linearly, not as a sine; they stay three tilts."""
    s = Synth(rate=rate)
    s.line(-0.05, 0.2).hold(1.0)
    for sign in (1, -1, 1):
        s.tilt(sign * 10 * DEG, 4 * 10 * DEG / 0.18 ** 2)
    s.hold(1.0)
    m = measure(s.recording())
    assert _kinds(m).count("tilt") == 3 and "shiver" not in _kinds(m), _kinds(m)
    assert m.descriptors["tilt_angle"] == pytest.approx(10.0, abs=0.5)


def test_an_oscillation_too_coarse_to_tell_is_neither_and_says_so():
    """A 5 Hz shiver sampled at 20 Hz (4 samples per cycle, 2 per swing) cannot be told
    from quick tilts: it is reported as neither, and R407 says why."""
    s = Synth(rate=20.0)
    s.line(-0.05, 0.2).hold(1.0).shiver(2 * DEG, 5.0, 6).hold(1.0)
    m = measure(s.recording())
    assert "tilt" not in _kinds(m) and "shiver" not in _kinds(m), _kinds(m)
    notes = [d for d in m.diagnostics if d.code == "R407"]
    assert len(notes) == 1
    assert notes[0].fields["samples_per_cycle"] < 6
    assert notes[0].fields["frequency"] == pytest.approx(5.0, rel=0.2)


# --- a joint-limited peak in recordings of the simulated arm ---------------------------------


@pytest.mark.slow
def test_a_joint_limited_peak_reads_through_every_logger(tmp_path):
    """The panda's joint-limited approach (3.37 m/s^2 at its start, 2.4 by 0.1 s later),
    replayed on the simulated arm and logged as real loggers do: every logger reads the
    peak within 5 % of the compiled one, but the 100 Hz teleoperation recorder (1.5e-4
    rad of noise), whose noise lets no reading be shorter than about 0.1 s and which
    reads within 12 % (its phase's mean is a third lower)."""
    from tests.integration.test_recordings import _signal, read_back
    from tests.recsim import PRESETS, record

    res = _compiled("panda-approach")
    exact = _truths(res)["approach"][0]
    doc = res.document
    signal = _signal(doc)
    for name, log in PRESETS.items():
        log = log.with_(noise=min(float(np.max(log.noise)), 1.5e-4), start=0.0)
        got = read_back(record(doc, log, signal=signal), tmp_path, name)
        rel = 0.12 if name == "teleop_guided" else 0.05
        assert got.descriptors["approach_acceleration"] == pytest.approx(exact, rel=rel), name
