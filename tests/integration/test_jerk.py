"""Jerk-limited motion: what a controller reading the trajectory at 1 kHz sees stays within
the robot's joint jerk limits, and the time law still shows the declared accelerations.

The jerk is computed here from its definition, the third derivative of the joint
positions, as a motion generator computes it: third differences of the positions it is
sent at its rate, the arm resting before the first and after the last."""

import functools
import math

import numpy as np
import pytest

from aou_dsl.compiler.pipeline import evaluate, sample
from aou_dsl.compiler.timelaw import SmoothLaw, TimeLaw
from aou_dsl.core.trajectory import Trajectory
from aou_dsl.driver.builder import build_source
from aou_dsl.lang.descriptors import REGISTRY
from aou_dsl.robot.load import load_arm
from aou_dsl.safety.controllers import controller_checks
from tests.conftest import BEHAVIOURS

RATE = 1000.0
ACCELERATIONS = ("approach_acceleration", "retreat_acceleration")


def _jerk_at(q: np.ndarray, rate: float) -> np.ndarray:
    """|third difference| * rate^3 of positions (N, n) held at rest before and after."""
    padded = np.vstack([q[:1]] * 3 + [q] + [q[-1:]] * 3)
    return np.abs(np.diff(padded, 3, axis=0)) * rate**3


@functools.cache
def _build(text: str):
    return build_source(text, "jerk.aou", check=False)


def _worst_jerk(res) -> tuple[float, str]:
    """The largest joint jerk over its limit, and that joint, of the compiled motion read
    every millisecond (after its end the arm holds the last configuration)."""
    tr = res.compiled.trajectory
    arm = load_arm(tr.robot)
    t = np.arange(int(math.ceil(tr.t[-1] * RATE)) + 1) / RATE
    q = evaluate(res.compiled, t)[0]
    ratio = _jerk_at(q, RATE) / arm.jmax
    j = int(np.argmax(ratio.max(axis=0)))
    return float(ratio.max()), arm.joint_names[j]


def _accelerations_as_declared(res) -> None:
    """Every approach and retreat reaches its declared peak acceleration within 3 %,
    unless the compiler said which limit prevented it (C304 on that statement): the
    hand's acceleration from forward kinematics of the motion read every millisecond."""
    tr, tl = res.compiled.trajectory, res.compiled.timeline
    arm = load_arm(tr.robot)
    blamed = {(d.span.line, d.span.col) for d in res.diagnostics if d.code == "C304"}
    for (kind, t0, t1), ep in zip(tr.episodes, tl.episodes, strict=True):
        if kind not in ("approach", "retreat") or (ep.span.line, ep.span.col) in blamed:
            continue
        t = np.arange(t0, t1, 1.0 / RATE)
        pos, _ = arm.fk(evaluate(res.compiled, t)[0])
        peak = np.linalg.norm(np.diff(pos, 2, axis=0), axis=1).max() * RATE**2
        assert peak == pytest.approx(ep.a, rel=0.03), (kind, t0, ep.a, peak)


def _measured_as_declared(res) -> None:
    """The document's measured accelerations (aouc measure's code) equal the declared."""
    doc = res.document
    for key in ACCELERATIONS:
        want, got = doc["descriptors"]["declared"][key], doc["descriptors"]["measured"][key]
        if want is not None:
            assert got == pytest.approx(want, rel=REGISTRY[key].rel_tol), (key, want, got)


def test_the_smoothed_law_is_the_moving_average_of_its_base():
    """s_T(t) = (1/T) * integral of s over [t-T, t]: it starts and ends at rest with zero
    acceleration, lasts T longer, keeps the base law's peak acceleration (each phase of
    it lasts longer than T) and its jerk is (s''(t) - s''(t-T)) / T."""
    base = TimeLaw.bang_bang(0.2, 1.6)  # |s''| = 4 L / D^2 = 0.3125 for 0.8 s each way
    law = SmoothLaw(base, 0.004)
    assert law.duration == pytest.approx(1.604)
    t = np.linspace(0.0, law.duration, 4001)
    s, sd, sdd = law(t)
    # The moving average, by quadrature of the base law (at rest outside [0, D]).
    fine = np.linspace(-0.004, base.duration + 0.004, 400001)
    sb = np.where(fine < 0, 0.0, np.where(fine > base.duration, 0.2, base(fine)[0]))
    cum = np.concatenate([[0.0], np.cumsum((sb[1:] + sb[:-1]) / 2 * np.diff(fine))])
    avg = (np.interp(t, fine, cum) - np.interp(t - 0.004, fine, cum)) / 0.004
    assert np.abs(s - avg).max() < 1e-8
    assert (s[0], sd[0], sdd[0]) == (0.0, 0.0, 0.0)
    assert s[-1] == pytest.approx(0.2) and abs(sd[-1]) < 1e-12 and abs(sdd[-1]) < 1e-12
    assert law.peak_acceleration() == pytest.approx(0.3125, rel=1e-9)
    assert np.abs(sdd).max() <= 0.3125 * (1 + 1e-12)
    dt = t[1] - t[0]
    # central differences are exact on a quadratic; where the jerk j acts, off by j dt^2/6
    assert np.abs(np.gradient(s, dt) - sd)[1:-1].max() < 157 * dt**2 / 6 * 1.01
    jerk = law.jerk(t)
    assert np.abs(jerk).max() == pytest.approx(2 * 0.3125 / 0.004)  # +a -> -a over T


