"""The closed loop: perception -> regulator -> re-planned motion -> checks, tick by tick.

:func:`run` drives a :class:`~.regulator.Regulator` from a perception (any callable or
object :func:`~.perception.as_perception` accepts) at the controller's rate. Each tick:

1. the perception answers (a rendered camera only every few ticks, at its own rate; the
   loop keeps its last answer in between);
2. the regulator gets the arm's state and ``uncertainty = 1 - confidence``; when the
   expressed state or intensity moves past its hysteresis it returns a re-plan (a reach
   that has ended starts again: ``restart``);
3. the re-plan is checked before the arm gets it (:func:`gate`): it starts at the arm's
   exact state, stays within the joint ranges, and its joint jerk at the controller's
   rate is within the arm's limits. A re-plan that fails, or that the regulator cannot
   make, is not sent: the arm keeps the last checked motion and the run says why.

The result, a :class:`Run`, holds the motion the arm executed on one clock, every tick
(confidence, uncertainty, expressed state and intensity, the evidence) and every switch.
:func:`document` makes it a trajectory document that ``aouc measure`` reads, the loop's
log under its ``live`` key.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..core.diagnostics import AouError
from ..lang.ir import State
from .perception import Estimate, as_perception, uncertainty_of
from .regulator import Hysteresis, Regulator, Replan

if TYPE_CHECKING:
    from ..core.trajectory import Trajectory

__all__ = ["HYSTERESIS", "Loop", "Run", "Switch", "Tick", "document", "gate", "run", "segments"]

#: The loop's hysteresis (unless the caller gives one): the regulator's default, made
#: for the rendered camera's confidence noise (:data:`.regulator.CONFIDENCE_NOISE`).
HYSTERESIS = Hysteresis()
#: A goal that follows the target moves once the target seen is this far from where the
#: goal was set [m] (a re-plan each time; closer moves are within the reach's own play).
FOLLOW_STEP = 0.02


@dataclass(frozen=True)
class Tick:
    """One tick: its time [s], the perception's confidence and the uncertainty the
    regulator took, the state and intensity expressed after it, the evidence."""

    t: float
    confidence: float
    uncertainty: float
    state: str
    intensity: float
    evidence: dict[str, Any]


@dataclass(frozen=True)
class Switch:
    """A change of the arm's motion, or a refused one (``held``).

    Attributes:
        t: when the tick asked for it [s]; start: where the new motion begins on the
            run's clock [s] (the arm's sample at that tick).
        kind: ``start``, ``replan`` (the estimate moved), ``restart`` (the reach ended and
            begins again), ``retarget`` (the target moved: the goal follows it) or
            ``held`` (refused: the arm keeps its motion).
        state, intensity: what the new motion expresses (for ``held``: what was asked).
        seconds: the re-plan's wall time, from the tick to the checked motion [s].
        reason: why a re-plan was held.
        transition: how long the motion moves into its plan [s]; join: where it joins
            the plan [s of the plan]; duration: the motion's length [s]; goal: the goal
            it reaches for [m].
    """

    t: float
    start: float
    kind: str
    state: str
    intensity: float
    seconds: float
    reason: str = ""
    transition: float = 0.0
    join: float = 0.0
    duration: float = 0.0
    goal: tuple[float, ...] | None = None


@dataclass
class Run:
    """What :func:`run` did (see the module's docstring)."""

    trajectory: Trajectory
    ticks: list[Tick]
    switches: list[Switch]
    robot: str
    rate: float
    title: str = ""
    timings: dict[str, float] = field(default_factory=dict)


def gate(reg: Regulator, traj: Trajectory, x: tuple[np.ndarray, np.ndarray, np.ndarray],
         rate: float) -> str | None:
    """Why ``traj`` may not go to the arm at state ``x``, or None when it may: it must
    start at ``x`` (position, velocity, acceleration), stay within the joint ranges, and
    its joint jerk at the controller's ``rate`` stay within the arm's limits."""
    from ..safety.controllers import controller_checks

    assert traj.qd is not None and traj.qdd is not None
    for name, got, want in (("position", traj.q[0], x[0]), ("velocity", traj.qd[0], x[1]),
                            ("acceleration", traj.qdd[0], x[2])):
        if not np.allclose(got, want, atol=1e-6, rtol=0):
            return f"it does not start at the arm's {name}"
    arm = reg.arm
    if np.any(traj.q < arm.lower - 1e-9) or np.any(traj.q > arm.upper + 1e-9):
        return "it leaves the joint ranges"
    if len(traj.t) < 3:
        return None
    jerk = [c for c in controller_checks(traj, None, rate=rate) if c.name == "joint-jerk"]
    bad = [c for c in jerk if not c.ok]
    return f"its joint jerk at {rate:g} Hz: {bad[0].detail}" if bad else None


def run(perception: Any, *, robot: str = "panda", duration: float = 10.0,
        rate: float = 100.0, goal: tuple[float, float, float] | None = None,
        perception_rate: float | None = None, hysteresis: Hysteresis | None = None,
        intensity_step: float = 0.25, regulator: Regulator | None = None,
        title: str = "", follow: tuple[float, float, float] | None = None) -> Run:
    """Run the loop for ``duration`` seconds of the arm's time at ``rate`` [Hz].

    Args:
        perception: a perception, a callable of the time, or an object with
            ``perceive(t)`` (:func:`~.perception.as_perception`).
        perception_rate: how often it is asked [Hz] (default: every tick).
        regulator: one to use (its plans kept); else one is made for ``robot`` with
            ``hysteresis`` (default :data:`HYSTERESIS`).
        follow: the goal follows the target the perception sees, kept this far from it
            [m] (a ``retarget`` switch each time it moves :data:`FOLLOW_STEP`).
    """
    lp = Loop(perception, robot=robot, rate=rate, goal=goal, perception_rate=perception_rate,
              hysteresis=hysteresis, intensity_step=intensity_step, regulator=regulator,
              follow=follow)
    for k in range(int(round(duration * rate))):
        lp.tick(k / rate)
    return lp.result(title)


class Loop:
    """The loop one tick at a time (:func:`run` runs it for a duration; the studio runs
    it on the wall clock). Arguments as :func:`run`'s; ``keep=False`` keeps no history
    of the motion (:meth:`result` then cannot be called), for a loop that runs on.

    Attributes:
        active: the motion the arm follows (None before the first tick), begun at
            ``since`` [s] on the loop's clock; switches: every switch so far.
    """

    def __init__(self, perception: Any, *, robot: str = "panda", rate: float = 100.0,
                 goal: tuple[float, float, float] | None = None,
                 perception_rate: float | None = None, hysteresis: Hysteresis | None = None,
                 intensity_step: float = 0.25, regulator: Regulator | None = None,
                 keep: bool = True, follow: tuple[float, float, float] | None = None
                 ) -> None:
        self.perception = as_perception(perception)
        self.reg = regulator or Regulator(robot, goal, hysteresis=hysteresis or HYSTERESIS,
                                          intensity_step=intensity_step)
        self.rate, self.keep, self.follow = rate, keep, follow
        self._anchor = None if follow is None else self.reg.goal
        self.every = max(1, round(rate / perception_rate)) if perception_rate else 1
        self.start_q = self.reg.plan(State.CONFIDENT, self.reg.level(1.0)).q[0]
        # the executed motion: pieces of returned trajectories, each up to where the next
        # began
        self.pieces: list[tuple[float, Trajectory, int]] = []
        self.active: Trajectory | None = None
        self.since = 0.0
        self.ticks: list[Tick] = []
        self.switches: list[Switch] = []
        self.estimate: Estimate | None = None
        self.perceive_s = 0.0
        self._k = 0

    def arm_at(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
        """The arm's state at ``t`` on the loop's clock (position, velocity,
        acceleration) and its sample of :attr:`active` (-1 before the first motion)."""
        n = self.reg.arm.n
        if self.active is None:
            return self.start_q, np.zeros(n), np.zeros(n), -1
        a = self.active
        i = max(0, int(np.searchsorted(a.t, t - self.since, side="right")) - 1)
        assert a.qd is not None and a.qdd is not None
        return a.q[i], a.qd[i], a.qdd[i], i

    def tick(self, t: float) -> Tick:
        """One tick at ``t`` [s] (later than the last one's): perceive, regulate, check,
        and switch the arm's motion or hold it (the module's docstring)."""
        reg = self.reg
        if self.estimate is None or self._k % self.every == 0:
            clock = time.perf_counter()
            self.estimate = self.perception.perceive(t)
            self.perceive_s += time.perf_counter() - clock
        self._k += 1
        est = self.estimate
        u = uncertainty_of(est)
        active = self.active
        q, qd, qdd, i = self.arm_at(t)
        x = (q, qd, qdd)
        if active is None:
            ended, elapsed = True, None
        else:
            ended, elapsed = t - self.since >= active.duration, float(active.t[i])
        clock = time.perf_counter()
        kept, goal = reg.checkpoint(), reg.goal
        moved = self._moved(est) if active is not None else None
        rep: Replan | None
        try:
            if moved is not None and reg.expressed is not None:
                reg.goal = moved  # the same state and level, reaching for the new goal
                rep = reg.replan(*x, *reg.expressed, restart=ended, elapsed=elapsed)
            else:
                rep = reg.update(*x, uncertainty=u, restart=ended, elapsed=elapsed)
            why = None if rep is None else gate(reg, rep.trajectory, x, self.rate)
        except AouError as exc:
            rep, why = None, exc.diagnostics[0].message if exc.diagnostics else str(exc)
        seconds = time.perf_counter() - clock
        at = self.since + (float(active.t[i]) if active is not None else 0.0)
        switches = self.switches
        if why is not None:
            state, level = (rep.state, rep.intensity) if rep is not None else \
                (reg.expressed or (State.INACTIVE, 0.0))
            reg.rollback(kept)  # the arm did not get it: it keeps what it was doing
            reg.goal = goal
            if not _same_hold(switches, why):
                switches.append(Switch(t, at, "held", str(state), level, seconds, why,
                                       goal=moved or goal))
        elif rep is not None:
            kind = "start" if active is None else ("restart" if ended else "replan")
            kind = "retarget" if moved is not None else kind
            if active is not None and self.keep:
                self.pieces.append((self.since, active, i))
            self.active, self.since = rep.trajectory, at
            switches.append(Switch(t, at, kind, str(rep.state), rep.intensity, seconds, "",
                                   rep.transition, rep.join_time, rep.trajectory.duration,
                                   rep.trajectory.goal))
        state, level = reg.expressed or (State.INACTIVE, 0.0)
        tk = Tick(t, est.confidence, u, str(state), level, est.evidence.to_json())
        if self.keep:
            self.ticks.append(tk)
        return tk

    def _moved(self, est: Estimate) -> tuple[float, float, float] | None:
        """The goal that follows the target the estimate sees, when the target has moved
        :data:`FOLLOW_STEP` from where the goal was last set (None: keep the goal)."""
        if self.follow is None or est.position is None or self.reg.expressed is None \
                or self.reg.expressed[0] is State.INACTIVE:
            return None
        want = tuple(round(p + o, 3) for p, o in zip(est.position, self.follow, strict=True))
        if self._anchor is not None and \
                float(np.linalg.norm(np.subtract(want, self._anchor))) < FOLLOW_STEP:
            return None
        self._anchor = want  # type: ignore[assignment]
        return want  # type: ignore[return-value]

    def result(self, title: str = "") -> Run:
        """The run so far (a loop made with ``keep``).

        Raises:
            AouError: C306 when the arm never got a motion.
        """
        if self.active is None:
            raise AouError(switches_message(self.switches))
        pieces = [*self.pieces, (self.since, self.active, len(self.active.t))]
        return Run(_executed(pieces), self.ticks, self.switches, self.reg.robot, self.rate,
                   title, {"perceive": self.perceive_s})


def _same_hold(switches: list[Switch], why: str) -> bool:
    """Whether the last switch already holds for this reason (a hold is logged once,
    not at every tick it lasts)."""
    return bool(switches) and switches[-1].kind == "held" and switches[-1].reason == why


def switches_message(switches: list[Switch]) -> list:
    from ..core.codes import C306
    from ..core.diagnostics import Span, diag

    why = switches[0].reason if switches else "no tick ran"
    return [diag(C306, f"the loop never sent the arm a motion: {why}",
                 Span.whole_file("<live>"))]


def _executed(pieces: list[tuple[float, Trajectory, int]]) -> Trajectory:
    """The pieces on one clock: each from its start up to (not including) the sample
    where the next began (the next starts with that very state)."""
    ts, qs, qds, qdds, episodes = [], [], [], [], []
    for j, (since, tr, upto) in enumerate(pieces):
        last = j == len(pieces) - 1
        stop = len(tr.t) if last else upto
        if stop == 0:
            continue
        assert tr.qd is not None and tr.qdd is not None
        ts.append(since + tr.t[:stop])
        qs.append(tr.q[:stop])
        qds.append(tr.qd[:stop])
        qdds.append(tr.qdd[:stop])
        end = since + float(tr.t[stop - 1])
        episodes += [(kind, since + a, min(since + b, end)) for kind, a, b in tr.episodes
                     if since + a < end]
    first = pieces[0][1]
    return first.with_(t=np.concatenate(ts), q=np.vstack(qs), qd=np.vstack(qds),
                       qdd=np.vstack(qdds), episodes=tuple(episodes), title="live run")


def document(r: Run) -> dict[str, Any]:
    """The run as a trajectory document (``aou-trajectory/1``): the executed motion,
    and under ``live`` the ticks and switches."""
    from ..compiler.output import _robot_keys
    from ..version import __version__

    tr = r.trajectory
    assert tr.qd is not None and tr.qdd is not None
    ticks = r.ticks
    evidence_keys = sorted({k for tk in ticks for k in tk.evidence if k != "source"})
    return {
        "format": "aou-trajectory/1",
        "generator": f"aouc {__version__}",
        "behaviour": "live",
        "state": None,
        "robot": tr.robot,
        "ee_frame": tr.ee_frame,
        **_robot_keys(tr),
        "joint_names": list(tr.joint_names),
        "goal": {"position": list(tr.goal or ())},
        "rate": float(round(1.0 / float(np.median(np.diff(tr.t))), 6)),
        "duration": tr.duration,
        "episodes": [{"kind": k, "t_start": a, "t_end": b} for k, a, b in tr.episodes],
        "live": {
            "title": r.title,
            "rate": r.rate,
            "ticks": {
                "t": [tk.t for tk in ticks],
                "confidence": [round(tk.confidence, 6) for tk in ticks],
                "uncertainty": [round(tk.uncertainty, 6) for tk in ticks],
                "state": [tk.state for tk in ticks],
                "intensity": [tk.intensity for tk in ticks],
                "evidence": {k: [tk.evidence.get(k) for tk in ticks] for k in evidence_keys},
            },
            "switches": [{"t": s.t, "start": s.start, "kind": s.kind, "state": s.state,
                          "intensity": s.intensity, "reason": s.reason,
                          "transition": s.transition, "join": s.join,
                          "duration": s.duration,
                          "goal": None if s.goal is None else list(s.goal)}
                         for s in r.switches],
        },
        "t": tr.t.tolist(),
        "q": tr.q.tolist(),
        "qd": tr.qd.tolist(),
        "qdd": tr.qdd.tolist(),
    }


def segments(r: Run, doc: dict[str, Any] | None = None) -> list[tuple[Switch, dict[str, Any]]]:
    """Each motion the arm followed after its transition, as a trajectory document of its
    own (time from 0 where it joined its plan): the switch that sent it, and the
    document. ``aouc measure`` reads each; its descriptors are those of the state and
    intensity the switch names."""
    doc = doc or document(r)
    t = np.asarray(doc["t"])
    sent = [s for s in r.switches if s.kind != "held"]
    out = []
    for k, s in enumerate(sent):
        begin = s.start + s.transition
        end = sent[k + 1].start if k + 1 < len(sent) else float(t[-1]) + 1.0
        rows = np.flatnonzero((t >= begin - 1e-9) & (t < end - 1e-9))
        if len(rows) < 3:
            continue
        sub = {key: doc[key] for key in doc if key not in ("t", "q", "qd", "qdd", "live",
                                                         "episodes")}
        t0 = float(t[rows[0]])
        if s.goal is not None:  # the goal it reached for (it may follow the target)
            sub["goal"] = {"position": list(s.goal)}
        sub |= {"behaviour": f"{s.state}_{s.intensity:g}".replace(".", "_"),
                "state": s.state,
                "duration": float(t[rows[-1]] - t0),
                "episodes": [{"kind": e["kind"], "t_start": e["t_start"] - t0,
                              "t_end": e["t_end"] - t0} for e in doc["episodes"]
                             if e["t_start"] >= t0 - 1e-9 and e["t_end"] <= t[rows[-1]] + 1e-9],
                "t": (t[rows] - t0).tolist(),
                **{key: [doc[key][i] for i in rows] for key in ("q", "qd", "qdd")},
                "live": {"switch": {"t": s.t, "kind": s.kind, "state": s.state,
                                    "intensity": s.intensity, "join": s.join,
                                    "complete": bool(end >= s.start + s.duration - 1e-6)}}}
        out.append((s, sub))
    return out
