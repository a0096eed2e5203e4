"""Fitting a synthesized behaviour to an arm: the limits it may use, and the values that fit.

:func:`fit_limits` reads the arm's rolling joint (the joint that shivers, which turns the
hand about its forward axis) from :func:`aou_dsl.robot.kinematics.load_arm`, and finds how hard
the joints can accelerate the hand along this reach by compiling a probe once per robot
and goal: a reach to the stand-off and back at an end-effector acceleration no arm
reaches, whose timing reports what the joints did reach (C304). :func:`fit` then keeps
every value within :data:`MARGIN` of those limits. Deterministic: the
same robot and goal always give the same limits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..core.codes import C304
from ..core.diagnostics import AouError, has_errors
from ..core.memo import cached
from ..fit.refusals import AccelerationShort
from ..fit.rounding import significant
from ..fit.search import DIGITS
from ..lang.ir import DEFAULTS
from ..lang.primitives import KINDS, LOOK_SHIVER_F, SHIVER, TILT, VISIBLE_SHIVER, shiver_duration
from .kind_recipes import kind_recipes
from .recipe import Recipe, descriptor

__all__ = ["SHIVER_F", "Limits", "fit", "fit_limits", "goal_line", "robot_line",
           "shiver_max_frequency"]

#: Fraction of a limit synthesis plans up to (the rest is margin for the path's bends).
MARGIN = 0.8
#: Tilts plan up to this fraction of the rolling joint's acceleration limit: a tilt has a
#: fixed duration, and a smoother time law over it needs a higher peak than bang-bang.
TILT_MARGIN = 0.5
#: The probe asks for this end-effector acceleration [m/s^2]: more than any arm reaches.
PROBE_ACCEL = 20.0
#: Shivers plan up to this fraction of the rolling joint's acceleration limit: their
#: motion is analytic, with no path to bend.
SHIVER_MARGIN = 0.9


@dataclass(frozen=True)
class Limits:
    """What a synthesized behaviour may ask of an arm.

    Attributes:
        robot: the robot's name; goal: the goal the probe reached for (None: default).
        reached: peak end-effector acceleration the joints reached on the probe [m/s^2].
        accel: the most an approach or retreat may declare [m/s^2] (``MARGIN * reached``).
        roll_joint: the joint that rolls the hand about its forward axis.
        roll_v, roll_a: its planning limits times the margin [rad/s, rad/s^2].
        arm: the content of the robot's files (:func:`~aou_dsl.robot.load.robot_key`):
            what is kept per limits is kept per arm as it is now.
    """

    robot: str
    goal: tuple[float, float, float] | None
    reached: float
    accel: float
    roll_joint: str
    roll_v: float
    roll_a: float
    arm: tuple = field(default=(), repr=False)


def robot_line(robot: str) -> str:
    """The ``robot`` setting naming ``robot``: a built-in name, or a robot file's path,
    quoted and absolute (a relative one would be read from the file's folder)."""
    import os

    from ..core.robot_specs import ROBOTS

    return f"robot {robot}" if robot in ROBOTS else f'robot "{os.path.abspath(robot)}"'


def goal_line(goal: tuple[float, float, float] | None) -> str:
    return "" if goal is None else f"goal ({goal[0]:g}, {goal[1]:g}, {goal[2]:g})\n"


def _probe(robot: str, goal: tuple[float, float, float] | None) -> str:
    back = DEFAULTS["start"] - DEFAULTS["standoff"]
    a = PROBE_ACCEL
    return (f"behaviour probe\n{robot_line(robot)}\n{goal_line(goal)}sequence {{\n"
            f"  approach a={a:g}\n"
            f"  pause 0.5s\n  retreat {back:g}m a={a:g}\n  pause 0.5s\n  approach a={a:g}\n}}\n")


def fit_limits(robot: str, goal: tuple[float, float, float] | None = None) -> Limits:
    """The limits a behaviour synthesized for ``robot`` (and ``goal``) must keep; kept
    per robot (its files' content included) and goal.

    Raises:
        AouError: V109 for an unknown robot; the probe's diagnostics when the reach
            itself cannot be compiled on the arm (e.g. an unreachable goal).
    """
    from ..robot.load import robot_key

    return _fit_limits(robot, goal, robot_key(robot))


@cached(maxsize=16)
def _fit_limits(robot: str, goal: tuple[float, float, float] | None, key: tuple) -> Limits:
    from ..driver.builder import build_source
    from ..robot.load import load_arm

    arm = load_arm(robot)
    res = build_source(_probe(robot, goal), f"<synth probe {robot}>", check=False)
    errors = [d for d in res.diagnostics if d.code != C304]
    if has_errors(errors):
        raise AouError([d for d in errors if d.severity.value == "error"])
    reached = min((float(d.refusal.achieved) for d in res.diagnostics
                   if isinstance(d.refusal, AccelerationShort)
                   and d.refusal.achieved is not None),
                  default=PROBE_ACCEL)
    j = arm.joint_names.index(arm.spec.shiver_joint)
    return Limits(robot, goal, reached, significant(MARGIN * reached, DIGITS),
                  arm.spec.shiver_joint,
                  MARGIN * float(arm.plan_vmax[j]), MARGIN * float(arm.plan_amax[j]), key)


def _cap_accel(r: Recipe, kind: str, lim: Limits) -> Recipe:
    """The ``kind`` statement's acceleration at most :attr:`Limits.accel`."""
    node = r.node(kind)
    if node is None or not node.count or node.a <= lim.accel:
        return r
    out = r.with_node(node.replace(a=lim.accel))
    try:
        name = descriptor(kind, "peak_acceleration").name
    except KeyError:  # a plugin kind without an acceleration descriptor: no note
        return out
    note = (f"{r.notes.get(name, '')}; capped from {node.a:g} at {lim.accel:g} for "
            f"{lim.robot} (its joints reach about {lim.reached:.2g} m/s^2 here)")
    return out.noted(name, note)


def shiver_max_frequency(amplitude: float, duration: float, lim: Limits) -> float:
    """Highest frequency [Hz] of a shiver of ``amplitude`` [rad] peak to peak that stays
    within the rolling joint's limits, by the compiler's own check
    (:func:`~aou_dsl.compiler.timing.shiver_segment`), with :data:`SHIVER_MARGIN` of its
    acceleration limit to spare."""
    import numpy as np

    from ..compiler.timing import shiver_segment
    from ..robot.load import load_arm

    arm = load_arm(lim.robot)
    probe_f = 1000.0  # so fast that the check fails and reports the frequency that fits
    _, fail = shiver_segment(arm, np.zeros(arm.n), amplitude, probe_f, duration)
    f_ok = float(fail.wanted) if fail is not None and fail.wanted else probe_f
    return f_ok * math.sqrt(SHIVER_MARGIN)


#: The note of a shiver's frequency (a parameter, not a descriptor).
SHIVER_F = "shiver frequency"


def _fit_shiver(r: Recipe, lim: Limits) -> Recipe:
    node = r.node(SHIVER)
    f_max = shiver_max_frequency(node.amplitude, node.duration, lim)
    if node.f <= f_max:
        return r.noted(SHIVER_F, "the language default (the study gives none)")
    floor = min(LOOK_SHIVER_F, node.f)  # a tremor's least frequency: slower is a roll
    if f_max >= floor:
        f = significant(f_max, DIGITS)
        return r.with_node(node.replace(f=f, duration=_whole(node.duration, f))).noted(
            SHIVER_F, f"the language default {node.f:g} Hz, lowered to {f:g} Hz for "
            f"{lim.robot}'s {lim.roll_joint} (the amplitude stays)")
    # the peaks are proportional to the amplitude at a fixed frequency
    least = math.degrees(VISIBLE_SHIVER)
    amp = significant(math.degrees(node.amplitude) * (f_max / floor) ** 2, DIGITS)
    while amp > least and shiver_max_frequency(math.radians(amp), node.duration,
                                               lim) < floor:
        amp = significant(max(amp * 0.9, least), DIGITS)
    name = descriptor(SHIVER, "amplitude").name
    note = (f"{r.notes.get(name, '')}; reduced from {math.degrees(node.amplitude):g} to "
            f"{amp:g} deg: {lim.robot}'s {lim.roll_joint} cannot shiver wider at "
            f"{floor:g} Hz, and a slower shiver would read as slow rolls, not a tremor")
    return (r.with_node(node.replace(f=floor, amplitude=math.radians(amp),
                                     duration=_whole(node.duration, floor)))
            .noted(SHIVER_F, f"lowered to {floor:g} Hz for {lim.robot}'s "
                   f"{lim.roll_joint}").noted(name, note))


def _whole(duration: float, f: float) -> float:
    """The duration a shiver asked to last ``duration`` [s] runs at ``f`` [Hz] (whole
    cycles, at least 3), to 3 significant digits that read back as the same cycles."""
    return float(f"{shiver_duration(duration, f):.3g}")


def _fit_tilt(r: Recipe, lim: Limits) -> Recipe:
    """A tilt lasts ``angle / v`` and peaks at ``2 v`` and ``4 v^2 / angle`` (rest to
    rest): the velocity is lowered until both fit the rolling joint."""
    node = r.node(TILT)
    name = descriptor(TILT, "velocity").name
    v_max = min(lim.roll_v / 2.0,
                math.sqrt(TILT_MARGIN / MARGIN * lim.roll_a * abs(node.angle) / 4.0))
    if node.v <= v_max:
        return r.noted(name, "the language default (the study gives none; no clear effect "
                       "on curious)")
    v_deg = significant(math.degrees(v_max), DIGITS)
    return r.with_node(node.replace(v=math.radians(v_deg))).noted(
        name, f"the language default {math.degrees(node.v):g} deg/s, lowered to {v_deg:g} "
        f"for {lim.robot}'s {lim.roll_joint} (no clear effect on curious)")


def fit(r: Recipe, lim: Limits) -> Recipe:
    """``r`` with every value within the arm's limits; the notes say what was lowered and
    why."""
    for kind in kind_recipes():  # every translation's acceleration, in the file's order
        if kind in KINDS and KINDS[kind].translation:
            r = _cap_accel(r, kind, lim)
    if r.count(SHIVER):
        r = _fit_shiver(r, lim)
    if r.count(TILT):
        r = _fit_tilt(r, lim)
    return r
