"""Live regulation: a perception loop's estimate -> a checked trajectory from the arm's state.

A :class:`Regulator` holds a robot and a goal. Each tick, the loop gives it the arm's
current state ``(q, qd, qdd)`` and either a C-V point with an intensity or an uncertainty
in [0, 1] (:func:`from_uncertainty` says how that maps). When the expressed state or
intensity changes by more than the :class:`Hysteresis`, it returns a :class:`Replan`: a
trajectory that starts exactly at the arm's state, moves there along a jerk-limited
transition (Ruckig, within the arm's joint velocity, acceleration and jerk limits) into
the plan of the new state, and follows that plan from there. Otherwise it returns None:
keep going.

Plans are synthesized (:func:`aou_dsl.synth.synthesis.synthesize`) for the expressed state at an
intensity level (a multiple of ``intensity_step``), compiled and checked once, and kept;
:meth:`Regulator.prepare` makes them ahead of time so that every re-plan in the loop is
warm. A re-plan joins its plan at the sample nearest the arm's state (joint positions,
and velocities over a tenth of a second) that is about as far along its plan as the arm
was along the old one, so the reach goes on from where it was instead of starting over;
``restart=True`` joins at the plan's start (a new reach). The
transition is checked like any trajectory (:func:`aou_dsl.check`); the plan was
checked when it was compiled. Inactive needs no plan: the arm brakes to rest and holds.
docs/synthesis.md has the details.

With ``through_dmp=True`` a reach the regulator starts follows its plan's DMPs, and a new
intensity level of the same state moves through them without a re-plan
(:mod:`.dmp_follow`, docs/dmp.md).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from ..core.codes import I504
from ..core.diagnostics import AouError, Span, diag
from ..lang.cv import CANONICAL, classify
from ..lang.ir import State
from .path import (
    CONFIDENCE_NOISE,
    NOISE_MARGIN,
    PATH,
    Hysteresis,
    from_uncertainty,
    hysteresis_for,
    hysteresis_margins,
)

if TYPE_CHECKING:
    import numpy as np

    from ..core.trajectory import Trajectory
    from ..robot.kinematics import ArmModel
    from .dmp_follow import DmpRun
    from .perception import Estimate

__all__ = ["CONFIDENCE_NOISE", "NOISE_MARGIN", "PATH", "Hysteresis", "Regulator", "Replan",
           "from_uncertainty", "hysteresis_for", "hysteresis_margins"]

_WHERE = Span.whole_file("<live>")

@dataclass
class Replan:
    """A new trajectory for the arm.

    Attributes:
        trajectory: starts at the arm's state at t = 0 (time relative to the re-plan).
        state, intensity: what it expresses (the intensity level of its plan).
        C, V: the point of the estimate that made it.
        join_time: where the trajectory joins its plan [s of the plan].
        transition: duration of the jerk-limited transition into the plan [s].
        seconds: wall time the re-plan took [s]; timings: per step [s].
    """

    trajectory: Trajectory
    state: State
    intensity: float
    C: float
    V: float
    join_time: float
    transition: float
    seconds: float
    timings: dict[str, float] = field(default_factory=dict)


class Regulator:
    """Regulates a reach's expression from a live estimate (see the module's docstring).

    Args:
        robot: the arm (a name of :data:`aou_dsl.core.robot_specs.ROBOTS`).
        goal: the goal in the robot's base frame [m] (default: the robot's).
        hysteresis: see :class:`Hysteresis`.
        intensity_step: plans are made at intensities that are multiples of this.
        transition_scale: fraction of the arm's planning velocity and acceleration limits
            and of its jerk limits that the transition may use (raised where the plan's
            state at the join needs more).
        through_dmp: follow a started reach as its plan's DMP rollout, and change its
            intensity through the DMPs (:meth:`change_intensity`); needs the ``dmp``
            extra.
    """

    def __init__(self, robot: str = "panda", goal: tuple[float, float, float] | None = None,
                 *, hysteresis: Hysteresis | None = None, intensity_step: float = 0.25,
                 transition_scale: float = 0.25, through_dmp: bool = False):
        from ..robot.load import load_arm

        if not 0.0 < intensity_step <= 1.0 or not 0.0 < transition_scale <= 1.0:
            raise AouError(diag(I504, "intensity_step and transition_scale must lie in "
                                "(0, 1]", _WHERE))
        self.robot, self.goal = robot, goal
        load_arm(robot)  # a robot that does not load is refused here, not at the first tick
        self.hysteresis = hysteresis or Hysteresis()
        self.intensity_step = intensity_step
        self.transition_scale = transition_scale
        self.expressed: tuple[State, float] | None = None
        self.through_dmp = through_dmp
        #: the reach followed as DMPs (None: a compiled plan), and each plan's sequence
        self._dmp: DmpRun | None = None
        self._sequences: dict[int, tuple] = {}
        self._u: float | None = None
        #: plans by text and the robot's files (levels may share a file), texts by state,
        #: level, goal and the robot's files: an edited robot file makes new ones
        self._plans: dict[tuple, Trajectory] = {}
        self._texts: dict[tuple, str] = {}
        #: the last trajectory returned: (it, join time, transition, plan duration, the
        #: phase an inactive hold keeps)
        self._last: tuple[Trajectory, float, float, float, float] | None = None

    # --- what to express ------------------------------------------------------------------

    def level(self, intensity: float) -> float:
        """The plan intensity for ``intensity``: the nearest multiple of the step."""
        step = self.intensity_step
        return min(1.0, max(0.0, round(round(intensity / step) * step, 6)))

    def decide(self, C: float, V: float, intensity: float) -> tuple[State, float] | None:
        """The (state, level) to express now, or None to keep the expressed one."""
        nearest, level = classify(C, V), self.level(intensity)
        if self.expressed is None:
            return nearest, level
        state, current = self.expressed
        if nearest is not state:
            d_now = math.dist((C, V), CANONICAL[state])
            if d_now - math.dist((C, V), CANONICAL[nearest]) > self.hysteresis.state:
                return nearest, level
        past = abs(intensity - current) - self.intensity_step / 2.0
        if level != current and past > self.hysteresis.intensity and state is not State.INACTIVE:
            return state, level
        return None

    def estimate(self, *, C: float | None = None, V: float | None = None,
                 intensity: float | None = None, uncertainty: float | None = None
                 ) -> tuple[float, float, float]:
        """(C, V, intensity) from what the loop gives: a point and an intensity, or an
        uncertainty (after its backlash).

        Raises:
            AouError: I501 for a missing or out-of-range value.
        """
        if uncertainty is not None:
            if C is not None or V is not None or intensity is not None:
                raise AouError(diag(I504, "give an uncertainty, or C, V and intensity; "
                                    "not both", _WHERE))
            c, v, i = from_uncertainty(uncertainty)
            if self._u is not None and abs(uncertainty - self._u) <= self.hysteresis.uncertainty:
                c, v, i = from_uncertainty(self._u)
            else:
                self._u = float(uncertainty)
            return c, v, i
        if C is None or V is None:
            raise AouError(diag(I504, "give C and V (and an intensity), or an "
                                "uncertainty", _WHERE))
        i = 0.5 if intensity is None else intensity
        for name, x, lo in (("C", C, -1.0), ("V", V, -1.0), ("intensity", i, 0.0)):
            if not (isinstance(x, int | float) and lo <= x <= 1.0):
                raise AouError(diag(I504, f"{name} must be a number in [{lo:g}, 1], found "
                                    f"{x!r}", _WHERE))
        return float(C), float(V), float(i)

    def observe(self, q, qd=None, qdd=None, estimate: Estimate | None = None,
                **kwargs) -> Replan | None:
        """:meth:`update` from a perception's :class:`~.perception.Estimate`: the
        uncertainty is ``1 - confidence`` (other keywords as :meth:`update`'s)."""
        from .perception import Estimate, uncertainty_of

        if not isinstance(estimate, Estimate):
            raise AouError(diag(I504, "observe() needs a perception's Estimate", _WHERE))
        return self.update(q, qd, qdd, uncertainty=uncertainty_of(estimate), **kwargs)

    def checkpoint(self) -> tuple:
        """What the regulator expresses and follows now, for :meth:`rollback`."""
        return (self.expressed, self._last, self._dmp)

    def rollback(self, kept: tuple) -> None:
        """Forget a re-plan the arm did not get: back to a :meth:`checkpoint`."""
        self.expressed, self._last, self._dmp = kept

    def reset(self) -> None:
        """Forget what was expressed and the last uncertainty used (the plans stay): a
        new run starts."""
        self.expressed, self._last, self._dmp, self._u = None, None, None, None

    # --- plans ----------------------------------------------------------------------------

    def plan(self, state: State, level: float) -> Trajectory:
        """The compiled, checked plan of ``state`` at intensity ``level`` (kept).

        Raises:
            AouError: the build's diagnostics when the plan does not compile or check.
        """
        from ..robot.load import robot_key
        from ..synth.synthesis import compiled, synthesize

        files = robot_key(self.robot)
        key = (state, level, self.goal, files)  # a goal that follows the target: new ones
        if key not in self._texts:
            self._texts[key] = synthesize(state, intensity=level, robot=self.robot,
                                          goal=self.goal)
        made = (self._texts[key], files)
        if made not in self._plans:
            from .splice import on_grid

            res = compiled(made[0])
            if not res.ok:
                raise AouError(res.diagnostics)
            self._plans[made] = on_grid(res.trajectory)
        return self._plans[made]

    @property
    def arm(self) -> ArmModel:
        """The robot as its files are now (a load the files did not change is kept)."""
        from ..robot.load import load_arm

        return load_arm(self.robot)

    def prepare(self, states: tuple[State, ...] = PATH[:-1]) -> int:
        """Compile every intensity level of ``states`` now; the number of plans made."""
        n = round(1.0 / self.intensity_step)
        before = len(self._plans)
        for state in states:
            for k in range(n + 1):
                self.plan(state, self.level(k * self.intensity_step))
        return len(self._plans) - before

    # --- the loop -------------------------------------------------------------------------

    def update(self, q, qd=None, qdd=None, *, C: float | None = None, V: float | None = None,
               intensity: float | None = None, uncertainty: float | None = None,
               restart: bool = False, elapsed: float | None = None) -> Replan | None:
        """One tick of the loop: a :class:`Replan` when the expression changes (or
        ``restart``), else None.

        Args:
            q, qd, qdd: the arm's joint positions, velocities, accelerations, shape (n,)
                in the robot's joint order (velocities and accelerations default to 0).
            C, V, intensity: the estimate as a C-V point; or ``uncertainty`` in [0, 1].
            restart: start a new reach: re-plan and join the plan at its start.
            elapsed: time since the arm began the trajectory last returned [s], when the
                loop knows it; it says how far along its reach the arm is (otherwise the
                sample nearest its state does).
        """
        c, v, i = self.estimate(C=C, V=V, intensity=intensity, uncertainty=uncertainty)
        choice = self.decide(c, v, i)
        if choice is None and not restart:
            return None
        state, level = choice or self.expressed  # type: ignore[misc]
        if (self._dmp is not None and not restart and self.expressed is not None
                and state is self.expressed[0]):
            return self.change_intensity(q, qd, qdd, level, point=(c, v), elapsed=elapsed)
        return self.replan(q, qd, qdd, state, level, restart=restart, point=(c, v),
                           elapsed=elapsed)

    def replan(self, q, qd, qdd, state: State, level: float, *, restart: bool = False,
               point: tuple[float, float] | None = None, elapsed: float | None = None
               ) -> Replan:
        """Re-plan now into ``state`` at ``level``, whatever the hysteresis says
        (arguments as :meth:`update`'s).

        Raises:
            AouError: C306 when no transition into the plan passes the checks.
        """
        from .splice import brake_and_hold, join_plan

        start = time.perf_counter()
        timings: dict[str, float] = {}
        x = self._state(q, qd, qdd)
        phase = None if restart else self._phase(x, elapsed)
        timings["phase"] = time.perf_counter() - start
        self._dmp = None
        if state is State.INACTIVE:
            traj, join, trans = brake_and_hold(self, x, timings)
            self._last = (traj, 0.0, trans, 0.0, phase or 0.0)
        elif self.through_dmp and (restart or self._last is None):
            from .dmp_follow import start as start_dmp

            traj, self._dmp, trans = start_dmp(self, state, level, x, timings)
            join = 0.0
            self._last = (traj, 0.0, trans, float(self._dmp.rollout.t[-1]), 0.0)
        else:
            t0 = time.perf_counter()
            plan = self.plan(state, level)
            timings["plan"] = time.perf_counter() - t0
            traj, join, trans = join_plan(self, plan, x, phase, timings)
            self._last = (traj, join, trans, plan.duration, 0.0)
        self.expressed = (state, level)
        c, v = point if point is not None else CANONICAL[state]
        return Replan(traj.with_(title=f"{state} at intensity {level:g}"), state, level, c, v,
                      join, trans, time.perf_counter() - start, timings)

    def change_intensity(self, q, qd, qdd, level: float, *,
                         point: tuple[float, float] | None = None,
                         elapsed: float | None = None) -> Replan:
        """Move the running reach to intensity ``level`` through its DMPs, without a
        re-plan (arguments as :meth:`update`'s; see :mod:`.dmp_follow`): the trajectory
        returned starts at the arm's sample of the one it follows.

        Raises:
            AouError: I504 when the reach does not follow DMPs (``through_dmp`` and a
                started reach); C306 when the changed motion fails a check.
        """
        from .dmp_follow import change

        if self._dmp is None or self.expressed is None or self._last is None:
            raise AouError(diag(I504, "no reach follows DMPs: make the regulator with "
                                "through_dmp=True and start a reach first", _WHERE))
        start = time.perf_counter()
        timings: dict[str, float] = {}
        x = self._state(q, qd, qdd)
        state, level = self.expressed[0], self.level(level)
        traj, self._dmp, at = change(self, self._dmp, self._last[0], level, x, elapsed,
                                     timings)
        self._last = (traj, at, 0.0, float(self._dmp.rollout.t[-1]), 0.0)
        self.expressed = (state, level)
        c, v = point if point is not None else CANONICAL[state]
        return Replan(traj.with_(title=f"{state} at intensity {level:g}"), state, level, c, v,
                      at, 0.0, time.perf_counter() - start, timings)

    def _phase(self, x, elapsed: float | None) -> float:
        """How far along its reach the arm is, in [0, 1] (0 before any plan)."""
        from .splice import phase_in

        if self._last is None:
            return 0.0
        traj, join, trans, duration, held = self._last
        return phase_in(traj, join, trans, duration, x, elapsed) if duration > 0 else held

    def _state(self, q, qd, qdd) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        import numpy as np

        n = self.arm.n
        out = []
        for name, x in (("q", q), ("qd", qd), ("qdd", qdd)):
            try:
                a = np.zeros(n) if x is None and name != "q" else np.asarray(x, dtype=float)
            except (TypeError, ValueError):
                a = np.full(1, np.nan)
            if a.shape != (n,) or not np.all(np.isfinite(a)):
                raise AouError(diag(I504, f"{name} must be {n} finite numbers (the joints "
                                    f"of {self.robot}), found {x!r:.60}", _WHERE))
            out.append(a)
        return out[0], out[1], out[2]
