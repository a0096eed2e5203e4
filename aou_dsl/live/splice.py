"""Splicing a plan onto the arm's current state, for :mod:`aou_dsl.live.regulator`.

The transition is a Ruckig trajectory from the arm's state ``(q, qd, qdd)`` to the plan's
state at the join sample (position, velocity and acceleration), :data:`LEAD` ahead of the
sample nearest the arm and lasting at least that long, time-optimal under the
regulator's share of the arm's joint velocity, acceleration and jerk limits. Position,
velocity and acceleration are therefore continuous where the re-plan takes over and where
the plan takes over from the transition, and the jerk in between stays within the limits.
The transition lasts a whole number of the plan's samples and is sampled on the plan's
clock, so that a run's recording keeps one sample step across every switch, as a
controller's clock does; it is checked (:func:`aou_dsl.check`);
a join whose transition would leave the joint ranges or fail a check is dropped for the
next candidate.
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Protocol

import numpy as np

from ..core.codes import C306
from ..core.diagnostics import AouError, Span, diag
from ..lang.primitives import PAUSE

if TYPE_CHECKING:
    from ..core.trajectory import Trajectory
    from ..robot.kinematics import ArmModel

__all__ = ["LEAD", "PHASE_WEIGHT", "RESTART_HOLD", "VELOCITY_WEIGHT", "brake_and_hold",
           "join_plan", "on_grid", "phase_in", "transition"]

#: Weight of the velocity difference when choosing where to join a plan [s]: a sample
#: moving 1 rad/s differently counts like one 0.1 rad away.
VELOCITY_WEIGHT = 0.1
#: A re-plan joins its plan this far [s] ahead of the sample nearest the arm, and the
#: transition takes at least as long: an arm already on the plan flows on along it
#: instead of turning back to a point it has just passed.
LEAD = 0.2
#: Weight of the phase difference when choosing where to join [rad per whole reach]: the
#: new plan goes on from about as far along as the arm was in the old one (a plan passes
#: near the same pose several times: advance, withdraw, advance).
PHASE_WEIGHT = 1.0
#: A new reach (a restart) waits this long at rest where it starts [s]: the arm comes
#: back and holds before it reaches again, so that the return and the reach are two
#: motions, not one through a reversal.
RESTART_HOLD = 0.3
_WHERE = Span.whole_file("<live>")

State3 = tuple[np.ndarray, np.ndarray, np.ndarray]


class Regulator(Protocol):
    """What a splice reads of the regulator that runs it (:class:`.regulator.Regulator`)."""

    @property
    def arm(self) -> ArmModel: ...

    robot: str
    goal: tuple[float, float, float] | None
    transition_scale: float


def _limits(reg: Regulator, x: State3, v: np.ndarray, a: np.ndarray
            ) -> tuple[list, list, list]:
    """Velocity, acceleration and jerk limits of a transition from ``x`` ending at velocity
    ``v`` and acceleration ``a``: the regulator's share of the arm's, raised to what the
    arm is doing and what the end needs (never above the arm's planning limits)."""
    arm, s = reg.arm, reg.transition_scale
    v_need = 1.001 * np.maximum(np.abs(v), np.abs(x[1]))
    a_need = 1.001 * np.maximum(np.abs(a), np.abs(x[2]))
    vmax = np.minimum(np.maximum(s * arm.plan_vmax, v_need), arm.plan_vmax)
    amax = np.minimum(np.maximum(s * arm.plan_amax, a_need), arm.plan_amax)
    return vmax.tolist(), amax.tolist(), (s * arm.jmax).tolist()


def transition(reg: Regulator, x: State3, target: State3 | None, rate: float,
               at_least: float = 0.0
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """The jerk-limited transition from ``x`` to ``target`` (None: to rest, anywhere),
    lasting at least ``at_least`` [s], sampled at ``rate`` [Hz] from t = 0 up to, not
    including, its end; and its end.

    Returns:
        ``(t, q, qd, qdd)``: times (K,), states (K, n), with the end state appended at
        its exact time, so ``t[-1]`` is the duration; None when Ruckig finds no
        trajectory or it would leave the joint ranges.
    """
    from ruckig import ControlInterface, InputParameter, Result, Ruckig
    from ruckig import Trajectory as RuckigTrajectory

    arm, n = reg.arm, reg.arm.n
    inp = InputParameter(n)
    inp.current_position, inp.current_velocity, inp.current_acceleration = (
        x[0].tolist(), x[1].tolist(), x[2].tolist())
    if target is None:
        inp.control_interface = ControlInterface.Velocity
        inp.target_velocity = inp.target_acceleration = [0.0] * n
        v_end = a_end = np.zeros(n)
    else:
        inp.target_position, inp.target_velocity, inp.target_acceleration = (
            target[0].tolist(), target[1].tolist(), target[2].tolist())
        v_end, a_end = target[1], target[2]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = _limits(reg, x, v_end, a_end)
    if at_least > 0:
        inp.minimum_duration = at_least
    traj = RuckigTrajectory(n)
    dt = 1.0 / rate
    for _ in range(4):  # a whole number of samples: the motion stays on the plan's clock
        try:
            result = Ruckig(n).calculate(inp, traj)
        except RuntimeError:
            return None
        if result not in (Result.Working, Result.Finished):
            return None
        steps = float(traj.duration) / dt
        if abs(steps - round(steps)) < 1e-6:
            break
        inp.minimum_duration = math.ceil(steps - 1e-6) * dt
    duration = float(traj.duration)
    if duration <= 0.0:  # already there (Ruckig's extrema of an empty motion are zeros)
        end = target if target is not None else (x[0], v_end, a_end)
        return (np.zeros(1), np.atleast_2d(end[0]), np.atleast_2d(end[1]),
                np.atleast_2d(end[2]))
    lo = np.array([e.min for e in traj.position_extrema])
    hi = np.array([e.max for e in traj.position_extrema])
    if np.any(lo < arm.lower) or np.any(hi > arm.upper):
        return None
    t = np.append(np.arange(0.0, duration - 0.25 / rate, 1.0 / rate), duration)
    out = np.array([np.concatenate(traj.at_time(float(ti))) for ti in t]).reshape(len(t),
                                                                                   3 * n)
    return t, out[:, :n], out[:, n:2 * n], out[:, 2 * n:]


def _candidates(plan: Trajectory, x: State3, phase: float | None) -> list[int]:
    """Plan samples to join, best first: the nearest to the arm's state and to the reach's
    phase, the nearest such one at rest, the plan's start. ``phase`` None joins at the
    start (a new reach)."""
    if phase is None:
        return [0]
    assert plan.qd is not None
    cost = (np.linalg.norm(plan.q - x[0], axis=1)
            + VELOCITY_WEIGHT * np.linalg.norm(plan.qd - x[1], axis=1)
            + PHASE_WEIGHT * np.abs(plan.t / max(plan.duration, 1e-9) - phase))
    out = [int(np.argmin(cost))]
    rest = np.flatnonzero(np.abs(plan.qd).max(axis=1) < 1e-9)
    if len(rest):
        out.append(int(rest[np.argmin(cost[rest])]))
    out.append(0)
    return list(dict.fromkeys(out))


def phase_in(last: Trajectory, join_time: float, transition: float, plan_duration: float,
             x: State3, elapsed: float | None) -> float:
    """How far along its plan the arm is, in [0, 1], when it is at ``x`` on ``last`` (a
    trajectory the regulator returned) ``elapsed`` seconds after it began; without
    ``elapsed``, at the sample of ``last`` nearest ``x`` (in a hold, where it ends: a
    re-plan must not keep the arm in a pause by starting it over)."""
    if elapsed is not None:
        tau = min(max(float(elapsed), 0.0), last.duration)
    else:
        assert last.qd is not None
        cost = (np.linalg.norm(last.q - x[0], axis=1)
                + VELOCITY_WEIGHT * np.linalg.norm(last.qd - x[1], axis=1))
        i = int(np.argmin(cost))
        while i + 1 < len(cost) and cost[i + 1] <= cost[i] + 1e-9:
            i += 1
        tau = float(last.t[i])
    at = join_time + max(0.0, tau - transition)
    return min(1.0, max(0.0, at / plan_duration)) if plan_duration > 0 else 0.0


def _checked(reg: Regulator, t, q, qd, qdd, goal) -> bool:
    from ..core.trajectory import Trajectory
    from ..safety.controllers import controller_checks
    from ..safety.replay import replay

    if len(t) < 2:
        return True
    tr = Trajectory(t, q, reg.arm.joint_names, reg.arm.spec.name, reg.arm.spec.ee_frame,
                    goal, qd, qdd)
    report = replay(tr, dynamic=False)
    report.checks += controller_checks(tr, None)
    return report.ok


def on_grid(plan: Trajectory) -> Trajectory:
    """``plan`` with its last sample one step after the one before (a compiled plan ends
    at its exact duration, up to 1.5 steps after its last regular sample), so that a run
    that follows plans end to end keeps one sample step; its last episodes end there.
    The state of the last sample is kept: a plan ends at (or within a hair of) rest."""
    if len(plan.t) < 3:
        return plan
    step = float(np.median(np.diff(plan.t)))
    end = float(plan.t[-2]) + step
    if abs(float(plan.t[-1]) - end) < 1e-9:
        return plan
    t = plan.t.copy()
    t[-1] = end
    episodes = tuple((kind, min(a, end), min(b, end)) for kind, a, b in plan.episodes)
    return plan.with_(t=t, episodes=episodes)


def _rate(plan: Trajectory) -> float:
    return 1.0 / float(np.median(np.diff(plan.t))) if len(plan.t) > 1 else 250.0


def _held(t, q, qd, qdd, rate: float):
    """The transition into a new reach, then :data:`RESTART_HOLD` at rest where the reach
    starts (a transition that moved the arm there and ends at rest)."""
    if len(t) < 2 or np.abs(qd[-1]).max() > 1e-9 or np.abs(qdd[-1]).max() > 1e-9:
        return t, q, qd, qdd  # already there (the first reach), or not at rest
    m = int(round(RESTART_HOLD * rate))
    extra = t[-1] + np.arange(1, m + 1) / rate
    still = lambda a: np.vstack([a, np.repeat(a[-1:], m, axis=0)])  # noqa: E731
    return np.concatenate([t, extra]), still(q), still(qd), still(qdd)


def join_plan(reg: Regulator, plan: Trajectory, x: State3, phase: float | None,
              timings: dict[str, float]) -> tuple[Trajectory, float, float]:
    """The arm's state, a transition, then ``plan`` from the join sample on (chosen by
    :func:`_candidates`); the join time [s of the plan] and the transition's duration [s].

    Raises:
        AouError: C306 when no candidate's transition passes the checks.
    """
    assert plan.qd is not None and plan.qdd is not None
    clock = time.perf_counter()
    rate = _rate(plan)
    for near in _candidates(plan, x, phase):
        lead = 0.0 if phase is None else LEAD
        k = min(int(np.searchsorted(plan.t, plan.t[near] + lead - 1e-9)), len(plan.t) - 1)
        target = (plan.q[k], plan.qd[k], plan.qdd[k])
        got = transition(reg, x, target, rate, float(plan.t[k] - plan.t[near]))
        now = time.perf_counter()
        timings["transition"] = timings.get("transition", 0.0) + now - clock
        clock = now
        if got is None:
            continue
        t, q, qd, qdd = got
        ok = _checked(reg, t, q, qd, qdd, plan.goal)
        now = time.perf_counter()
        timings["check"] = timings.get("check", 0.0) + now - clock
        clock = now
        if not ok:
            continue
        if phase is None:
            t, q, qd, qdd = _held(t, q, qd, qdd, rate)
        t_k, T = float(plan.t[k]), float(t[-1])
        episodes = tuple((kind, max(a, t_k) - t_k + T, b - t_k + T)
                         for kind, a, b in plan.episodes if b > t_k)
        out = plan.with_(t=np.concatenate([t[:-1], plan.t[k:] - t_k + T]),
                         q=np.vstack([q[:-1], plan.q[k:]]),
                         qd=np.vstack([qd[:-1], plan.qd[k:]]),
                         qdd=np.vstack([qdd[:-1], plan.qdd[k:]]), episodes=episodes)
        timings["splice"] = time.perf_counter() - clock
        return out, t_k, T
    raise AouError(diag(C306, f"no jerk-limited transition from the arm's state into the "
                        f"plan passes the checks on {reg.robot}", _WHERE,
                        hint="the arm may be too close to a joint limit or an obstacle; "
                        "try restart=True"))


def brake_and_hold(reg: Regulator, x: State3, timings: dict[str, float]
                   ) -> tuple[Trajectory, float, float]:
    """Inactive: brake to rest (jerk-limited) wherever the arm is, then hold as long as
    the inactive behaviour does."""
    from ..core.trajectory import Trajectory
    from ..lang.ir import State
    from ..synth.synthesis import study

    hold_for = study(State.INACTIVE).node(PAUSE).duration
    clock = time.perf_counter()
    rate = 250.0
    got = transition(reg, x, None, rate)
    timings["transition"] = time.perf_counter() - clock
    if got is None:
        raise AouError(diag(C306, f"the arm cannot brake within its joint ranges on "
                            f"{reg.robot}", _WHERE))
    t, q, qd, qdd = got
    goal = reg.goal or reg.arm.spec.goal
    clock = time.perf_counter()
    if not _checked(reg, t, q, qd, qdd, goal):
        raise AouError(diag(C306, "braking to rest fails the checks", _WHERE))
    timings["check"] = time.perf_counter() - clock
    T = float(t[-1])
    hold = T + np.arange(1, int(round(hold_for * rate)) + 1) / rate
    n = len(hold)
    zeros = np.zeros((n, reg.arm.n))
    tr = Trajectory(np.concatenate([t, hold]), np.vstack([q, np.tile(q[-1], (n, 1))]),
                    reg.arm.joint_names, reg.arm.spec.name, reg.arm.spec.ee_frame,
                    tuple(goal), np.vstack([qd, zeros]), np.vstack([qdd, zeros]),
                    ((PAUSE, T, T + hold_for),))
    return tr, 0.0, T
