"""Intensity moved through a running behaviour's DMPs, without a re-plan.

The descriptors an intensity changes continuously are DMP parameters (docs/dmp.md):
the holds' durations, the motions' time scales (their peak accelerations), the shiver's
amplitude. When the intensity changes at time ``at``, the part running then finishes as
it was rolled out, and every later part takes the new intensity
(:func:`aou_dsl.dmp.rollout.roll` with ``since``). Every part starts and ends at rest,
so the joint motion stays continuous in position, velocity and acceleration across the
change, and nothing is synthesized, compiled or laid out again: only the remaining DMPs
are rolled out and solved.
"""

from __future__ import annotations

from typing import Any

from .export import DmpSequence
from .rollout import Rollout, roll

__all__ = ["change_intensity"]


def change_intensity(seq: DmpSequence, at: float, intensity: float, **options: Any
                     ) -> Rollout:
    """The rollout of ``seq`` (``options`` as :func:`~aou_dsl.dmp.rollout.roll`) whose
    intensity becomes ``intensity`` after the part running at ``at`` [s] ends. Pass the
    ``cache`` the running rollout was made with: only the motions whose time scale the
    intensity changes are then rolled out again.

    Raises:
        AouError: I504 for an intensity or option out of range.
    """
    options.setdefault("cache", {})
    running = roll(seq, **options)
    after = next((k + 1 for k, (_, t0, t1) in enumerate(running.parts) if t0 <= at < t1),
                 len(seq.parts))
    return roll(seq, intensity=intensity, since=after, **options)
