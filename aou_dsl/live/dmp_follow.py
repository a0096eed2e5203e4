"""A reach followed as its DMPs, so the regulator can move its intensity without a re-plan.

With ``Regulator(..., through_dmp=True)`` a reach the regulator starts (its first tick, or
``restart=True``) follows the DMP rollout of its plan (:mod:`aou_dsl.dmp`): the plan is
written as DMPs once (:func:`aou_dsl.dmp.export.to_dmp`, kept per plan) and rolled out
at its own goal and tempo. When the estimate then asks for another intensity level of
the same state, :func:`change` gives the rest of the reach through the DMPs
(:func:`aou_dsl.dmp.intensity.change_intensity`): the part running at the arm's time
finishes as it was rolled out and every later part takes the new level's parameters
(holds, execution times, shiver amplitude). Only the samples after the first one the
change moves are solved again, and only those are checked; the trajectory returned
starts at the arm's sample, so position, velocity and acceleration carry on unchanged.
A change of state re-plans as before (:mod:`.splice`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..core.codes import C306, D604
from ..core.diagnostics import AouError, Span, diag

if TYPE_CHECKING:
    from ..core.trajectory import Trajectory
    from ..lang.ir import State
    from .splice import Regulator, State3

__all__ = ["DmpRun", "change", "start"]

_WHERE = Span.whole_file("<live>")


@dataclass
class DmpRun:
    """A reach that follows DMPs: its sequence, the rollout and joint trajectory it
    follows now, the rolled motions kept (``cache``), and when the rollout's clock
    began on the clock of the trajectory the regulator last returned (``begins`` [s]:
    after the transition into it; ``returned_at``: the rollout's time at that
    trajectory's first sample)."""

    sequence: Any
    rollout: Any
    trajectory: Trajectory
    cache: dict
    begins: float
    returned_at: float = 0.0


def _sequence(reg: Any, state: State, level: float, plan: Trajectory) -> Any:
    """The plan's DMP sequence, made once per plan."""
    from ..dmp.export import to_dmp

    key = id(plan)
    kept = reg._sequences.get(key)
    if kept is None or kept[0] is not plan:
        kept = (plan, to_dmp(plan, intensity=level, state=state.value))
        reg._sequences[key] = kept
    return kept[1]


def _checked(reg: Regulator, tr: Trajectory) -> bool:
    from ..safety.controllers import controller_checks
    from ..safety.replay import replay

    report = replay(tr, dynamic=False)
    report.checks += controller_checks(tr, None)
    return report.ok


def start(reg: Any, state: State, level: float, x: State3, timings: dict[str, float]
          ) -> tuple[Trajectory, DmpRun, float]:
    """The arm's state, a jerk-limited transition to the start of the plan's DMP rollout,
    then the rollout; the run to keep and the transition's duration [s].

    Raises:
        AouError: D603/D604 when the rollout cannot be solved or fails a check; C306
            when no transition passes the checks.
    """
    from ..dmp.rollout import roll
    from ..dmp.solve import to_trajectory
    from .splice import join_plan

    clock = time.perf_counter()
    plan = reg.plan(state, level)
    seq = _sequence(reg, state, level, plan)
    cache: dict = {}
    ro = roll(seq, cache=cache, retime=True)
    tr = to_trajectory(seq, ro, _WHERE)
    timings["dmp"] = time.perf_counter() - clock
    if not _checked(reg, tr):
        raise AouError(diag(D604, f"the DMP rollout of {state} at intensity {level:g} "
                            f"fails the checks on {reg.robot}", _WHERE))
    out, _, trans = join_plan(reg, tr, x, None, timings)
    return out, DmpRun(seq, ro, tr, cache, trans), trans


def _now(run: DmpRun, last: Trajectory, x: State3, elapsed: float | None) -> float:
    """The arm's time on the running rollout's clock: from ``elapsed`` (since the last
    trajectory returned began), else the sample of ``last`` nearest the arm's state."""
    from .splice import VELOCITY_WEIGHT

    if elapsed is None:
        assert last.qd is not None
        cost = (np.linalg.norm(last.q - x[0], axis=1)
                + VELOCITY_WEIGHT * np.linalg.norm(last.qd - x[1], axis=1))
        elapsed = float(last.t[int(np.argmin(cost))])
    return run.returned_at + max(0.0, float(elapsed) - run.begins)


def change(reg: Regulator, run: DmpRun, last: Trajectory, level: float, x: State3,
           elapsed: float | None, timings: dict[str, float]) -> tuple[Trajectory, DmpRun, float]:
    """The rest of the reach with its intensity moved to ``level`` through the DMPs: the
    trajectory from the arm's sample on (t = 0 there), the run to keep, and the arm's
    time on the rollout's clock [s].

    Raises:
        AouError: D603 when the changed rollout cannot be solved; C306 when it fails a
            check (the caller may re-plan instead).
    """
    from ..dmp.intensity import change_intensity
    from ..dmp.solve import to_trajectory

    clock = time.perf_counter()
    at = _now(run, last, x, elapsed)
    ro = change_intensity(run.sequence, at, level, running=run.rollout, cache=run.cache,
                          retime=True)
    timings["roll"] = time.perf_counter() - clock
    clock = time.perf_counter()
    tr = to_trajectory(run.sequence, ro, _WHERE, reuse=(run.rollout, run.trajectory))
    timings["solve"] = time.perf_counter() - clock
    clock = time.perf_counter()
    i = min(int(np.searchsorted(tr.t, at - 1e-9)), len(tr.t) - 1)
    t0 = float(tr.t[i])
    episodes = tuple((kind, max(a, t0) - t0, b - t0) for kind, a, b in tr.episodes if b > t0)
    out = tr.with_(t=tr.t[i:] - t0, q=tr.q[i:], qd=tr.qd[i:], qdd=tr.qdd[i:],
                   episodes=episodes)
    changed = int(np.argmax(np.any(tr.q[i:] != _resampled(run, tr, i), axis=1)))
    if not _checked(reg, out.with_(t=out.t[changed:], q=out.q[changed:],
                                   qd=out.qd[changed:], qdd=out.qdd[changed:],
                                   episodes=())):
        raise AouError(diag(C306, f"the intensity change to {level:g} through the DMPs "
                            f"fails the checks on {reg.robot}", _WHERE))
    timings["check"] = time.perf_counter() - clock
    return out, DmpRun(run.sequence, ro, tr, run.cache, 0.0, t0), at


def _resampled(run: DmpRun, tr: Trajectory, i: int) -> np.ndarray:
    """The running trajectory's joint positions on ``tr``'s samples from ``i`` on (rows
    past its end repeat its last): where they equal ``tr``'s, nothing changed."""
    old = run.trajectory.q
    n = len(tr.t) - i
    rows = np.minimum(np.arange(i, i + n), len(old) - 1)
    return old[rows]
