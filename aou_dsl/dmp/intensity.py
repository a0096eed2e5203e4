"""Intensity moved through a running behaviour's DMPs, without a re-plan.

The descriptors an intensity changes continuously are DMP parameters (docs/dmp.md):
the holds' durations, the motions' execution times (their peak accelerations), the
shiver's amplitude. When the intensity changes at time ``at``, the part running then
finishes as it was rolled out, and every later part takes the new intensity
(:func:`aou_dsl.dmp.rollout.roll` with ``since``, and ``schedule`` for a behaviour whose
intensity already changed). Every part starts and ends at rest, so the joint motion
stays continuous in position, velocity and acceleration across the change, and nothing
is synthesized, compiled or laid out again.

What it costs: a motion at a new execution time is its rollout at the old one stretched
in time (``retime``: the DMP's temporal scaling, exact but for the integrator's error),
so no DMP is integrated again; and :func:`aou_dsl.dmp.solve.to_trajectory` given the
running rollout and its trajectory solves the inverse kinematics only from the first
sample whose pose the change moves.
"""

from __future__ import annotations

from typing import Any

from .export import DmpSequence
from .rollout import Rollout, roll

__all__ = ["change_intensity", "part_after"]


def part_after(ro: Rollout, at: float) -> int:
    """The index of the first part that starts after the part running at ``at`` [s, on
    the rollout's clock] (the number of parts when none is left)."""
    return next((k + 1 for k, (_, t0, t1) in enumerate(ro.parts) if t0 <= at < t1),
                len(ro.parts) if at >= ro.parts[-1][2] else 0)


def change_intensity(seq: DmpSequence, at: float, intensity: float, *,
                     running: Rollout | None = None, **options: Any) -> Rollout:
    """The rollout of ``seq`` (``options`` as :func:`~aou_dsl.dmp.rollout.roll`) whose
    intensity becomes ``intensity`` after the part running at ``at`` [s] ends.

    Args:
        running: the rollout the behaviour runs now (default: ``seq`` rolled out with
            ``options``); its earlier intensity changes are kept.
        options: pass the ``cache`` the running rollout was made with, and
            ``retime=True``, so that no motion is integrated again.

    Raises:
        AouError: I504 for an intensity or option out of range.
    """
    options.setdefault("cache", {})
    if running is None:
        running = roll(seq, **options)
    after = part_after(running, at)
    first, *later = running.schedule or ((0, seq.intensity),)
    return roll(seq, intensity=first[1], since=first[0],
                schedule=(*later, (after, intensity)), **options)
