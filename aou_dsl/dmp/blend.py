"""A goal changed in the middle of a motion: blend to it within the declared peak.

Switching a DMP's goal while it runs (``step()`` with a new ``goal_y``) steps the
acceleration: the spring pulls toward the new goal at once. Here the motion that is
running when the goal changes (or, in a pause or a shiver, the next motion, so that
holds stay holds) carries the change: from the change on, its pose moves from the
rollout toward the old goal to the rollout toward the new one along a quintic blend
``b(t)`` that ends with the motion, and every later part follows the new goal.
The blend adds ``2 b' (v_new - v_old) + b'' (p_new - p_old)`` to the acceleration, so
when the blended peak would be more than 10 % over the larger of the two rollouts'
peaks for that motion (its declared peak, at its own tempo), the motion is slowed (in
both rollouts, so their clocks stay one) by steps of 15 % until it is not. The result is
solved, checked and measured like a rollout; it is refused (D606) when no slowing up to
4x keeps within the 10 %, or when it fails a safety check.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from ..core.codes import D606, I504
from ..core.diagnostics import AouError, Span, diag
from .export import DmpSequence
from .parts import moves
from .rollout import Rollout, roll
from .solve import Solved

__all__ = ["BLEND_MARGIN", "change_goal"]

#: How far over the motion's own peak a blend may accelerate the hand.
BLEND_MARGIN = 0.10


def _carrier(ro: Rollout, at: float) -> int:
    """The motion running at ``at``, else the next one; -1 when none is left."""
    motions = moves()
    for k, (kind, _t0, t1) in enumerate(ro.parts):
        if kind in motions and t1 > at:
            return k
    return -1


def _peak(t: np.ndarray, pos: np.ndarray, sel: np.ndarray) -> float:
    acc = np.gradient(np.gradient(pos, t, axis=0), t, axis=0)
    return float(np.linalg.norm(acc[sel], axis=1).max()) if sel.any() else 0.0


def _blended(old: Rollout, new: Rollout, start: float, end: float) -> Rollout:
    x = np.clip((new.t - start) / max(end - start, 1e-9), 0.0, 1.0)
    b = (10 * x ** 3 - 15 * x ** 4 + 6 * x ** 5)[:, None]
    pos = (1 - b) * old.pos + b * new.pos
    q_old = old.quat * np.sign(np.sum(old.quat * new.quat, axis=1, keepdims=True) + 1e-300)
    quat = (1 - b) * q_old + b * new.quat
    quat /= np.linalg.norm(quat, axis=1, keepdims=True)
    return replace(new, pos=pos, quat=quat)


def change_goal(seq: DmpSequence, at: float, goal: tuple[float, float, float], *,
                path: str = "<dmp>", check: bool = True, **options: Any) -> Solved:
    """The sequence rolled toward its own goal (``options['goal']`` or the sequence's),
    changed at ``at`` [s, on the rollout's clock] to ``goal`` (see the module's docstring).

    Raises:
        AouError: I504 when no motion is left after ``at``.
    """
    where = Span.whole_file(path)
    first = options.pop("goal", None)
    stretch: dict[int, float] = {}
    probe = roll(seq, goal=first, **options)
    k = _carrier(probe, at)
    if k < 0:
        raise AouError(diag(I504, f"no motion is left after t={at:.3f}s to carry the "
                            "goal change", where))
    factor, out, declared = 1.0, None, 0.0
    cache: dict = {}
    while factor <= 4.0:
        old = roll(seq, goal=first, stretch=stretch, cache=cache, **options)
        new = roll(seq, goal=goal, stretch=stretch, cache=cache, **options)
        _, t0, t1 = new.parts[k]
        start, end = max(at, t0), t1
        sel = (new.t >= start - 0.05) & (new.t <= end + 0.05)
        if not declared:  # the motion's peak toward either goal, at its own tempo
            declared = max(_peak(old.t, old.pos, sel), _peak(new.t, new.pos, sel))
        out = _blended(old, new, start, end)
        if _peak(out.t, out.pos, sel) <= (1 + BLEND_MARGIN) * declared:
            return _solve(seq, out, where, check)
        factor *= 1.15
        stretch = {k: factor}
    assert out is not None
    solved = Solved(out)
    solved.diagnostics.append(diag(
        D606, f"the goal change at t={at:.3f}s cannot be blended into the "
        f"{out.parts[k][0]} within {BLEND_MARGIN:.0%} of its peak acceleration, even "
        "slowed 4x", where, time=at))
    return solved


def _solve(seq: DmpSequence, ro: Rollout, where: Span, check: bool) -> Solved:
    from ..measuring.measured import measure
    from .solve import to_trajectory

    out = Solved(ro)
    try:
        out.trajectory = tr = to_trajectory(seq, ro, where)
    except AouError as err:
        out.diagnostics += err.diagnostics
        return out
    if check:
        from ..safety.replay import replay

        report = replay(tr)
        out.checks = report.checks
        for c in report.failed():
            out.diagnostics.append(diag(
                D606, f"the blended motion fails the {c.name} check at "
                f"t={(c.time or 0.0):.3f}s: {c.joint or ''} {c.value} (limit {c.limit})",
                where, check=c.name, time=c.time, joint=c.joint, value=c.value,
                limit=c.limit))
        if out.diagnostics:
            return out
    out.measured = measure(tr)
    return out