#: Hand-picked files with every primitive, on both robots.
FILES = {
    "brisk": "approach a=1.5\npause 0.5s x3\nretreat 0.05m a=4 x2\n",
    "slow cap": "approach a=0.1 v=0.02\npause 1s\n",
    "tilts": "approach a=0.2\npause 0.5s x2\ntilt 15deg v=30deg/s x2\n",
    "gazes": "approach a=0.3\npause 0.6s x3\ngaze horizontal 25deg x2\n",
    "shiver": "approach a=0.1\npause 0.8s x2\nretreat 0.05m a=1.5\nshiver 6deg for 1.2s\n",
    "ur5": "robot ur5\napproach a=0.3\npause 0.5s x3\nretreat 0.05m a=1 x2\n"
           "gaze horizontal 20deg\n",
}


@pytest.mark.parametrize("name", ["confident", "curious", "hesitant", "fearful", "inactive"])
def test_shipped_behaviours_stay_within_joint_jerk_limits_at_1khz(name):
    """Each shipped behaviour, compiled and read at 1 kHz, needs at most its robot's
    joint jerk limits, and its declared accelerations are still measured."""
    res = _build((BEHAVIOURS / f"{name}.aou").read_text())
    assert res.ok, [d.message for d in res.diagnostics]
    worst, joint = _worst_jerk(res)
    assert worst <= 1.0, (joint, worst)
    _accelerations_as_declared(res)
    _measured_as_declared(res)


@pytest.mark.parametrize("name", list(FILES))
def test_every_primitive_stays_within_joint_jerk_limits_at_1khz(name):
    """The same for files with retreats, gazes, tilts, shivers, speed caps, on the Panda
    and the UR5 (whose jerk limit is the conservative default)."""
    res = _build(FILES[name])
    assert res.ok, [d.message for d in res.diagnostics]
    worst, joint = _worst_jerk(res)
    assert worst <= 1.0, (joint, worst)
    _accelerations_as_declared(res)
    assert controller_checks(res.compiled)[0].ok  # the check agrees


def test_a_speed_cap_reached_within_one_grid_step_keeps_the_declared_acceleration():
    """`approach a=0.1 v=0.02` reaches its cap after v^2 / 2a = 2 mm, less than a grid
    step of the time law: the hand still accelerates at 0.1 m/s^2, and nothing is
    blamed on a joint."""
    res = _build(FILES["slow cap"])
    assert "C304" not in {d.code for d in res.diagnostics}
    got = res.document["descriptors"]["measured"]["approach_acceleration"]
    assert got == pytest.approx(0.1, rel=REGISTRY["approach_acceleration"].rel_tol)


def test_c304_names_the_joint_that_is_at_its_acceleration_limit():
    """`retreat 0.05m a=4` cannot reach 4 m/s^2 on the Panda: the joint C304 names is one
    whose acceleration, read from the compiled motion, is at its planned limit."""
    res = _build(FILES["brisk"])
    c304 = [d for d in res.diagnostics if d.code == "C304"]
    assert c304
    arm = load_arm("panda")
    tr = sample(res.compiled, RATE)
    for d in c304:
        j = arm.joint_names.index(d.fields["joint"])
        peak = np.abs(tr.qdd[:, j]).max()
        assert peak >= 0.95 * arm.plan_amax[j], (d.fields["joint"], peak)
        assert "acceleration limit" in d.message


def test_c304_says_when_the_speed_cap_is_what_binds():
    """With v / a shorter than the jerk ramp, the acceleration cannot build up before the
    speed cap ends it: the failure names the speed cap, not a joint, and the law's peak
    is below the declared acceleration."""
    from aou_dsl.compiler.timing import time_path
    from aou_dsl.lang.timeline import Pose
    from aou_dsl.robot.geometry import reach_frame
    from aou_dsl.robot.ik import solve_path

    arm = load_arm("panda")
    frame = reach_frame((0.55, 0.0, 0.25), (-0.6, 0.0, 0.8))
    s = np.linspace(0.0, 0.01, 9)
    ik = solve_path(arm, [frame.target(Pose(0.3 - x)) for x in s])
    seg, fail = time_path(arm, s, ik.q, 2.0, 0.002, cartesian=True)  # v / a = 1 ms
    assert seg is not None and fail is not None
    assert fail.joint is None and "speed cap" in fail.reason
    assert seg.law.peak_acceleration() < 0.97 * 2.0


def test_a_bang_bang_law_fails_the_jerk_check_at_its_switch():
    """A joint whose acceleration jumps from +5 to -5 rad/s^2 (the old bang-bang law)
    needs 10 rad/s^2 in one 1 ms step, 10000 rad/s^3, over panda_joint2's 3750: the check
    fails, naming the joint, the time of the jump and the value."""
    law = TimeLaw.bang_bang(0.8, 0.8)  # |s''| = 5 for 0.4 s each way
    t = np.arange(801) / RATE
    q = np.tile(load_arm("panda").spec.posture, (len(t), 1))
    q[:, 1] += law(t)[0]
    tr = Trajectory(t, q, load_arm("panda").joint_names, "panda")
    jerk = [c for c in controller_checks(tr) if c.name == "joint-jerk"][0]
    assert not jerk.ok and jerk.joint == "panda_joint2"
    assert abs(jerk.time - 0.4) <= 0.003  # the switch (the start needs only 5000)
    assert abs(jerk.value) == pytest.approx(_jerk_at(q, RATE)[:, 1].max())
    assert jerk.limit == 3750.0


@pytest.mark.parametrize("n", [pytest.param(40, marks=pytest.mark.slow),
                               pytest.param(300, marks=pytest.mark.large)])
def test_generated_behaviours_stay_within_joint_jerk_limits_at_1khz(n):
    """Over ``n`` files generated from the whole language (both robots), every compiled
    one stays within its robot's joint jerk limits at 1 kHz, and each approach and
    retreat reaches its declared acceleration within 3 % unless C304 says which limit
    binds; two in three compile."""
    from tests import langgen

    compiled = 0
    for case in langgen.random_cases(n, seed=21):
        res = build_source(case.text, f"{case.stem}.aou", check=False)
        if not res.ok:
            continue
        compiled += 1
        worst, joint = _worst_jerk(res)
        assert worst <= 1.0, (case.text, joint, worst)
        _accelerations_as_declared(res)
    assert compiled >= 2 * n // 3


def test_the_franka_controller_applies_its_published_limits():
    """`franka` reads at 1 kHz and holds the Panda to the FCI's joint velocity,
    acceleration and jerk limits: a smooth joint-1 motion at 2.4 rad/s passes the URDF's
    jerk check but exceeds the FCI's 2.175 rad/s, and the check names it."""
    arm = load_arm("panda")
    t = np.arange(2001) / RATE
    q = np.tile(arm.spec.posture, (len(t), 1))
    # speed 1.2 (1 - cos(pi t)) over 2 s: rest to rest (zero speed and acceleration at
    # both ends), peak 2.4 rad/s, acceleration at most 3.8 rad/s^2, jerk 12 rad/s^3
    q[:, 0] += 1.2 * (t - np.sin(np.pi * t) / np.pi)
    tr = Trajectory(t, q, arm.joint_names, "panda")
    peak_speed = np.abs(np.diff(q[:, 0])).max() * RATE
    checks = {c.name: c for c in controller_checks(tr, "franka")}
    assert set(checks) == {"joint-rate-velocity", "joint-rate-acceleration", "joint-jerk"}
    v = checks["joint-rate-velocity"]
    assert not v.ok and v.joint == "panda_joint1" and v.limit == 2.175
    assert abs(v.value) == pytest.approx(peak_speed)
    assert checks["joint-rate-acceleration"].ok and checks["joint-jerk"].ok
    assert [c.ok for c in controller_checks(tr)] == [True]  # the default checks jerk only


def test_a_controller_refuses_a_robot_it_does_not_drive():
    """The Franka controller does not drive a UR5, nor the UR one a Panda; an unknown
    controller is a diagnostic, not an exception of another kind."""
    from aou_dsl.core.diagnostics import AouError

    ur5 = _build(FILES["ur5"])
    assert [(c.name, c.ok) for c in controller_checks(ur5.compiled, "franka")] == [
        ("controller", False)]
    panda = _build(FILES["tilts"])
    assert [(c.name, c.ok) for c in controller_checks(panda.compiled, "ur")] == [
        ("controller", False)]
    with pytest.raises(AouError):
        controller_checks(panda.compiled, "kuka")
